"""Numerical verdict on Eq. (9): integrate, detect the period, estimate the largest Lyapunov
exponent, classify, and describe the response.

Public entry points: ``simulate`` (one parameter point, one or several initial states),
``lyapunov`` and ``poincare`` (short verbs), ``warm_up`` (compile/load every kernel);
``numerics.batch.simulate_batch`` runs a sweep's points.

Any ``System`` runs through ``simulate``; the spur pair of Eq. (9) is the default. Its
integrators (``systems.spur_pair.kernels``, chosen in ``systems.spur_pair.system.INTEGRATORS``):
classical fixed-step RK4 with the tangent equation for the cubic law; for the piecewise law of
Eq. (8) the kink-splitting RK4 (steps split at |x| = 1). The largest Lyapunov exponent is the
tangent-space estimate of Benettin, Galgani, Giorgilli & Strelcyn (Meccanica 15, 1980); the period
is read from
the Poincare (stroboscopic) section; see Parker & Chua, *Practical Numerical Algorithms for
Chaotic Systems* (Springer 1989), ch. 6.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from gearengine.model.params import GearParams
from gearengine.numerics import physical
from gearengine.numerics.batch import simulate_batch
from gearengine.numerics.floquet import floquet_of
from gearengine.numerics.results import NumericsResult, SpectrumPeak, TimeHistory
from gearengine.numerics.runs import (
    Run,
    StartVerdict,
    as_system,
    finite_or_none,
    history_stride,
    integrate,
    start_verdict,
)
from gearengine.numerics.settings import SimulationSettings, check_work
from gearengine.signals.classify import DIVERGENCE_BOUND, severity
from gearengine.signals.diagnostics import (
    impact_regime,
    poincare_points,
    rms,
    spectrum_peaks,
    time_history,
)
from gearengine.signals.nolds_check import lyap_r_check
from gearengine.systems.base import System
from gearengine.systems.spur_pair.forcing import StepPlan


def simulate(
    params: GearParams | System, settings: SimulationSettings | None = None
) -> NumericsResult:
    """Integrate Eq. (9) (or any ``System``) from every start of ``settings`` and return the
    numerical verdict.

    The detailed fields (LLE statistics, spectrum, Poincare points, time history, nolds) describe
    the worst start; ``starts`` holds a summary per start. A periodic worst start under
    commensurate forcing also gets its Floquet multipliers and stability margin (``floquet``:
    Newton shooting from its last strobe, ``numerics.floquet``); otherwise ``floquet_note``
    says why there are none.
    """
    settings = settings or SimulationSettings()
    system = as_system(params)
    plan = system.plan(settings.steps_per_period)
    check_work(settings, plan.steps)
    commensurate = plan.omega0 is not None
    notes = list(plan.notes)
    runs: list[tuple[Run, StartVerdict]] = []
    starts = [system.start_state(x0, v0) for x0, v0 in settings.starts()]
    if physical.applies(settings, plan, system.damping_rate()):
        done, spans = physical_runs(system, plan, settings, starts)
    else:
        done = [integrate(system, settings, start, plan) for start in starts]
        fixed = (settings.transient_periods, "fixed", settings.record_periods, "fixed")
        spans = [fixed] * len(starts)
    for run, start in zip(done, starts, strict=True):
        runs.append((run, start_verdict(run, start, plan.period, commensurate)))
    w = max(range(len(runs)), key=lambda i: severity(runs[i][1].classification, runs[i][1].period))
    (worst, wv), span = runs[w], spans[w]
    n_trans, why_trans, n_rec, why_rec = span
    settings = settings.model_copy(update={"transient_periods": n_trans, "record_periods": n_rec})
    base: dict[str, Any] = {
        "classification": wv.classification,
        "period": wv.period,
        "forcing_period": plan.period if commensurate else None,
        "sampling_interval": plan.period,
        "steps_per_forcing_period": plan.steps,
        "method": system.method(plan),
        "starts": [v.summary for _, v in runs],
        "worst_case": wv.summary,
    }
    if worst.diverged:
        result = _diverged(base, worst, plan, notes)
    else:
        result = _detailed(base, worst, wv, plan, settings, notes)
    states = worst.strobes if worst.states is None else worst.states
    last = states[worst.recorded - 1] if states is not None and worst.recorded > 0 else None
    orbit, why = floquet_of(system, settings, result, last)
    return result.model_copy(update={
        "floquet": orbit, "floquet_note": why,
        "transient": physical.run_length(n_trans, plan, why_trans),
        "record": physical.run_length(n_rec, plan, why_rec),
    })  # fmt: skip


def physical_runs(
    system: System, plan: StepPlan, settings: SimulationSettings, starts: list[tuple]
) -> tuple[list[Run], list[tuple[int, str, int, str]]]:
    """The runs of ``starts`` with their lengths decided in physical time
    (``numerics.physical``) through the single kernels, and per start (transient periods,
    reason, record periods, reason); each ``Run`` is its record, ``done`` counting the
    transient too."""

    def advance(idx: np.ndarray, x0: np.ndarray, v0: np.ndarray, n: int) -> physical.Chunk:
        stride = history_stride(settings.model_copy(update={"record_periods": n}), plan.steps)
        got = [system.integrate(plan, (float(a), float(b)), 0, n, stride)
               for a, b in zip(x0, v0, strict=True)]  # fmt: skip
        return physical.Chunk(
            np.array([r.xs for r in got]), np.array([r.vs for r in got]),
            np.array([r.logs for r in got]), np.array([r.xmin for r in got]),
            np.array([r.xmax for r in got]), np.array([r.final[0] for r in got]),
            np.array([r.final[1] for r in got]), np.array([r.diverged for r in got]), got,
        )  # fmt: skip

    x0 = np.array([s[0] for s in starts], dtype=np.float64)
    v0 = np.array([s[1] for s in starts], dtype=np.float64)
    mu = system.damping_rate()
    assert mu is not None
    r = plan.fast_periods
    lanes = physical.lengths(advance, x0, v0, np.full(x0.size, plan.period), np.full(x0.size, mu),
                             r, settings)  # fmt: skip
    runs, spans = [], []
    for s in lanes:
        run: Run = s.keep
        before = s.transient - (run.xs.size if s.transient_reason == "diverged" else 0)
        runs.append(replace(run, done=run.done + before))
        spans.append((s.transient, s.transient_reason, s.record, s.record_reason or "diverged"))
    return runs, spans


def _diverged(base: dict[str, Any], worst: Run, plan: StepPlan, notes: list[str]) -> NumericsResult:
    """The result of a run that left the divergence bound: no statistics, the strobes so far."""
    t_div = (worst.done + 1) * plan.period
    notes.append(f"|x| or |v| exceeded {DIVERGENCE_BOUND:g} by tau = {t_div:g}; stopped")
    return NumericsResult(
        **base,
        lle=None,
        lle_stderr=None,
        lle_first_half=None,
        lle_converged=False,
        impact_regime=None,
        x_rms=None,
        x_peak_to_peak=None,
        spectrum_peaks=[],
        poincare=poincare_points(worst.xs[: worst.recorded], worst.vs[: worst.recorded]),
        time_history=None,
        nolds=None,
        notes=notes,
    )


def _detailed(
    base: dict[str, Any],
    worst: Run,
    wv: StartVerdict,
    plan: StepPlan,
    settings: SimulationSettings,
    notes: list[str],
) -> NumericsResult:
    """The full result of the worst start: LLE statistics, spectrum, strobes, history, nolds."""
    dt = history_stride(settings, plan.steps) * plan.h
    t0 = settings.transient_periods * plan.period + dt
    commensurate = plan.omega0 is not None
    est = wv.lle
    peaks = spectrum_peaks(worst.hx, dt, plan.omega_ref)
    assert est is not None
    negative = est.lle < -3.0 * (est.stderr or 0.0)
    if commensurate and wv.classification == "quasi_periodic" and negative:
        notes.append(
            "LLE clearly negative but no period <= 64 found: longer period or unfinished "
            "transient; try more transient_periods"
        )
    if not est.converged:
        notes.append("LLE not converged: first half and whole record disagree")
    nolds_result = None
    if settings.lyapunov_nolds:
        if peaks:
            nolds_result = lyap_r_check(worst.hx, dt, peaks[0]["frequency"])
        else:
            notes.append("nolds skipped: x(t) is constant")
    return NumericsResult(
        **base,
        lle=finite_or_none(est.lle),
        lle_stderr=finite_or_none(est.stderr),
        lle_first_half=finite_or_none(est.first_half),
        lle_converged=est.converged,
        impact_regime=impact_regime(worst.xmin, worst.xmax),
        x_rms=finite_or_none(rms(worst.hx)),
        x_peak_to_peak=finite_or_none(worst.xmax - worst.xmin),
        force_max=finite_or_none(worst.fmax),
        force_min=finite_or_none(worst.fmin),
        spectrum_peaks=[SpectrumPeak(**p) for p in peaks],
        poincare=poincare_points(worst.xs, worst.vs),
        time_history=TimeHistory(**time_history(t0, dt, worst.hx, worst.hv, plan.period)),
        nolds=nolds_result,
        notes=notes,
    )


def lyapunov(params: GearParams, settings: SimulationSettings | None = None) -> float | None:
    """Largest Lyapunov exponent per unit tau of the worst start (None if diverged)."""
    return simulate(params, settings).lle


def poincare(params: GearParams, settings: SimulationSettings | None = None) -> list[list[float]]:
    """Last (<= 256) stroboscopic points [[x, v], ...] of the worst start."""
    return simulate(params, settings).poincare


def warm_up() -> None:
    """Compile or load from cache every kernel on a tiny problem (call once at start-up)."""
    tiny = SimulationSettings(transient_periods=1, record_periods=4, steps_per_period=8)
    base = {
        "damping": 0.07,
        "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.1}]},
    }
    torque = {"frequency": math.sqrt(2.0), "harmonics": [{"amplitude": 0.01}]}
    cubic = GearParams.model_validate(base)
    piecewise = GearParams.model_validate({**base, "backlash": {"model": "piecewise"}})
    for extra in ({}, {"torque": torque}, {"backlash": {"model": "piecewise"}}):
        simulate(GearParams.model_validate({**base, **extra}), tiny)
    simulate_batch([cubic, cubic, piecewise, piecewise], tiny)  # both lock-step kernels
