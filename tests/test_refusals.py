"""Refusals that name the field at fault, before any compute (issue 30 item 7)."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
from pydantic import ValidationError

from gearengine.cli.main import main
from gearengine.model.design import Design
from tests.test_robustness import DESIGN

GEOMETRY = {
    "driver": {"teeth": 18, "module": "3 mm", "face_width": "25 mm"},
    "driven": {"teeth": 30, "module": "3 mm", "face_width": "25 mm"},
    "speed": "3000 rpm",
    "torque": "60 N*m",
    "mesh": {"stiffness": "iso6336", "damping_ratio": 0.04, "half_backlash": "50 um"},
}


def _errors(doc: dict) -> list[dict]:
    with pytest.raises(ValidationError) as err:
        Design.model_validate(doc)
    return err.value.errors()


def test_robustness_with_radii_off_the_tooth_ratio_is_422_naming_the_field(client) -> None:
    design = copy.deepcopy(DESIGN)
    design["driven"]["base_radius"] = "80 mm"
    answer = client.post("/v1/robustness", json={"design": design, "samples": 8})
    assert answer.status_code == 422
    assert [e["path"] for e in answer.json()["errors"]] == ["design.driven.base_radius"]


def test_a_bare_module_of_2_5_is_refused_as_a_module() -> None:
    doc = copy.deepcopy(GEOMETRY)
    doc["driver"]["module"] = 2.5
    (error,) = _errors(doc)
    assert error["loc"] == ("driver", "module")
    assert "2.5 m is outside the plausible range of a module" in error["msg"]
    assert "did you mean 2.5 mm?" in error["msg"]


def test_a_negative_backlash_gets_no_unit_guess() -> None:
    doc = copy.deepcopy(GEOMETRY)
    doc["mesh"]["half_backlash"] = "-50 um"
    (error,) = _errors(doc)
    assert error["loc"] == ("mesh", "half_backlash")
    assert "is negative; a half backlash is a positive magnitude" in error["msg"]
    assert "did you mean" not in error["msg"]


@pytest.fixture()
def design_file(tmp_path: Path) -> Path:
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": DESIGN}))
    return path


def test_cli_check_refuses_1e8_points_before_computing(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    big = ["--speed", "1000:6000", "--speed-points", "10000",
           "--torque", "5:60", "--torque-points", "10000"]  # fmt: skip
    assert main(["check", str(design_file), *big]) == 2
    assert "this envelope check has 100000000 points, the limit is 40000" in (
        capsys.readouterr().err
    )
    gate = ["--max-probability", "chaotic=0.4", "--samples", "8"]
    assert main(["check", str(design_file), *big, *gate]) == 2
    assert "this robustness study has 100000000 points" in capsys.readouterr().err


def test_cli_check_refuses_work_over_the_job_budget(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """40 000 points x 256 starts x (60 + 60) periods x 128 steps = 1.6e11 RK4 steps, over the
    2e10 the API allows a job (the points alone are within its 40 000)."""
    many = ["--speed", "1000:6000", "--speed-points", "200", "--torque", "5:60",
            "--torque-points", "200", "--starts", "256"]  # fmt: skip
    assert main(["check", str(design_file), *many]) == 2
    err = capsys.readouterr().err
    assert "over the budget of 20000000000 RK4 steps per job" in err
    assert " min on two cores" not in err  # 2.07e10 steps were "about 1 min"; 1.08e10 took 98 s
    assert (
        "40000 points x 257 starts (256 basin starts and the settings' own start) = "
        "10280000 runs; the budget "
        "allows 2236 points"
        in err  # the slow end's steps resolve the contact (test_step_resolution)
    )


def test_a_torque_axis_through_zero_is_refused_before_any_compute() -> None:
    """A torque range through 0 N*m passed the corner checks (-5 and 5 N*m were valid designs;
    a negative mean torque is refused now) and crashed at its middle point, 0 N*m, where the
    ISO 6336 stiffness has no load (the CLI printed a traceback, exit 70; the API took the
    job); 0:5 N*m was refused under the speed axis. Both are refused naming the torque axis,
    the value and the way out."""
    from gearengine.studies.sweep import validated
    from tests.conftest import ROOT

    design = json.loads((ROOT / "examples/remedies-z23-67.json").read_text())["design"]

    def refusal(torque: tuple[str, str]) -> list[dict]:
        axes = [
            {"parameter": "speed", "start": "1000 rpm", "stop": "6000 rpm", "num": 3},
            {"parameter": "torque", "start": torque[0], "stop": torque[1], "num": 3},
        ]
        with pytest.raises(ValidationError) as err:
            validated({"design": design, "axes": axes})
        return err.value.errors(include_url=False)

    (e,) = refusal(("-5 N*m", "5 N*m"))  # a negative mean torque is refused at the corner
    assert e["loc"] == ("axes", 1, "start") and "-5 N*m is negative; a mean torque" in e["msg"]
    (e,) = refusal(("0 N*m", "5 N*m"))
    assert e["loc"] == ("axes", 1, "start") and "positive tangential load" in e["msg"]


CLASS_WORDS = "ISO 1328-1:2013 flank tolerance class is a whole number from 1 (finest) to 11"


def test_an_accuracy_class_as_text_is_refused_saying_what_is_accepted(
    client, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``"accuracy_class": "7"`` got pydantic's "Input should be a valid integer" (review of issue
    30): the library, the API (422 naming the field) and the CLI say that a class is a whole
    number 1..11 written as a number; so does the robustness tolerances' ``class``."""
    doc = {**copy.deepcopy(GEOMETRY), "transmission_error": {"accuracy_class": "7"}}
    (error,) = _errors(doc)
    assert error["loc"] == ("transmission_error", "accuracy_class")
    assert CLASS_WORDS in error["msg"] and "the number 7, not the text '7'" in error["msg"]
    for bad in (12, 7.5, True):
        doc["transmission_error"]["accuracy_class"] = bad
        assert CLASS_WORDS in _errors(doc)[0]["msg"]
    doc["transmission_error"]["accuracy_class"] = 7.0  # a whole number, as JSON Schema counts
    assert Design.model_validate(doc).transmission_error.harmonics is not None
    doc["transmission_error"]["accuracy_class"] = "7"
    answer = client.post("/v1/conversions/design", json={"design": doc})
    assert answer.status_code == 422
    assert answer.headers["content-type"].startswith("application/problem+json")
    (problem,) = answer.json()["errors"]
    assert problem["path"] == "design.transmission_error.accuracy_class"
    assert CLASS_WORDS in problem["message"]
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": doc}))
    assert main(["convert", str(path)]) == 2
    err = capsys.readouterr().err
    assert "design.transmission_error.accuracy_class" in err and CLASS_WORDS in err
    robust = copy.deepcopy(DESIGN)
    robust["tolerances"]["accuracy"]["class"] = "7"
    answer = client.post("/v1/robustness", json={"design": robust, "samples": 8})
    assert answer.status_code == 422 and CLASS_WORDS in answer.json()["errors"][0]["message"]
