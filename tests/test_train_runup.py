"""Run-ups of a gear train (issue 32): the run-up room drives the ``System`` interface, so a
design with ``train`` runs up through the same profile, reading and job code as the pair.

Stiff limit: with shafts and bearings 1e6 times stiffer the train's run-up is the single-DOF
pair's with I_a = I_m + I_p, I_b = I_g + I_l (``equivalent_design``) bin by bin."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from gearengine.model.design import Design
from gearengine.model.train import EXAMPLE_TRAIN
from gearengine.studies.runup import run_local
from gearengine.studies.runup.profile import ramp_forcing, validated_runup
from gearengine.studies.runup.request import RunupRequest
from gearengine.systems.gear_train.model import equivalent_design, train_of
from gearengine.systems.gear_train.system import train_system
from service.core.config import Settings
from service.main import create_app

ROOT = Path(__file__).resolve().parents[1]
PAIR = json.loads((ROOT / "examples" / "design-direct.json").read_text())["design"]
TRAIN_DESIGN = {
    **PAIR,
    "transmission_error": {"harmonics": [{"amplitude": "20 um"}]},
    "train": EXAMPLE_TRAIN,
}
PROFILE = {
    "from_speed": "2000 rpm",
    "to_speed": "3000 rpm",
    "rate": "20000 rpm/s",
    "bin_rpm": 100,
    "ensemble": {"size": 1},
    "quasi_static": {"transient_periods": 20, "record_periods": 10, "steps_per_period": 32},
}


def test_stiff_train_runs_up_as_its_equivalent_pair(monkeypatch: pytest.MonkeyPatch) -> None:
    """2000 -> 3000 rpm across the stiff pair's mesh resonance (2464 rpm), separations in every
    bin: the train (its shafts and bearings 1e6 times stiffer, beyond the plausible ranges a
    design accepts, hence set on its model) gives each bin's contact regime, its FTLE within 3
    standard errors, and its DTE and dynamic factor within 1 %, of the equivalent pair's
    run-up (the pair's kernel splits its steps at the backlash edges, the train's does not)."""
    pair = validated_runup({"design": json.loads(equivalent_design(Design.model_validate(
        TRAIN_DESIGN)).model_dump_json()), **PROFILE})  # fmt: skip
    train = validated_runup({"design": TRAIN_DESIGN, **PROFILE})
    own = RunupRequest.model

    def stiffened(request: RunupRequest):
        if request.design is None or request.design.train is None:
            return own(request)
        model, conversion = train_of(request.design)
        return train_system(model.stiffened(1e6), conversion), conversion

    monkeypatch.setattr(RunupRequest, "model", stiffened)
    expected, got = run_local(pair), run_local(train)
    assert expected.up is not None and got.up is not None
    assert len(got.up.bins) == len(expected.up.bins) == 10
    for mine, theirs in zip(got.up.bins, expected.up.bins, strict=True):
        assert mine.speed_rpm == theirs.speed_rpm
        assert mine.contact == theirs.contact == "separation", (mine, theirs)
        assert mine.dte_peak_to_peak_um == pytest.approx(theirs.dte_peak_to_peak_um, rel=0.01)
        assert mine.dynamic_factor == pytest.approx(theirs.dynamic_factor, rel=0.01)
        # the tooth contact force (0 while apart) beside the model's force, as the pair's
        assert mine.contact_force_max_n == pytest.approx(theirs.contact_force_max_n, rel=0.01)
        assert mine.contact_force_min_n == pytest.approx(theirs.contact_force_min_n, abs=1e-9)
        assert mine.separation_fraction == pytest.approx(theirs.separation_fraction, abs=0.02)
        error = 3.0 * math.hypot(mine.lle_stderr, theirs.lle_stderr)
        assert abs(mine.lle - theirs.lle) <= error, (mine.lle, theirs.lle, error)
    assert "RK4 of the gear train" in got.method.integration
    assert any("gear train" in note for note in got.notes)


def test_train_runup_is_accepted_by_the_api(tmp_path: Path) -> None:
    """POST /v1/runups with a design with ``train`` is a job (it was a 422 naming
    design.train), and its method names the train's kernel."""
    app = create_app(Settings(data_dir=tmp_path, workers=0))
    body = {"design": {**TRAIN_DESIGN, "train": {k: v for k, v in EXAMPLE_TRAIN.items()
                                                 if k != "bearings"}},
            "from_speed": "2000 rpm", "to_speed": "2200 rpm", "rate": "20000 rpm/s",
            "ensemble": {"size": 1}}  # fmt: skip
    with TestClient(app) as client:
        r = client.post("/v1/runups", json=body)
    assert r.status_code in (200, 202), r.text


def test_a_train_ramp_without_acceleration_is_its_stationary_run() -> None:
    """beta = 0, no torque ramp: the ramp kernel over 20 periods T0 from a state gives the
    stationary kernel's extremes of delta and of the mesh force, block by block (one block a
    period), to rounding: the forcing by order of the driver angle (TE in delta, torque
    fluctuation on the motor) and the mean force through ``load`` are the stationary ones."""
    design = Design.model_validate({**TRAIN_DESIGN, "torque_fluctuation": {
        "order": 2, "harmonics": [{"amplitude": "4 N*m"}]}})  # fmt: skip
    system, conv = RunupRequest.model_validate({"design": design}).model()
    plan = system.plan(128)
    wn = 1.0 / conv.time_scale_s
    forcing = ramp_forcing(conv.params, design.speed, wn)
    record = np.array([conv.params.mean_force, 0.0, design.speed / wn, 0.0, 0.0])
    state = system.ramp_start(0.5, 0.1)
    start = np.concatenate([state[0], state[1]])
    run = system.integrate(plan, start, 0, 20, 1)
    table, done = system.run_ramp(state, forcing.kc, forcing.fc, record, 0.0, plan.h, 20,
                                  plan.steps)  # fmt: skip
    assert done == 20
    steps = run.hx.reshape(20, plan.steps)
    assert np.allclose(table[:, 0], steps.min(axis=1), rtol=0, atol=1e-9)
    assert np.allclose(table[:, 1], steps.max(axis=1), rtol=0, atol=1e-9)
    assert table[:, 3].max() == pytest.approx(run.fmax, rel=1e-9)


def test_a_train_run_up_builds_its_system_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The train's ``TrainSystem`` is built when its request is validated and carried: the
    budget check and every plan read that one (each ``runup_plan`` built it again before)."""
    import gearengine.studies.runup.request as runup_request
    from gearengine.studies.runup.profile import runup_plan

    built: list[object] = []
    build = runup_request.design_model

    def counted(design: Design) -> tuple:
        built.append(design)
        return build(design)

    monkeypatch.setattr(runup_request, "design_model", counted)
    request = validated_runup({"design": TRAIN_DESIGN, **PROFILE})  # the budget: one plan
    first, again = runup_plan(request), runup_plan(request)
    assert first.system is again.system
    assert len(built) == 1
