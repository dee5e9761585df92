"""Computing a sweep's chunks: the numerical verdict of each point (``numerics.batch``) with the
Melnikov verdict beside it; continuation carries the final state along a line.
"""

from __future__ import annotations

from collections.abc import Callable

from gearengine.homoclinic.thresholds import chaos_possible
from gearengine.model.aliases import with_aliases
from gearengine.model.params import GearParams
from gearengine.numerics.batch import simulate_batch
from gearengine.numerics.results import BatchPoint
from gearengine.numerics.settings import SimulationSettings
from gearengine.sweeps.export import result_json
from gearengine.sweeps.plan import DEFAULT_CHUNK_POINTS, SweepPlan
from gearengine.sweeps.request import SweepBranch, SweepRequest
from gearengine.sweeps.results import SweepPoint, SweepResult


def _point(
    values: dict[str, float], branch: SweepBranch | None, params: GearParams, bp: BatchPoint
):
    return SweepPoint(
        values=values,
        branch=branch,
        classification=bp.classification,
        period=bp.period,
        lle=bp.lle,
        lle_stderr=bp.lle_stderr,
        impact_regime=bp.impact_regime,
        melnikov_chaos_possible=chaos_possible(params),
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
