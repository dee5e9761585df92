"""Request schemas as strict as their validation where JSON Schema can say it (issue 30 item 7):
each body below is refused by the service's model (422) and now by the committed OpenAPI
schema too, so a client or schemathesis learns the rule from the document. Bodies the model
accepts stay valid."""

from __future__ import annotations

import copy
import json
from typing import Any

import jsonschema_rs
import pytest

from gearengine.model.design import EXAMPLE_DESIGN
from tests.conftest import ROOT

SPEC = json.loads((ROOT / "openapi.json").read_text())
GEOMETRY = {"teeth": 23, "module": "2.5 mm", "face_width": "20 mm"}


def valid(name: str, body: Any) -> bool:
    schema = {"$ref": f"#/components/schemas/{name}", "components": SPEC["components"]}
    return jsonschema_rs.validator_for(schema).is_valid(body)


def design(**changes: Any) -> dict[str, Any]:
    """The README's design (its driven inertia in the spelling the schema's pattern knows)."""
    doc = copy.deepcopy(EXAMPLE_DESIGN)
    doc["driven"]["inertia"] = "2e-3 kg*m^2"
    doc.update(changes)
    return doc


TOLERATED = design(tolerances={"mesh.damping_ratio": {"uniform": [0.04, 0.06]}})
SIGNAL = {"values": [0.0, 1.0] * 1024, "sample_rate": "2 kHz"}


SHAFT = {"torsional_stiffness": "3e4 N*m/rad"}
INERTIAL = {"inertia": "2e-3 kg*m^2"}
TRAIN = design(train={"motor": INERTIAL, "input_shaft": SHAFT, "output_shaft": SHAFT,
                      "load": INERTIAL})  # fmt: skip
PARAMS = {"damping": 0.05}
CASES = [  # (schema, accepted body, refused body: the rule)
    ("SimulationSettings", {"initial_states": [[0.1, 0.0]]},
     {"initial_states": [[0.1, 0.0]],
      "random_initial_states": {"count": 2, "box": [[-1, 1], [-1, 1]]}}),
    ("BasinSettings", {"starts": 10, "grid": False}, {"starts": 10}),
    ("RobustnessRequest", {"design": TOLERATED, "samples": 64},
     {"design": TOLERATED, "samples": 100}),
    ("SignalRequest", {"signal": SIGNAL, "speed": "1500 rpm", "teeth": 18},
     {"signal": SIGNAL, "teeth": 18}),
    ("Shaft", SHAFT, {**SHAFT, "length": "0.3 m", "diameter": "30 mm"}),
    ("Design", design(driver=GEOMETRY, driven={**GEOMETRY, "teeth": 67},
                      mesh={**EXAMPLE_DESIGN["mesh"], "stiffness": "iso6336"}),
     design(mesh={**EXAMPLE_DESIGN["mesh"], "stiffness": "iso6336"})),
    ("Design", design(driver=GEOMETRY, driven={**GEOMETRY, "teeth": 67},
                      transmission_error={"accuracy_class": 7}),
     design(transmission_error={"accuracy_class": 7})),
    ("Design", design(),
     design(tolerances={"accuracy": {"standard": "ISO 1328-1:2013", "class": 7}})),
    ("Mesh", {"stiffness": "1e8 N/m", "damping_ratio": 0.05, "backlash": "100 um"},
     {"stiffness": "1e8 N/m", "damping_ratio": 0.05, "backlash": "100 um",
      "half_backlash": "50 um"}),
    # a request that takes a design alone: no params beside it (found by schemathesis)
    ("CampbellRequest", {"design": TRAIN}, {"design": TRAIN, "params": PARAMS}),
    ("DesignRequest", {"design": design()}, {"design": design(), "params": PARAMS}),
    # a request that does not model a gear train refuses design.train (found by schemathesis)
    ("MelnikovRequest", {"design": design()}, {"design": TRAIN}),
    ("ThresholdsRequest", {"design": design(), "parameter": "F_e1"},
     {"design": TRAIN, "parameter": "F_e1"}),
]  # fmt: skip


@pytest.mark.parametrize(("name", "good", "bad"), CASES)
def test_the_schema_refuses_what_the_model_refuses(name: str, good: Any, bad: Any) -> None:
    assert valid(name, good)
    assert not valid(name, bad)


@pytest.mark.parametrize(("name", "good", "bad"), CASES)
def test_the_models_agree(name: str, good: Any, bad: Any) -> None:
    """The same bodies through the service's models: accepted and refused alike."""
    from pydantic import ValidationError

    from gearengine.analysis import DesignRequest
    from gearengine.homoclinic.schemas import MelnikovRequest, ThresholdsRequest
    from gearengine.model.design import Design, Mesh
    from gearengine.model.train import Shaft
    from gearengine.numerics.settings import BasinSettings, SimulationSettings
    from gearengine.signals.series import SignalRequest
    from gearengine.studies.robustness.study import RobustnessRequest, checked
    from gearengine.systems.gear_train.campbell import CampbellRequest

    models = {"SimulationSettings": SimulationSettings, "BasinSettings": BasinSettings,
              "SignalRequest": SignalRequest, "Shaft": Shaft, "Design": Design,
              "Mesh": Mesh, "CampbellRequest": CampbellRequest, "DesignRequest": DesignRequest,
              "MelnikovRequest": MelnikovRequest,
              "ThresholdsRequest": ThresholdsRequest}  # fmt: skip
    validate = models[name].model_validate if name in models else (
        lambda b: checked(RobustnessRequest.model_validate(b)))  # fmt: skip
    validate(good)
    with pytest.raises(ValidationError):
        validate(bad)


def test_the_documented_examples_are_accepted(tmp_path) -> None:
    """Schemathesis' examples phase sends the fields' examples combined: each must pass the
    validation (it found speed_range ['1500 rpm', '1500 rpm'], a 2-row upload, and a constant
    series built from no example)."""
    from fastapi.testclient import TestClient

    from service.core.config import Settings
    from service.main import create_app

    props = SPEC["components"]["schemas"]["Design"]["properties"]
    (array,) = [s for s in props["speed_range"]["anyOf"] if s.get("type") == "array"]
    low, high = array["examples"][0]
    assert float(low.split()[0]) < float(high.split()[0])
    values = SPEC["components"]["schemas"]["Signal"]["properties"]["values"]["examples"][0]
    upload = SPEC["paths"]["/v1/signals/upload"]["post"]["requestBody"]["content"]["text/csv"]
    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0, api_keys=""))) as client:
        body = {"signal": {"values": values, "sample_rate": "20 kHz"}}
        assert client.post("/v1/signals", json=body).status_code == 200
        response = client.post("/v1/signals/upload", content=upload["example"],
                               headers={"content-type": "text/csv"})  # fmt: skip
        assert response.status_code == 200
