"""Floquet multipliers of a gear train (issue 32): the n x n monodromy matrix of the train's
kernel (``kernel.flow_train``) against an independent one, central differences of the period
map integrated by scipy's DOP853 (rtol 1e-12) from the Newton-refined orbit state."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gearengine.model.design import Design
from gearengine.model.train import EXAMPLE_TRAIN
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import simulate
from gearengine.systems.designs import design_model
from gearengine.systems.gear_train.kernel import train_forcing

ROOT = Path(__file__).resolve().parents[1]
PAIR = json.loads((ROOT / "examples" / "design-direct.json").read_text())["design"]


def test_train_multipliers_agree_with_dop853() -> None:
    """3000 rpm, the issue's train: a periodic 1T response in contact (no impacts), so the
    period map is linear around the orbit and central differences are exact up to the
    integration error. The kernel's orbit is a fixed point of DOP853's period map, and its 10
    multipliers equal DOP853's within 1e-5; det Phi obeys Liouville (``liouville_error``)."""
    design = Design.model_validate({**PAIR, "speed": "3000 rpm", "train": EXAMPLE_TRAIN})
    system, _ = design_model(design)
    result = simulate(system, SimulationSettings(transient_periods=200, record_periods=30))
    assert result.classification == "periodic" and result.period == 1
    assert result.impact_regime == "no_impact"
    fl = result.floquet
    assert fl is not None and fl.converged, result.floquet_note
    assert len(fl.multipliers) == system.n == 10
    assert fl.liouville_error < 1e-3
    n = len(system.w)
    twomu = 2.0 * system.params.damping

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        """Eq. of docs/gear-trains.md (dimensionless), in contact: f_h(delta) = delta - 1."""
        K, e, ed, T = train_forcing(t, system.kc, system.ec, system.tc)
        u, v = y[:n], y[n:]
        delta, deltad = system.w @ u - e, system.w @ v - ed
        assert delta > 1.0  # in contact throughout (the piecewise law's linear branch)
        W = K * (delta - 1.0) + twomu * deltad
        acc = system.f + system.p * T - system.AK @ u - system.AC @ v - system.g * W
        return np.concatenate([v, acc])

    period = result.forcing_period
    X = np.array(fl.orbit_state)

    def period_map(x0: np.ndarray) -> np.ndarray:
        sol = solve_ivp(rhs, (0.0, period), x0, method="DOP853", rtol=1e-12, atol=1e-12)
        return sol.y[:, -1]

    assert np.max(np.abs(period_map(X) - X)) < 1e-7 * max(1.0, np.max(np.abs(X)))
    eps = 1e-6
    phi = np.column_stack(
        [(period_map(X + eps * d) - period_map(X - eps * d)) / (2 * eps) for d in np.eye(len(X))]
    )
    reference = sorted(np.linalg.eigvals(phi), key=lambda m: (-abs(m), m.imag))
    got = [complex(re, im) for re, im in fl.multipliers]
    assert [abs(m) for m in got] == pytest.approx([abs(m) for m in reference], abs=1e-5)
    assert fl.stability_margin == pytest.approx(1.0 - abs(reference[0]), abs=1e-5)
