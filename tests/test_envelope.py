"""The operating envelope: physical sweep axes, one Melnikov boundary, speed windows, the CI
gate over speed x torque (exit codes, JUnit, --server) and the CI examples as written."""

from __future__ import annotations

import copy
import json
import math
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
import xmlschema
from pydantic import ValidationError

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.gate.envelope import check_envelope, check_or_failures, envelope_report
from gearengine.gate.rules import Rules
from gearengine.homoclinic import melnikov
from gearengine.homoclinic.boundary import flips
from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.studies.sweep import run_local, validated
from tests.conftest import PAPER_PARAMS, ROOT, Server

LIGHT = {"transient_periods": 60, "record_periods": 60, "steps_per_period": 128}


def rattling() -> dict:
    """The README design with 5 µm half backlash, 10 µm transmission error and 1 N m: it
    rattles on both flanks and is chaotic at some speeds between 1000 and 2000 rpm."""
    d = copy.deepcopy(EXAMPLE_DESIGN)
    d["mesh"]["half_backlash"] = "5 um"
    d["torque"] = "1 N*m"
    d["transmission_error"]["harmonics"][0]["amplitude"] = "10 um"
    return d


def speed_sweep(design: dict, lo: str, hi: str, num: int, **more: object) -> dict:
    axes = [{"parameter": "speed", "start": lo, "stop": hi, "num": num}]
    return {"design": design, "settings": LIGHT, "axes": axes, **more}


def test_speed_sweep_points_are_single_analyses_at_that_speed() -> None:
    req = validated(speed_sweep(EXAMPLE_DESIGN, "500 rpm", "6000 rpm", 4))
    result = run_local(req)
    for p in result.points:
        d = copy.deepcopy(EXAMPLE_DESIGN)
        d["speed"] = f"{p.physical['speed'].value} rpm"
        single = analyze(AnalysisRequest.model_validate({"design": d, "settings": LIGHT}))
        assert (p.classification, p.period) == (single.numerics.classification,
                                                single.numerics.period)  # fmt: skip
        assert p.melnikov_chaos_possible == single.melnikov.chaos_possible
        dte = single.engineering.response.dte_peak_to_peak_um
        assert p.physical["dte"].value == pytest.approx(dte, rel=1e-9)
    assert [p.physical["speed"].value for p in result.points] == [
        500,
        2333.33333333,
        4166.66666667,
        6000,
    ]


def test_sweep_boundary_is_the_melnikov_verdict_of_each_point() -> None:
    """The thresholds drawn on a speed sweep are where /v1/melnikov flips for the same design
    (lightly loaded: at 40 N m the README design is above its critical torque, 9.62 N m)."""
    light = copy.deepcopy(EXAMPLE_DESIGN)
    light["torque"] = "3 N*m"
    light["torque_fluctuation"]["harmonics"][0]["amplitude"] = "1 N*m"
    req = validated(speed_sweep(light, "500 rpm", "6000 rpm", 3))
    crossings = flips(lambda v: req.point({"speed": v}), 52.36, 628.3, 60)
    assert len(crossings) == 2
    for edge in crossings:
        below, above = (
            melnikov(req.point({"speed": edge * f})).chaos_possible for f in (0.999, 1.001)
        )
        assert below != above


def test_axes_that_change_nothing_or_need_a_design_are_refused() -> None:
    only_k = {"damping": 0.1, "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.1}]}}
    with pytest.raises(ValidationError, match="changes nothing"):
        validated(
            {
                "params": only_k,
                "axes": [{"parameter": "Omega_e", "start": 0.1, "stop": 1, "num": 3}],
            }
        )
    with pytest.raises(ValidationError, match="need a design"):
        validated(
            {
                "params": PAPER_PARAMS,
                "axes": [{"parameter": "speed", "start": 1, "stop": 2, "num": 2}],
            }
        )
    with pytest.raises(ValidationError, match="1 / \\[time\\]"):
        validated(speed_sweep(EXAMPLE_DESIGN, "500 mm", "6000 rpm", 3))
    with pytest.raises(ValidationError, match="no field"):
        validated({**speed_sweep(EXAMPLE_DESIGN, "1 rpm", "2 rpm", 2), "axes": [
            {"parameter": "mesh.nothing", "start": 1, "stop": 2, "num": 2}]})  # fmt: skip


def test_omega_axis_scales_every_frequency() -> None:
    p = {**PAPER_PARAMS, "torque": {"frequency": 0.25, "harmonics": [{"amplitude": 0.01}]}}
    req = validated(
        {"params": p, "axes": [{"parameter": "Omega", "start": 0.5, "stop": 1.0, "num": 2}]}
    )
    at = req.point({"Omega": 1.0})
    assert at.transmission_error.frequency == 1.0 and at.torque.frequency == 0.5


def test_windows_and_failing_windows_of_a_rattling_design() -> None:
    doc = speed_sweep(rattling(), "1000 rpm", "2000 rpm", 6)
    doc["axes"].append({"parameter": "torque", "start": "1 N*m", "stop": "3 N*m", "num": 2})
    result = run_local(validated(doc))
    assert [w.level["torque"].value for w in result.windows] == [1.0, 3.0]
    assert result.windows[0].contact == {
        "separation": [[1000.0, 2000.0]],
        "back_flank": [[1000.0, 2000.0]],
    }
    report = envelope_report(result, Rules())
    assert not report.passed and report.failing_points == sum(
        p.classification == "chaotic" for p in result.points
    )
    chaotic = {tuple(s) for w in result.windows for s in w.response.get("chaotic", [])}
    assert {tuple(f.speeds_rpm) for f in report.failures} == chaotic
    assert envelope_report(result, Rules(fail_on=["diverged"])).passed
    back = envelope_report(result, Rules(fail_on=["diverged", "back_flank"]))
    assert {f.rule for f in back.failures} == {"back-flank impacts"}


def test_pass_or_fail_stops_at_the_first_failing_chunk(monkeypatch: pytest.MonkeyPatch) -> None:
    """``check_or_failures`` (a remedies bisection step) runs the chunks holding the points
    expected to fail first and stops at the first chunk with a failure; a grid that passes
    gives ``check_envelope``'s report, byte for byte."""
    from gearengine.studies import jobs

    doc = speed_sweep(rattling(), "1000 rpm", "2000 rpm", 6)
    doc["axes"].append({"parameter": "torque", "start": "1 N*m", "stop": "3 N*m", "num": 2})
    request = validated(doc)
    full = check_envelope(request, Rules())
    assert not full.passed
    last = next(p for p in reversed(full.sweep.points) if p.classification == "chaotic")
    ran: list[int] = []
    compute = jobs.compute_chunk_json
    monkeypatch.setattr(jobs, "compute_chunk_json", lambda *a: ran.append(a[2]) or compute(*a))
    failing = check_or_failures(request, Rules(), first=[last.values])
    assert isinstance(failing, list) and last.values in [p.values for p in failing]
    assert ran == [full.sweep.points.index(last) // 3]  # the chunk (of 3 points) holding it
    passing = Rules(fail_on=["diverged"])
    report = check_or_failures(request, passing)
    assert not isinstance(report, list)
    assert report.model_dump_json() == check_envelope(request, passing, refine_failing=False
                                                      ).model_dump_json()  # fmt: skip


def gearengine(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "gearengine.cli", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=600)  # fmt: skip


def test_gate_exit_codes_and_junit(tmp_path: Path) -> None:
    bad = tmp_path / "rattling.json"
    bad.write_text(json.dumps({"design": rattling(), "settings": LIGHT}))
    junit = tmp_path / "envelope.xml"
    out = gearengine("check", str(bad), "--speed", "1000:2000", "--speed-points", "6",
                     "--torque", "1:3", "--torque-points", "2", "--junit", str(junit),
                     "--refine", "0")  # the grid's two torque levels only  # fmt: skip
    assert out.returncode == 1, out.stderr
    assert out.stdout.startswith("FAIL") and "chaotic at" in out.stdout and "rpm" in out.stdout
    schema = xmlschema.XMLSchema(ROOT / "tests" / "data" / "junit.xsd")
    schema.validate(junit)
    assert junit.read_text().count("<testcase ") == 2 and "<failure " in junit.read_text()
    good = tmp_path / "damped.json"
    damped = copy.deepcopy(EXAMPLE_DESIGN)
    good.write_text(json.dumps({"design": damped, "settings": LIGHT}))
    out = gearengine("check", str(good), "--speed", "500:6000", "--speed-points", "5",
                     "--torque", "20 N*m:200 N*m", "--torque-points", "2",
                     "--max-lle", "0.01")  # fmt: skip
    assert out.returncode == 0 and out.stdout.startswith("PASS"), out.stdout + out.stderr
    out = gearengine("check", str(good), "--speed", "500:6000", "--speed-points", "3",
                     "--max-dte", "1um")  # fmt: skip
    assert out.returncode == 1 and "DTE > 1 µm" in out.stdout
    out = gearengine("check", str(good), "--speed", "500mm:6000")
    assert out.returncode == 2 and "--speed (its low end)" in out.stderr


def test_server_gives_the_same_report(tmp_path: Path) -> None:
    bad = tmp_path / "rattling.json"
    bad.write_text(json.dumps({"design": rattling(), "settings": LIGHT}))
    args = ["check", str(bad), "--speed", "1000:2000", "--speed-points", "4", "--torque", "1:3",
            "--torque-points", "2"]  # fmt: skip
    local, remote = tmp_path / "local.json", tmp_path / "remote.json"
    assert gearengine(*args, "--json", str(local)).returncode == 1
    server = Server(tmp_path / "data")
    try:
        out = gearengine(*args, "--json", str(remote), "--server", server.url)
    finally:
        server.stop()
    assert out.returncode == 1, out.stderr
    assert json.loads(remote.read_text()) == json.loads(local.read_text())


@pytest.mark.parametrize("example", ["github-actions.yml", "gitlab-ci.yml"])
def test_ci_examples_run_as_written(example: str, tmp_path: Path) -> None:
    """The gate command of each CI example, run as written from the repository root."""
    text = (ROOT / "examples" / "ci" / example).read_text()
    (command,) = re.findall(r"(gearengine check .*)$", text, flags=re.M)
    argv = shlex.split(command)[1:]
    argv = [str(tmp_path / a) if a.startswith("envelope.") else a for a in argv]
    out = gearengine(*argv)
    assert out.returncode == 0, out.stdout + out.stderr
    xmlschema.XMLSchema(ROOT / "tests" / "data" / "junit.xsd").validate(tmp_path / "envelope.xml")
    # installed from gearchaos' git repository, not the checkout (`pip install .` works only
    # inside this repository), and the report published where the CI shows it
    assert 'python -m pip install "$GEARCHAOS"' in text and "pip install ." not in text
    assert re.search(r'GEARCHAOS: "gearchaos @ git\+https://\S+\.git@\S+"', text)
    if example == "github-actions.yml":  # GitHub shows a check and a summary, not an artifact
        assert "uses: mikepenz/action-junit-report@v4" in text
        assert "report_paths: envelope.xml" in text and "checks: write" in text


def test_period_doubling_of_a_design_is_reported_in_rpm() -> None:
    """The paper's case (mu~ = 0.07, F~_m = 0.01, F~_e1 = 0.22, cubic law) as gear data:
    b = 50 µm, k_m = 1e8 N/m, T = 1.5 N m (F^_m = 50 N = 0.01 b k_m), e_1 = 11 µm. A
    continuation sweep over the speed locates its period doubling in rpm, at the Omega the
    same sweep of its dimensionless params finds (Omega_e = 18 w_a / w_n)."""
    d = copy.deepcopy(EXAMPLE_DESIGN)
    d["mesh"] = {"stiffness": "1e8 N/m", "damping_ratio": 0.07, "half_backlash": "50 um"}
    d["transmission_error"]["harmonics"][0]["amplitude"] = "11 um"
    d["torque"] = "1.5 N*m"
    d["backlash_law"] = "cubic_fit"
    del d["torque_fluctuation"]
    req = validated({**speed_sweep(d, "1800 rpm", "2600 rpm", 17), "continuation": True})
    (pd,) = [b for b in run_local(req).bifurcations if b.type == "period_doubling"]
    conv = req.conversion
    omega = pd.value / (2 * math.pi * conv.natural_frequency_hz) * 18
    axis = {"parameter": "Omega", "start": omega - 0.01, "stop": omega + 0.01, "num": 5}
    params = {"params": conv.params.model_dump(), "continuation": True, "axes": [axis],
              "settings": req.settings.model_dump()}  # fmt: skip
    (same,) = [b for b in run_local(validated(params)).bifurcations if b.type == "period_doubling"]
    assert same.value == pytest.approx(omega, rel=1e-8)
    assert pd.physical.unit == "rpm" and 2000 < pd.physical.value < 2400
    assert pd.physical.value == pytest.approx(pd.value * 60 / (2 * math.pi), rel=1e-9)
