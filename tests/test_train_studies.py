"""Sweeps, the envelope gate and basins of a design with a ``train`` (issue 32): the studies run
the train's ``System`` at every point, with no code of their own for it; what a train cannot do
yet (continuation, dimensionless axes) is refused naming the field."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from pydantic import ValidationError

import gearengine
from gearengine.analysis import AnalysisRequest
from gearengine.gate.envelope import check_envelope
from gearengine.gate.envelope_text import windows_summary
from gearengine.gate.remedies.compute import remedies
from gearengine.gate.remedies.request import RemediesRequest as RemediesRequest_
from gearengine.gate.remedies.search import verify_depth
from gearengine.gate.rules import Rules, attractor_failures
from gearengine.homoclinic.train_reduction import not_judged_reason
from gearengine.model.design import Design
from gearengine.model.train import EXAMPLE_TRAIN
from gearengine.numerics.runs import work
from gearengine.numerics.settings import SimulationSettings, run_steps
from gearengine.numerics.trains import simulate_train
from gearengine.studies.basins import basins_work
from gearengine.studies.robustness.study import RobustnessRequest
from gearengine.studies.robustness.study import checked as checked_robustness
from gearengine.studies.robustness.study import run_local as run_robustness
from gearengine.studies.sweep import run_local, validated
from gearengine.studies.sweep.plan import sweep_work
from gearengine.studies.sweep.points import SpeedWindows
from gearengine.systems.designs import design_model
from gearengine.systems.gear_train.system import TRAIN_STEP_COST
from service.core.config import Settings
from service.main import create_app
from tests.conftest import started

ROOT = Path(__file__).resolve().parents[1]
PAIR = json.loads((ROOT / "examples" / "design-direct.json").read_text())["design"]
TRAIN = {**PAIR, "train": EXAMPLE_TRAIN}
SPEEDS = {"parameter": "speed", "start": "1000 rpm", "stop": "2000 rpm", "num": 3}
LIGHT = {"transient_periods": 40, "record_periods": 30, "steps_per_period": 128}


def sweep(axes: list[dict], **extra: object) -> dict:
    return {"design": TRAIN, "settings": LIGHT, "axes": axes, **extra}


def at(rpm: float) -> Design:
    return Design.model_validate({**TRAIN, "speed": f"{rpm} rpm"})


def test_a_speed_sweep_of_a_train_is_the_trains_verdict_at_each_speed() -> None:
    """Each point is exactly what the train's own verdict (``simulate_train``) says at that
    speed: class, period, LLE, contact, DTE and dynamic factor; the pair alone differs."""
    doc = sweep([{"parameter": "speed", "start": "1000 rpm", "stop": "3000 rpm", "num": 2}])
    result = run_local(validated(doc))
    settings = SimulationSettings.model_validate(LIGHT)
    for point, rpm in zip(result.points, (1000, 3000), strict=True):
        train = simulate_train(at(rpm), settings)
        assert point.classification == train.classification
        assert point.period == train.period and point.lle == train.lle
        assert point.impact_regime == train.impact_regime
        assert point.physical["dte"].value == pytest.approx(train.dte_um, rel=1e-9)
        assert point.physical["dynamic_factor"].value == pytest.approx(
            train.dynamic_factor, rel=1e-9
        )
        # the mesh mode holds 56 % of the mesh energy: no one-mode reduction, no Melnikov
        assert point.melnikov_chaos_possible is None
    alone = run_local(validated({**doc, "design": PAIR}))
    assert [p.lle for p in alone.points] != [p.lle for p in result.points]


def test_a_train_field_is_an_axis() -> None:
    """``train.input_shaft.torsional_stiffness`` moves the answer (a stiffer input shaft)."""
    axis = {"parameter": "train.input_shaft.torsional_stiffness", "start": "1e4 N*m/rad",
            "stop": "1e5 N*m/rad", "num": 2}  # fmt: skip
    result = run_local(validated(sweep([axis])))
    soft, stiff = (p.physical["dte"].value for p in result.points)
    assert soft != pytest.approx(stiff, rel=1e-3)
    assert result.points[1].physical["train.input_shaft.torsional_stiffness"].value == 1e5


@pytest.mark.parametrize(
    ("doc", "path"),
    [
        (sweep([{"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 3}]), "axes.0.parameter"),
        (sweep([{"parameter": "Omega", "start": 0.5, "stop": 1.0, "num": 3}]), "axes.0.parameter"),
        (sweep([SPEEDS], continuation=True), "continuation"),
    ],
)
def test_what_a_train_cannot_sweep_yet_is_refused_naming_the_field(doc: dict, path: str) -> None:
    with pytest.raises(ValidationError) as err:
        validated(doc)
    errors = err.value.errors()
    assert [".".join(map(str, e["loc"])) for e in errors] == [path]
    assert "train" in errors[0]["msg"]


def test_the_budget_counts_the_trains_steps() -> None:
    """A train's steps (raised for stiff shafts and bearings) count at its step cost, in sweeps
    and in basin jobs as in an analysis (the system its request carries)."""
    settings = SimulationSettings.model_validate(LIGHT)
    model, _ = design_model(at(1500))
    steps = run_steps(settings, model.plan(settings.steps_per_period).steps)
    analysis = AnalysisRequest(design=at(1500), settings=LIGHT)
    assert work(analysis.system, settings) == work(model, settings) == TRAIN_STEP_COST * steps
    doc = sweep([{"parameter": "speed", "start": "1000 rpm", "stop": "3000 rpm", "num": 4}])
    pair = sweep_work(validated({**doc, "design": PAIR}))
    assert sweep_work(validated(doc)) == 3 * pair  # same steps per T0 here, step cost 3
    request = AnalysisRequest(design=TRAIN, settings={**LIGHT, "basins": {"starts": 4}})
    assert basins_work(request) == work(request.system, request.settings)


def test_the_envelope_gate_checks_a_train() -> None:
    """``check_envelope`` over speed x torque of a train: every point checked against the
    train's own DTE; a DTE limit between the points' DTEs fails exactly those above it."""
    axes = [
        {"parameter": "speed", "start": "1000 rpm", "stop": "3000 rpm", "num": 2},
        {"parameter": "torque", "start": "20 N*m", "stop": "40 N*m", "num": 2},
    ]
    request = validated(sweep(axes))
    report = check_envelope(request, Rules(max_dte_um=1.0), refine=0)
    dtes = [p.physical["dte"].value for p in report.sweep.points]
    limit = sorted(dtes)[1] * 1.0001
    report = check_envelope(request, Rules(max_dte_um=limit), refine=0)  # the grid's points
    assert report.points == 4
    assert report.failing_points == sum(d > limit for d in dtes) == 2
    assert not report.passed and all("DTE" in w.rule for w in report.failures)
    train = simulate_train(
        Design.model_validate({**TRAIN, "speed": "1000 rpm", "torque": "20 N*m"}),
        SimulationSettings.model_validate(LIGHT),
    )
    assert dtes[0] == pytest.approx(train.dte_um, rel=1e-9)


def test_gearengine_check_of_a_train_file(tmp_path: Path) -> None:
    """The CLI gate takes a train design file and writes its JUnit report."""
    path = tmp_path / "train.json"
    path.write_text(json.dumps({"design": TRAIN, "settings": LIGHT}))
    junit = tmp_path / "junit.xml"
    out = subprocess.run(
        [sys.executable, "-m", "gearengine.cli", "check", str(path), "--speed", "1000:3000",
         "--speed-points", "2", "--starts", "1", "--max-dte", "1", "--junit", str(junit)],
        capture_output=True, text=True, timeout=600, cwd=ROOT,
    )  # fmt: skip
    assert out.returncode == 1, out.stderr
    assert "FAIL" in out.stdout and "DTE > 1 µm at 1000-3000 rpm" in out.stdout
    assert 'failures="1"' in junit.read_text()


def test_basins_of_a_train() -> None:
    """Basins over the mesh coordinate (the rest at its static deflection, at rest): every
    start of a periodic point settles on one 1T orbit whose DTE is the train's verdict's, and
    the engineering summary names it with its fraction (issue 30)."""
    settings = {**LIGHT, "transient_periods": 200, "basins": {"starts": 4}}
    result = gearengine.analyze(AnalysisRequest(design=TRAIN, settings=settings))
    found, counts = result.numerics.attractors, result.numerics.basins
    assert counts.starts == 4 and counts.diverged == counts.unsettled == 0
    assert [a.label for a in found] == ["periodic 1T, teeth always in contact"] and found[
        0
    ].count == 4
    train = simulate_train(Design.model_validate(TRAIN), SimulationSettings(**settings))
    assert found[0].dte_um == pytest.approx(train.dte_um, rel=1e-3)
    assert result.verdict.decided_by == "periodic 1T, teeth always in contact from 100 % of starts"
    # issue 30: the summary names the deciding attractor, though this train has no reduction
    assert not result.melnikov.applicable
    assert f"({result.verdict.decided_by})" in result.engineering.summary


def test_robustness_of_a_train_is_the_trains() -> None:
    """A toleranced train samples the train, not the pair alone (on main the study silently
    ran the pair): with a damping ratio in [0.0499, 0.0501] every sample is the nominal train
    to 1e-3, its DTE the train's, far from the pair's alone."""
    tol = {"mesh.damping_ratio": {"uniform": [0.0499, 0.0501]}}
    doc = {"design": {**TRAIN, "tolerances": tol}, "samples": 4, "settings": LIGHT}
    result = run_robustness(checked_robustness(RobustnessRequest.model_validate(doc)))
    (point,) = result.points
    settings = SimulationSettings.model_validate(LIGHT)
    train = simulate_train(Design.model_validate(TRAIN), settings)
    pair = gearengine.analyze(Design.model_validate(PAIR), settings).engineering.response
    assert point.probabilities[train.classification].value == 1.0
    assert point.dte_um["mean"] == pytest.approx(train.dte_um, rel=1e-3)
    assert point.dte_um["mean"] != pytest.approx(pair.dte_peak_to_peak_um, rel=0.05)
    assert point.probabilities["melnikov_chaos_possible"].count == 0  # no reduction


def test_remedies_of_a_train_pass_the_trains_gate() -> None:
    """A train failing --max-dte 30 µm at 900-1000 rpm (tooth separation, DTE ~50 µm):
    the remedy found on the mesh damping ratio passes the train's own gate (simulated on its
    own at the grid's speeds), and the last failing value tried fails the gate at a point the
    train, simulated on its own, confirms over 30 µm (a refined speed between the grid's: the
    gate refines where a point is near its limit) of the grid the remedy is verified on."""
    body = {"design": TRAIN, "envelope": {"speed": "900:1000", "speed_points": 2},
            "max_dte_um": 30.0, "starts": 1, "settings": LIGHT,
            "levers": [{"lever": "mesh.damping_ratio", "bounds": [0.05, 0.4]}]}  # fmt: skip
    request = RemediesRequest_.model_validate(body)
    result = remedies(request)
    assert not result.passed_already and result.check.failing_points >= 1
    (remedy,) = result.remedies
    settings = SimulationSettings.model_validate(LIGHT)

    def dte_um(damping: float, rpm: float) -> float:
        mesh = {**TRAIN["mesh"], "damping_ratio": damping}
        design = Design.model_validate({**TRAIN, "speed": f"{rpm!r} rpm", "mesh": mesh})
        return simulate_train(design, settings).dte_um

    assert all(dte_um(remedy.to, rpm) <= 30.0 for rpm in (900, 1000))
    fail = remedy.bracket[0]
    design = Design.model_validate({**TRAIN, "mesh": {**TRAIN["mesh"], "damping_ratio": fail}})
    report = check_envelope(
        request.sweep(design, finer=True), request.rules(), refine=verify_depth(request)
    )  # where the remedy was verified
    failing = [
        p for p in [*report.sweep.points, *report.refined] if attractor_failures(p, request.rules())
    ]
    assert not report.passed and failing
    rpm = failing[0].physical["speed"].value
    assert dte_um(fail, rpm) > 30.0, (fail, rpm)


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[TestClient]:
    app = create_app(Settings(data_dir=tmp_path_factory.mktemp("train_sweeps"), workers=0))
    with started(app) as c:
        yield c


def test_the_api_takes_a_train_sweep_and_refuses_what_it_cannot_do(client: TestClient) -> None:
    doc = sweep([{"parameter": "speed", "start": "1000 rpm", "stop": "3000 rpm", "num": 2}])
    r = client.post("/v1/sweeps", json=doc)
    assert r.status_code == 202, r.text
    r = client.post("/v1/sweeps", json={**doc, "continuation": True})
    assert r.status_code == 422, r.text
    assert [e["path"] for e in r.json()["errors"]] == ["continuation"]


def test_the_gates_text_says_why_melnikov_judges_no_point_of_a_train() -> None:
    """``gearengine check``'s windows said "(above T_crit)" for a train whose mesh no single
    mode carries (56 % of the mesh strain energy in the example's mesh mode): there the
    criterion judges no point at any torque. It names the reason now; a train with stiff
    shafts and bearings (the reduction holds, 99.96 %) names the reduction's T_crit, and the
    pair keeps its words."""
    row = SpeedWindows(level={}, response={}, contact={}, melnikov=[],
                       melnikov_not_applicable=[[1000.0, 3000.0]])  # fmt: skip
    stiff = json.loads(json.dumps(EXAMPLE_TRAIN))
    for shaft in ("input_shaft", "output_shaft"):
        stiff[shaft]["torsional_stiffness"] = "1e9 N*m/rad"
    for side in ("driver", "driven"):
        stiff["bearings"][side]["stiffness"] = "1e12 N/m"
    cases = [
        (TRAIN, "no single mode of the train holds 90% of the mesh strain energy"),
        ({**PAIR, "train": stiff}, "above the mesh-mode reduction's T_crit"),
        (PAIR, "above T_crit"),
    ]
    for design, words in cases:
        short, _ = not_judged_reason(Design.model_validate(design))
        assert short == words
        (line,) = windows_summary([row], short)
        assert line.endswith(f"Melnikov: not applicable at 1000-3000 rpm ({words})"), line
    assert "reduction" in not_judged_reason(Design.model_validate(TRAIN))[1]
