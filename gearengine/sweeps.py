"""Parameter sweeps of Eq. (9): bifurcation diagrams (one axis) and 2-D chaos maps (two axes).

A sweep is a grid of parameter points, each a copy of ``params`` with the axes' aliases set
(``F_e1``, ``mu``, ``Omega_e``, ...). Points are enumerated with the first axis fastest and split
into chunks, the unit of work of the job queue. Chunk i depends only on (request, i, chunk size),
so a chunk computed twice gives the same bytes and an interrupted sweep resumes exactly.

With ``continuation`` a chunk is a whole line along the first axis, integrated point by point,
each point starting from the previous point's final state; ``direction`` runs each line forward
(start -> stop, branch "up"), backward (stop -> start, branch "down") or both, each branch from
the settings' initial state at its own end. Without continuation every point starts from the
settings' initial states and points of a chunk run together in ``simulate_batch``.
"""

from __future__ import annotations

import csv
import io
import itertools
import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Annotated, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError
from pydantic_core import InitErrorDetails, PydanticCustomError

from gearengine.melnikov import cubic_coefficients
from gearengine.params import Alias, GearParams, request_config, with_aliases
from gearengine.requests import PAPER_SECTION_41
from gearengine.simulation import BatchPoint, SimulationSettings, simulate_batch, work
from gearengine.thresholds import sign_change_strength

MAX_AXIS_POINTS = 100_000
"""Upper cap of ``num`` of one axis (the service caps the product lower, max_sweep_points)."""
DEFAULT_CHUNK_POINTS = 64
"""Points per chunk without continuation (the service's sweep_chunk_points default)."""

Branch = Literal["up", "down"]
Direction = Literal["forward", "backward", "both"]
Finite = Annotated[float, Field(allow_inf_nan=False)]


class SweepAxis(BaseModel):
    """One axis: ``num`` equally spaced values of a parameter alias from ``start`` to ``stop``."""

    model_config = request_config()

    parameter: Alias = Field(
        description="Parameter alias: mu, F_m, k_p1, F_e1, F_p1, Omega_k, Omega_e or Omega_p "
        "(first-harmonic amplitudes and excitation frequencies, dimensionless).",
        examples=["F_e1"],
    )
    start: Finite = Field(description="First value (dimensionless).", examples=[0.0])
    stop: Finite = Field(description="Last value (dimensionless).", examples=[0.3])
    num: int = Field(
        ge=1,
        le=MAX_AXIS_POINTS,
        description=f"Number of values, start and stop included (1..{MAX_AXIS_POINTS}).",
        examples=[301],
    )

    def values(self) -> list[float]:
        """The ``num`` values, start to stop (``numpy.linspace``)."""
        return [float(v) for v in np.linspace(self.start, self.stop, self.num)]


class SweepRequest(BaseModel):
    """A bifurcation diagram (one axis) or a chaos map (two axes) of the design ``params``."""

    model_config = request_config(
        {
            "params": PAPER_SECTION_41,
            "settings": {"transient_periods": 500, "record_periods": 500},
            "axes": [{"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 301}],
            "continuation": False,
            "direction": "forward",
        }
    )

    params: GearParams = Field(description="The design; the axes' parameters are overwritten.")
    settings: SimulationSettings = Field(
        default_factory=SimulationSettings,
        description="Integration settings of every point (periods, steps, initial states).",
    )
    axes: list[SweepAxis] = Field(
        min_length=1,
        max_length=2,
        description="One axis: bifurcation diagram; two axes: chaos map (first axis fastest).",
    )
    continuation: bool = Field(
        False,
        description="Carry the final state [x, v] from point to point along the first axis.",
    )
    direction: Direction = Field(
        "forward",
        description="With continuation: forward (start -> stop), backward, or both (exposes "
        "hysteresis; points carry branch up or down).",
    )

    def branches(self) -> list[Branch]:
        """Branches run along the first axis: up (forward), down (backward) or both."""
        return {"forward": ["up"], "backward": ["down"], "both": ["up", "down"]}[self.direction]

    def n_points(self) -> int:
        """Number of computed points, every branch counted."""
        return math.prod(a.num for a in self.axes) * len(self.branches())


class SweepPoint(BaseModel):
    """Numerical and Melnikov verdicts of one point of the sweep."""

    model_config = ConfigDict(frozen=True, allow_inf_nan=False)

    values: dict[str, float] = Field(
        description="The axes' parameter values at this point.", examples=[{"F_e1": 0.2}]
    )
    branch: Branch | None = Field(
        description="With continuation: up (forward) or down (backward) branch; else null."
    )
    classification: str = Field(description="periodic | chaotic | quasi_periodic | diverged.")
    period: int | None = Field(description="Period in units of T0, null if none found.")
    lle: float | None = Field(description="Largest Lyapunov exponent per unit tau.")
    lle_stderr: float | None = Field(description="Standard error of lle.")
    impact_regime: str | None = Field(
        description="no_impact | single_sided | double_sided, null when not reported."
    )
    melnikov_chaos_possible: bool | None = Field(
        description="Melnikov verdict at this point; null when not applicable (a or c <= 0)."
    )
    poincare_x: list[float] = Field(description="x of the last stroboscopic points (units of b).")


class SweepResult(BaseModel):
    """All points of a sweep, in chunk order (first axis fastest; branch up before down)."""

    model_config = ConfigDict(frozen=True)

    axes: list[SweepAxis] = Field(description="The axes of the request.")
    points: list[SweepPoint] = Field(description="One entry per point and branch.")


FREQUENCY_ALIASES = frozenset({"Omega_k", "Omega_e", "Omega_p"})


def sweep_work(request: SweepRequest) -> int:
    """RK4 steps of the whole sweep, for the compute budget.

    The steps per T0 depend on how the excitation frequencies line up, so every combination of
    swept frequencies is costed; the other axes (amplitudes, damping, mean force) only switch an
    excitation on or off, so their corners bound them.
    """
    freq = [a for a in request.axes if a.parameter in FREQUENCY_ALIASES]
    rest = [a for a in request.axes if a.parameter not in FREQUENCY_ALIASES]
    per_combination = request.n_points() // math.prod(a.num for a in freq)
    corners = list(itertools.product(*((a.start, a.stop) for a in rest)))
    total = 0
    for values in itertools.product(*(a.values() for a in freq)):
        point = dict(zip((a.parameter for a in freq), values, strict=True))
        total += per_combination * max(
            work(
                with_aliases(
                    request.params,
                    {**point, **dict(zip((a.parameter for a in rest), c, strict=True))},
                ),
                request.settings,
            )
            for c in corners
        )
    return total


def request_errors(request: SweepRequest, max_points: int | None = None) -> list[InitErrorDetails]:
    """Checks across fields that pydantic cannot express, as pydantic error details.

    Distinct axis parameters, stop != start when num > 1, direction only with continuation,
    the point count under ``max_points``, and every corner of the grid a valid design (the
    admissible set of each alias is an interval, so the corners decide).
    """
    errors: list[InitErrorDetails] = []

    def add(loc: tuple[str | int, ...], message: str, value: object) -> None:
        errors.append({"type": PydanticCustomError("sweep", message), "loc": loc, "input": value})

    for i, axis in enumerate(request.axes):
        if axis.num > 1 and axis.stop == axis.start:
            add(("axes", i, "stop"), "stop must differ from start when num > 1", axis.stop)
        if i and axis.parameter in [a.parameter for a in request.axes[:i]]:
            add(("axes", i, "parameter"), f"{axis.parameter} is already swept", axis.parameter)
    if request.direction != "forward" and not request.continuation:
        add(("direction",), "backward and both need continuation: true", request.direction)
    if max_points is not None and request.n_points() > max_points:
        add(
            ("axes",),
            f"{request.n_points()} points, over the limit of {max_points} per sweep "
            "(max_sweep_points)",
            [a.num for a in request.axes],
        )
    if errors:
        return errors
    base = {a.parameter: a.start for a in request.axes}
    for i, axis in enumerate(request.axes):
        for end in ("start", "stop"):
            value = getattr(axis, end)
            try:
                with_aliases(request.params, {**base, axis.parameter: value})
            except ValidationError as exc:
                e = exc.errors(include_url=False)[0]
                where = ".".join(map(str, e["loc"]))
                add(("axes", i, end), f"gives an invalid design: {where}: {e['msg']}", value)
            except ValueError as exc:
                add(("axes", i, "parameter"), str(exc), axis.parameter)
                break
    return errors


def validated(data: object, max_points: int | None = None) -> SweepRequest:
    """Parse and check a sweep request document; raises ``ValidationError`` naming each field."""
    request = SweepRequest.model_validate(data)
    errors = request_errors(request, max_points)
    if errors:
        raise ValidationError.from_exception_data("SweepRequest", errors)
    return request


# --- enumeration and chunking ---------------------------------------------------------------


@dataclass(frozen=True)
class Chunk:
    """A unit of work: grid points in the order computed, and how."""

    index: int
    points: list[tuple[int, ...]]
    """Grid indices (i0, i1?) per point, in computation order."""
    branch: Branch | None
    """With continuation: the branch of this line; None without continuation."""


@dataclass(frozen=True)
class SweepPlan:
    """Deterministic split of a request's points into chunks.

    Without continuation: ``chunk_points`` consecutive grid points per chunk (first axis
    fastest). With continuation: one line along the first axis per chunk, for each value of the
    second axis and each branch (up lines first).
    """

    request: SweepRequest
    chunk_points: int = DEFAULT_CHUNK_POINTS

    def _grid(self) -> list[tuple[int, ...]]:
        shape = [a.num for a in self.request.axes]
        return [tuple(reversed(ix)) for ix in np.ndindex(*reversed(shape))]

    def n_chunks(self) -> int:
        """Number of chunks."""
        req = self.request
        if req.continuation:
            lines = req.axes[1].num if len(req.axes) == 2 else 1
            return lines * len(req.branches())
        return math.ceil(req.n_points() / self.chunk_points)

    def chunk(self, index: int) -> Chunk:
        """Chunk ``index`` (0 <= index < n_chunks())."""
        req = self.request
        if not 0 <= index < self.n_chunks():
            raise IndexError(f"chunk {index} out of range 0..{self.n_chunks() - 1}")
        if req.continuation:
            lines = req.axes[1].num if len(req.axes) == 2 else 1
            branch = req.branches()[index // lines]
            rest = () if len(req.axes) == 1 else (index % lines,)
            line = [(i0, *rest) for i0 in range(req.axes[0].num)]
            return Chunk(index, line if branch == "up" else line[::-1], branch)
        lo = index * self.chunk_points
        return Chunk(index, self._grid()[lo : lo + self.chunk_points], None)

    def point_counts(self) -> list[int]:
        """Number of points of each chunk."""
        return [len(self.chunk(i).points) for i in range(self.n_chunks())]


# --- computation ----------------------------------------------------------------------------


def melnikov_chaos_possible(params: GearParams) -> bool | None:
    """The Melnikov verdict (``melnikov(params).chaos_possible``) without the thresholds.

    Some branch changes sign iff ``sign_change_strength > 0``; None when the cubic law has no
    saddle loop (a <= 0 or c <= 0). About 20 us per point.
    """
    a, c, _ = cubic_coefficients(params)
    if not (a > 0.0 and c > 0.0):
        return None
    return sign_change_strength(params, a, c) > 0.0


def _point(values: dict[str, float], branch: Branch | None, params: GearParams, bp: BatchPoint):
    return SweepPoint(
        values=values,
        branch=branch,
        classification=bp.classification,
        period=bp.period,
        lle=bp.lle,
        lle_stderr=bp.lle_stderr,
        impact_regime=bp.impact_regime,
        melnikov_chaos_possible=melnikov_chaos_possible(params),
        poincare_x=[s[0] for s in bp.poincare],
    )


def compute_chunk(
    request: SweepRequest, chunk_index: int, chunk_points: int = DEFAULT_CHUNK_POINTS
) -> list[SweepPoint]:
    """Verdicts of the points of one chunk, in the chunk's order (deterministic)."""
    chunk = SweepPlan(request, chunk_points).chunk(chunk_index)
    axes = request.axes
    grids = [a.values() for a in axes]
    values = [{a.parameter: grids[k][ix[k]] for k, a in enumerate(axes)} for ix in chunk.points]
    designs = [with_aliases(request.params, v) for v in values]
    if not request.continuation:
        verdicts = simulate_batch(designs, request.settings)
    else:
        verdicts = []
        settings = request.settings
        for design in designs:
            (bp,) = simulate_batch([design], settings)
            verdicts.append(bp)
            settings = _carried(request.settings, bp)
    return [
        _point(v, chunk.branch, d, bp) for v, d, bp in zip(values, designs, verdicts, strict=True)
    ]


def _carried(settings: SimulationSettings, bp: BatchPoint) -> SimulationSettings:
    """Settings starting from the final state of ``bp`` (the original starts if it diverged)."""
    if bp.final_state is None:
        return settings
    return settings.model_copy(
        update={
            "initial_state": list(bp.final_state),
            "initial_states": None,
            "random_initial_states": None,
        }
    )


def compute_chunk_json(request_json: str, chunk_index: int, chunk_points: int) -> str:
    """``compute_chunk`` on JSON text, returning a JSON array (what workers exchange)."""
    request = SweepRequest.model_validate_json(request_json)
    points = compute_chunk(request, chunk_index, chunk_points)
    return "[" + ",".join(p.model_dump_json() for p in points) + "]"


def result_json(axes: list[SweepAxis], chunk_arrays: Iterable[str]) -> Iterator[str]:
    """The JSON text of a ``SweepResult`` from the chunks' JSON arrays (in chunk order)."""
    yield '{"axes":[' + ",".join(a.model_dump_json() for a in axes) + '],"points":['
    first = True
    for array in chunk_arrays:
        inner = array.strip()[1:-1]
        if inner:
            yield ("" if first else ",") + inner
            first = False
    yield "]}"


def run_local(
    request: SweepRequest,
    progress_callback: Callable[[int, int], None] | None = None,
    chunk_points: int = DEFAULT_CHUNK_POINTS,
) -> SweepResult:
    """Compute every chunk in this process; ``progress_callback(done, total)`` in points."""
    plan = SweepPlan(request, chunk_points)
    total, done = request.n_points(), 0
    arrays = []
    for i in range(plan.n_chunks()):
        arrays.append(compute_chunk_json(request.model_dump_json(), i, chunk_points))
        done += len(plan.chunk(i).points)
        if progress_callback is not None:
            progress_callback(done, total)
    return SweepResult.model_validate_json("".join(result_json(request.axes, arrays)))


# --- CSV and agreement ----------------------------------------------------------------------

CSV_FIELDS = (
    "branch",
    "classification",
    "period",
    "lle",
    "lle_stderr",
    "impact_regime",
    "melnikov_chaos_possible",
    "poincare_x",
)


def to_csv(result: SweepResult) -> Iterator[str]:
    """CSV rows of a result (see ``csv_rows``)."""
    return csv_rows(result.axes, result.points)


def csv_rows(axes: list[SweepAxis], points: Iterable[SweepPoint]) -> Iterator[str]:
    """CSV rows (header first): one column per axis, the verdicts, and poincare_x as
    space-separated numbers. Empty cells are nulls; booleans are true/false."""
    names = [a.parameter for a in axes]
    yield _csv_row([*names, *CSV_FIELDS])
    for p in points:
        cells = [p.values[n] for n in names]
        cells += [getattr(p, f) for f in CSV_FIELDS[:-1]]
        cells.append(" ".join(repr(x) for x in p.poincare_x))
        yield _csv_row(cells)


def _csv_row(cells: list[object]) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(
        ["" if c is None else str(c).lower() if isinstance(c, bool) else c for c in cells]
    )
    return buf.getvalue()


class Agreement(BaseModel):
    """How the numerical classification agrees with the Melnikov region (counts of points)."""

    chaotic_inside: int = Field(description="Numerically chaotic, Melnikov: chaos possible.")
    chaotic_outside: int = Field(description="Numerically chaotic, Melnikov: no chaos.")
    regular_inside: int = Field(description="Not chaotic, Melnikov: chaos possible.")
    regular_outside: int = Field(description="Not chaotic, Melnikov: no chaos.")
    not_applicable: int = Field(description="Points without a Melnikov verdict.")


def agreement(points: Iterable[SweepPoint]) -> Agreement:
    """Count points by numerical chaos (classification chaotic) and Melnikov region."""
    counts = dict.fromkeys(Agreement.model_fields, 0)
    for p in points:
        if p.melnikov_chaos_possible is None:
            counts["not_applicable"] += 1
            continue
        kind = "chaotic" if p.classification == "chaotic" else "regular"
        counts[f"{kind}_{'inside' if p.melnikov_chaos_possible else 'outside'}"] += 1
    return Agreement(**counts)
