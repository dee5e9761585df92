"""A second, trivial ``System`` runs through the numerics unchanged: ``simulate``, the
attractors of its basin starts and Floquet shooting, with n = 3 coordinates.

The system is a damped linear oscillator under the spur pair's forcing F(t) (the same packed
terms), with a decoupled relaxing coordinate z:

    x' = v,   v' = -2 mu v - x + F(t),   z' = -gamma z,        gamma > mu,

whose every response is periodic with the forcing's period (1T), whose largest Lyapunov
exponent is -mu exactly (the slowest decay of the homogeneous solutions, eigenvalues
-mu +- i sqrt(1 - mu^2) and -gamma), and whose Floquet multipliers over T0 are
exp((-mu +- i sqrt(1 - mu^2)) T0) and exp(-gamma T0). The integrator (RK4 with the tangent
equation, renormalised every T0) is written here, apart from the engine's kernels.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Sequence

import numpy as np

from gearengine.model.params import GearParams
from gearengine.numerics.attractors import attractors
from gearengine.numerics.floquet import floquet
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import simulate
from gearengine.systems.base import Run, StepPlan, System
from gearengine.systems.spur_pair.forcing import packed_forcing, step_plan

MU, GAMMA = 0.1, 0.5
PARAMS = GearParams.model_validate(
    {"damping": MU, "mean_force": 0.1,
     "transmission_error": {"frequency": 0.8, "harmonics": [{"amplitude": 0.3}]}}
)  # fmt: skip


class LinearOscillator(System):
    """x'' + 2 mu x' + x = F(t) beside z' = -gamma z (see the module doc)."""

    name = "linear_oscillator"
    n = 3
    coordinates = ("x", "v", "z")

    def __init__(self, params: GearParams, gamma: float) -> None:
        self.params, self.gamma = params, gamma
        self.kc, self.fm, self.fc = packed_forcing(params)
        mu = params.damping
        self.A = np.array([[0.0, 1.0, 0.0], [-1.0, -2.0 * mu, 0.0], [0.0, 0.0, -gamma]])

    def plan(self, steps_per_period: int) -> StepPlan:
        return step_plan(self.params, steps_per_period)

    def force(self, t: float) -> float:
        return self.fm + float(np.sum(self.fc[0] * np.cos(self.fc[1] * t + self.fc[2])))

    def rk4(self, y: np.ndarray, dy: np.ndarray, t: float, h: float) -> tuple:
        """One RK4 step of the state y (3,) and of tangent vectors dy, (3,) or (3, k)."""

        def f(s: float, u: np.ndarray) -> np.ndarray:
            return self.A @ u + np.array([0.0, self.force(s), 0.0])

        k1 = f(t, y)
        k2 = f(t + h / 2, y + h / 2 * k1)
        k3 = f(t + h / 2, y + h / 2 * k2)
        k4 = f(t + h, y + h * k3)
        # the tangent equation of a linear system is its homogeneous part
        g1 = self.A @ dy
        g2 = self.A @ (dy + h / 2 * g1)
        g3 = self.A @ (dy + h / 2 * g2)
        g4 = self.A @ (dy + h * g3)
        return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), dy + h / 6 * (g1 + 2 * g2 + 2 * g3 + g4)

    def integrate(
        self, plan: StepPlan, start: Sequence[float], n_trans: int, n_rec: int, stride: int
    ) -> Run:
        y, dy = np.array(start, dtype=float), np.ones(3) / math.sqrt(3.0)
        h, t = plan.h, 0.0
        strobes, logs, hist = [], [], []
        xmin, xmax = math.inf, -math.inf
        for k in range(n_trans + n_rec):
            for j in range(plan.steps):
                y, dy = self.rk4(y, dy, t, h)
                t = (k * plan.steps + j + 1) * h
                if k >= n_trans:
                    xmin, xmax = min(xmin, y[0]), max(xmax, y[0])
                    if j % stride == 0:
                        hist.append(y.copy())
            growth = float(np.linalg.norm(dy))
            dy /= growth
            if k >= n_trans:
                strobes.append(y.copy())
                logs.append(math.log(growth))
        s, hs = np.array(strobes), np.array(hist)
        return Run(s[:, 0], s[:, 1], np.array(logs), hs[:, 0], hs[:, 1], xmin, xmax,
                   n_trans + n_rec, tuple(y), False, n_rec, xmin, xmax, s)  # fmt: skip

    def stroboscopic_flow(self, steps_per_period: int):
        system, plan = self, self.plan(steps_per_period)

        class Flow:
            period, steps = plan.period, plan.steps
            trace_rate = -2.0 * MU - GAMMA

            def __call__(self, X: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
                y, phi = np.array(X, dtype=float), np.eye(3)
                for step in range(m * plan.steps):  # the tangent step takes Phi whole
                    y, phi = system.rk4(y, phi, step * plan.h, plan.h)
                return y, phi

        return Flow()

    def method(self, plan: StepPlan) -> str:
        return "rk4 of a linear oscillator (test system)"


SETTINGS = SimulationSettings(transient_periods=40, record_periods=30, steps_per_period=48)


def test_simulate_gives_the_closed_form_period_and_lle() -> None:
    result = simulate(LinearOscillator(PARAMS, GAMMA), SETTINGS)
    assert result.classification == "periodic" and result.period == 1
    assert result.method == "rk4 of a linear oscillator (test system)"
    assert abs(result.lle + MU) < 1e-3 and result.lle_stderr is not None
    assert len(result.worst_case.final_state) == 3
    # the steady response: x = F_m + |H| F cos(Omega t + phase - delta), H = 1/(1 - W^2 + 2 i mu W)
    amp, w = PARAMS.transmission_error.harmonics[0].amplitude * 0.8**2, 0.8
    H = 1.0 / complex(1.0 - w * w, 2.0 * MU * w)
    assert math.isclose(result.x_peak_to_peak, 2.0 * amp * abs(H), rel_tol=2e-3)


def test_attractors_of_a_linear_system_are_one() -> None:
    basins = SETTINGS.model_copy(update={"basins": {"starts": 4, "grid": True}})
    basins = SimulationSettings.model_validate(basins.model_dump())
    found, counts = attractors(LinearOscillator(PARAMS, GAMMA), basins)
    assert len(found) == 1 and found[0].count == 4 and counts.diverged == 0
    assert found[0].classification == "periodic" and found[0].period == 1
    assert abs(found[0].lle + MU) < 1e-3
    assert len(found[0].strobes[0]) == 3  # strobes of all n coordinates


def test_floquet_multipliers_are_the_closed_form() -> None:
    system = LinearOscillator(PARAMS, GAMMA)
    result = simulate(system, SETTINGS)
    assert result.floquet is not None, result.floquet_note
    T0 = step_plan(PARAMS, 48).period
    wd = math.sqrt(1.0 - MU * MU)
    exact = sorted([cmath.exp(complex(-MU, wd) * T0), cmath.exp(complex(-MU, -wd) * T0),
                    cmath.exp(-GAMMA * T0)], key=abs, reverse=True)  # fmt: skip
    got = [complex(re, im) for re, im in result.floquet.multipliers]
    assert len(got) == 3  # RK4 at 48 steps per T0 = 7.85: multipliers to about 3e-5
    assert all(min(abs(g - e) / abs(e) for g in got) < 1e-4 for e in exact)
    assert result.floquet.liouville_error < 1e-4
    assert math.isclose(result.floquet.stability_margin, 1.0 - math.exp(-MU * T0), rel_tol=1e-4)
    again = floquet(system, SETTINGS, result.floquet.orbit_state, 1)
    assert again.converged and len(again.orbit_state) == 3
