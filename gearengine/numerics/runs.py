"""One run of the kernels from one initial state, and its verdict.

``integrate`` picks the integrator of the design's backlash law from ``INTEGRATORS`` (the smooth
RK4 for the cubic law, the kink-splitting RK4 for the piecewise law of Eq. 8) and returns the raw
``Run``; ``start_verdict`` turns it into period, LLE (Benettin) and classification.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gearengine.model.params import GearParams
from gearengine.numerics import kernels
from gearengine.numerics.forcing import Law, StepPlan, law, packed_forcing, step_plan
from gearengine.numerics.results import StartSummary
from gearengine.numerics.settings import SimulationSettings
from gearengine.signals.classify import DIVERGENCE_BOUND, Classification, classify
from gearengine.signals.diagnostics import impact_regime
from gearengine.signals.lyapunov import LyapunovEstimate, benettin
from gearengine.signals.periodicity import attractor_size, detect_period

MAX_HISTORY_SAMPLES = 2**15
"""Largest number of (x, v) samples kept from the record for spectrum, RMS and nolds."""


@dataclass(frozen=True)
class Run:
    """Raw kernel output for one start (shapes as in ``kernels.run_rk4``); ``done`` intervals
    were run, the record is ``xs[:recorded]`` (shorter than n_rec when the run stopped early,
    ``kernels.adaptive``); fmin, fmax: extremes of the mesh force over the record's steps."""

    xs: np.ndarray
    vs: np.ndarray
    logs: np.ndarray
    hx: np.ndarray
    hv: np.ndarray
    xmin: float
    xmax: float
    done: int
    final: tuple[float, float]
    diverged: bool
    recorded: int
    fmin: float = math.nan
    fmax: float = math.nan


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


Kernel = Callable[..., tuple]
"""A kernel call: (law, mu, start, forcing, plan, n_trans, n_rec, stride) -> kernel outputs."""


def _smooth(lw: Law, mu: float, start: tuple[float, float], forcing: tuple, plan: StepPlan,
            n_trans: int, n_rec: int, stride: int) -> tuple:  # fmt: skip
    return kernels.run_rk4(
        lw.code, lw.a, lw.c, lw.alpha, mu, start[0], start[1], *forcing, plan.omega0 is not None,
        plan.period, plan.steps, n_trans, n_rec, stride, DIVERGENCE_BOUND,
    )  # fmt: skip


def _kink(lw: Law, mu: float, start: tuple[float, float], forcing: tuple, plan: StepPlan,
          n_trans: int, n_rec: int, stride: int) -> tuple:  # fmt: skip
    return kernels.run_kink(
        lw.alpha, mu, start[0], start[1], *forcing, plan.period, plan.steps, n_trans, n_rec,
        stride, DIVERGENCE_BOUND, plan.omega0 is not None,
    )  # fmt: skip


INTEGRATORS: dict[str, tuple[Kernel, str]] = {
    "cubic": (_smooth, "rk4"),
    "piecewise": (_kink, "rk4 split at the kinks |x| = 1 (Illinois regula falsi)"),
}
"""Integrator of each backlash law (``model.backlash.LAWS`` names) and its description."""


def method_of(params: GearParams, plan: StepPlan) -> str:
    """How ``integrate`` runs this design, in words (the ``method`` of the result)."""
    name = params.backlash.model
    table = plan.omega0 is not None
    return INTEGRATORS[name][1] + (", forcing table" if table else ", forcing at abs. time")


def integrate(params: GearParams, settings: SimulationSettings, start: tuple[float, float]) -> Run:
    """Integrate Eq. (9) + tangent from ``start`` over the transient and the record."""
    plan = step_plan(params, settings.steps_per_period)
    lw = law(params)
    n_trans, n_rec = settings.transient_periods, settings.record_periods
    kernel = INTEGRATORS[lw.name][0]
    out = kernel(lw, params.damping, start, packed_forcing(params), plan, n_trans, n_rec,
                 history_stride(settings, plan.steps))  # fmt: skip
    xs, vs, logs, hx, hv, xmin, xmax, done, xf, vf, fmin, fmax = out
    return Run(
        xs, vs, logs, hx, hv, xmin, xmax, done, (xf, vf), done < n_trans + n_rec,
        max(0, done - n_trans), fmin, fmax,
    )  # fmt: skip


def start_verdict(
    run: Run, start: tuple[float, float], period_T: float, commensurate: bool
) -> StartVerdict:
    """Period (stroboscopic), LLE (Benettin) and classification of one run."""
    # model_construct: every field below is built here with its exact type (no re-validation)
    if run.diverged:
        summary = StartSummary.model_construct(
            initial_state=[float(start[0]), float(start[1])],
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
    final = [finite_or_none(run.final[0]), finite_or_none(run.final[1])]
    summary = StartSummary.model_construct(
        initial_state=[float(start[0]), float(start[1])],
        classification=verdict,
        period=None if period is None else int(period),
        lle=finite_or_none(est.lle),
        lle_stderr=finite_or_none(est.stderr),
        impact_regime=impact_regime(run.xmin, run.xmax),
        final_state=None if None in final else final,
    )
    return StartVerdict(verdict, period, est, summary)
