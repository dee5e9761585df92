"""Robustness studies: the probability of each response of the gears that will be built, at one
operating point or over an envelope (speed x torque), and which tolerance matters. A kind of
durable job (``gearengine.studies.jobs``): chunks of samples.

A request is a design with ``tolerances``, integration settings, ``samples`` (N), a ``seed``,
optional ``axes`` (physical fields of the design, as in sweeps) and ``sensitivity``. Its runs
are the rows of the sample matrix (N rows; with sensitivity the N (D + 2) rows of the Saltelli
design, ``studies.robustness.sensitivity``) at every operating point; chunk k holds rows
[k c, (k + 1) c) at every point, so a chunk's result depends only on (request, k, c), and a
resumed job equals an uninterrupted one. Every (point, row) is one design, analysed from every
start of the settings by ``numerics.batch.simulate_batch`` (lanes of ``run_lanes``; the sample
counts as its worst start, as the single analysis does), with the Melnikov verdict beside it.
With ``settings.basins`` every sample also runs the basin starts (``numerics.attractors``,
every sample's starts in one ``run_lanes`` call, as a sweep's chunk) and counts as its worst
attractor whose basin fraction is above ``basins.min_fraction`` (``numerics.headline.headline``,
as the gate and the sweep decide a point): class, contact, DTE and dynamic factor are that
attractor's. Without basins (the default) a sample is its settings' own start: N runs a point;
with B basin starts N (1 + B) (the budget, ``robustness_work``, counts them).

A chunk stores, per point and row: class code, contact code, Melnikov flag, DTE [µm] and
dynamic factor F_max / F_m (compact JSON, ``RUN_FIELDS``).
"""

from __future__ import annotations

import itertools
import json
import math
from typing import Any

import numpy as np
from pydantic import BaseModel, Field, PrivateAttr, field_validator, model_validator
from pydantic_core import InitErrorDetails

from gearengine.homoclinic.thresholds import chaos_possible
from gearengine.homoclinic.train_reduction import melnikov_point
from gearengine.model.design import Design
from gearengine.model.errors import InputError, Problems
from gearengine.model.fields import design_with
from gearengine.model.params import request_config
from gearengine.model.reduction import convert_design
from gearengine.model.units import Scales, display_unit, in_display_unit, response_values
from gearengine.numerics.attractors import points_attractors
from gearengine.numerics.batch import simulate_batch
from gearengine.numerics.headline import headline
from gearengine.numerics.magnitudes import most_adverse
from gearengine.numerics.runs import work
from gearengine.numerics.settings import ENVELOPE_SETTINGS, SimulationSettings, over_light
from gearengine.studies import jobs
from gearengine.studies.robustness import sensitivity
from gearengine.studies.robustness.results import (
    ASSUMPTIONS,
    SALTELLI_SAMPLES,
    RobustnessPoint,
    RobustnessResult,
    RobustnessVariable,
    basin_assumption,
)
from gearengine.studies.robustness.tolerances import (
    Variable,
    base_design,
    probability,
    sample_design,
    sample_values,
    sobol_points,
    variables,
)
from gearengine.studies.sweep.axes import (
    axis_problem,
    axis_unit,
    is_dimensionless,
)
from gearengine.studies.sweep.request import SweepAxis
from gearengine.systems.designs import design_model

CLASSES = ("periodic", "quasi_periodic", "chaotic", "diverged")
CONTACTS = ("no_impact", "single_sided", "double_sided")
RUN_FIELDS = ("class", "contact", "melnikov", "dte_um", "dynamic_factor")
"""The entries of one stored run, in order."""
EVENTS = (
    "separation",
    "back_flank",
    "dynamic_factor_above_limit",
    "melnikov_chaos_possible",
)
OUTPUTS = ("chaotic", "separation", "back_flank", "dte", "dynamic_factor")
"""The outputs whose Sobol indices are reported."""
DEFAULT_CHUNK_ROWS = 16
MAX_SAMPLES = 4096


class RobustnessRequest(BaseModel):
    """A robustness study of a design with tolerances."""

    model_config = request_config()

    label: str | None = Field(None, max_length=200, description="Free text shown with the job.")
    design: Design = Field(description="The nominal pair, with its tolerances.")
    settings: SimulationSettings = Field(
        default_factory=lambda: SimulationSettings.model_validate(ENVELOPE_SETTINGS),
        description="Integration settings of every run, merged over the light settings of the "
        "envelope check (60 + 60 periods, 128 steps a period), as in gearengine robustness.",
    )
    samples: int = Field(
        256, ge=2, le=MAX_SAMPLES, description="Samples N of the tolerances (a power of 2).",
        json_schema_extra={"enum": [1 << k for k in range(1, MAX_SAMPLES.bit_length())]},
    )  # fmt: skip
    seed: int = Field(0, ge=0, le=2**32 - 1, description="Seed of the scrambled Sobol samples.")
    sensitivity: bool = Field(
        False, description="Also Sobol indices (SALib): N (D + 2) runs per point, D the fields."
    )
    dynamic_factor_limit: float = Field(
        1.5, gt=1.0, le=100.0, allow_inf_nan=False,
        description="The event dynamic_factor_above_limit: F_max / F_m above this.",
    )  # fmt: skip
    axes: list[SweepAxis] = Field(
        default_factory=list,
        max_length=2,
        description="Operating envelope: physical fields of the design (speed, torque, ...); "
        "none: the design's operating point.",
    )

    @field_validator("settings", mode="before")
    @classmethod
    def _over_light(cls, given: object) -> object:
        return over_light(given)

    _variables: list[Variable] | InputError | None = PrivateAttr(None)

    @model_validator(mode="after")
    def _carry_variables(self) -> RobustnessRequest:
        """Read the toleranced fields once, when the request is validated (the row count, every
        chunk's sample rows and the assembly read them; each read validated the design's
        tolerance values again): the variables, or the ``InputError`` refusing one, which
        ``request_errors`` names beside the request's other problems."""
        try:
            self._variables = variables(self.design)
        except InputError as exc:
            self._variables = exc
        return self

    def variables(self) -> list[Variable]:
        """The toleranced fields (``studies.robustness.tolerances.variables``), read when the
        request was validated; raises the ``InputError`` that refused one."""
        if isinstance(self._variables, InputError):
            raise self._variables
        assert self._variables is not None
        return self._variables

    def unit_rows(self) -> np.ndarray:
        """Every run's point of the unit cube, shape (rows, D)."""
        d = len(self.variables())
        if self.sensitivity:
            return sensitivity.saltelli_points(d, self.samples, self.seed)
        return sobol_points(d, self.samples, self.seed)

    def n_rows(self) -> int:
        d = len(self.variables())
        return self.samples * (d + 2) if self.sensitivity else self.samples

    def points(self) -> list[dict[str, float]]:
        """The operating points (SI values of the axes' fields), first axis fastest."""
        grids = [a.values(self.design) for a in self.axes]
        names = [a.parameter for a in self.axes]
        return [
            dict(zip(names, values[::-1], strict=True))
            for values in itertools.product(*grids[::-1])
        ]


def request_errors(request: RobustnessRequest) -> list[InitErrorDetails]:
    """Checks needing the design: every tolerance (naming its field), every axis, N a power
    of 2 (the Sobol sequence's balance)."""
    problems = Problems("robustness")
    try:
        request.variables()
    except InputError as exc:
        problems.add_error(exc, exc.loc[-1] if exc.loc else None)
    if request.samples & (request.samples - 1):
        problems.add(("samples",), "give a power of 2 (the Sobol points' balance)", 0)
    try:  # the pair itself, before its axes: a geometry that does not mesh is the design's
        pair = convert_design(request.design)
    except InputError as exc:  # naming its field (design.driven.base_radius, ...)
        problems.add_error(exc, None)
        return problems.details
    except ValueError as exc:
        problems.add(("design",), str(exc), 0)
        return problems.details
    for i, axis in enumerate(request.axes):
        if is_dimensionless(axis.parameter):
            problems.add(("axes", i, "parameter"), "a physical field of the design", 0)
            continue
        if (count := axis.count_problem()) is not None:
            problems.add(("axes", i, count[0]), count[1], getattr(axis, count[0]))
            continue
        problem = axis_problem(pair.params, request.design, axis.parameter, axis.start,
                               axis.stop, {})  # fmt: skip
        if problem is not None:
            problems.add(("axes", i, problem[0]), problem[1], axis.parameter)
    return problems.details


def checked(request: RobustnessRequest, max_points: int | None = None) -> RobustnessRequest:
    """``request`` if its tolerances and axes are sound; else ``ValidationError`` naming each
    field (what the API and the CLI share)."""
    problems = Problems("robustness")
    problems.details += request_errors(request)
    n = math.prod(a.num for a in request.axes)
    if not problems.details and max_points is not None and n > max_points:
        problems.add(("axes",), f"{n} points, the limit is {max_points}", n)
    problems.raise_if_any("RobustnessRequest")
    return request


def chunk_counts(request: RobustnessRequest, rows: int) -> list[int]:
    """Runs (point x row) of each chunk of ``rows`` rows."""
    n, p = request.n_rows(), max(1, len(request.points()))
    return [p * (min(n, lo + rows) - lo) for lo in range(0, n, rows)]


def robustness_work(request: RobustnessRequest) -> int:
    """RK4 steps of every run (nominal design at each point, times the rows)."""
    return request.n_rows() * sum(point_work(request))


def point_work(request: RobustnessRequest) -> list[int]:
    """RK4 steps of one run of the nominal design at each operating point of ``request`` (one
    entry, the design's own point, without axes): the cost of a sample there."""
    points = request.points() or [{}]
    base = base_design(request.design)
    return [work(design_model(design_with(base, p))[0], request.settings) for p in points]


def robustness_terms(request: RobustnessRequest, cap: int) -> str:
    """The study's cost in its own terms and what ``cap`` RK4 steps allow (``JobKind.terms``):
    "512 samples x 1 start x 115 points = 58880 runs; the budget allows 256 samples at these
    points, or 57 points at 512 samples"."""
    points, starts = max(1, len(request.points())), request.settings.lanes()
    basins = request.settings.basins
    steps, rows = robustness_work(request), request.n_rows()
    fit = cap * request.samples // steps  # samples that fit (the work is linear in them)
    samples = 1 << (fit.bit_length() - 1) if fit >= 2 else 0  # a power of 2
    sobol = f" x {rows // request.samples} (Sobol indices)" if request.sensitivity else ""
    return (f"{request.samples} samples{sobol} x "
            f"{jobs.starts_words(starts, 0 if basins is None else basins.starts)} x "
            f"{points} point{'s' if points != 1 else ''} = {rows * starts * points} runs; the "
            f"budget allows {samples} samples at these points, or {cap * points // steps} "
            f"points at {request.samples} samples")  # fmt: skip


def _run(bp: Any, model: Any, scales: Scales) -> list[Any]:
    """One run's row: class, contact, Melnikov verdict (of a train, its mesh-mode reduction's,
    null without one), DTE [um] and dynamic factor (the one definition,
    ``model.units.response_values``)."""
    response = response_values(bp.x_peak_to_peak, bp.force_max, scales)
    contact = CONTACTS.index(bp.impact_regime) if bp.impact_regime in CONTACTS else None
    judged = melnikov_point(model)
    return [
        CLASSES.index(bp.classification),
        contact,
        None if judged is None else chaos_possible(judged),
        response["dte"],
        response["dynamic_factor"],
    ]


def _worst(run: list[Any], found: list[Any], counts: Any, min_fraction: float) -> list[Any]:
    """``run`` decided by its worst attractor above ``min_fraction`` (``headline``): its class
    and contact, and the DTE and dynamic factor at their largest over those attractors
    (``most_adverse``, as a sweep point shows and the gate judges them; None where it
    diverged); ``run`` itself when no basin is above the fraction (the settings' own start
    decides, as in a sweep)."""
    head = headline(found, counts, min_fraction)
    if head is None:
        return run
    a = head.attractor
    if a is None:  # diverged: no contact or response numbers
        return [CLASSES.index("diverged"), None, run[2], None, None]
    contact = CONTACTS.index(a.impact_regime) if a.impact_regime in CONTACTS else None
    worst = most_adverse(found, head, min_fraction)
    dte, factor = (None if (w := worst.get(k)) is None else w.value
                   for k in ("dte", "dynamic_factor"))  # fmt: skip
    return [CLASSES.index(a.classification), contact, run[2], dte, factor]


def compute_chunk(request: RobustnessRequest, index: int, rows: int) -> str:
    """Chunk ``index``: rows [index rows, (index + 1) rows) at every point, as compact JSON
    ``{"index", "first_row", "runs": [[run per row] per point]}``."""
    variables_ = request.variables()
    lo, hi = index * rows, min(request.n_rows(), (index + 1) * rows)
    if not 0 <= lo < hi:
        raise IndexError(f"chunk {index} out of range")
    values = sample_values(variables_, request.unit_rows()[lo:hi])
    base = base_design(request.design)
    points = request.points() or [{}]
    designs = [sample_design(base, {**v, **p}) for p in points for v in values]
    models = [design_model(d) for d in designs]  # a design with a train runs as its System
    systems = [m for m, _ in models]
    verdicts = simulate_batch(systems, request.settings)
    runs = [_run(bp, m, c.scales) for bp, (m, c) in zip(verdicts, models, strict=True)]
    basins = request.settings.basins
    if basins is not None:
        found = points_attractors(systems, request.settings, [c.scales for _, c in models])
        runs = [_worst(r, a, n, basins.min_fraction) for r, (a, n) in zip(runs, found, strict=True)]
    per_point = [runs[i * len(values) : (i + 1) * len(values)] for i in range(len(points))]
    return json.dumps({"index": index, "first_row": lo, "runs": per_point}, separators=(",", ":"))


def _point_answer(request: RobustnessRequest, runs: list[list[Any]], rows: list[int],
                  complete: bool, variables_: list[Variable]) -> dict[str, Any]:  # fmt: skip
    names, d = [v.path for v in variables_], len(variables_)
    counted = set(sensitivity.base_rows(request.n_rows(), d)) if request.sensitivity else None
    base = [r for row, r in zip(rows, runs, strict=True) if counted is None or row in counted]
    n = len(base)
    probs = {c: probability(sum(r[0] == k for r in base), n) for k, c in enumerate(CLASSES)}
    probs["separation"] = probability(sum(r[1] in (1, 2) for r in base), n)
    probs["back_flank"] = probability(sum(r[1] == 2 for r in base), n)
    limit = request.dynamic_factor_limit
    probs["dynamic_factor_above_limit"] = probability(
        sum(r[4] is not None and r[4] > limit for r in base), n
    )
    probs["melnikov_chaos_possible"] = probability(sum(r[2] is True for r in base), n)
    dte = np.array([r[3] for r in base if r[3] is not None], dtype=float)
    stats_ = {"mean": None, "p5": None, "p95": None}
    if dte.size:
        stats_ = {"mean": round(float(dte.mean()), 4),
                  "p5": round(float(np.percentile(dte, 5)), 4),
                  "p95": round(float(np.percentile(dte, 95)), 4)}  # fmt: skip
    out: dict[str, Any] = {"samples": n, "probabilities": probs, "dte_um": stats_}
    if request.sensitivity and complete:
        ys = {
            "chaotic": [r[0] == 2 for r in runs],
            "separation": [r[1] in (1, 2) for r in runs],
            "back_flank": [r[1] == 2 for r in runs],
            "dte": [math.nan if r[3] is None else r[3] for r in runs],
            "dynamic_factor": [math.nan if r[4] is None else r[4] for r in runs],
        }
        assert tuple(ys) == OUTPUTS
        table = {k: sensitivity.indices(names, np.array(y, float), request.seed)
                 for k, y in ys.items()}  # fmt: skip
        labels = {v.path: v.name for v in variables_}
        out["ranking"] = [sensitivity.ranked(k, t, labels) for k, t in table.items()]
        out["sensitivity"] = table
    return out


def assemble(request: RobustnessRequest, chunks: list[str]) -> RobustnessResult:
    """The result from the chunks present (any subset, any order: a partial result counts the
    samples it has; Sobol indices need every chunk)."""
    variables_ = request.variables()
    basins = request.settings.basins
    points = request.points() or [{}]
    decoded = sorted((json.loads(c) for c in chunks), key=lambda c: c["first_row"])
    complete = sum(len(c["runs"][0]) for c in decoded) == request.n_rows()
    answers = []
    for i, values in enumerate(points):
        runs = [r for c in decoded for r in c["runs"][i]]
        rows = [c["first_row"] + j for c in decoded for j in range(len(c["runs"][i]))]
        answer = _point_answer(request, runs, rows, complete, variables_)
        shown = {k: in_display_unit(k, v) for k, v in values.items()}
        answers.append(RobustnessPoint.model_validate({"values": values, "shown": shown, **answer}))
    return RobustnessResult(
        points=answers,
        samples=request.samples,
        seed=request.seed,
        variables=[RobustnessVariable(path=v.path, distribution=v.words) for v in variables_],
        partial=not complete,
        model=ASSUMPTIONS
        + ([] if basins is None else [basin_assumption(basins)])
        + ([SALTELLI_SAMPLES] if request.sensitivity else []),
        settings=request.settings,
        dynamic_factor_limit=request.dynamic_factor_limit,
        starts_per_sample=len(request.settings.starts()) if basins is None else basins.starts,
        values_units={a.parameter: axis_unit(a.parameter) for a in request.axes},
        shown_units={a.parameter: display_unit(a.parameter)[0] for a in request.axes},
    )


def run_local(request: RobustnessRequest, progress_callback=None, workers: int = 1):
    """Every chunk in this process (``jobs.run_local``): the CLI's document equals the API's."""
    result = jobs.run_local("robustness", request, progress_callback, None, workers)
    assert isinstance(result, RobustnessResult)
    return result


ROBUSTNESS_JOB = jobs.JobKind(
    name="robustness",
    request=RobustnessRequest,
    chunk_points=DEFAULT_CHUNK_ROWS,
    chunk_counts=chunk_counts,
    work=robustness_work,
    compute_chunk=compute_chunk,
    assemble=assemble,
    terms=robustness_terms,
)
"""Robustness studies as a kind of job (``gearengine.studies.jobs.KINDS``)."""
