"""One vocabulary for contact (issue 30 item 6): separation (the teeth lose contact, on either
flank's side) and back_flank (back-flank impacts) mean the same in the gate's rules and the
robustness probabilities; the DTE without and with the static TE and the contact force (zero
while apart) beside the model's force, each defined where it is reported."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gearengine.gate.rules import Rules, point_failures
from gearengine.model.params import GearParams, PiecewiseBacklash
from gearengine.numerics.attractors import IMPACT_TEXT, describe
from gearengine.studies.robustness.study import RobustnessRequest, run_local
from gearengine.studies.sweep.points import SweepPoint
from gearengine.systems.spur_pair.forcing import contact_force_of, static_error
from tests.test_robustness import DESIGN


def _point(regime: str) -> SweepPoint:
    return SweepPoint(values={}, branch=None, classification="periodic", period=1,
                      impact_regime=regime)  # fmt: skip


def test_back_flank_is_the_gate_rule_of_back_flank_impacts() -> None:
    rules = Rules(fail_on=["back_flank"])
    assert point_failures(_point("double_sided"), rules) == ["back-flank impacts"]
    assert point_failures(_point("single_sided"), rules) == []
    rules = Rules(fail_on=["separation"])
    assert point_failures(_point("single_sided"), rules) == ["tooth separation"]


def test_robustness_names_separation_as_the_gate_does() -> None:
    request = RobustnessRequest.model_validate(
        {"design": DESIGN, "samples": 8,
         "axes": [{"parameter": "speed", "start": "5000 rpm", "stop": "5000 rpm", "num": 1}],
         "settings": {"transient_periods": 60, "record_periods": 60, "steps_per_period": 128}}
    )  # fmt: skip
    (point,) = run_local(request).points
    probs = point.probabilities
    assert probs["separation"].count > 0  # this point separates in 7 of 8 samples
    assert "impacts" not in probs  # one word per outcome
    assert probs["back_flank"].count <= probs["separation"].count


def test_static_error_is_the_te_harmonics() -> None:
    params = GearParams.model_validate(
        {"damping": 0.05, "mean_force": 0.1,
         "transmission_error": {"frequency": 0.5, "harmonics": [
             {"amplitude": 0.2, "phase": 0.3}, {"amplitude": 0.05, "phase": 0.0}]}}
    )  # fmt: skip
    t = np.linspace(0.0, 30.0, 301)
    expected = 0.2 * np.cos(0.5 * t + 0.3) + 0.05 * np.cos(1.0 * t)
    np.testing.assert_allclose(static_error(params, t), expected, atol=1e-15)


def test_contact_force_is_zero_while_apart_and_a_flank_never_pulls() -> None:
    params = GearParams(damping=0.1, mean_force=0.1, backlash=PiecewiseBacklash(alpha=0.0))
    t = np.zeros(5)
    x = np.array([0.5, 1.5, -1.5, 1.01, 0.0])
    v = np.array([3.0, 0.0, 0.0, -1.0, -4.0])
    force = contact_force_of(params, t, x, v)
    # apart (|x| <= 1): 0 although the model's damping force 2 mu x' is 0.6 and -0.8
    assert force[0] == 0.0 and force[4] == 0.0
    assert force[1] == pytest.approx(0.5) and force[2] == pytest.approx(-0.5)  # f_h(+-1.5)
    assert force[3] == 0.0  # 0.01 - 0.2 < 0 on the drive flank: released, not pulling


def test_analysis_reports_both_transmission_errors_and_the_contact_force() -> None:
    """examples/ci/design.json: always in contact, so the contact force follows the model's
    force (to the decimation of the history); its static TE adds to the DTE an encoder sees."""
    import json
    from pathlib import Path

    from gearengine.analysis import AnalysisRequest, analyze

    doc = json.loads((Path(__file__).parents[1] / "examples/ci/design.json").read_text())
    r = analyze(AnalysisRequest.model_validate(doc)).engineering.response
    assert r.contact.separation_fraction == 0.0
    assert r.te_with_static_peak_to_peak_um > r.dte_peak_to_peak_um
    assert r.dynamic_mesh_force_min_n <= r.contact_force_min_n <= r.contact_force_max_n
    assert r.contact_force_max_n <= r.dynamic_mesh_force_max_n
    assert r.contact_force_max_n == pytest.approx(r.dynamic_mesh_force_max_n, rel=1e-3)


def test_the_old_word_impacts_is_refused_everywhere_naming_the_two_words(tmp_path, capsys):
    """'impacts' meant back-flank contact in ``check --fail-on`` and any separation in
    ``--max-probability``; read with a note it stayed ambiguous (issue 30 review, finding 3).
    It is refused in the library, the API and the CLI, naming the field or option and the two
    words to write."""
    import json

    from pydantic import ValidationError

    from gearengine.cli.documents import InvalidInputError
    from gearengine.cli.main import main
    from gearengine.cli.robustness import limits_of
    from gearengine.gate.remedies.request import RemediesRequest
    from gearengine.model.errors import InputError
    from service.main import create_app
    from tests.conftest import ROOT

    words = "write back_flank (back-flank impacts) or separation (the teeth apart at some time)"
    with pytest.raises(ValidationError) as caught:
        Rules(fail_on=["chaotic", "impacts"])
    (error,) = caught.value.errors()
    assert isinstance(error["ctx"]["error"], InputError) and words in error["msg"]
    assert error["ctx"]["error"].loc == ("fail_on", "1") and "fail_on.1: " in error["msg"]
    with pytest.raises(InvalidInputError) as refused:
        limits_of(["impacts=0.05"])
    assert "--max-probability impacts=0.05" in str(refused.value) and words in str(refused.value)
    design = tmp_path / "design.json"
    design.write_text((ROOT / "examples/ci/design.json").read_text())
    with pytest.raises(SystemExit) as stopped:
        main(["check", str(design), "--fail-on", "impacts"])
    assert stopped.value.code == 2
    err = capsys.readouterr().err
    assert "--fail-on" in err and words in err
    from fastapi.testclient import TestClient

    doc = {"design": json.loads(design.read_text())["design"], "fail_on": ["impacts"],
           "envelope": {"speed": "1000:2000", "speed_points": 2}}  # fmt: skip
    with pytest.raises(ValidationError):
        RemediesRequest.model_validate(doc)
    with TestClient(create_app()) as client:
        r = client.post("/v1/remedies", json=doc)
    assert r.status_code == 422, r.text
    (refusal,) = r.json()["errors"]
    assert refusal["path"] == "fail_on[0]" and words in refusal["message"]


def test_robustness_outputs_and_panels_say_separation() -> None:
    """The robustness figure's panel and the Sobol output of tooth separation are named
    separation, as P(separation) and --fail-on separation (they said impacts)."""
    from gearengine.plots.robustness import PANELS
    from gearengine.studies.robustness.study import OUTPUTS

    assert "separation" in PANELS and "impacts" not in PANELS
    assert "separation" in OUTPUTS and "impacts" not in OUTPUTS


def test_runup_bins_give_the_contact_force_beside_the_models() -> None:
    """A run-up through the separating branch of examples/ci/design.json (4300-4500 rpm): the
    model's smallest force is negative in every bin (its damping acts in the clearance: -254 N
    was read as a pull of the teeth), the contact force is 0 there (apart, no back flank), and
    never exceeds the model's largest force (issue 30 item 6, new-user review)."""
    import json

    from gearengine.studies.runup import run_local
    from gearengine.studies.runup.profile import validated_runup
    from tests.conftest import ROOT

    design = json.loads((ROOT / "examples" / "ci" / "design.json").read_text())["design"]
    r = validated_runup({"design": design, "from_speed": "4300 rpm", "to_speed": "4500 rpm",
                   "rate": "4000 rpm/s", "direction": "up", "settle_periods": 0,
                   "ensemble": {"size": 1}})  # fmt: skip
    bins = run_local(r).up.bins  # type: ignore[union-attr]
    assert bins and all(b.separation_fraction > 0 and b.back_flank_fraction == 0 for b in bins)
    for b in bins:
        assert b.force_min_n < 0.0
        assert b.contact_force_min_n == 0.0
        assert 0.0 < b.contact_force_max_n <= b.force_max_n


def test_attractor_labels_say_the_contact_in_the_text_words() -> None:
    """Gate lines said "3920 rpm: periodic 1T, single-sided impacts from 56 % of starts"
    beside windows saying "tooth separation", where docs/units.md's one vocabulary has the
    text words "teeth always in contact", "tooth separation" and "back-flank impacts": an
    attractor's label (JSON, gate and sweep text) uses them, as the gate's rules do."""
    assert describe("periodic", 1, "single_sided") == "periodic 1T, tooth separation"
    assert describe("chaotic", None, "double_sided") == "chaotic, back-flank impacts"
    assert describe("periodic", 2, "no_impact") == "periodic 2T, teeth always in contact"
    table = (Path(__file__).resolve().parents[1] / "docs" / "units.md").read_text()
    for words in IMPACT_TEXT.values():
        assert f"| {words} |" in table
    rules = Rules(fail_on=["back_flank", "separation"])
    assert point_failures(_point("double_sided"), rules) == [
        IMPACT_TEXT["double_sided"],
        IMPACT_TEXT["single_sided"],
    ]
