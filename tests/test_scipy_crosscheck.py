"""The RK4 kernels against scipy DOP853 (rtol 1e-10, atol 1e-12) of the same ODE + tangent.

Same transient (300 T0) and record (200 T0) for both. Periodic cases: same period and LLE within
2e-3 per unit time (the Floquet exponent; both integrators are accurate to far better). Chaotic
cases: both LLEs positive and within 0.015 (finite-record estimates along diverging trajectories
scatter by a few 1e-3).
"""

from __future__ import annotations

import pytest

from gearengine.model.params import GearParams
from gearengine.numerics.simulation import SimulationSettings, simulate
from tests._gear_cases import paper, scipy_run

# the kernel and DOP853 integrate the same 300 + 200 periods (the integrators are compared, not
# the physical-time lengths, which tests/test_physical.py checks against fixed-length runs)
SETTINGS = SimulationSettings(transient_periods=300, record_periods=200, physical_time=False)
MULTI = GearParams.model_validate(
    {
        "damping": 0.1,
        "mean_force": 0.02,
        "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.05, "phase": 0.3}]},
        "transmission_error": {
            "frequency": 0.5,
            "harmonics": [{"amplitude": 0.1}, {"amplitude": 0.02, "phase": 1.0}],
        },
        "torque": {"frequency": 0.25, "harmonics": [{"amplitude": 0.03, "phase": -0.5}]},
    }
)

CASES = {
    "fe0.1_P1": paper(0.1),
    "fe0.22_P2": paper(0.22),
    "fe0.23_P4": paper(0.23),
    "we0.7_mu0.15_P1": paper(0.3, mu=0.15, we=0.7),
    "we0.7_mu0.135_P2": paper(0.3, mu=0.135, we=0.7),
    "three_excitations": MULTI,
    "fe0.25_chaos": paper(0.25),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rk4_agrees_with_dop853(name: str) -> None:
    params = CASES[name]
    period, lle, _ = scipy_run(params, SETTINGS.transient_periods, SETTINGS.record_periods)
    r = simulate(params, SETTINGS)
    assert r.period == period
    assert r.lle is not None
    if period is None:
        assert r.classification == "chaotic"
        assert lle > 0.0 and r.lle > 0.0
        assert r.lle == pytest.approx(lle, abs=0.015)
    else:
        assert r.lle < 0.0 and lle < 0.0
        assert r.lle == pytest.approx(lle, abs=2e-3)
