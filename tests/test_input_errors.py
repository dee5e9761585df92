"""Engine input errors are typed objects (``model.errors.InputError``): the service and the CLI
read the field from the object, never from the message's text."""

from __future__ import annotations

import copy

from fastapi.testclient import TestClient

from gearengine.jsonio import error_lines
from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.model.errors import InputError
from gearengine.model.reduction import ParamsOrDesign
from service.api.deps import engine_refusal


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
