"""The paper's spur pair as a ``System``: Eq. (9), state (x, v), n = 2.

    x' = v,    v' = -2 mu v - K(t) f_h(x) + F(t)                       (Eq. 9)

Its integrator is its backlash law's, from ``laws.LAWS`` (the smooth RK4 for the cubic law, the
kink-splitting RK4 for the piecewise law of Eq. 8); its stroboscopic flow and 2 x 2 monodromy
matrix come from ``kernels.monodromy`` (both laws, the same RK4 arithmetic).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gearengine.model.params import GearParams, PiecewiseBacklash
from gearengine.signals.classify import DIVERGENCE_BOUND
from gearengine.systems.base import Run, StepPlan, System
from gearengine.systems.spur_pair import kernels
from gearengine.systems.spur_pair.forcing import packed_forcing, step_plan
from gearengine.systems.spur_pair.kernels.ramp import run_ramp
from gearengine.systems.spur_pair.kernels.smooth import SQRT1_2
from gearengine.systems.spur_pair.laws import LAWS, Law, law


@dataclass(frozen=True)
class PairFlow:
    """The stroboscopic flow of one parameter point: kernel arguments of ``monodromy``.

    ``flow(X, m)`` gives phi_{m T0}(X) and its Jacobian Phi (2 x 2); trace J = -2 mu.
    """

    law: Law
    mu: float
    kc: np.ndarray
    fm: float
    fc: np.ndarray
    period: float
    steps: int

    @property
    def trace_rate(self) -> float:
        """trace J = -2 mu (Liouville: det Phi = exp(-2 mu m T0))."""
        return -2.0 * self.mu

    def __call__(self, X: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
        lw = self.law
        x, v, phi = kernels.monodromy(
            lw.code, lw.a, lw.c, lw.alpha, self.mu, float(X[0]), float(X[1]), self.kc, self.fm,
            self.fc, self.period, self.steps, m,
        )  # fmt: skip
        return np.array([x, v]), phi


class SpurPair(System):
    """The single-DOF spur pair of Eq. (9) at the parameter point ``params``."""

    name = "spur_pair"
    n = 2
    coordinates = ("x", "v")
    ramp_method = (
        "RK4 split at every backlash edge |x| = 1 (kink-accurate, systems.spur_pair.kernels.kink)"
    )

    def __init__(self, params: GearParams) -> None:
        self.params = params

    def plan(self, steps_per_period: int) -> StepPlan:
        return step_plan(self.params, steps_per_period)

    def integrate(
        self, plan: StepPlan, start: Sequence[float], n_trans: int, n_rec: int, stride: int
    ) -> Run:
        lw = law(self.params)
        out = LAWS[lw.name].run(lw, self.params.damping, start, packed_forcing(self.params),
                                plan, n_trans, n_rec, stride)  # fmt: skip
        xs, vs, logs, hx, hv, xmin, xmax, done, xf, vf, fmin, fmax = out
        return Run(
            xs, vs, logs, hx, hv, xmin, xmax, done, (xf, vf), done < n_trans + n_rec,
            max(0, done - n_trans), fmin, fmax,
        )  # fmt: skip

    def stroboscopic_flow(self, steps_per_period: int) -> PairFlow:
        plan = self.plan(steps_per_period)
        if plan.omega0 is None:
            raise ValueError("incommensurate forcing: no Poincare period, hence no periodic orbit")
        kc, fm, fc = packed_forcing(self.params)
        return PairFlow(law(self.params), self.params.damping, kc, fm, fc, plan.period,
                        plan.steps)  # fmt: skip

    def damping_rate(self) -> float:
        return self.params.damping

    def ramp_start(self, x: float, v: float) -> np.ndarray:
        return np.array([[x], [v], [SQRT1_2], [SQRT1_2]])

    def run_ramp(
        self, state: np.ndarray, kc: np.ndarray, fc: np.ndarray, ramp: np.ndarray,
        inertia: float, h: float, n_blocks: int, steps: int,
    ) -> tuple[np.ndarray, int]:  # fmt: skip
        """The kink-splitting ramp kernel of the piecewise law (``kernels.ramp``); the mean
        force of ``ramp`` includes ``inertia`` already."""
        backlash = self.params.backlash
        assert isinstance(backlash, PiecewiseBacklash)
        flat = state.reshape(-1)  # (x, v, dx, dv), a view: the kernel updates it in place
        return run_ramp(float(backlash.alpha), float(self.params.damping), flat, kc, ramp, fc, h,
                        n_blocks, steps, DIVERGENCE_BOUND)  # fmt: skip

    def method(self, plan: StepPlan) -> str:
        name = self.params.backlash.model
        table = plan.omega0 is not None
        return LAWS[name].method + (", forcing table" if table else ", forcing at abs. time")
