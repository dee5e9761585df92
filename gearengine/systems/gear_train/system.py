"""A gear train as a ``System``: the kernel's arguments, its step plan and one run.

The train is integrated in the dimensionless form of ``model.Dimensionless`` on the scales of
its equivalent pair (the stiff limit, ``model.equivalent_design``): the same Poincare period,
forcing terms (``systems.spur_pair.forcing``), backlash law and mesh damping mu~ as that pair. A
start (x0, v0) of the settings sets the mesh deflection delta and its rate; the shafts and bearings
start at their static deflection under the mean load, at rest. The verdict of each start is the
pair's (``numerics.runs.start_verdict``: strobes of (delta, delta'), Benettin on the
2n-dimensional tangent, ``signals.classify``); the worst start is reported.

RK4 is explicit: the step must resolve the train's fastest mode, h omega_max <= ``H_OMEGA``, so
the steps per period are raised above ``settings.steps_per_period`` when the shafts or bearings
are stiff (a note says so).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gearengine.model.params import GearParams
from gearengine.model.reduction import DesignConversion
from gearengine.signals.classify import DIVERGENCE_BOUND
from gearengine.systems.base import H_OMEGA, Run, StepPlan, StroboscopicFlow, System, resolving
from gearengine.systems.gear_train import ramp as train_ramp
from gearengine.systems.gear_train.kernel import flow_train, forcing_table, run_train, train_forcing
from gearengine.systems.gear_train.lanes import run_train_lanes
from gearengine.systems.gear_train.model import (
    RELATIVE,
    Dimensionless,
    TrainModel,
    dimensionless,
)
from gearengine.systems.spur_pair.forcing import packed_forcing, step_plan
from gearengine.systems.spur_pair.laws import law

TRAIN_STEP_COST = 3
"""A train's RK4 step in steps of the pair's analysis, for compute budgets: the median ratio of a
train's analysis to the pair's at the same steps (``benchmarks/bench_train.py``: 3.18)."""


@dataclass(frozen=True)
class TrainSystem(System):
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
    load: np.ndarray
    """A^-1 f~ per unit of the pair's mean force F~_m (``model.Dimensionless.load_direction``)."""
    omega_max: float
    torque_ratio: float
    """T_p / (r_p b k_m) per unit of the pair's F~_p: I_a / (m_e r_a^2)."""

    @property
    def conversion(self) -> DesignConversion:
        return self.form.conversion

    def plan(self, steps_per_period: int) -> StepPlan:
        """The pair's step plan, with at least T0 omega_max / ``H_OMEGA`` steps per T0."""
        return resolving(step_plan(self.params, steps_per_period), self.omega_max,
                         "the train's fastest mode")  # fmt: skip

    name = "gear_train"
    step_cost = TRAIN_STEP_COST
    mesh_column = RELATIVE.index("mesh_rotation")  # delta = w~ . u~ - e with w~_mesh = 1
    ramp_method = (
        "RK4 of the gear train stepped straight across the backlash edges "
        f"(systems.gear_train.ramp), h omega_max <= {H_OMEGA} for its fastest mode"
    )

    def step_limit(self) -> float:
        """h omega_max <= ``H_OMEGA`` (module docstring)."""
        return H_OMEGA / self.omega_max

    def ramp_start(self, x: float, v: float) -> np.ndarray:
        """(u, v) of ``start`` and the tangent with equal components, shape (4, n / 2)."""
        u0, v0 = self.start(x, v)
        tangent = np.full(u0.size, 1.0 / math.sqrt(self.n))
        return np.vstack([u0, v0, tangent, tangent])

    def run_ramp(
        self, state: np.ndarray, kc: np.ndarray, fc: np.ndarray, ramp: np.ndarray,
        inertia: float, h: float, n_blocks: int, steps: int,
    ) -> tuple[np.ndarray, int]:  # fmt: skip
        """One segment by ``ramp.run_ramp``. The pair's forcing by order maps to the train's as
        ``train_system`` maps the stationary one: transmission-error terms (kind 1, amplitude
        e_r / b) displace delta, torque terms act on the motor (x ``torque_ratio``). The mean
        force F~_m - ``inertia`` is the torque's (driver and balancing brake, ``load``);
        ``inertia``, the pair's force that accelerates the driven inertia, is here the motor
        torque m_0 (d w_p / dt) that accelerates the whole train (``torque_ratio`` x it, the
        free rotation's inertia m_0 = phi_0^T M phi_0): its relative part P e_motor m_0 a is
        the d'Alembert load -M phi_0 a, which P annihilates, plus that torque."""
        te = fc[3] == 1.0
        ec = np.ascontiguousarray(fc[:3, te])
        tc = np.ascontiguousarray(fc[:3, ~te])
        tc[0] *= self.torque_ratio
        means = np.vstack([
            self.load * (ramp[0] - inertia) + self.p * (self.torque_ratio * inertia),
            self.load * ramp[1],
        ])  # fmt: skip
        lw = law(self.params)
        return train_ramp.run_ramp(
            lw.code, lw.a, lw.c, lw.alpha, self.params.damping, self.AK, self.AC, self.g, self.w,
            self.p, kc, ec, tc, means, np.ascontiguousarray(ramp[2:]), state, h, n_blocks, steps,
            DIVERGENCE_BOUND,
        )  # fmt: skip

    def lane_group(self, plan: StepPlan) -> tuple | None:
        """Trains of one state dimension, law and N under periodic forcing step together."""
        if plan.omega0 is None:
            return None
        lw = law(self.params)
        return (self.name, self.n, lw.code, lw.a, lw.c, lw.alpha, plan.steps)

    def run_lanes(
        self, points: Sequence[System], owner: np.ndarray, starts: np.ndarray,
        plans: Sequence[StepPlan], n_trans: int, n_rec: int, stride: int,
    ) -> tuple:  # fmt: skip
        """``lanes.run_train_lanes`` of the group (``System.run_lanes``)."""
        trains = [t for t in points if isinstance(t, TrainSystem)]
        assert len(trains) == len(points)
        N = plans[0].steps
        lw = law(self.params)

        def stack(name: str) -> np.ndarray:
            return np.ascontiguousarray(np.stack([getattr(t, name) for t in trains]))

        tables = np.stack([forcing_table(t.kc, t.ec, t.tc, pl.period, N)
                           for t, pl in zip(trains, plans, strict=True)])  # fmt: skip
        half = starts.shape[1] // 2
        return run_train_lanes(
            lw.code, lw.a, lw.c, lw.alpha, np.array([t.params.damping for t in trains]),
            stack("AK"), stack("AC"), stack("g"), stack("w"), stack("f"), stack("p"), tables,
            owner, np.array([pl.period for pl in plans]),
            np.ascontiguousarray(starts[:, :half]), np.ascontiguousarray(starts[:, half:]),
            N, n_trans, n_rec, (n_rec * N // stride) * stride, DIVERGENCE_BOUND,
        )  # fmt: skip

    def dynamics_key(self) -> tuple:
        """The kernel's arguments (matrices, forcing terms, law and mesh damping) as bytes."""
        arrays = (self.AK, self.AC, self.g, self.w, self.f, self.p, self.kc, self.ec, self.tc)
        return (self.params.damping, self.params.backlash, *(a.tobytes() for a in arrays))

    @property
    def n(self) -> int:  # type: ignore[override]
        """State dimension: every relative coordinate and its rate."""
        return 2 * len(self.w)

    @property
    def coordinates(self) -> tuple[str, ...]:  # type: ignore[override]
        return (*RELATIVE, *(f"{c}_rate" for c in RELATIVE))

    def start_state(self, x: float, v: float) -> tuple[float, ...]:
        """The full state of ``start`` (delta = x, delta' = v): (u, v) flattened."""
        u0, v0 = self.start(x, v)
        return tuple(float(q) for q in np.concatenate([u0, v0]))

    def integrate(
        self, plan: StepPlan, start: Sequence[float], n_trans: int, n_rec: int, stride: int
    ) -> Run:
        """One run from the full state ``start`` (``start_state``), delta for x."""
        half = len(start) // 2
        u0 = np.array(start[:half], dtype=np.float64)
        v0 = np.array(start[half:], dtype=np.float64)
        return integrate_train(self, plan, u0, v0, n_trans, n_rec, stride)

    def stroboscopic_flow(self, steps_per_period: int) -> StroboscopicFlow:
        """The train's flow sampled every T0 and its n x n Jacobian (``kernel.flow_train``, the
        RK4 grid of ``plan``); ValueError under incommensurate forcing."""
        plan = self.plan(steps_per_period)
        if plan.omega0 is None:
            raise ValueError("incommensurate forcing: no Poincare period, hence no periodic orbit")
        return TrainFlow(self, plan.period, plan.steps)

    def method(self, plan: StepPlan) -> str:
        return f"rk4 of the gear train ({self.n} states), forcing at abs. time"

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


@dataclass(frozen=True)
class TrainFlow:
    """phi_{m T0} of a train and its Jacobian (``systems.base.StroboscopicFlow``): X = (u, v)
    flattened as ``TrainSystem.start_state``; trace J = -tr(A^-1 C~) - 2 mu~ g . w, constant."""

    system: TrainSystem
    period: float
    steps: int

    @property
    def trace_rate(self) -> float:
        s = self.system
        return float(-np.trace(s.AC) - 2.0 * s.params.damping * (s.g @ s.w))

    def __call__(self, X: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
        s = self.system
        lw = law(s.params)
        half = len(X) // 2
        u0 = np.ascontiguousarray(X[:half], dtype=np.float64)
        v0 = np.ascontiguousarray(X[half:], dtype=np.float64)
        u, v, phi = flow_train(
            lw.code, lw.a, lw.c, lw.alpha, s.params.damping, s.AK, s.AC, s.g, s.w, s.f, s.p,
            s.kc, s.ec, s.tc, u0, v0, self.period, self.steps, m,
        )  # fmt: skip
        return np.concatenate([u, v]), phi


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
        kc=kc, ec=ec, tc=tc, load=inv @ form.load_direction,
        omega_max=float(np.sqrt(np.max(np.abs(linear)))),
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
    system: TrainSystem,
    plan: StepPlan,
    u0: np.ndarray,
    v0: np.ndarray,
    n_trans: int,
    n_rec: int,
    stride: int,
) -> Run:
    """One run of the train from (u0, v0) (``systems.base.Run`` with delta for x)."""
    lw = law(system.params)
    out = run_train(
        lw.code, lw.a, lw.c, lw.alpha, system.params.damping,
        system.AK, system.AC, system.g, system.w, system.f, system.p,
        system.kc, system.ec, system.tc, u0, v0,
        plan.omega0 is not None, plan.period, plan.steps, n_trans, n_rec,
        stride, DIVERGENCE_BOUND,
    )  # fmt: skip
    xs, vs, logs, hx, hv, xmin, xmax, done, _, _, fmin, fmax, full = out
    final = (float(hx[-1]), float(hv[-1])) if hx.size else (math.nan, math.nan)
    return Run(
        xs, vs, logs, hx, hv, xmin, xmax, done, final, done < n_trans + n_rec,
        max(0, done - n_trans), fmin, fmax, None, full,
    )  # fmt: skip
