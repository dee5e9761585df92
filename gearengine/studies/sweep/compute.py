"""Computing a sweep's chunks: the numerical verdict of each point (``numerics.batch``) with the
Melnikov verdict beside it; continuation carries the final state along a line, and on a
one-axis sweep locates the line's bifurcation points, carried in the chunk's output.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gearengine.homoclinic.thresholds import chaos_possible
from gearengine.homoclinic.train_reduction import melnikov_point
from gearengine.model.aliases import ALIASES, get_alias
from gearengine.model.params import GearParams
from gearengine.model.units import (
    OUTPUTS,
    POINT_OUTPUTS,
    RECORD_FORCES,
    Scales,
    display_unit,
    in_display_unit,
    response_values,
    shown,
    to_physical,
)
from gearengine.numerics.attractors import (
    coexisting,
    points_attractors,
    verdicts_and_attractors,
)
from gearengine.numerics.batch import simulate_batch, threads_may_share_kernels
from gearengine.numerics.bifurcations import PointResponse, locate_bifurcations
from gearengine.numerics.headline import headline
from gearengine.numerics.magnitudes import most_adverse
from gearengine.numerics.results import Attractor, BasinCounts, BatchPoint, FromAttractor
from gearengine.numerics.settings import SimulationSettings
from gearengine.studies import jobs
from gearengine.studies.sweep.axes import is_dimensionless
from gearengine.studies.sweep.export import chunk_json, points_of_chunk, result_json
from gearengine.studies.sweep.plan import (
    DEFAULT_CHUNK_POINTS,
    LARGEST_CHUNK_POINTS,
    SweepPlan,
    sweep_work,
)
from gearengine.studies.sweep.points import PhysicalValue, SweepBifurcation, SweepPoint
from gearengine.studies.sweep.request import SweepBranch, SweepRequest
from gearengine.studies.sweep.results import SweepResult
from gearengine.studies.sweep.windows import SPEED, speed_windows
from gearengine.systems.base import System
from gearengine.systems.designs import params_of
from gearengine.systems.spur_pair.forcing import step_plan


def _physical(
    values: dict[str, float],
    params: GearParams,
    scales: Scales | None,
    bp: BatchPoint,
    responses: dict[str, float | None] | None = None,
) -> dict[str, Any]:
    """With a design (its ``scales``): the axes in display units, the responses (DTE in µm,
    dynamic factor), the mesh forces in N and the point's aliases. With basins these magnitudes
    are the most adverse over the attractors above the threshold (``responses``, from
    ``_decided``: the largest DTE, dynamic factor and force_max, the smallest force_min), else
    those of the settings' own run ``bp`` (``model.units.response_values``, its ``force_max``
    and ``force_min`` x b k_m)."""
    if scales is None:
        return {}
    out = {
        name: PhysicalValue(value=in_display_unit(name, si), unit=display_unit(name)[0])
        for name, si in values.items()
        if not is_dimensionless(name)
    }
    record = response_values(bp.x_peak_to_peak, bp.force_max, scales)
    forces = {
        key: None if f is None else shown(to_physical("mesh_force", f, scales))
        for key, f in zip(RECORD_FORCES, (bp.force_max, bp.force_min), strict=True)
    }
    for key, value in {**record, **forces, **(responses or {})}.items():
        if value is not None:
            out[key] = PhysicalValue(value=value, unit=OUTPUTS[key].unit)
    aliases = {a: get_alias(params, a) for a in ALIASES}
    return {"physical": out, "dimensionless": {k: v for k, v in aliases.items() if v is not None}}


def _point(
    values: dict[str, float],
    branch: SweepBranch | None,
    model: GearParams | System,
    scales: Scales | None,
    bp: BatchPoint,
    basins: dict[str, Any],
) -> SweepPoint:
    """The sweep's point from the engine's verdict ``bp`` (typed and finite, built by
    ``numerics.batch``), so ``model_construct`` skips a second validation (~0.05 ms a point);
    ``basins`` its attractors, basins and coexisting entries (empty without basins) and the
    verdict of its worst attractor (``_decided``). Melnikov judges the point's own Eq. (9), or
    a train's mesh-mode reduction (``homoclinic.train_reduction.melnikov_point``: null when it
    does not hold); the dimensionless aliases are the pair's (a train's equivalent pair's)."""
    params = params_of(model)
    judged = melnikov_point(model)
    possible = None if judged is None else chaos_possible(judged)
    verdict = {
        "classification": bp.classification,
        "period": bp.period,
        "lle": bp.lle,
        "lle_stderr": bp.lle_stderr,
        "impact_regime": bp.impact_regime,
    }
    return SweepPoint.model_construct(
        values={name: float(v) for name, v in values.items()},
        branch=branch,
        **{**verdict, **basins.pop("verdict", {})},
        melnikov_chaos_possible=None if possible is None else bool(possible),
        poincare_x=[s[0] for s in bp.poincare] if bp.poincare_x is None else bp.poincare_x,
        x_peak_to_peak=bp.x_peak_to_peak,
        periods_run=bp.periods_run,
        force_max=bp.force_max,
        force_min=bp.force_min,
        **_physical(values, params, scales, bp, basins.pop("responses", None)),
        **basins,
    )


def compute_chunk(
    request: SweepRequest, chunk_index: int, chunk_points: int = DEFAULT_CHUNK_POINTS
) -> list[SweepPoint]:
    """Verdicts of the points of one chunk, in the chunk's order (deterministic)."""
    return _compute(request, chunk_index, chunk_points)[0]


def continuation_line(request: SweepRequest, chunk_index: int) -> tuple[str, list[float] | None]:
    """Line ``chunk_index`` of a continuation sweep: its chunk output (as ``compute_chunk_json``
    gives it) and the state [x, v] its last point ends in (None: it diverged), from which
    another line may continue (a run-up's quasi-static loop: down from where up ended)."""
    assert request.continuation, "only a continuation line ends in a state to carry on from"
    points, bifurcations, end = _compute(request, chunk_index, DEFAULT_CHUNK_POINTS)
    return chunk_json(points, bifurcations, request.outputs), end


def _compute(
    request: SweepRequest, chunk_index: int, chunk_points: int
) -> tuple[list[SweepPoint], list[SweepBifurcation] | None, list[float] | None]:
    """A chunk's points, for a line of a one-axis continuation sweep the bifurcation points
    located on it (``numerics.bifurcations``; None for other chunks), and for a continuation
    line the state its last point ends in (None otherwise, or if it diverged)."""
    chunk = SweepPlan(request, chunk_points).chunk(chunk_index)
    axes = request.axes
    grids = request.grids()
    values = [{a.parameter: grids[k][ix[k]] for k, a in enumerate(axes)} for ix in chunk.points]
    scaled = [request.scaled_point(v) for v in values]
    designs = [params for params, _ in scaled]
    if not request.continuation:
        return _points(request, values, chunk.branch, scaled), None, None
    verdicts = []
    settings = request.settings
    for design in designs:
        (bp,) = simulate_batch([design], settings)
        verdicts.append(bp)
        settings = _carried(request.settings, bp)
    points = _points(request, values, chunk.branch, scaled, verdicts)
    last = verdicts[-1].final_state if verdicts else None
    end = None if last is None else [float(c) for c in last]
    if len(axes) != 1 or len(values) < 2:
        return points, None, end
    line = [v[axes[0].parameter] for v in values]
    return points, _line_bifurcations(request, line, designs, verdicts), end


def points_at(request: SweepRequest, values: list[dict[str, float]]) -> list[SweepPoint]:
    """The points of a sweep without continuation at any ``values`` of its axes (SI, as a
    point's ``values``), not only its grid's: each computed as a grid point is (the same
    settings, starts and verdict), e.g. the gate's refinement between grid points."""
    assert not request.continuation, "a continuation line's points depend on their order"
    return _points(request, values, None, [request.scaled_point(v) for v in values])


def _points(request: SweepRequest, values: list[dict[str, float]], branch: SweepBranch | None,
            scaled: list[tuple[GearParams, Scales | None]],
            verdicts: list[BatchPoint] | None = None) -> list[SweepPoint]:  # fmt: skip
    """The sweep's points from the engine's verdicts at ``values`` (None: computed here, with
    the basin starts in the same kernel call), with their ensembles."""
    designs = [params for params, _ in scaled]
    if verdicts is None and request.settings.basins is not None:
        verdicts, found = verdicts_and_attractors(designs, request.settings,
                                                  [sc for _, sc in scaled])  # fmt: skip
        ensembles = _ensembles(request, found, verdicts)
    else:
        if verdicts is None:  # only the strobes' x is shown: no [x, v] lists to build
            verdicts = simulate_batch(designs, request.settings, x_only=True)
        ensembles = _basins(request, scaled, verdicts)
    return [
        _point(v, branch, params, scales, bp, e)
        for v, (params, scales), bp, e in zip(values, scaled, verdicts, ensembles, strict=True)
    ]


def _basins(
    request: SweepRequest,
    scaled: list[tuple[GearParams | System, Scales | None]],
    verdicts: list[BatchPoint],
) -> list[dict[str, Any]]:
    """Per point, with ``settings.basins``: its attractors and basin counts
    (``numerics.attractors``, every point's starts in one ``run_lanes`` call; a box in units
    read with the point's own scales) and, on a continuation line, the attractors coexisting
    with the followed branch; else empty."""
    if request.settings.basins is None:
        return [{} for _ in scaled]
    designs = [params for params, _ in scaled]
    found = points_attractors(designs, request.settings, [sc for _, sc in scaled])
    return _ensembles(request, found, verdicts)


def _ensembles(request: SweepRequest, found: list[tuple[list[Attractor], BasinCounts]],
               verdicts: list[BatchPoint]) -> list[dict[str, Any]]:  # fmt: skip
    """Per point, its attractors and basin counts ``found``, the verdict they decide, and on a
    continuation line the attractors coexisting with the followed branch."""
    assert request.settings.basins is not None
    min_fraction = request.settings.basins.min_fraction
    out: list[dict[str, Any]] = [
        {"attractors": a, "basins": c, **_decided(a, c, min_fraction)} for a, c in found
    ]
    if request.continuation:
        for entry, bp in zip(out, verdicts, strict=True):
            entry["coexisting"] = coexisting(bp, entry["attractors"], entry["basins"])
    return out


def _decided(found: list[Attractor], counts: BasinCounts, min_fraction: float) -> dict[str, Any]:
    """The point's verdict from its ensemble (docs/basins.md): the worst attractor (or the
    divergence) whose basin fraction is above ``min_fraction`` (``numerics.headline.headline``),
    its classification, period, LLE and impacts, named with its fraction in ``decided_by``; and
    the magnitudes (DTE, dynamic factor, forces: the point's ``physical`` entries, so the CSV's
    and the DataFrame's columns too) at their most adverse over the attractors above it
    (``most_adverse``), each named in ``magnitudes_from``; none after a divergence. Empty when
    no basin is above it (the settings' own starts decide)."""
    head = headline(found, counts, min_fraction)
    if head is None:
        return {}
    verdict: dict[str, Any] = {"classification": head.classification, "period": head.period}
    a = head.attractor
    if a is None:  # diverged: no LLE, no impact verdict
        verdict.update(lle=None, lle_stderr=None, impact_regime=None)
    else:
        verdict.update(lle=a.lle, lle_stderr=a.lle_stderr, impact_regime=a.impact_regime)
    worst = most_adverse(found, head, min_fraction)
    responses = {key: None if key not in worst else worst[key].value for key in POINT_OUTPUTS}
    named = {key: FromAttractor(**w.model_dump(include=set(FromAttractor.model_fields)))
             for key, w in worst.items()}  # fmt: skip
    return {"verdict": verdict, "responses": responses, "decided_by": head.decided_by,
            "decided_fraction": head.fraction, "magnitudes_from": named or None}  # fmt: skip


def _line_bifurcations(
    request: SweepRequest, line: list[float], designs: list[GearParams], verdicts: list[BatchPoint]
) -> list[SweepBifurcation]:
    """Bifurcation points of one continuation line, followed from its computed responses.

    The line's points are reused (``PointResponse``), so only Newton shooting, the location of each
    crossing and one simulation per crossing (the branch switch) are added. Incommensurate
    forcing has no Poincare period and so no multipliers: no points then.
    """
    responses = [
        PointResponse(
            bp.classification,
            bp.period,
            bp.poincare[-1] if bp.poincare else None,
            None if bp.final_state is None else (bp.final_state[0], bp.final_state[1]),
        )
        for bp in verdicts
    ]
    alias = request.axes[0].parameter
    steps = request.settings.steps_per_period
    if any(step_plan(d, steps).omega0 is None for d in designs):
        return []

    def path(v: float) -> GearParams:
        return request.point({alias: v})

    assert request.params is not None
    events = locate_bifurcations(
        request.params, alias, line, request.settings, responses=responses, path=path
    )
    if is_dimensionless(alias):
        return [SweepBifurcation.model_validate(e) for e in events]
    unit = display_unit(alias)[0]
    return [
        SweepBifurcation.model_validate(
            {**e, "physical": None if e["value"] is None else
             PhysicalValue(value=in_display_unit(alias, e["value"]), unit=unit)}
        )
        for e in events
    ]  # fmt: skip


def _carried(settings: SimulationSettings, bp: BatchPoint) -> SimulationSettings:
    """Settings starting from the final state of ``bp`` (the original starts if it diverged)."""
    if bp.final_state is None:
        return settings
    return starting_from(settings, list(bp.final_state))


def starting_from(settings: SimulationSettings, state: list[float]) -> SimulationSettings:
    """``settings`` with one start, ``state`` [x, v] (its other starts dropped)."""
    return settings.model_copy(
        update={"initial_state": state, "initial_states": None, "random_initial_states": None}
    )


def _chunk_text(request: SweepRequest, chunk_index: int, chunk_points: int) -> str:
    points, bifurcations, _ = _compute(request, chunk_index, chunk_points)
    return chunk_json(points, bifurcations, request.outputs)


def compute_chunk_json(request_json: str, chunk_index: int, chunk_points: int) -> str:
    """``compute_chunk`` on JSON text, returning the chunk's output (what workers exchange):
    a JSON array of points, or for a continuation line also its bifurcations (``chunk_json``)."""
    return _chunk_text(SweepRequest.model_validate_json(request_json), chunk_index, chunk_points)


def run_local(
    request: SweepRequest,
    progress_callback: Callable[[int, int], None] | None = None,
    chunk_points: int | None = None,
    workers: int = 1,
) -> SweepResult:
    """Compute every chunk in this process (``jobs.run_local``); ``progress_callback(done,
    total)`` in points.

    ``workers`` > 1 computes chunks on that many threads: the kernels release the GIL
    (``nogil``), so one chunk's verdicts (Python) overlap another's integration. The result
    does not depend on it; under numba's workqueue threading layer, which cannot run two
    parallel kernels at once, the chunks run one after the other.

    ``chunk_points`` defaults to ``LARGEST_CHUNK_POINTS`` without continuation: the batch
    kernel refills a lane as soon as its point stops early (adaptive stopping), which pays
    only when a lane has several points to run; points do not depend on their chunk.
    """
    if chunk_points is None:
        chunk_points = DEFAULT_CHUNK_POINTS if request.continuation else LARGEST_CHUNK_POINTS
    if workers > 1 and not threads_may_share_kernels():
        workers = 1  # numba's workqueue layer: one kernel call at a time, or it aborts
    result = jobs.run_local("sweep", request, progress_callback, chunk_points, workers)
    assert isinstance(result, SweepResult)
    return result


def assemble(request: SweepRequest, arrays: list[str]) -> SweepResult:
    """The ``SweepResult`` of a sweep from its chunks' outputs in index order (with speed
    windows for a speed axis)."""
    windows = None  # only a speed axis has windows: else the points are not read back
    if any(a.parameter == SPEED for a in request.axes):
        points = [SweepPoint.model_validate(p) for text in arrays for p in points_of_chunk(text)]
        windows = speed_windows(request, points)
    text = "".join(result_json(request.axes, arrays, windows=windows))
    return SweepResult.model_validate_json(text)


def sweep_terms(request: SweepRequest, cap: int) -> str:
    """The sweep's cost in its own terms and what ``cap`` RK4 steps allow (``JobKind.terms``):
    "115 points x 17 starts = 1955 runs; the budget allows 80 points"."""
    points, starts, basins = request.n_points(), request.settings.lanes(), request.settings.basins
    words = jobs.starts_words(starts, 0 if basins is None else basins.starts)
    return (f"{points} points x {words} = {points * starts} runs; the budget allows "
            f"{cap * points // sweep_work(request)} points")  # fmt: skip


SWEEP_JOB = jobs.JobKind(
    name="sweep",
    request=SweepRequest,
    chunk_points=DEFAULT_CHUNK_POINTS,
    chunk_counts=lambda request, size: SweepPlan(request, size).point_counts(),
    work=sweep_work,
    compute_chunk=_chunk_text,
    assemble=assemble,
    terms=sweep_terms,
)
"""Sweeps as a kind of job (``gearengine.studies.jobs.KINDS``)."""
