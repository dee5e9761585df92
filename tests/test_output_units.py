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


def test_a_bare_number_on_a_physical_axis_is_read_with_a_note() -> None:
    """A bare 157 on the speed axis is 157 rad/s (1,499 rpm): read as a design's bare speed is,
    and said so in the result and by the CLI (issue 30 item 2; it was read with no note). Unit
    strings and unitless fields (the damping ratio) get none."""
    request = SweepRequest.model_validate({
        "design": DOC["design"],
        "settings": {"transient_periods": 30, "record_periods": 20, "steps_per_period": 64},
        "axes": [{"parameter": "speed", "start": 157, "stop": "2000 rpm", "num": 2},
                 {"parameter": "mesh.damping_ratio", "start": 0.05, "stop": 0.05, "num": 1}],
    })  # fmt: skip
    result = run_local(request)
    assert result.notes == [
        "axes[0].start (speed): the bare number 157 read as 157 rad/s = 1,499.24 rpm; "
        "write '157 rpm' if rpm was meant"
    ]
    assert json.loads(result.model_dump_json())["notes"] == result.notes
    assert result.points[0].values["speed"] == 157.0


def test_axes_with_units_carry_no_notes(sweep) -> None:
    assert sweep.notes is None


def test_the_lle_columns_name_their_unit_per_unit_tau(sweep) -> None:
    """The CSV's and the DataFrame's ``lle`` had no unit (review of issue 30): the LLE is per
    unit of the dimensionless time tau = omega_n t, titled ``lle [1/tau]`` as docs/units.md
    says, and equal to the JSON's ``lle``."""
    header = next(iter(to_csv(sweep, design=True))).strip().split(",")
    assert {"lle [1/tau]", "lle_stderr [1/tau]"} <= set(header) and "lle" not in header
    frame = sweep.to_pandas()
    assert list(frame["lle [1/tau]"]) == [p.lle for p in sweep.points]
    units = (ROOT / "docs" / "units.md").read_text()
    assert "`lle [1/tau]`" in units


def test_a_one_design_check_reads_the_designs_bare_speed_in_its_si_unit(tmp_path) -> None:
    """``check FILE --torque ...`` takes the design's own speed as the speed axis; a bare number
    there is the design's rad/s (the JSON's SI), while a bare number on the command line is rpm:
    418.879 rad/s was checked at 418.879 rpm (noticed in a review of issue 30)."""
    import math

    from gearengine.cli.main import main

    doc = json.loads((ROOT / "examples" / "remedies-z23-67.json").read_text())
    doc["design"]["speed"] = 4000.0 * 2.0 * math.pi / 60.0
    design, out = tmp_path / "design.json", tmp_path / "report.json"
    design.write_text(json.dumps(doc))
    main(["check", str(design), "--torque", "10:10", "--torque-points", "1", "--starts", "1",
          "--json", str(out)])  # fmt: skip
    point = json.loads(out.read_text())["sweep"]["points"][0]
    assert point["physical"]["speed"] == {"value": pytest.approx(4000.0), "unit": "rpm"}


def test_the_summary_gives_the_encoders_te_beside_the_dte() -> None:
    """ "dynamic transmission error 0.856 µm peak to peak" at 1,000 rpm where the JSON's
    te_with_static_peak_to_peak_um was 23.04 µm (third new-user review): the DTE is the mesh
    deflection's, the static TE excluded, which the summary now says, with the encoders'
    number beside it."""
    from gearengine.analysis import AnalysisRequest, analyze

    result = analyze(AnalysisRequest.model_validate(DOC))
    resp = result.engineering.response
    assert resp.te_with_static_peak_to_peak_um > 1.5 * resp.dte_peak_to_peak_um
    said = (f"dynamic transmission error {resp.dte_peak_to_peak_um:.3g} µm peak to peak (the "
            f"static transmission error excluded; with it {resp.te_with_static_peak_to_peak_um:.3g}"
            " µm, what shaft encoders read)")  # fmt: skip
    assert said in result.engineering.summary
