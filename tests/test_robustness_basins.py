"""Robustness honours ``settings.basins`` (issue 30 item 5): a sample counts as its worst
attractor above ``basins.min_fraction``, as the gate and the sweep decide a point, not as the
settings' own start.

The pair of ``examples/basins-5750rpm.json`` at 5,750 rpm / 2 N*m: its own start settles on a
period-1 orbit, while 9 of 16 basin starts reach a chaotic attractor
(tests/test_worst_attractor.py).
Its damping ratio is toleranced within 0.1 %, so every sample is that pair."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from gearengine.studies.robustness.study import RobustnessRequest, checked, run_local

ROOT = Path(__file__).resolve().parents[1]
DOC = json.loads((ROOT / "examples" / "basins-5750rpm.json").read_text())
BASINS = {"starts": 16, "box": [["-30 um", "30 um"], ["-250 mm/s", "250 mm/s"]]}


def study(basins: dict | None):
    design = copy.deepcopy(DOC["design"])
    design["tolerances"] = {"mesh.damping_ratio": {"uniform": [0.05, 0.05005]}}
    settings = {k: v for k, v in DOC["settings"].items() if k != "basins"}
    if basins is not None:
        settings["basins"] = basins
    request = checked(RobustnessRequest.model_validate(
        {"design": design, "settings": settings, "samples": 2}))  # fmt: skip
    result = run_local(request)
    (point,) = result.points
    return point, result.model


@pytest.fixture(scope="module")
def with_basins():
    return study(BASINS)


def test_every_sample_counts_as_its_worst_attractor(with_basins):
    point, model = with_basins
    assert point.samples == 2
    assert point.probabilities["chaotic"].count == 2
    assert point.probabilities["periodic"].count == 0
    assert point.probabilities["back_flank"].count == 2  # the chaotic attractor's double-sided
    assert any("16 basin starts per sample" in line for line in model)


def test_a_basin_below_min_fraction_leaves_the_verdict_to_the_start():
    """min_fraction 0.6 is above the chaotic basin's 9/16: the chaotic attractor no longer
    decides, the worst one above 0.6 (or else the settings' own start) does."""
    point, model = study({**BASINS, "min_fraction": 0.6})
    assert point.probabilities["chaotic"].count == 0
    assert any("above 0.6" in line for line in model)


def test_a_pair_that_does_not_mesh_is_refused_naming_the_design(tmp_path) -> None:
    """POST /v1/robustness answered 500 for gears of different modules (the conversion's
    ValueError after validation; schemathesis' stateful phase found it): now 422."""
    from fastapi.testclient import TestClient

    from service.core.config import Settings
    from service.main import create_app

    gear = {"module": "2.5 mm", "face_width": "20 mm"}
    design = {"driver": {"teeth": 23, **gear}, "driven": {"teeth": 67, **gear, "module": "3 mm"},
              "speed": "3000 rpm", "torque": "10 N*m",
              "mesh": {"stiffness": "iso6336", "damping_ratio": 0.05, "half_backlash": "50 um"},
              "tolerances": {"mesh.damping_ratio": {"uniform": [0.04, 0.06]}}}  # fmt: skip
    axis = {"parameter": "speed", "start": "1000 rpm", "stop": "2000 rpm", "num": 2}
    body = {"design": design, "samples": 4, "axes": [axis]}
    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0, api_keys=""))) as client:
        response = client.post("/v1/robustness", json=body)
    assert response.status_code == 422, response.text
    (error,) = response.json()["errors"]
    assert error["path"] == "design" and "same module" in error["message"]
