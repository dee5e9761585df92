"""Section 4.1 of the seed paper reproduced by ``simulate`` (cubic law, RK4, 200 steps/period),
plus the request/response contract of the simulation models."""

from __future__ import annotations

import json
import math

import pytest
from pydantic import ValidationError

from gearengine.model.params import GearParams
from gearengine.numerics.simulation import (
    NumericsResult,
    SimulationSettings,
    lyapunov,
    poincare,
    simulate,
)
from tests._gear_cases import paper


@pytest.mark.parametrize(
    ("fe", "period"),
    [(0.1, 1), (0.2, 1), (0.21, 1), (0.2125, 2), (0.22, 2), (0.23, 4), (0.2325, 8)],
)
def test_period_doubling_cascade_in_fe(fe: float, period: int) -> None:
    r = simulate(paper(fe))
    assert r.classification == "periodic"
    assert r.period == period
    assert r.lle is not None and r.lle < 0.0
    assert r.forcing_period == pytest.approx(4.0 * math.pi)
    assert r.steps_per_forcing_period == 200
    assert r.record is not None and len(r.poincare) == min(256, r.record.periods)
    distinct = {(round(x, 6), round(v, 6)) for x, v in r.poincare}
    assert len(distinct) == period


@pytest.mark.parametrize("fe", [0.25, 0.28])
def test_chaos_beyond_the_cascade(fe: float) -> None:
    r = simulate(paper(fe))
    assert r.classification == "chaotic"
    assert r.period is None
    assert r.lle is not None and r.lle_stderr is not None
    assert r.lle > 0.03 and r.lle > 3.0 * r.lle_stderr
    assert r.lle_converged
    assert r.impact_regime == "double_sided"


@pytest.mark.parametrize(
    ("mu", "verdict", "period"),
    [(0.15, "periodic", 1), (0.135, "periodic", 2), (0.12, "chaotic", None)],
)
def test_damping_sweep_at_omega_07(mu: float, verdict: str, period: int | None) -> None:
    r = simulate(paper(0.3, mu=mu, we=0.7))
    assert (r.classification, r.period) == (verdict, period)
    assert (r.lle > 0.0) == (verdict == "chaotic")


def test_stable_period_one_lle_is_damping_rate() -> None:
    # far from resonance the Floquet exponents of the linearisation are -mu +- i w: LLE = -mu
    assert lyapunov(paper(0.1)) == pytest.approx(-0.07, abs=1e-4)


def test_result_is_json_without_nan_and_diagnostics_are_physical() -> None:
    r = simulate(paper(0.2))
    data = json.loads(r.model_dump_json())
    assert NumericsResult.model_validate(data) == r
    assert r.impact_regime == "single_sided"  # x dips into the clearance but never below -1
    assert r.x_peak_to_peak is not None and 0.5 < r.x_peak_to_peak < 3.0
    assert r.x_rms is not None and 0.5 < r.x_rms < 1.5
    top = r.spectrum_peaks[0]
    assert top.order == pytest.approx(1.0, abs=1e-3)  # response at the forcing frequency
    assert top.frequency == pytest.approx(0.5, abs=1e-3)
    th = r.time_history
    assert th is not None and 0 < len(th.t) <= 2000 and len(th.t) == len(th.x) == len(th.v)
    assert r.transient is not None and r.record is not None
    ran = r.transient.periods + r.record.periods  # decided in physical time (numerics.physical)
    assert th.t[-1] == pytest.approx(ran * 4.0 * math.pi)
    assert th.x[-1] == pytest.approx(r.poincare[-1][0])
    assert r.nolds is None


def test_period_two_spectrum_has_subharmonic() -> None:
    orders = [round(p.order, 3) for p in simulate(paper(0.22)).spectrum_peaks]
    assert 0.5 in orders and 1.0 in orders


def test_no_impact_for_weak_forcing_with_large_mean_force() -> None:
    p = GearParams.model_validate(
        {
            "damping": 0.07,
            "mean_force": 0.5,
            "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.05}]},
        }
    )
    r = simulate(p, SimulationSettings(initial_state=[1.8, 0.0]))
    assert r.impact_regime == "no_impact"
    assert r.period == 1


def test_several_starts_and_worst_case() -> None:
    s = SimulationSettings(initial_states=[[0.01, 0.01], [2.0, 0.0], [-2.0, 0.0]])
    r = simulate(paper(0.25), s)
    assert len(r.starts) == 3
    worst = max(
        r.starts,
        key=lambda st: {"periodic": 0, "quasi_periodic": 1, "chaotic": 2}[st.classification],
    )
    assert r.worst_case.classification == worst.classification == r.classification
    assert r.starts[0].lle == pytest.approx(simulate(paper(0.25)).lle)


def test_random_starts_are_reproducible() -> None:
    s = SimulationSettings(
        random_initial_states={"count": 3, "box": [[-1.0, 1.0], [-0.5, 0.5]], "seed": 7},
        transient_periods=50,
        record_periods=50,
    )
    a, b = simulate(paper(0.1), s), simulate(paper(0.1), s)
    assert [st.initial_state for st in a.starts] == [st.initial_state for st in b.starts]
    assert all(-1.0 <= st.initial_state[0] <= 1.0 for st in a.starts)


def test_divergence_is_reported_without_nan() -> None:
    # softening cubic (c < 0): the well is finite and strong forcing throws the state out
    p = GearParams.model_validate(
        {
            "damping": 0.01,
            "backlash": {"model": "cubic", "a": -1.0, "c": -1.0},
            "transmission_error": {"frequency": 1.0, "harmonics": [{"amplitude": 5.0}]},
        }
    )
    r = simulate(p, SimulationSettings(transient_periods=10, record_periods=10))
    assert r.classification == "diverged"
    assert r.lle is None and r.period is None
    text = r.model_dump_json()
    assert "NaN" not in text and "Infinity" not in text
    assert any("exceeded" in n for n in r.notes)


def test_incommensurate_forcing_never_claims_a_period() -> None:
    p = paper(0.1).model_copy(deep=True)
    p = GearParams.model_validate(
        {
            **p.model_dump(),
            "torque": {"frequency": math.sqrt(2.0), "harmonics": [{"amplitude": 0.01}]},
        }
    )
    r = simulate(p, SimulationSettings(transient_periods=200, record_periods=200))
    assert r.period is None and r.forcing_period is None
    assert r.classification == "quasi_periodic"
    assert r.sampling_interval == pytest.approx(2.0 * math.pi / math.sqrt(2.0))
    assert any("incommensurate" in n for n in r.notes)


def test_commensurate_two_excitations_use_common_period() -> None:
    p = GearParams.model_validate(
        {
            **paper(0.1).model_dump(),
            "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.02}]},
        }
    )
    r = simulate(p, SimulationSettings(transient_periods=200, record_periods=100))
    assert r.forcing_period == pytest.approx(4.0 * math.pi)
    assert r.steps_per_forcing_period == 400  # 200 per period of the fastest excitation
    assert r.period == 1


def test_unforced_system_settles_on_equilibrium() -> None:
    p = GearParams.model_validate({"damping": 0.1, "mean_force": 0.01})
    r = simulate(p, SimulationSettings(transient_periods=100, record_periods=20))
    assert r.forcing_period == pytest.approx(2.0 * math.pi)
    assert r.period == 1
    assert any("no active excitation" in n for n in r.notes)
    assert poincare(p, SimulationSettings(transient_periods=100, record_periods=20))[-1][
        1
    ] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(
    ("patch", "field"),
    [
        ({"transient_periods": -1}, "transient_periods"),
        ({"record_periods": 0}, "record_periods"),
        ({"steps_per_period": 3}, "steps_per_period"),
        ({"steps_per_period": 10**6}, "steps_per_period"),
        ({"initial_state": [0.0, float("nan")]}, "initial_state"),
        ({"initial_states": [[0.0, 0.0]] * 65}, "initial_states"),
        ({"random_initial_states": {"count": 2, "box": [[1.0, 0.0], [0.0, 1.0]]}}, "box"),
        ({"record_periods": 100000, "steps_per_period": 10000}, "steps_per_period"),
        ({"speed": 1}, "speed"),
    ],
)
def test_settings_validation_names_the_field(patch: dict, field: str) -> None:
    with pytest.raises(ValidationError) as err:
        SimulationSettings.model_validate(patch)
    assert field in str(err.value)
