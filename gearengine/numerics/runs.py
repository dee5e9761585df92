"""One run of a system from one initial state, and its verdict.

``integrate`` runs a ``System`` (a parameter point of Eq. 9 is the spur pair, whose integrator
is chosen by its backlash law) and returns the raw ``Run``; ``start_verdict`` turns it into
period, LLE (Benettin) and classification, reading the mesh coordinate's strobes (and the full
state's, for systems with more coordinates).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from gearengine.model.params import GearParams
from gearengine.numerics.results import StartSummary
from gearengine.numerics.settings import SimulationSettings, plan_work
from gearengine.signals.classify import Classification, classify
from gearengine.signals.diagnostics import impact_regime
from gearengine.signals.lyapunov import LyapunovEstimate, benettin
from gearengine.signals.periodicity import attractor_size, detect_period
from gearengine.systems.base import Run, StepPlan, System
from gearengine.systems.spur_pair.system import SpurPair

MAX_HISTORY_SAMPLES = 2**15
"""Largest number of (x, v) samples kept from the record for spectrum, RMS and nolds."""


@dataclass(frozen=True)
class StartVerdict:
    """Classification, period and LLE of one run, with its summary document."""

    classification: Classification
    period: int | None
    lle: LyapunovEstimate | None
    summary: StartSummary


def finite_or_none(value: float | None) -> float | None:
    """``value`` as a float, or None when it is None, NaN or infinite (JSON has no NaN)."""
    return None if value is None or not math.isfinite(value) else float(value)


def history_stride(settings: SimulationSettings, steps: int) -> int:
    """Steps between kept (x, v) samples, so the record keeps <= ``MAX_HISTORY_SAMPLES``."""
    return max(1, math.ceil(settings.record_periods * steps / MAX_HISTORY_SAMPLES))


def as_system(model: GearParams | System) -> System:
    """The system a numerical verdict runs: a ``System`` as given, a parameter point of Eq. (9)
    as the paper's spur pair."""
    return model if isinstance(model, System) else SpurPair(model)


def work(params: GearParams | System, settings: SimulationSettings) -> int:
    """RK4 steps ``simulate(params, settings)`` takes (for compute budgets): ``plan_work`` on
    the step plan of its system (``as_system``) at ``settings.steps_per_period``."""
    return plan_work(params, settings, as_system(params).plan(settings.steps_per_period))


def integrate(
    model: GearParams | System,
    settings: SimulationSettings,
    start: Sequence[float],
    plan: StepPlan | None = None,
) -> Run:
    """Integrate a system (and its tangent) from ``start`` over the transient and the record;
    ``plan``: its step plan at ``settings.steps_per_period`` where the caller has made it
    already (every start of a run, every basin start, shares one), else made here."""
    system = as_system(model)
    plan = system.plan(settings.steps_per_period) if plan is None else plan
    return system.integrate(plan, start, settings.transient_periods, settings.record_periods,
                            history_stride(settings, plan.steps))  # fmt: skip


def start_verdict(
    run: Run, start: Sequence[float], period_T: float, commensurate: bool
) -> StartVerdict:
    """Period (stroboscopic), LLE (Benettin) and classification of one run."""
    # model_construct: every field below is built here with its exact type (no re-validation)
    if run.diverged:
        summary = StartSummary.model_construct(
            initial_state=[float(s) for s in start],
            classification="diverged",
            period=None,
            lle=None,
            lle_stderr=None,
            impact_regime=None,
            final_state=None,
        )
        return StartVerdict("diverged", None, None, summary)
    est = benettin(run.logs, period_T)
    period = None
    if commensurate:
        period = detect_period(run.xs, run.vs, attractor_size(run.xmin, run.xmax))
    verdict = classify(False, period, est.lle, est.stderr)
    final = [finite_or_none(f) for f in run.final]
    summary = StartSummary.model_construct(
        initial_state=[float(s) for s in start],
        classification=verdict,
        period=None if period is None else int(period),
        lle=finite_or_none(est.lle),
        lle_stderr=finite_or_none(est.stderr),
        impact_regime=impact_regime(run.xmin, run.xmax),
        final_state=None if None in final else final,
    )
    return StartVerdict(verdict, period, est, summary)
