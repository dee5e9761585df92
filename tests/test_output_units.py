"""Units named in the outputs (issue 30 item 6, a new-user review): a sweep's JSON says the
unit of its points' ``values`` (``values.speed`` is rad/s, unnamed before), and a design's CSV
gives the mesh forces in N under titles with their unit, as ``dte [um]``."""

from __future__ import annotations

import json

import pytest

from gearengine.model.reduction import convert_design
from gearengine.studies.sweep import SweepRequest, run_local
from gearengine.studies.sweep.results import to_csv
from tests.conftest import ROOT

DOC = json.loads((ROOT / "examples" / "ci" / "design.json").read_text())


@pytest.fixture(scope="module")
def sweep():
    request = SweepRequest.model_validate({
        "design": DOC["design"],
        "settings": {"transient_periods": 30, "record_periods": 20, "steps_per_period": 64},
        "axes": [{"parameter": "speed", "start": "1500 rpm", "stop": "2000 rpm", "num": 2},
                 {"parameter": "mesh.damping_ratio", "start": 0.05, "stop": 0.05, "num": 1}],
    })  # fmt: skip
    return run_local(request)


def test_the_result_names_the_unit_of_its_values(sweep) -> None:
    assert sweep.values_units == {"speed": "rad/s", "mesh.damping_ratio": "1"}
    document = json.loads(sweep.model_dump_json())
    assert document["values_units"]["speed"] == "rad/s"


def test_the_csv_gives_the_mesh_forces_in_newtons(sweep) -> None:
    scales = convert_design(sweep_design()).scales
    frame = sweep.to_pandas()
    assert {"force_max [N]", "force_min [N]"} <= set(frame.columns)
    for (_, row), p in zip(frame.iterrows(), sweep.points, strict=True):
        newtons = scales.half_backlash * scales.mesh_stiffness
        assert row["force_max [N]"] == pytest.approx(p.force_max * newtons, rel=1e-9)
        assert row["force_min [N]"] == pytest.approx(p.force_min * newtons, rel=1e-9)
    header = next(iter(to_csv(sweep, design=True))).strip().split(",")
    assert header.index("force_max [N]") == header.index("dynamic_factor") + 1


def sweep_design():
    from gearengine.model.design import Design

    return Design.model_validate(DOC["design"])
