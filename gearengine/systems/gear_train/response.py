"""The nonlinear response of a train: period, LLE, contact regime, DTE and dynamic factor.

The train is integrated in the dimensionless form of ``model.Dimensionless`` on the scales of
its equivalent pair (the stiff limit, ``model.equivalent_design``): the same Poincare period,
forcing terms (``numerics.forcing``), backlash law and mesh damping mu~ as that pair. A start
(x0, v0) of the settings sets the mesh deflection delta and its rate; the shafts and bearings
start at their static deflection under the mean load, at rest. The verdict of each start is the
pair's (``numerics.runs.start_verdict``: strobes of (delta, delta'), Benettin on the
2n-dimensional tangent, ``numerics.classify``); the worst start is reported.

RK4 is explicit: the step must resolve the train's fastest mode, h omega_max <= ``H_OMEGA``, so
the steps per period are raised above ``settings.steps_per_period`` when the shafts or bearings
are stiff (a note says so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from gearengine.model.design import Design
from gearengine.model.errors import InputError
from gearengine.model.params import GearParams
from gearengine.model.reduction import DesignConversion
from gearengine.model.units import response_values
from gearengine.numerics.classify import DIVERGENCE_BOUND, severity
from gearengine.numerics.diagnostics import ImpactRegime, impact_regime
from gearengine.numerics.forcing import StepPlan, law, packed_forcing, step_plan
from gearengine.numerics.runs import Run, history_stride, start_verdict
from gearengine.numerics.settings import MAX_TOTAL_STEPS, SimulationSettings, run_steps
from gearengine.systems.gear_train.kernel import run_train, train_forcing
from gearengine.systems.gear_train.model import (
    RELATIVE,
    Dimensionless,
    TrainModel,
    dimensionless,
    train_of,
)

TRAIN_STEP_COST = 3
"""A train's RK4 step in steps of the pair's analysis, for compute budgets: the median ratio of a
train's analysis to the pair's at the same steps (``benchmarks/bench_train.py``: 3.18)."""

H_OMEGA = 0.5
"""Largest h omega_max of the RK4 step against the train's fastest mode (RK4's stability limit
is 2.83; 0.5 keeps a fast mode's phase error per step near 1e-4)."""


@dataclass(frozen=True)
class TrainSystem:
    """The kernel's arguments of one train (``kernel.run_train``) and its scales."""

    model: TrainModel
    form: Dimensionless
    params: GearParams
    AK: np.ndarray
    AC: np.ndarray
    g: np.ndarray
    w: np.ndarray
    f: np.ndarray
    p: np.ndarray
    kc: np.ndarray
    ec: np.ndarray
    tc: np.ndarray
    omega_max: float
    torque_ratio: float
    """T_p / (r_p b k_m) per unit of the pair's F~_p: I_a / (m_e r_a^2)."""

    @property
    def conversion(self) -> DesignConversion:
        return self.form.conversion

    def plan(self, steps_per_period: int) -> StepPlan:
        """The pair's step plan, with at least T0 omega_max / ``H_OMEGA`` steps per T0."""
        plan = step_plan(self.params, steps_per_period)
        need = math.ceil(plan.period * self.omega_max / H_OMEGA)
        if need <= plan.steps:
            return plan
        note = (
            f"the train's fastest mode (omega = {self.omega_max:.4g} omega_n) needs {need} RK4 "
            f"steps per T0 (h omega <= {H_OMEGA}); {plan.steps} were asked"
        )
        return StepPlan(plan.omega0, plan.period, need, plan.omega_ref, (*plan.notes, note))

    def integrate(self, settings: SimulationSettings, start: tuple[float, float]) -> Run:
        """One run from (delta, delta') = ``start`` (``numerics.simulation.System``)."""
        return integrate_train(self, settings, start)

    def start(self, x0: float, v0: float) -> tuple[np.ndarray, np.ndarray]:
        """(u, v) at tau = 0: delta = x0, delta' = v0, shafts and bearings at their static
        deflection under the mean load (the train linearised in contact), at rest."""
        form = self.form
        w = form.mesh_direction
        static = np.linalg.solve(form.stiffness + np.outer(w, w), form.mean_force)
        _, e, ed, _ = train_forcing(0.0, self.kc, self.ec, self.tc)
        mesh = RELATIVE.index("mesh_rotation")
        u = static.copy()
        u[mesh] += x0 + e - w @ static
        v = np.zeros_like(u)
        v[mesh] = v0 + ed
        return u, v


def train_system(model: TrainModel, pair: DesignConversion) -> TrainSystem:
    """The kernel's arrays of ``model`` on the scales of its equivalent pair ``pair``."""
    form = dimensionless(model, pair)
    params = pair.params
    inv = np.linalg.inv(form.mass)
    w = form.mesh_direction
    kc, _, _ = packed_forcing(params)
    scale = (model.mass[0, 0] + model.mass[1, 1]) / (pair.equivalent_mass_kg * model.radii[0] ** 2)
    ec = _terms(params.transmission_error, 1.0)  # e_r / b
    tc = _terms(params.torque, scale)  # F~_pr = m r_a T_pr / (I_a b k_m) -> T_pr / (r_p b k_m)
    linear = np.linalg.eigvals(inv @ (form.stiffness + np.outer(w, w)))
    return TrainSystem(
        model=model, form=form, params=params,
        AK=inv @ form.stiffness, AC=inv @ form.damping, g=inv @ w, w=w,
        f=inv @ form.mean_force, p=inv @ form.torque_direction,
        kc=kc, ec=ec, tc=tc, omega_max=float(np.sqrt(np.max(np.abs(linear)))),
        torque_ratio=scale,
    )  # fmt: skip


def _terms(excitation, factor: float) -> np.ndarray:
    """(3, terms): amplitude x factor, r Omega, phase of the active harmonics."""
    rows = []
    if excitation is not None:
        omega = excitation.frequency
        rows = [(h.amplitude * factor, r * omega, h.phase) for r, h in excitation.active()]
    return np.ascontiguousarray(np.array(rows, dtype=np.float64).reshape(-1, 3).T)


def integrate_train(
    system: TrainSystem, settings: SimulationSettings, start: tuple[float, float]
) -> Run:
    """One run of the train from the start (delta, delta') = ``start`` (``numerics.runs.Run``
    with delta for x)."""
    plan = system.plan(settings.steps_per_period)
    lw = law(system.params)
    u0, v0 = system.start(*start)
    n_trans, n_rec = settings.transient_periods, settings.record_periods
    out = run_train(
        lw.code, lw.a, lw.c, lw.alpha, system.params.damping,
        system.AK, system.AC, system.g, system.w, system.f, system.p,
        system.kc, system.ec, system.tc, u0, v0,
        plan.omega0 is not None, plan.period, plan.steps, n_trans, n_rec,
        history_stride(settings, plan.steps), DIVERGENCE_BOUND,
    )  # fmt: skip
    xs, vs, logs, hx, hv, xmin, xmax, done, _, _, fmin, fmax = out
    final = (float(hx[-1]), float(hv[-1])) if hx.size else (math.nan, math.nan)
    return Run(
        xs, vs, logs, hx, hv, xmin, xmax, done, final, done < n_trans + n_rec,
        max(0, done - n_trans), fmin, fmax,
    )  # fmt: skip


class TrainResponse(BaseModel):
    """The numerical verdict of a train at its design point (worst start)."""

    model_config = ConfigDict(frozen=True)

    classification: str = Field(description="periodic, chaotic, quasi_periodic or diverged.")
    period: int | None = Field(description="Period in forcing periods T0 (periodic only).")
    lle: float | None = Field(description="Largest Lyapunov exponent per unit tau (Benettin, "
                              "2n-dimensional tangent).")  # fmt: skip
    lle_stderr: float | None = Field(description="Its standard error (block estimates).")
    impact_regime: ImpactRegime | None = Field(description="Contact regime of delta.")
    delta_peak_to_peak: float | None = Field(description="Peak to peak of delta [units of b].")
    force_max: float | None = Field(description="Largest mesh force [units of b k_m].")
    dte_um: float | None = Field(description="DTE: peak to peak of delta [um].")
    dynamic_factor: float | None = Field(description="Largest mesh force / static force.")
    steps_per_period: int = Field(description="RK4 steps per T0 used.")
    sampling_interval: float = Field(description="T0 [units of tau].")
    notes: list[str] = Field(description="Remarks on the run.")


def simulate_train(design: Design, settings: SimulationSettings | None = None) -> TrainResponse:
    """The numerical verdict of a design with a ``train`` (module docstring)."""
    settings = settings or SimulationSettings()
    model, pair = train_of(design)
    return respond(train_system(model, pair), settings)


def respond(system: TrainSystem, settings: SimulationSettings) -> TrainResponse:
    """Run every start of ``settings`` on ``system``; the worst start's verdict."""
    plan = system.plan(settings.steps_per_period)
    total = (
        (settings.transient_periods + settings.record_periods) * plan.steps * len(settings.starts())
    )
    if total > MAX_TOTAL_STEPS:
        raise InputError(
            "steps_per_period",
            f"the train needs {plan.steps} RK4 steps per T0, {total} steps in all, over the cap "
            f"{MAX_TOTAL_STEPS}; lower the periods or soften the stiffest shaft or bearing",
        )
    commensurate = plan.omega0 is not None
    runs = []
    for start in settings.starts():
        run = integrate_train(system, settings, start)
        runs.append((run, start_verdict(run, start, plan.period, commensurate)))
    worst, verdict = max(runs, key=lambda rv: severity(rv[1].classification, rv[1].period))
    if worst.diverged:
        ptp = fmax = None
        regime = None
    else:
        ptp, fmax = float(worst.xmax - worst.xmin), float(worst.fmax)
        regime = impact_regime(worst.xmin, worst.xmax)
    values = response_values(ptp, fmax, system.conversion.scales)
    est = verdict.lle
    return TrainResponse(
        classification=verdict.classification,
        period=verdict.period,
        lle=None if est is None else est.lle,
        lle_stderr=None if est is None else est.stderr,
        impact_regime=regime,
        delta_peak_to_peak=ptp,
        force_max=fmax,
        dte_um=values["dte"],
        dynamic_factor=values["dynamic_factor"],
        steps_per_period=plan.steps,
        sampling_interval=plan.period,
        notes=list(plan.notes),
    )


def train_work(design: Design, settings: SimulationSettings) -> int:
    """The compute budget of analysing a train (``numerics.settings.work``'s unit: the pair's RK4
    steps): its steps (raised for stiff shafts and bearings) times ``TRAIN_STEP_COST``."""
    model, pair = train_of(design)
    steps = train_system(model, pair).plan(settings.steps_per_period).steps
    return TRAIN_STEP_COST * run_steps(settings, steps)
