"""The resolution of a gate's check, and its refinement between grid points.

A grid of 23 speeds x 5 torques proves nothing between its points: chaos in a narrow window
(a speed band, or a torque level between two of the five) passes unseen. The gate therefore
states what it checked (``Resolution``: grid spacing in rpm and N*m, points, starts) and refines
where the grid cannot be trusted: between two neighbouring points (along speed or torque) whose
verdicts or attractor sets differ, or next to a point near a limit, it inserts the midpoint, and
repeats on the halves so created, ``depth`` times, down to a finest spacing of the grid's
/ 2**depth. Every inserted point is computed exactly as a grid point is
(``studies.sweep.compute.points_at``) and checked by the same rules.

"Near a limit" is ``gate.envelope.near_limit``.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

from pydantic import BaseModel, ConfigDict, Field

from gearengine.model.units import in_display_unit
from gearengine.numerics.batch import threads_may_share_kernels
from gearengine.studies.sweep.compute import points_at
from gearengine.studies.sweep.points import SweepPoint
from gearengine.studies.sweep.request import SweepRequest

REFINE_DEPTH = 2
"""Default halvings of the grid spacing where neighbours differ, a point is near a limit or the
attractor set changes: the finest spacing checked is the grid's / 4 there. One halving missed
chaos between a refined point near the limit and its grid neighbours (the z = 23/67 pair at
5 N*m, 3,557 rpm, 19 % of starts; a chaotic 8.44 N*m level at 4,636 rpm, 38 %): depth 2 finds
them at 1.6x the CPU of depth 1 on its 1,000-6,000 rpm x 5-60 N*m envelope (benchmarks)."""
MAX_REFINE_DEPTH = 4


class Resolution(BaseModel):
    """What a gate's check ran: the grid, the starts, and the refinement between grid points."""

    model_config = ConfigDict(frozen=True)

    speed_points: int = Field(description="Grid speeds.")
    torque_points: int = Field(1, description="Grid torque levels (1: one torque).")
    speed_step_rpm: float | None = Field(description="Grid speed spacing [rpm].")
    torque_step_nm: float | None = Field(None, description="Grid torque spacing [N*m].")
    starts: int = Field(description="Initial states run per operating point (basin starts).")
    depth: int = Field(description="Halvings of the spacing allowed where refined (0: none).")
    finest_speed_step_rpm: float | None = Field(description="Finest speed spacing [rpm].")
    finest_torque_step_nm: float | None = Field(None, description="Finest torque spacing [N*m].")
    refined_points: int = Field(0, description="Points inserted between grid points.")

    def text(self) -> str:
        """ "23 x 5 grid (227 rpm x 13.8 N*m), 16 starts a point; refined ... 7 points added"."""
        grid = f"{self.speed_points} x {self.torque_points} grid" if self.torque_points > 1 \
            else f"{self.speed_points} speeds" if self.speed_points > 1 else "1 speed"  # fmt: skip
        steps = [f"{s:.4g} {u}" for s, u in ((self.speed_step_rpm, "rpm"),
                 (self.torque_step_nm, "N*m")) if s is not None]  # fmt: skip
        out = f"{grid} ({' x '.join(steps) or 'one point'}), {self.starts} starts a point"
        fine = [f"{s:.4g} {u}" for s, u in ((self.finest_speed_step_rpm, "rpm"),
                (self.finest_torque_step_nm, "N*m")) if s is not None]  # fmt: skip
        if not fine:  # one operating point: no neighbours, nothing between them
            return out + "; no neighbours to refine between"
        if self.depth == 0:
            return out + "; not refined between grid points"
        return (f"{out}; refined to {' x '.join(fine)} where neighbours differ (verdict or "
                "attractors) or a point is near a limit: "
                f"{self.refined_points} points added")  # fmt: skip


def resolution(request: SweepRequest, depth: int, refined: int = 0) -> Resolution:
    """The ``Resolution`` of an envelope sweep (speed axis first, then torque if any)."""
    grids = request.grids()
    steps: list[float | None] = []
    for axis, grid in zip(request.axes, grids, strict=True):
        lo, hi = in_display_unit(axis.parameter, grid[0]), in_display_unit(axis.parameter, grid[-1])
        steps.append(abs(hi - lo) / (len(grid) - 1) if len(grid) > 1 else None)
    steps += [None] * (2 - len(steps))
    basins = request.settings.basins
    return Resolution(
        speed_points=len(grids[0]), torque_points=len(grids[1]) if len(grids) > 1 else 1,
        speed_step_rpm=steps[0], torque_step_nm=steps[1],
        starts=1 if basins is None else basins.starts, depth=depth,
        finest_speed_step_rpm=None if steps[0] is None else steps[0] / 2**depth,
        finest_torque_step_nm=None if steps[1] is None else steps[1] / 2**depth,
        refined_points=refined,
    )  # fmt: skip


Lattice = tuple[int, int]


def refine(
    request: SweepRequest, points: list[SweepPoint], fails: Callable[[SweepPoint], bool],
    near: Callable[[SweepPoint], bool], depth: int, workers: int = 1,
    kind: Callable[[SweepPoint], object] = lambda p: None,
) -> list[SweepPoint]:  # fmt: skip
    """The points inserted between the grid ``points`` of ``request`` (its speed axis first,
    then a torque axis if any): midpoints of neighbour pairs (along speed and along torque)
    that differ in ``fails`` or in ``kind`` (the attractor set) or where either is ``near``,
    then of the halves so made, ``depth`` times. Computed ``workers`` at a time."""
    grids = request.grids()
    names = [a.parameter for a in request.axes]
    if depth <= 0 or not points:
        return []
    f = 2**depth
    sizes = [(len(g) - 1) * f for g in grids] + [0] * (2 - len(grids))

    def values(ij: Lattice) -> dict[str, float]:
        out = {}
        for k, name in enumerate(names):
            g = grids[k]
            out[name] = g[0] if len(g) == 1 else g[0] + ij[k] * (g[-1] - g[0]) / sizes[k]
        return out

    known: dict[Lattice, SweepPoint] = {}
    index = {round(v, 9): i for i, v in enumerate(grids[0])}
    index2 = {round(v, 9): i for i, v in enumerate(grids[1])} if len(grids) > 1 else {}
    for p in points:
        i = index[round(p.values[names[0]], 9)] * f
        j = index2[round(p.values[names[1]], 9)] * f if len(names) > 1 else 0
        known[(i, j)] = p
    pairs = [((i, j), (i + f, j)) for (i, j) in known if (i + f, j) in known]
    pairs += [((i, j), (i, j + f)) for (i, j) in known if (i, j + f) in known]
    added: list[SweepPoint] = []
    flags: dict[Lattice, tuple[bool, bool, object]] = {}

    def flag(ij: Lattice) -> tuple[bool, bool, object]:
        if ij not in flags:
            flags[ij] = (fails(known[ij]), near(known[ij]), kind(known[ij]))
        return flags[ij]

    h = f
    while h > 1 and pairs:
        chosen = [(a, b) for a, b in pairs if flag(a)[0] != flag(b)[0] or flag(a)[1]
                  or flag(b)[1] or flag(a)[2] != flag(b)[2]]  # fmt: skip
        mids = {(a, b): ((a[0] + b[0]) // 2, (a[1] + b[1]) // 2) for a, b in chosen}
        todo = list(dict.fromkeys(m for m in mids.values() if m not in known))
        for ij, p in zip(todo, _compute(request, [values(ij) for ij in todo], workers),
                         strict=True):  # fmt: skip
            known[ij] = p
            added.append(p)
        pairs = [half for a, b in chosen for m in [mids[(a, b)]] for half in ((a, m), (m, b))]
        h //= 2
    return added


def _compute(request: SweepRequest, values: list[dict[str, float]], workers: int
             ) -> list[SweepPoint]:  # fmt: skip
    """``points_at`` in ``workers`` slices on threads (the kernels release the GIL)."""
    if not values:
        return []
    if workers <= 1 or not threads_may_share_kernels() or len(values) == 1:
        return points_at(request, values)
    n = min(workers, len(values), os.cpu_count() or 1)
    slices = [values[k::n] for k in range(n)]
    with ThreadPoolExecutor(n) as pool:
        parts = list(pool.map(lambda part: points_at(request, part), slices))
    out: list[SweepPoint] = [None] * len(values)  # type: ignore[list-item]
    for k, part in enumerate(parts):
        out[k::n] = part
    return out
