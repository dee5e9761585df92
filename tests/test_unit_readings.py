"""No quantity read in a unit the user did not write without a note (issue 30 item 2): "%" only
where a share of a nominal value is meant (a torque ripple of the mean torque, scaling when the
torque is swept), a bare number read in SI units with a note naming the field, and a given
value beside the geometry form used and said so."""

from __future__ import annotations

import contextlib
import copy
import json
import math
from pathlib import Path

import pytest
from pydantic import ValidationError

from gearengine.cli.main import main
from gearengine.gate.envelope import envelope_axis, envelope_sweep
from gearengine.model.design import EXAMPLE_DESIGN, Design
from gearengine.model.fields import design_with
from gearengine.model.reduction import convert_design
from gearengine.studies import jobs
from gearengine.studies.jobs import validated_json
from gearengine.studies.runup.request import RunupRequest
from gearengine.studies.sweep.request import validated
from tests.conftest import ROOT


def _design(**changes: object) -> dict:
    doc = copy.deepcopy(EXAMPLE_DESIGN)
    doc.update(changes)
    return doc


def test_percent_is_refused_where_no_share_is_meant() -> None:
    doc = _design()
    doc["mesh"]["half_backlash"] = "3 %"
    with pytest.raises(ValidationError) as err:
        Design.model_validate(doc)
    ((error,),) = [err.value.errors()]
    assert error["loc"] == ("mesh", "half_backlash")
    assert "'3 %' is a share, not a half backlash" in error["msg"]


def test_torque_ripple_in_percent_is_a_share_of_the_mean_torque() -> None:
    doc = _design(torque_fluctuation={"harmonics": [{"amplitude": "3 %"}]})
    design = Design.model_validate(doc)
    assert design.torque_fluctuation.harmonics[0].amplitude == pytest.approx(1.2)
    notes = convert_design(design).notes
    assert any("3 % read as 1.2 N*m, 3 % of the mean torque 40 N*m" in n for n in notes)
    halved = design_with(design, {"torque": "20 N*m"})  # a torque axis' point
    assert halved.torque_fluctuation.harmonics[0].amplitude == pytest.approx(0.6)


def test_bare_speed_is_read_in_rad_per_s_with_a_note(client) -> None:
    body = {"design": _design(speed=6000)}
    answer = client.post("/v1/conversions/design", json=body)
    assert answer.status_code == 200
    notes = answer.json()["conversion"]["notes"]
    assert any("speed: the bare number 6000 read as 6000 rad/s = 57,295.8 rpm" in n for n in notes)


def test_unit_strings_leave_no_bare_number_note() -> None:
    notes = convert_design(Design.model_validate(_design())).notes
    assert not [n for n in notes if "bare number" in n]


def test_given_inertia_beside_the_geometry_is_used_and_said() -> None:
    gear = {"teeth": 18, "module": "3 mm", "face_width": "25 mm", "inertia": "2e-3 kg*m^2"}
    other = {"teeth": 30, "module": "3 mm", "face_width": "25 mm"}
    doc = _design(driver=gear, driven=other)
    doc["mesh"] = {**doc["mesh"], "stiffness": "iso6336"}
    doc.pop("torque_fluctuation")
    conv = convert_design(Design.model_validate(doc))
    assert conv.derived["inertia_driver"].value == pytest.approx(2e-3)
    assert conv.derived["inertia_driver"].source == "given"
    assert any(n.startswith("driver.inertia: the given 0.002 kg*m^2 is used") for n in conv.notes)


def test_a_bare_speed_over_100000_rpm_is_refused_the_same_way_everywhere(
    client, tmp_path, capsys
) -> None:
    """A bare 20000 is read as rad/s (191,000 rpm): over the plausible 100,000 rpm of a driver,
    refused with the field, the value and the unit in the API, the library and the CLI (whose
    bare --speed is rpm, its documented unit)."""
    answer = client.post("/v1/analyses", json={"design": _design(speed=20000)})
    assert answer.status_code == 422
    (error,) = answer.json()["errors"]
    assert error["path"] == "design.speed"
    assert "20000 rad/s is outside the plausible range of a shaft speed" in error["message"]
    assert "100,000 rpm" in error["message"]
    with pytest.raises(ValidationError, match="20000 rad/s is outside"):
        Design.model_validate(_design(speed=20000))
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": _design()}))
    assert main(["robustness", str(path), "--speed", "1000:150000", "--samples", "2"]) == 2
    assert "--speed (its high end): 150000 rpm is outside the plausible range" in (
        capsys.readouterr().err
    )


def test_a_damping_ratio_in_percent_is_refused_as_a_plain_number(client) -> None:
    doc = _design()
    doc["mesh"]["damping_ratio"] = "5 %"
    with pytest.raises(ValidationError) as err:
        Design.model_validate(doc)
    ((error,),) = [err.value.errors()]
    assert error["loc"] == ("mesh", "damping_ratio")
    assert "a damping ratio is a plain number: write 0.05 for 5 %" in error["msg"]
    answer = client.post("/v1/analyses", json={"design": doc})
    assert answer.status_code == 422
    (problem,) = answer.json()["errors"]
    assert problem["path"] == "design.mesh.damping_ratio"
    assert "write 0.05 for 5 %" in problem["message"]


def test_a_speed_in_hz_is_refused_naming_the_field_everywhere(client, tmp_path, capsys) -> None:
    """pint reads a radian as dimensionless, so "50 Hz" was 50 rad/s (477 rpm) without a word
    where a shaft's 50 Hz is 50 rev/s (3000 rpm): a frequency with no angle is refused naming
    the field and both readings, in the API, the library and the CLI (and a run-up's rate)."""
    said = "'50 Hz' has no angle"
    answer = client.post("/v1/analyses", json={"design": _design(speed="50 Hz")})
    assert answer.status_code == 422
    (error,) = answer.json()["errors"]
    assert error["path"] == "design.speed"
    assert said in error["message"] and "'3000 rpm' or '50 rev/s'" in error["message"]
    for speed in ("50 Hz", "3000 1/min", "0.05 kHz"):
        with pytest.raises(ValidationError, match="has no angle") as err:
            Design.model_validate(_design(speed=speed))
        assert err.value.errors()[0]["loc"] == ("speed",)
    with pytest.raises(ValidationError, match="'600 rpm/s' or '10 rev/s\\^2'"):
        RunupRequest.model_validate({"design": _design(), "from_speed": "1000 rpm",
                                     "to_speed": "2000 rpm", "rate": "10 Hz/s"})  # fmt: skip
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": _design()}))
    assert main(["check", str(path), "--speed", "10Hz:100Hz", "--starts", "1"]) == 2
    assert "--speed (its low end): '10Hz' has no angle" in capsys.readouterr().err


@pytest.mark.parametrize("speed", ["3000 rev/min", "50 rev/s", "50 rps", "314.159265 rad/s"])
def test_revolutions_per_time_are_read_as_written(speed: str) -> None:
    assert Design.model_validate(_design(speed=speed)).speed == pytest.approx(100 * math.pi)


def test_digits_split_by_a_comma_or_a_space_are_refused_everywhere(
    client, tmp_path, capsys
) -> None:
    """pint read "2,5 mm" as 25 mm, "1 500 rpm" as 500 rpm, and a sweep end "12,5 N*m" as
    12 (second new-user review): a decimal comma or a thousands space is refused naming the
    field, in the API, the library and the CLI's options."""
    said = "write the number with a decimal point and no separators"
    answer = client.post("/v1/analyses", json={"design": _design(speed="1 500 rpm")})
    assert answer.status_code == 422
    (error,) = answer.json()["errors"]
    assert error["path"] == "design.speed" and said in error["message"]
    driver = {**EXAMPLE_DESIGN["driver"], "base_radius": "2,5 mm"}
    with pytest.raises(ValidationError, match=said) as err:
        Design.model_validate(_design(driver=driver))
    assert err.value.errors()[0]["loc"] == ("driver", "base_radius")
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": _design()}))
    for option in (["--torque", "12,5:30"], ["--speed", "2,5krpm:3krpm"], ["--max-dte", "1,5um"]):
        with contextlib.suppress(SystemExit):  # argparse exits 2 on an option it refuses
            assert main(["check", str(path), *option, "--starts", "1"]) == 2
        assert said in capsys.readouterr().err


def test_the_text_says_how_a_bare_design_speed_was_read(tmp_path, capsys) -> None:
    """A bare design speed is rad/s (the JSON's SI), noted in the JSON only: ``analyze`` and
    ``check`` said nothing in their text, where a bare --speed is rpm (second new-user
    review). Both now say the reading."""
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": _design(speed=300)}))
    said = "speed: the bare number 300 read as 300 rad/s = 2,864.79 rpm"
    assert main(["analyze", str(path)]) == 0
    assert f"note: {said}" in capsys.readouterr().out
    main(["check", str(path)])
    assert f"note: {said}" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("command", "options", "refused"),
    [
        ("check", ["--speed", "1000:6000", "--torque", "5%:60%"], "--torque (its low end): '5%'"),
        ("check", ["--speed", "1000:6000", "--torque=5:60%"], "--torque (its high end): '60%'"),
        ("check", ["--speed=50%:100%"], "--speed (its low end): '50%'"),
        ("robustness", ["--speed", "1000:6000", "--torque", "5:60%"], "--torque (its high end)"),
        ("remedies", ["--speed", "1000:6000", "--torque", "5%:60"], "--torque: '5%'"),
        ("runup", ["--from", "1000", "--to", "2000", "--rate", "5%"], "--rate: '5%'"),
        ("runup", ["--from", "10%", "--to", "2000", "--rate", "500"], "--from: '10%'"),
    ],
)
def test_a_share_is_refused_in_every_cli_quantity_option(
    client, tmp_path, capsys, command: str, options: list[str], refused: str
) -> None:
    """``--torque 5%:60%`` ran the envelope at 0.05 and 0.6 N*m without a word, and
    ``--torque=5:60%`` from 5 to 0.6 N*m ("5%" got the option's unit appended: "5% N*m",
    which pint reads as 0.05 N*m), where the API refuses "5 %" on a torque axis: a share is
    refused in every dimensional option, naming the option, as in the API and the library."""
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": _design()}))
    assert main([command, str(path), *options]) == 2
    err = capsys.readouterr().err
    assert refused in err and "is a share, not a" in err
    axis = {"parameter": "torque", "start": "5 %", "stop": "60 N*m", "num": 2}
    answer = client.post("/v1/sweeps", json={"design": _design(), "axes": [axis]})
    assert answer.status_code == 422 and "is a share" in answer.text
    with pytest.raises(ValidationError, match="is a share, not a torque"):
        validated(envelope_sweep(_design(), None, [envelope_axis("torque", "5:60%", "N*m", 2)],
                                 "x"))  # fmt: skip


def test_a_bare_number_in_exponent_form_is_in_the_option_s_unit() -> None:
    """A bare "1e3" holds a letter, so it kept no unit and was read in SI units (1000 rad/s = 9549
    rpm) where "1000" is 1000 rpm."""
    assert envelope_axis("speed", "1e3:6e3", "rpm", 2)["start"] == "1e3 rpm"
    assert envelope_axis("speed", "52 rad/s:6e3", "rpm", 2)["start"] == "52 rad/s"


@pytest.mark.parametrize(
    ("fields", "path"),
    [
        ({"rate": 2000}, "rate"),
        ({"rate": "2000"}, "rate"),
        ({"from_speed": 500, "rate": "1000 rpm/s"}, "from_speed"),
        ({"to_speed": "6000", "rate": "1000 rpm/s"}, "to_speed"),
    ],
)
def test_a_run_up_s_bare_rate_or_speed_is_refused_with_its_unit(
    client, tmp_path, capsys, fields: dict, path: str
) -> None:
    """A bare ``"rate": 2000`` was read as 2000 rad/s^2 (a 0.26 s ramp from 1000 to 6000 rpm)
    with no note, where the CLI's ``--rate 2000`` is rpm/s (2.5 s), and the run-up's answer
    has no notes of the request's readings: a bare number in a run-up's rate and speeds is
    refused naming the field and both units, in the API, the library and a file given to the
    CLI; a stored request's SI numbers are read back (``jobs.validated_json``)."""
    body = {"design": _design(), "from_speed": "1000 rpm", "to_speed": "6000 rpm", **fields}
    answer = client.post("/v1/runups", json=body)
    assert answer.status_code == 422
    (error,) = answer.json()["errors"]
    assert error["path"] == path and "has no unit" in error["message"]
    with pytest.raises(ValidationError, match="has no unit: a"):
        RunupRequest.model_validate(body)
    file = tmp_path / "runup.json"
    file.write_text(json.dumps(body))
    assert main(["runup", str(file)]) == 2
    assert f"{path}: the bare number" in capsys.readouterr().err
    good = RunupRequest.model_validate({**body, "rate": "2000 rpm/s", "from_speed": "1000 rpm",
                                        "to_speed": "6000 rpm"})  # fmt: skip
    again = validated_json(jobs.kind("runup"), good.model_dump_json())
    assert again.rate == pytest.approx(good.rate) and again.leg_seconds() == pytest.approx(2.5)


def test_a_negative_mean_torque_is_refused_saying_the_response_mirrors(
    client, tmp_path, capsys
) -> None:
    """A design torque of "-20 N*m" was read (convert exit 0, the API 200) and its Melnikov
    answer was +20 N*m's, unsaid, where the documented range is 0 .. 1e6 N*m: a negative mean
    torque is refused naming the field and why (the backlash is symmetric: a reversed torque
    mirrors the response), in the API, the library, the CLI and a sweep's torque axis."""
    said = "-20 N*m is negative; a mean torque is a magnitude"
    answer = client.post("/v1/conversions/design", json={"design": _design(torque="-20 N*m")})
    assert answer.status_code == 422
    (error,) = answer.json()["errors"]
    assert error["path"] == "design.torque" and said in error["message"]
    assert "mirrors the response" in error["message"] and "'20 N*m'" in error["message"]
    for field in ("torque", "braking_torque"):
        with pytest.raises(ValidationError, match="is negative; a mean torque") as err:
            Design.model_validate(_design(**{field: -20}))
        assert err.value.errors()[0]["loc"] == (field,)
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": _design(torque="-20 N*m")}))
    assert main(["convert", str(path)]) == 2
    assert f"design.torque: {said}" in capsys.readouterr().err
    path.write_text(json.dumps({"design": _design()}))
    assert main(["check", str(path), "--speed", "1000:2000", "--torque=-5:60"]) == 2
    assert "--torque (its low end): -5 N*m is negative" in capsys.readouterr().err
    assert Design.model_validate(_design(torque=0)).torque == 0.0


def test_a_design_validated_again_keeps_its_readings_and_the_run_up_says_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A run-up of a design with a bare torque printed no note: its request was validated
    again inside the run, and a Design handed back through its validator had its readings
    (and its ripple shares in % of the mean torque) reset to those of no text. A Design given
    again is now itself, and ``gearengine runup`` prints the design's readings."""
    doc = json.loads((ROOT / "examples" / "ci" / "design.json").read_text())
    doc["design"]["torque"] = 40
    design = Design.model_validate(doc["design"])
    said = "torque: the bare number 40 read as 40 N*m"
    assert said in design.readings
    assert Design.model_validate(design).readings == design.readings
    path = tmp_path / "bare.json"
    path.write_text(json.dumps(doc))
    argv = ["runup", str(path), "--from", "3500", "--to", "3600", "--rate", "2000",
            "--direction", "up"]  # fmt: skip
    assert main(argv) == 0
    assert f"note: {said}" in capsys.readouterr().out


def test_a_text_is_read_by_pint_once_and_noted_every_time_it_is_read(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A design validated again for every envelope point reads the same texts: pint reads a
    text once per process, while each read still gets its note (a respelled unit, a bare
    number) and its range check."""
    from gearengine.model.units import quantities

    kind = quantities.QUANTITIES["torque"]
    quantities._text_readings.clear()
    read: list[str] = []
    first = quantities._text_reading
    monkeypatch.setattr(quantities, "_text_reading",
                        lambda text, k: read.append(text) or first(text, k))  # fmt: skip
    for _ in range(2):
        with quantities.readings() as notes:
            assert quantities.parse_quantity("40 Nm", kind) == pytest.approx(40.0)
            assert quantities.parse_quantity("12", kind) == 12.0
        assert notes[0] == "torque '40 Nm' read as '40 N*m'" and "bare number 12" in notes[1]
    assert read == ["40 N*m", "12"]
    assert quantities.parse_quantity("2 m", quantities.QUANTITIES["length"]) == 2.0
    with pytest.raises(ValueError):  # the same text read, out of a module's range
        quantities.parse_quantity("2 m", quantities.QUANTITIES["module"])
    assert read[-1] == "2 m" and read.count("2 m") == 1


def test_the_kept_readings_are_bounded_oldest_out_and_refusals_never_kept(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Past ``TEXT_READINGS`` texts the oldest reading is let go (insertion order), the same
    value still comes back for it, read by pint again; a text pint refuses is not kept."""
    from gearengine.model.units import quantities

    kind = quantities.QUANTITIES["torque"]
    quantities._text_readings.clear()
    monkeypatch.setattr(quantities, "TEXT_READINGS", 2)
    for text in ("10 N*m", "20 N*m", "30 N*m"):
        quantities.parse_quantity(text, kind)
    assert [k[0] for k in quantities._text_readings] == ["20 N*m", "30 N*m"]
    assert quantities.parse_quantity("10 N*m", kind) == pytest.approx(10.0)
    assert [k[0] for k in quantities._text_readings] == ["30 N*m", "10 N*m"]
    with pytest.raises(ValueError, match="dimension"):
        quantities.parse_quantity("3 kg", kind)
    assert [k[0] for k in quantities._text_readings] == ["30 N*m", "10 N*m"]
    quantities._text_readings.clear()
