"""Engine input errors are typed objects (``model.errors.InputError``): the service and the CLI
read the field from the object, never from the message's text."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from gearengine.homoclinic.thresholds import threshold_curve
from gearengine.jsonio import error_lines
from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.model.errors import InputError
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.params import GearParams
from gearengine.model.reduction import ParamsOrDesign
from gearengine.model.standards.backlash import half_backlash_band
from service.api.deps import engine_refusal

ROBUSTNESS_EXAMPLE = Path(__file__).parents[1] / "examples" / "robustness-gears.json"


def test_a_design_s_inconsistent_radii_name_the_field(client: TestClient) -> None:
    """Raised in a model validator: pydantic keeps the object, the 422 names its field (before:
    path "(body)", pointer "/", the field only inside the message)."""
    design = copy.deepcopy(EXAMPLE_DESIGN)
    design["driven"]["base_radius"] = "60 mm"
    r = client.post("/v1/melnikov", json={"design": design})
    assert r.status_code == 422
    (error,) = r.json()["errors"]
    assert error["path"] == "design.driven.base_radius"
    assert error["pointer"] == "/design/driven/base_radius"
    assert error["message"].startswith("base radii ratio r_a / r_b = 0.5000 differs")


def test_cli_lines_name_the_field_too() -> None:
    design = copy.deepcopy(EXAMPLE_DESIGN)
    design["speed_range"] = ["3000 rpm", "1000 rpm"]
    try:
        ParamsOrDesign.model_validate({"design": design})
    except ValueError as exc:
        lines = error_lines(exc)  # type: ignore[arg-type]
    assert lines == ["design.speed_range: the first speed must be below the second"]


def test_the_refusal_takes_the_path_from_the_object_not_the_text() -> None:
    """A message that itself holds a colon is not cut there."""
    problem = engine_refusal(InputError("steps_per_period", "ratio 3:1 needs more steps")).problem
    assert [e.path for e in problem.errors] == ["steps_per_period"]
    assert problem.errors[0].pointer == "/steps_per_period"
    assert engine_refusal(InputError("", "no field: refused")).problem.errors == []


def test_an_iso1328_input_outside_its_range_names_the_gear_s_field(client: TestClient) -> None:
    """Raised by the standard inside the design's conversion: before, path "(body)", pointer "/"."""
    design = json.loads(ROBUSTNESS_EXAMPLE.read_text())["design"]  # ISO 1328 class 7
    design["driven"]["module"] = design["driver"]["module"] = "80 mm"
    r = client.post("/v1/analyses", json={"design": design})
    assert r.status_code == 422
    (error,) = r.json()["errors"]
    assert (error["path"], error["pointer"]) == ("design.driver.module", "/design/driver/module")
    assert error["message"].startswith("module: 80 is outside the range of ISO 1328-1:2013")


@pytest.mark.parametrize(
    ("backlash", "mean_force", "path"),
    [({"model": "cubic", "a": -1.0}, 0.1, "params.backlash"), (None, 50.0, "params.mean_force")],
)
def test_threshold_refusals_are_typed(
    client: TestClient, backlash: dict | None, mean_force: float, path: str
) -> None:
    """The engine raises ``InputError`` (no message prefix to parse); the 422 says where."""
    params = {**PAPER_SECTION_41, "mean_force": mean_force}
    params |= {"backlash": backlash} if backlash else {}
    with pytest.raises(InputError) as raised:
        threshold_curve(GearParams.model_validate(params), "F_e1", num=3)
    assert raised.value.path == path and not raised.value.message.startswith(path)
    r = client.post("/v1/thresholds", json={"params": params})
    assert r.status_code == 422
    (error,) = r.json()["errors"]
    assert error == {
        "path": path,
        "pointer": "/" + path.replace(".", "/"),
        "message": raised.value.message,
    }


def test_a_backlash_band_out_of_order_is_typed() -> None:
    with pytest.raises(InputError) as raised:
        half_backlash_band(120e-6, 80e-6, 0.35)
    assert raised.value.path == "design.tolerances.backlash"


@pytest.mark.parametrize("route", ["/v1/melnikov", "/v1/robustness"])
def test_a_bore_wider_than_the_gear_is_a_422_naming_the_gear(
    client: TestClient, route: str
) -> None:
    """A bore at or past the reference diameter leaves no disc for the inertia: schemathesis
    found it as a 500 on /v1/robustness, which converts designs after validation."""
    design = copy.deepcopy(EXAMPLE_DESIGN)
    design["driver"] = {"teeth": 18, "module": "3 mm", "face_width": "25 mm", "bore": "60 mm"}
    r = client.post(route, json={"design": design})
    assert r.status_code == 422
    (error,) = r.json()["errors"]
    assert error["path"] == "design.driver" and "bore" in error["message"]
