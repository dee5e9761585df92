"""Verdicts of many parameter points at once: the sweeps' path to the kernels.

Cubic-law points with commensurate forcing are grouped by steps per T0 and advanced in lock-step
by the SIMD kernel ``kernels.run_batch`` (parallel over chunks of lanes), and their verdicts are
taken array-wise (``numerics.lanes``); other points run one by one in the single kernels
(``numerics.runs``). Numbers equal those of ``simulate``.
"""

from __future__ import annotations

import numba
import numpy as np

from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.params import GearParams
from gearengine.numerics import kernels
from gearengine.numerics.classify import DIVERGENCE_BOUND, severity
from gearengine.numerics.forcing import StepPlan, law, packed_forcing, step_plan
from gearengine.numerics.lanes import lockstep_points
from gearengine.numerics.results import BATCH_POINCARE, BatchPoint
from gearengine.numerics.runs import Run, StartVerdict, finite_or_none, integrate, start_verdict
from gearengine.numerics.settings import SimulationSettings, check_work


def batch_point(runs: list[tuple[Run, StartVerdict]]) -> BatchPoint:
    """The verdict of a point: its worst start's, with that start's last strobes.

    Built with ``model_construct``: the fields come typed and finite from ``start_verdict`` and
    ``finite_or_none``, so validating them again would only cost time (~0.1 ms a point).
    """
    idx = max(
        range(len(runs)), key=lambda i: severity(runs[i][1].classification, runs[i][1].period)
    )
    run, v = runs[idx]
    n_ok = run.recorded
    return BatchPoint.model_construct(
        classification=v.classification,
        period=v.period,
        lle=v.summary.lle,
        lle_stderr=v.summary.lle_stderr,
        final_state=v.summary.final_state,
        impact_regime=v.summary.impact_regime,
        poincare=np.column_stack([run.xs[:n_ok], run.vs[:n_ok]])[-BATCH_POINCARE:].tolist(),
        start_index=int(idx),
        x_peak_to_peak=None if run.diverged else finite_or_none(run.xmax - run.xmin),
        periods_run=int(run.done),
        force_max=None if run.diverged else finite_or_none(run.fmax),
        force_min=None if run.diverged else finite_or_none(run.fmin),
    )


def step_plans(points: list[GearParams], steps_per_period: int) -> list[StepPlan]:
    """``step_plan`` of each point, computed once per set of active harmonics: the plan depends
    only on the excitations' frequencies and which of their harmonics are active."""
    known: dict[tuple, StepPlan] = {}
    plans = []
    for p in points:
        key = tuple(
            (name, exc.frequency, tuple(r for r, _ in exc.active()))
            for name, exc in p.excitations()
        )
        if key not in known:
            known[key] = step_plan(p, steps_per_period)
        plans.append(known[key])
    return plans


def simulate_batch(
    points: list[GearParams], settings: SimulationSettings | None = None
) -> list[BatchPoint]:
    """Verdict (period, LLE, final state, last strobes) for each parameter point of a sweep.

    Cubic-law points with commensurate forcing are grouped by steps per T0 and run in the
    lock-step SIMD kernel (``kernels.run_batch``, parallel over chunks of lanes; one lane per
    point and start). Other points (piecewise law, incommensurate forcing) run one by one in the
    single kernels. Numbers equal those of ``simulate`` for the same point and start.
    """
    settings = settings or SimulationSettings()
    starts = settings.starts()
    n_trans, n_rec = settings.transient_periods, settings.record_periods
    results: dict[int, BatchPoint] = {}
    groups: dict[int, list[int]] = {}
    plans = step_plans(points, settings.steps_per_period)
    for i, (p, plan) in enumerate(zip(points, plans, strict=True)):
        check_work(settings, plan.steps)
        if p.backlash.model == "cubic" and plan.omega0 is not None:
            groups.setdefault(plan.steps, []).append(i)
        else:
            runs = []
            for s in starts:
                run = integrate(p, settings, s)
                runs.append((run, start_verdict(run, s, plan.period, plan.omega0 is not None)))
            results[i] = batch_point(runs)
    for N, members in groups.items():
        lanes = [(i, s) for i in members for s in starts]
        tables = [
            kernels.forcing_table(plans[i].period, N, *packed_forcing(points[i])) for i in members
        ]
        rows = {i: k for k, i in enumerate(members)}
        Kt = np.array([tables[rows[i]][0] for i, _ in lanes])
        Ft = np.array([tables[rows[i]][1] for i, _ in lanes])
        per = np.array([plans[i].period for i, _ in lanes])
        laws = {i: law(points[i]) for i in members}
        a = np.array([laws[i].a for i, _ in lanes])
        c = np.array([laws[i].c for i, _ in lanes])
        mu = np.array([points[i].damping for i, _ in lanes])
        x0 = np.array([s[0] for _, s in lanes])
        v0 = np.array([s[1] for _, s in lanes])
        streams = max(1, min(numba.get_num_threads(), -(-len(lanes) // kernels.LANES)))
        out = kernels.run_batch(
            a, c, mu, x0, v0, Kt, Ft, per, N, n_trans, n_rec, DIVERGENCE_BOUND,
            settings.adaptive, streams,
        )  # fmt: skip
        results.update(lockstep_points(out, members, lanes, per))
    return [results[i] for i in range(len(points))]


def threads_may_share_kernels() -> bool:
    """True when several threads may run the parallel kernel ``run_batch`` at once.

    numba's OpenMP and TBB threading layers allow it; its fallback, the workqueue layer (where
    neither library is installed), aborts the process instead ("Concurrent access has been
    detected"). The layer is chosen on the first parallel run, so a tiny one runs if needed.
    """
    try:
        return numba.threading_layer() != "workqueue"
    except ValueError:  # no parallel kernel has run in this process yet
        tiny = SimulationSettings(transient_periods=1, record_periods=4, steps_per_period=8)
        point = GearParams.model_validate(PAPER_SECTION_41)
        simulate_batch([point, point], tiny)
        return numba.threading_layer() != "workqueue"
