"""The resolution of a gate's check, and its refinement between grid points.

A grid of 23 speeds x 5 torques proves nothing between its points: chaos in a narrow window
(a speed band, or a torque level between two of the five) passes unseen. The gate therefore
states what it checked (``Resolution``: grid spacing in rpm and N*m, points, starts) and refines
where the grid cannot be trusted: a grid cell (two neighbouring speeds, or four corners of a
speed x torque cell) whose corners' verdicts or attractor sets differ, or one of whose corners
is near a limit, is split in halves along each axis (edge midpoints and centre), and the halves
so created again, ``depth`` times, down to a finest spacing of the grid's / 2**depth. Splitting
cells, not edges, reaches a window inside a cell: the TE remedy's damping twin (0.1672) of the
z = 23/67 pair passed its 45 x 9 verification refined along edges and is chaotic from every
start at 5,489 rpm / 6.72 N*m, inside a cell. Every inserted point is computed exactly as a
grid point is (``studies.sweep.compute.points_at``) and checked by the same rules.

"Near a limit" is ``gate.rules.near_limit``.
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Callable, Hashable, Sequence
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
GRID_POINTS = {"speed": 23, "torque": 5}
"""The gate's grid (speeds, torque levels) unless ``--speed-points`` / ``--torque-points`` (the
remedies' envelope's ``speed_points`` / ``torque_points``) say otherwise."""
STOP_BATCH = 4
"""Points of the first batch of each level of a refinement that stops at its first failure
(``refine``'s ``stop``), each next batch twice the last: a failure early in a level leaves the
rest unrun, and a level that passes runs in few kernel calls (batches of 4 throughout cost 20 %
more CPU a point than whole levels on the z = 23/67 remedies' verification: 39 against 33 ms)."""


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
        starts = f"{self.starts} start{'s' if self.starts != 1 else ''} a point"
        out = f"{grid} ({' x '.join(steps) or 'one point'}), {starts}"
        fine = [f"{s:.4g} {u}" for s, u in ((self.finest_speed_step_rpm, "rpm"),
                (self.finest_torque_step_nm, "N*m")) if s is not None]  # fmt: skip
        if not fine:  # one operating point: no neighbours, nothing between them
            return out + "; no neighbours to refine between"
        if self.depth == 0:
            return out + "; not refined between grid points"
        if self.refined_points == 0:  # it read "refined to ...: 0 points added"
            return out + ("; no neighbours differ and no point is near a limit: nothing to "
                          f"refine (up to {self.depth} halvings)")  # fmt: skip
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
    kind: Callable[[SweepPoint], Hashable] = lambda p: None,
    stop: Callable[[SweepPoint], bool] | None = None,
    first: Sequence[dict[str, float]] = (),
    levels: bool = True,
) -> list[SweepPoint]:  # fmt: skip
    """The points inserted between the grid ``points`` of ``request`` (its speed axis first,
    then a torque axis if any), cell by cell: a grid cell (two neighbours on a one-axis grid,
    four corners on a speed x torque grid) whose corners differ in ``fails`` or in ``kind``
    (the attractor set), or one of which is ``near``, is split in halves along each axis (its
    edges' midpoints and, in two axes, its centre: a window inside the cell is reached, not
    only one on its edges), then the halves so made, ``depth`` times. Computed ``workers`` at
    a time. With ``stop`` (where only pass or fail is needed), the refinement first goes
    down toward each point of ``first`` (values expected to stop it), through the cells
    holding it while each is split, then level by level, in batches from ``STOP_BATCH`` points,
    and ends at the first computed point that ``stop`` accepts (the points computed are
    returned). Every point computed is one the refinement computes: one that never stops
    returns the same points in the same order, the same bits. ``levels`` False: the way down
    toward ``first`` alone (the points it computed)."""
    grids = request.grids()
    names = [a.parameter for a in request.axes]
    if depth <= 0 or not points:
        return []
    f = 2**depth
    sizes = [(len(g) - 1) * f for g in grids] + [0] * (2 - len(grids))
    axes = [k for k in (0, 1) if sizes[k] > 0]  # the axes with more than one grid value

    def values(ij: Lattice) -> dict[str, float]:
        out = {}
        for k, name in enumerate(names):
            g = grids[k]
            out[name] = g[0] if len(g) == 1 else g[0] + ij[k] * (g[-1] - g[0]) / sizes[k]
        return out

    def offsets(step: int) -> list[Lattice]:
        """The lattice offsets of a cell's corners with side ``step`` (its lower one first)."""
        return [(di if 0 in axes else 0, dj if 1 in axes else 0)
                for di, dj in itertools.product((0, step), repeat=2)
                if (0 in axes or di == 0) and (1 in axes or dj == 0)]  # fmt: skip

    known: dict[Lattice, SweepPoint] = {}
    index = {round(v, 9): i for i, v in enumerate(grids[0])}
    index2 = {round(v, 9): i for i, v in enumerate(grids[1])} if len(grids) > 1 else {}
    for p in points:
        i = index[round(p.values[names[0]], 9)] * f
        j = index2[round(p.values[names[1]], 9)] * f if len(names) > 1 else 0
        known[(i, j)] = p
    flags: dict[Lattice, tuple[bool, bool, Hashable]] = {}

    def flag(ij: Lattice) -> tuple[bool, bool, Hashable]:
        if ij not in flags:
            flags[ij] = (fails(known[ij]), near(known[ij]), kind(known[ij]))
        return flags[ij]

    def corners(cell: Lattice, step: int) -> list[Lattice]:
        return [(cell[0] + di, cell[1] + dj) for di, dj in offsets(step)]

    def chosen(cell: Lattice, step: int) -> bool:
        found = [flag(c) for c in corners(cell, step)]
        return (len({x[0] for x in found}) > 1 or any(x[1] for x in found)
                or len({x[2] for x in found}) > 1)  # fmt: skip

    def computed(ijs: list[Lattice]) -> bool:
        """Compute the points at ``ijs`` not known yet; did one of them meet ``stop``?"""
        missing = [ij for ij in ijs if ij not in known]
        got = _compute(request, [values(ij) for ij in missing], workers)
        known.update(zip(missing, got, strict=True))
        return stop is not None and any(stop(p) for p in got)

    def descend(target: Lattice) -> bool:
        """Down the cells that hold ``target``, from its grid cell, while each is split: the
        corners of each half so reached (points the refinement computes at that level); did
        one of them meet ``stop``?"""

        def inner(lower: Lattice, step: int) -> Lattice:  # the cell of side step holding it
            i, j = ((min((target[k] - lower[k]) // step, 1) * step if k in axes else 0)
                    for k in (0, 1))  # fmt: skip
            return lower[0] + i, lower[1] + j

        i, j = (min(target[k] // f * f, sizes[k] - f) if k in axes else 0 for k in (0, 1))
        cell, h = (i, j), f
        if not all(c in known for c in corners(cell, h)):
            return False
        while h > 1 and target not in known and chosen(cell, h):
            cell, h = inner(cell, h // 2), h // 2
            if computed(corners(cell, h)):
                return True
        return False

    grid = set(known)
    if stop is not None:
        for target in (_lattice(v, names, grids, sizes) for v in first):
            if target is not None and descend(target):
                return [p for ij, p in known.items() if ij not in grid]
    if not levels:
        return [p for ij, p in known.items() if ij not in grid]
    cells = [c for c in grid if axes and all(x in known for x in corners(c, f))]
    added: list[SweepPoint] = []
    placed = set(grid)
    h = f
    while h > 1 and cells:
        split = [c for c in cells if chosen(c, h)]
        halves = [(c[0] + di, c[1] + dj) for c in split for di, dj in offsets(h // 2)]
        todo = sorted({x for c in halves for x in corners(c, h // 2)} - placed,
                      key=lambda ij: (ij[1], ij[0]))  # fmt: skip
        k, batch = 0, max(len(todo), 1) if stop is None else STOP_BATCH
        while k < len(todo):
            if computed(todo[k : k + batch]):
                return [p for ij, p in known.items() if ij not in grid]
            k, batch = k + batch, 2 * batch
        added += [known[ij] for ij in todo]
        placed.update(todo)
        cells, h = halves, h // 2
    return added


def _lattice(values: dict[str, float], names: list[str], grids: list[list[float]],
             sizes: list[int]) -> Lattice | None:  # fmt: skip
    """The refinement lattice's point at ``values`` of the axes ``names`` (None: off it)."""
    ij = [0, 0]
    for k, (name, g) in enumerate(zip(names, grids, strict=True)):
        if len(g) > 1:
            ij[k] = round((values[name] - g[0]) / (g[-1] - g[0]) * sizes[k])
            if not math.isclose(g[0] + ij[k] * (g[-1] - g[0]) / sizes[k], values[name],
                                rel_tol=1e-9):  # fmt: skip
                return None
    return ij[0], ij[1]


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
