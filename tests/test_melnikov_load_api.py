"""Applicability under load through every door: /v1/melnikov and /v1/melnikov/batch (params
and designs, both sides of F_crit), analyses, sweeps (null verdicts above the critical torque)
and the gate (never fails a point it cannot judge, and says how many)."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from gearengine.gate.envelope import envelope_report
from gearengine.gate.rules import Rules
from gearengine.homoclinic.coefficients import critical_mean_force
from gearengine.studies.sweep import run_local, validated
from tests.conftest import PAPER_PARAMS
from tests.test_design import LIGHT, design

F_CRIT = critical_mean_force(0.1667, 0.1667)
T_CRIT = 9.6231  # N m: F_crit b k_m r_a of the README pair (50 µm, 1e8 N/m, 30 mm)


def params_at(fm: float) -> dict:
    return {**PAPER_PARAMS, "mean_force": fm}


@pytest.mark.parametrize("factor", [1 - 1e-9, 1 + 1e-9])
def test_melnikov_and_batch_endpoints_at_both_sides_of_f_crit(
    client: TestClient, factor: float
) -> None:
    inside = factor < 1
    body = {"params": params_at(factor * F_CRIT)}
    one = client.post("/v1/melnikov", json=body).json()
    assert one["applicable"] is inside
    assert (one["chaos_possible"] is None) is not inside
    assert one["critical_mean_force"] == pytest.approx(F_CRIT)
    paper = client.post("/v1/melnikov", json={**body, "mean_load": "perturbation"}).json()
    assert paper["applicable"] is True and paper["mean_load"] == "perturbation"
    batch = client.post("/v1/melnikov/batch", json={"designs": [body["params"]] * 2}).json()
    assert [(r["chaos_possible"] is None) for r in batch["results"]] == [not inside] * 2


@pytest.mark.parametrize("factor", [0.999, 1.001])
def test_designs_at_both_sides_of_the_critical_torque(client: TestClient, factor: float) -> None:
    inside = factor < 1
    d = design(torque=f"{factor * T_CRIT} N*m")
    mel = client.post("/v1/melnikov", json={"design": d}).json()
    assert mel["applicable"] is inside
    assert mel["engineering"]["critical_torque_nm"] == pytest.approx(T_CRIT, rel=1e-4)
    note = mel["engineering"]["speed_windows_note"] or ""
    assert note.startswith("not applicable above T_crit") is not inside
    ana = client.post(
        "/v1/analyses", json={"design": d, "settings": {"transient_periods": 20,
                                                        "record_periods": 20}}
    ).json()  # fmt: skip
    assert ana["melnikov"]["applicable"] is inside
    assert ana["numerics"]["classification"]  # the numerical verdict still applies


def test_sweep_and_gate_skip_the_points_above_the_critical_torque() -> None:
    """A torque axis across T_crit: points above have a null Melnikov verdict, the gate with
    --fail-on melnikov fails none of them and counts them as not judged."""
    doc = {
        "design": LIGHT,
        "settings": {"transient_periods": 10, "record_periods": 10, "steps_per_period": 64},
        "axes": [
            {"parameter": "speed", "start": "3000 rpm", "stop": "4000 rpm", "num": 2},
            {"parameter": "torque", "start": "3 N*m", "stop": "30 N*m", "num": 3},
        ],
    }
    result = run_local(validated(doc))
    above = [p for p in result.points if p.physical["torque"].value > T_CRIT]
    below = [p for p in result.points if p.physical["torque"].value < T_CRIT]
    assert above and all(p.melnikov_chaos_possible is None for p in above)
    assert below and all(p.melnikov_chaos_possible is not None for p in below)
    report = envelope_report(result, Rules(fail_on=["melnikov"]))
    assert report.melnikov_not_judged == len(above)
    failed = {w.level["torque"].value for w in report.failures}
    assert all(t < T_CRIT for t in failed)
    assert any(p.melnikov_chaos_possible for p in below) == (not report.passed)
