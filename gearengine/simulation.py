"""Numerical verdict on Eq. (9): integrate, detect the period, estimate the largest Lyapunov
exponent, classify, and describe the response.

Public entry points: ``simulate`` (one parameter point, one or several initial states),
``simulate_batch`` (a sweep; cubic commensurate points run in the SIMD batch kernel),
``lyapunov`` and ``poincare`` (short verbs), ``warm_up`` (compile/load every kernel).

Integrators (``gearengine.kernels``): classical fixed-step RK4 with the tangent equation for the
cubic law; for the piecewise law of Eq. (8) the kink-splitting RK4 (steps split at |x| = 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from gearengine import kernels
from gearengine.classify import DIVERGENCE_BOUND, classify, severity
from gearengine.diagnostics import (
    impact_regime,
    poincare_points,
    rms,
    spectrum_peaks,
    time_history,
)
from gearengine.forcing import CUBIC, coefficients, law, step_plan
from gearengine.lyapunov import LyapunovEstimate, benettin
from gearengine.params import GearParams, request_config
from gearengine.periodicity import attractor_size, detect_period
from gearengine.timeseries import NoldsResult, lyap_r_check

MAX_PERIODS = 100_000
"""Upper cap of transient_periods and record_periods."""
MAX_STEPS_PER_PERIOD = 10_000
"""Upper cap of steps_per_period."""
MAX_STARTS = 64
"""Upper cap of the number of initial states."""
MAX_TOTAL_STEPS = 1_000_000_000
"""Cap on RK4 steps of one request: (transient + record) x steps per T0 x starts."""
MAX_HISTORY_SAMPLES = 2**15
"""Largest number of (x, v) samples kept from the record for spectrum, RMS and nolds."""
BATCH_POINCARE = 64
"""Strobes returned per point by ``simulate_batch``."""

Finite = Annotated[float, Field(allow_inf_nan=False)]
State = Annotated[list[Finite], Field(min_length=2, max_length=2)]


class RandomStarts(BaseModel):
    """Initial states drawn uniformly from a box [xmin, xmax] x [vmin, vmax]."""

    model_config = request_config()

    count: int = Field(ge=1, le=MAX_STARTS, description="Number of initial states.", examples=[8])
    box: Annotated[list[State], Field(min_length=2, max_length=2)] = Field(
        description="[[xmin, xmax], [vmin, vmax]] of the uniform draw.",
        examples=[[[-1.5, 1.5], [-0.5, 0.5]]],
    )
    seed: int = Field(0, ge=0, description="Seed of numpy.random.default_rng.", examples=[0])

    @model_validator(mode="after")
    def _ordered(self) -> RandomStarts:
        for name, (lo, hi) in zip(("x", "v"), self.box, strict=True):
            if lo > hi:
                raise ValueError(f"box: {name} range [{lo}, {hi}] is reversed")
        return self


class SimulationSettings(BaseModel):
    """How to integrate and analyse Eq. (9). Times are in sampling intervals T0."""

    model_config = request_config(
        {
            "transient_periods": 500,
            "record_periods": 500,
            "steps_per_period": 200,
            "initial_state": [0.01, 0.01],
        }
    )

    transient_periods: int = Field(
        500,
        ge=0,
        le=MAX_PERIODS,
        description="Intervals T0 integrated and discarded before recording.",
        examples=[500],
    )
    record_periods: int = Field(
        500,
        ge=1,
        le=MAX_PERIODS,
        description="Intervals T0 recorded (strobes, Lyapunov sums, spectrum).",
        examples=[500],
    )
    steps_per_period: int = Field(
        200,
        ge=4,
        le=MAX_STEPS_PER_PERIOD,
        description="RK4 steps per period of the fastest active excitation.",
        examples=[200],
    )
    initial_state: State = Field(
        default_factory=lambda: [0.01, 0.01],
        description="Initial state [x, v] at tau = 0 (used when no other starts are given).",
        examples=[[0.01, 0.01]],
    )
    initial_states: Annotated[list[State], Field(min_length=1, max_length=MAX_STARTS)] | None = (
        Field(
            None,
            description=f"Several initial states [[x, v], ...], at most {MAX_STARTS}.",
            examples=[[[0.01, 0.01], [1.5, 0.0]]],
        )
    )
    random_initial_states: RandomStarts | None = Field(
        None, description="Initial states drawn at random from a box."
    )
    lyapunov_nolds: bool = Field(
        False,
        description="Also estimate the LLE from x(t) with nolds.lyap_r (slow).",
        examples=[False],
    )

    @model_validator(mode="after")
    def _work(self) -> SimulationSettings:
        if self.initial_states is not None and self.random_initial_states is not None:
            raise ValueError("give initial_states or random_initial_states, not both")
        work = (self.transient_periods + self.record_periods) * self.steps_per_period
        work *= len(self.starts())
        if work > MAX_TOTAL_STEPS:
            raise ValueError(
                f"(transient_periods + record_periods) x steps_per_period x starts = {work} RK4 "
                f"steps exceeds {MAX_TOTAL_STEPS}"
            )
        return self

    def starts(self) -> list[tuple[float, float]]:
        """Initial states (x0, v0) in order: initial_states, random ones, or initial_state."""
        if self.initial_states is not None:
            return [(s[0], s[1]) for s in self.initial_states]
        r = self.random_initial_states
        if r is not None:
            rng = np.random.default_rng(r.seed)
            xs = rng.uniform(r.box[0][0], r.box[0][1], r.count)
            vs = rng.uniform(r.box[1][0], r.box[1][1], r.count)
            return [(float(x), float(v)) for x, v in zip(xs, vs, strict=True)]
        return [(self.initial_state[0], self.initial_state[1])]


class _Result(BaseModel):
    model_config = ConfigDict(frozen=True, allow_inf_nan=False)


class SpectrumPeak(_Result):
    """One peak of the amplitude spectrum of x."""

    frequency: float = Field(description="Angular frequency, rad per unit tau.")
    amplitude: float = Field(description="Amplitude of x at that frequency (units of b).")
    order: float = Field(
        description="frequency / Omega_0 (or / fastest excitation frequency if incommensurate)."
    )


class TimeHistory(_Result):
    """Decimated samples of the last recorded intervals."""

    t: list[float] = Field(description="Dimensionless time tau.")
    x: list[float] = Field(description="Displacement x (units of b).")
    v: list[float] = Field(description="Velocity x'.")


class StartSummary(_Result):
    """Verdict for one initial state."""

    initial_state: list[float]
    classification: str
    period: int | None
    lle: float | None
    lle_stderr: float | None
    impact_regime: str | None
    final_state: list[float] | None


class NumericsResult(_Result):
    """Numerical verdict. Detailed fields describe the worst-case start (``worst_case``)."""

    classification: str = Field(description="periodic | chaotic | quasi_periodic | diverged.")
    period: int | None = Field(description="Period in units of T0, null if none found.")
    forcing_period: float | None = Field(description="T0 = 2 pi / Omega_0, null if none.")
    sampling_interval: float = Field(description="Interval between strobes, tau units.")
    lle: float | None = Field(description="Largest Lyapunov exponent per unit tau (Benettin).")
    lle_stderr: float | None = Field(description="Standard error of lle from 10 blocks.")
    lle_first_half: float | None = Field(description="lle over the first half of the record.")
    lle_converged: bool = Field(description="First half and whole record agree.")
    impact_regime: str | None = Field(description="no_impact | single_sided | double_sided.")
    x_rms: float | None = Field(description="sqrt(mean x^2) over the record.")
    x_peak_to_peak: float | None = Field(description="max x - min x over the record.")
    spectrum_peaks: list[SpectrumPeak] = Field(description="Largest peaks of the spectrum of x.")
    poincare: list[list[float]] = Field(description="Last strobes [[x, v], ...] (<= 256).")
    time_history: TimeHistory | None = Field(description="Last 20 intervals, <= 2000 samples.")
    nolds: NoldsResult | None = Field(description="nolds.lyap_r cross-check, if requested.")
    steps_per_forcing_period: int = Field(description="RK4 steps per sampling interval.")
    method: str = Field(description="Integrator used.")
    starts: list[StartSummary] = Field(description="One verdict per initial state.")
    worst_case: StartSummary = Field(description="The worst start.")
    notes: list[str] = Field(description="Remarks on choices and limitations.")


class BatchPoint(_Result):
    """Verdict of ``simulate_batch`` for one parameter point (its worst start)."""

    classification: str
    period: int | None
    lle: float | None
    lle_stderr: float | None
    final_state: list[float] | None
    impact_regime: str | None = Field(description="no_impact | single_sided | double_sided.")
    poincare: list[list[float]] = Field(description=f"Last <= {BATCH_POINCARE} strobes.")
    start_index: int = Field(description="Index of the worst start in settings.starts().")


@dataclass(frozen=True)
class _Run:
    """Raw kernel output for one start (shapes as in ``kernels.run_rk4``)."""

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


@dataclass(frozen=True)
class _Verdict:
    classification: str
    period: int | None
    lle: LyapunovEstimate | None
    summary: StartSummary


def _finite(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _packed(params: GearParams) -> tuple[np.ndarray, float, np.ndarray]:
    co = coefficients(params)
    kc = np.ascontiguousarray(np.vstack([co.k_amp, co.k_omega, co.k_phase]))
    fc = np.ascontiguousarray(np.vstack([co.f_amp, co.f_omega, co.f_phase]))
    return kc, co.mean_force, fc


def run_steps(settings: SimulationSettings, steps: int) -> int:
    """RK4 steps of a run: (transient + record) periods x ``steps`` per T0 x starts."""
    return (settings.transient_periods + settings.record_periods) * steps * len(settings.starts())


def work(params: GearParams, settings: SimulationSettings) -> int:
    """RK4 steps ``simulate(params, settings)`` takes (for compute budgets)."""
    return run_steps(settings, step_plan(params, settings.steps_per_period).steps)


def _check_work(settings: SimulationSettings, steps: int) -> None:
    work = run_steps(settings, steps)
    if work > MAX_TOTAL_STEPS:
        raise ValueError(
            f"steps_per_period: the excitation frequencies need {steps} RK4 steps per T0, "
            f"{work} steps in all, over the cap {MAX_TOTAL_STEPS}; lower steps_per_period or "
            "the periods"
        )


def _stride(settings: SimulationSettings, steps: int) -> int:
    return max(1, math.ceil(settings.record_periods * steps / MAX_HISTORY_SAMPLES))


def _integrate(
    params: GearParams, settings: SimulationSettings, start: tuple[float, float]
) -> tuple[_Run, str]:
    plan = step_plan(params, settings.steps_per_period)
    kc, fm, fc = _packed(params)
    lw = law(params)
    n_trans, n_rec = settings.transient_periods, settings.record_periods
    stride = _stride(settings, plan.steps)
    if lw.code == CUBIC:
        out = kernels.run_rk4(
            lw.code, lw.a, lw.c, lw.alpha, params.damping, start[0], start[1], kc, fm, fc,
            plan.omega0 is not None, plan.period, plan.steps, n_trans, n_rec, stride,
            DIVERGENCE_BOUND,
        )  # fmt: skip
        method = "rk4, forcing table" if plan.omega0 is not None else "rk4, forcing at abs. time"
    else:
        out = kernels.run_kink(
            lw.alpha, params.damping, start[0], start[1], kc, fm, fc, plan.period, plan.steps,
            n_trans, n_rec, stride, DIVERGENCE_BOUND,
        )  # fmt: skip
        method = "rk4 split at the kinks |x| = 1 (Illinois regula falsi), forcing at abs. time"
    xs, vs, logs, hx, hv, xmin, xmax, done, xf, vf = out
    run = _Run(
        xs, vs, logs, hx, hv, xmin, xmax, done, (xf, vf), done < n_trans + n_rec,
        max(0, done - n_trans),
    )  # fmt: skip
    return run, method


def _verdict(
    run: _Run, start: tuple[float, float], period_T: float, commensurate: bool
) -> _Verdict:
    if run.diverged:
        summary = StartSummary(
            initial_state=list(start),
            classification="diverged",
            period=None,
            lle=None,
            lle_stderr=None,
            impact_regime=None,
            final_state=None,
        )
        return _Verdict("diverged", None, None, summary)
    est = benettin(run.logs, period_T)
    period = None
    if commensurate:
        period = detect_period(run.xs, run.vs, attractor_size(run.xmin, run.xmax))
    verdict = classify(False, period, est.lle, est.stderr)
    final = [_finite(run.final[0]), _finite(run.final[1])]
    summary = StartSummary(
        initial_state=list(start),
        classification=verdict,
        period=period,
        lle=_finite(est.lle),
        lle_stderr=_finite(est.stderr),
        impact_regime=impact_regime(run.xmin, run.xmax),
        final_state=None if None in final else final,
    )
    return _Verdict(verdict, period, est, summary)


def simulate(params: GearParams, settings: SimulationSettings | None = None) -> NumericsResult:
    """Integrate Eq. (9) from every start of ``settings`` and return the numerical verdict.

    The detailed fields (LLE statistics, spectrum, Poincare points, time history, nolds) describe
    the worst start; ``starts`` holds a summary per start.
    """
    settings = settings or SimulationSettings()
    plan = step_plan(params, settings.steps_per_period)
    _check_work(settings, plan.steps)
    commensurate = plan.omega0 is not None
    notes = list(plan.notes)
    runs: list[tuple[_Run, _Verdict]] = []
    method = ""
    for start in settings.starts():
        run, method = _integrate(params, settings, start)
        runs.append((run, _verdict(run, start, plan.period, commensurate)))
    worst, wv = max(runs, key=lambda rv: severity(rv[1].classification, rv[1].period))
    dt = _stride(settings, plan.steps) * plan.h
    t0 = settings.transient_periods * plan.period + dt
    base: dict[str, Any] = {
        "classification": wv.classification,
        "period": wv.period,
        "forcing_period": plan.period if commensurate else None,
        "sampling_interval": plan.period,
        "steps_per_forcing_period": plan.steps,
        "method": method,
        "starts": [v.summary for _, v in runs],
        "worst_case": wv.summary,
    }
    if worst.diverged:
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
        lle=_finite(est.lle),
        lle_stderr=_finite(est.stderr),
        lle_first_half=_finite(est.first_half),
        lle_converged=est.converged,
        impact_regime=impact_regime(worst.xmin, worst.xmax),
        x_rms=_finite(rms(worst.hx)),
        x_peak_to_peak=_finite(worst.xmax - worst.xmin),
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


def _batch_point(runs: list[tuple[_Run, _Verdict]]) -> BatchPoint:
    idx = max(
        range(len(runs)), key=lambda i: severity(runs[i][1].classification, runs[i][1].period)
    )
    run, v = runs[idx]
    n_ok = run.recorded
    return BatchPoint(
        classification=v.classification,
        period=v.period,
        lle=v.summary.lle,
        lle_stderr=v.summary.lle_stderr,
        final_state=v.summary.final_state,
        impact_regime=v.summary.impact_regime,
        poincare=np.column_stack([run.xs[:n_ok], run.vs[:n_ok]])[-BATCH_POINCARE:].tolist(),
        start_index=idx,
    )


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
    plans = [step_plan(p, settings.steps_per_period) for p in points]
    for i, (p, plan) in enumerate(zip(points, plans, strict=True)):
        _check_work(settings, plan.steps)
        if law(p).code == CUBIC and plan.omega0 is not None:
            groups.setdefault(plan.steps, []).append(i)
        else:
            runs = []
            for s in starts:
                run, _ = _integrate(p, settings, s)
                runs.append((run, _verdict(run, s, plan.period, plan.omega0 is not None)))
            results[i] = _batch_point(runs)
    for N, members in groups.items():
        lanes = [(i, s) for i in members for s in starts]
        tables = [kernels.forcing_table(plans[i].period, N, *_packed(points[i])) for i in members]
        rows = {i: k for k, i in enumerate(members)}
        Kt = np.array([tables[rows[i]][0] for i, _ in lanes])
        Ft = np.array([tables[rows[i]][1] for i, _ in lanes])
        per = np.array([plans[i].period for i, _ in lanes])
        a = np.array([law(points[i]).a for i, _ in lanes])
        c = np.array([law(points[i]).c for i, _ in lanes])
        mu = np.array([points[i].damping for i, _ in lanes])
        x0 = np.array([s[0] for _, s in lanes])
        v0 = np.array([s[1] for _, s in lanes])
        xs, vs, logs, xmin, xmax, done, xf, vf = kernels.run_batch(
            a, c, mu, x0, v0, Kt, Ft, per, N, n_trans, n_rec, DIVERGENCE_BOUND
        )
        per_point: dict[int, list[tuple[_Run, _Verdict]]] = {i: [] for i in members}
        empty = np.zeros(0)
        for lane, (i, s) in enumerate(lanes):
            run = _Run(
                xs[lane], vs[lane], logs[lane], empty, empty, float(xmin[lane]),
                float(xmax[lane]), int(done[lane]), (float(xf[lane]), float(vf[lane])),
                bool(done[lane] < n_trans + n_rec), max(0, int(done[lane]) - n_trans),
            )  # fmt: skip
            per_point[i].append((run, _verdict(run, s, plans[i].period, True)))
        for i, runs in per_point.items():
            results[i] = _batch_point(runs)
    return [results[i] for i in range(len(points))]


def warm_up() -> None:
    """Compile or load from cache every kernel on a tiny problem (call once at start-up)."""
    tiny = SimulationSettings(transient_periods=1, record_periods=4, steps_per_period=8)
    base = {
        "damping": 0.07,
        "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.1}]},
    }
    torque = {"frequency": math.sqrt(2.0), "harmonics": [{"amplitude": 0.01}]}
    cubic = GearParams.model_validate(base)
    for extra in ({}, {"torque": torque}, {"backlash": {"model": "piecewise"}}):
        simulate(GearParams.model_validate({**base, **extra}), tiny)
    simulate_batch([cubic, cubic], tiny)
