"""``gearengine robustness`` and the probability gate of ``gearengine check``: the CLI's JSON is
the API's document, the gate fails on the 95 % upper bound and JUnit names the points."""

from __future__ import annotations

import json
from pathlib import Path
from xml.etree import ElementTree

import pytest

from gearengine.cli.main import main
from gearengine.gate.envelope import ENVELOPE_SETTINGS
from gearengine.gate.probability import ONE_LOOK, ONE_START
from gearengine.studies.robustness.study import RobustnessRequest, run_local
from tests.test_robustness import DESIGN


@pytest.fixture(scope="module")
def design_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("cli") / "design.json"
    path.write_text(json.dumps({"design": DESIGN}))
    return path


def test_cli_json_is_the_api_document_and_the_map_is_a_png(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A file without settings: the CLI ran the request model's default (the API's and the
    library's), and the answer says which; before, the CLI ran the gate's light settings and the
    API 500 + 500 periods at 200 steps (23 against 26 chaotic of 128), neither saying so."""
    out, png = design_file.with_name("r.json"), design_file.with_name("r.png")
    args = [str(design_file), "--speed", "2000:5000", "--speed-points", "2", "--samples", "8"]
    assert main(["robustness", *args, "--json", str(out), "--plot", str(png)]) == 0
    shown = "settings: <= 60 + 60 periods (ended when settled), 128 steps a period"
    assert shown in capsys.readouterr().out
    document = json.loads(out.read_text())
    request = RobustnessRequest.model_validate(
        {"design": DESIGN, "samples": 8,
         "axes": [{"parameter": "speed", "start": "2000 rpm", "stop": "5000 rpm", "num": 2}]}
    )  # fmt: skip
    assert out.read_text() == run_local(request).model_dump_json()
    ran = {k: document["settings"][k] for k in ENVELOPE_SETTINGS}
    assert ran == ENVELOPE_SETTINGS
    assert [p["shown"] for p in document["points"]] == [{"speed": 2000.0}, {"speed": 5000.0}]
    assert png.read_bytes().startswith(b"\x89PNG")


def test_the_gate_fails_on_the_upper_bound_and_names_the_points(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    junit = design_file.with_name("junit.xml")
    base = ["check", str(design_file), "--speed", "2000:5000", "--speed-points", "2"]
    # 8 samples prove 0.4 (0 events: upper bound 0.369); 7 of 8 impact at 5000 rpm
    assert main([*base, "--samples", "8", "--max-probability", "separation=0.4",
                 "--junit", str(junit)]) == 1  # fmt: skip
    cases = ElementTree.parse(junit).getroot().findall("testsuite/testcase")
    assert [c.get("name") for c in cases] == ["speed 2000 rpm", "speed 5000 rpm"]
    assert [c.find("failure") is not None for c in cases] == [False, True]
    out = capsys.readouterr().out
    # a fixed count's reasons name its 95 % as auto's name 99.3 %, and a pass names the bound
    # that proves it (new-user review, finding 7)
    assert (
        "FAIL: speed 5000 rpm (8 samples) [P(separation) lower bound at 95 % 0.473 > 0.4 (7/8 "
        "samples)]" in out
    )
    assert (
        "PASS: speed 2000 rpm (8 samples) [P(separation) upper bound at 95 % 0.369 <= 0.4 (0/8 "
        "samples)]" in out
    )
    assert main([*base, "--samples", "8", "--max-probability", "back_flank=0.5"]) == 0
    assert main([*base, "--max-probability", "nonsense=0.1"]) == 2


def test_samples_to_prove_is_where_the_clopper_pearson_bound_of_no_event_meets_the_limit() -> None:
    """Checked against scipy's exact interval (``binomtest(0, n).proportion_ci``)."""
    from scipy.stats import binomtest

    from gearengine.studies.robustness.tolerances import samples_to_prove

    def upper(n: int) -> float:
        return binomtest(0, n).proportion_ci(0.95, method="exact").high

    for limit in (0.01, 0.05, 0.1, 0.369):
        n = samples_to_prove(limit)
        assert upper(n) <= limit < upper(n - 1)
    assert samples_to_prove(0.01) == 368
    assert samples_to_prove(0.0) is None


def test_a_gate_that_cannot_pass_is_refused_before_computing(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """256 samples cannot prove 1 % even with no event (upper bound 0.0143): exit 2 at once,
    naming the count needed; a zero limit no count proves."""
    base = ["check", str(design_file), "--speed", "2000:5000", "--speed-points", "2"]
    assert main([*base, "--samples", "256", "--max-probability", "chaotic=0.01"]) == 2
    err = capsys.readouterr().err
    assert "--samples 256 cannot prove P(chaotic) <= 0.01" in err
    assert "upper bound of 0.0143" in err and "it takes 368 samples with 0 events" in err
    assert "--samples 512" in err
    assert main([*base, "--max-probability", "chaotic=0"]) == 2
    assert "no number of samples can prove a probability of 0" in capsys.readouterr().err


def test_samples_auto_samples_until_every_point_is_decided(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    base = ["check", str(design_file), "--speed", "2000:5000", "--speed-points", "2"]
    assert main([*base, "--samples", "auto", "--max-probability", "separation=0.4"]) == 1
    captured = capsys.readouterr()
    assert "--samples auto: every point decided by 64 samples" in captured.err
    assert "PASS: speed 2000 rpm" in captured.out and "FAIL: speed 5000 rpm" in captured.out


def test_the_answers_say_how_many_starts_decided_each_sample(
    design_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The probability gate and the study say how many starts each sample ran (one, the
    settings' start, unless settings.basins or --starts give more), in the text and the JSON:
    the gate's envelope check runs 16 starts a point, and nothing said that P(chaotic) came
    from one (issue 30 item 5, a new-user review)."""
    out = tmp_path / "p.json"
    base = ["check", str(design_file), "--speed", "5000:5000", "--speed-points", "1",
            "--samples", "8", "--max-probability", "back_flank=0.5"]  # fmt: skip
    assert main([*base, "--json", str(out)]) == 0
    report, text = json.loads(out.read_text()), capsys.readouterr().out
    assert report["result"]["starts_per_sample"] == 1
    assert "8 samples a point, 1 start a sample" in text
    # one start is the gate's default, unlike the envelope check's 16: said where it is read
    # (review of issue 30), with the way to the envelope's rule and its cost
    assert ONE_START in text and ONE_START in report["notes"]
    assert "worst attractor of the 16 starts" in ONE_START and "--starts 16" in ONE_START
    assert main([*base, "--starts", "4", "--json", str(out)]) == 0
    report, text = json.loads(out.read_text()), capsys.readouterr().out
    assert report["verdicts"][0]["starts_per_sample"] == 4
    assert "8 samples a point, 4 starts a sample (settings.basins)" in text
    assert ONE_START not in text and ONE_START not in report["notes"]
    args = [str(design_file), "--speed", "5000:5000", "--speed-points", "1", "--samples", "8"]
    assert main(["robustness", *args]) == 0
    text = capsys.readouterr().out
    assert "(8 samples, 1 start a sample)" in text
    # the dynamic factor's event is shown with its limit, which nothing printed (leftover d)
    assert ", dynamic factor > 1.5 " in text
    gate = [*base[:-2], "--max-probability", "dynamic_factor_above_limit=0.9"]
    assert main([*gate, "--json", str(out)]) in (0, 1)
    report, text = json.loads(out.read_text()), capsys.readouterr().out
    said = "the largest dynamic mesh force above 1.5 times the static force"
    assert report["result"]["dynamic_factor_limit"] == 1.5
    assert any(said in n for n in report["notes"]) and said in text


def test_the_result_names_the_units_of_its_points_values(design_file: Path, tmp_path: Path) -> None:
    """A robustness point's values are SI and its shown values in gear units: the result names
    both (values.speed read as rpm by a new user is rad/s; issue 30 item 2)."""
    out = tmp_path / "r.json"
    args = [str(design_file), "--speed", "5000:5000", "--speed-points", "1", "--samples", "2"]
    assert main(["robustness", *args, "--json", str(out)]) == 0
    document = json.loads(out.read_text())
    assert document["values_units"] == {"speed": "rad/s"}
    assert document["shown_units"] == {"speed": "rpm"}


def test_samples_auto_reads_a_design_from_standard_input_once(
    design_file: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every round of ``--samples auto`` studies the one document ``check`` read: from standard
    input the second round used to read it again, find it empty and exit 2."""
    import io

    monkeypatch.setenv("GEARCHAOS_MAX_JOB_STEPS", "3500000")  # stops after a second round
    monkeypatch.setattr("sys.stdin", io.StringIO(design_file.read_text()))
    args = ["check", "-", "--speed", "2000:5000", "--speed-points", "2", "--samples", "auto",
            "--max-probability", "separation=0.01"]  # fmt: skip
    assert main(args) == 1  # not 2: the second round read no empty standard input
    assert "rounds of 64, 128 samples" in capsys.readouterr().err


def test_a_probability_gate_over_the_budget_is_refused_in_the_users_terms(
    design_file: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--samples 512`` over the job budget was refused naming the internal max_job_steps
    alone, and ``--samples auto`` was then refused too (review of issue 30, item 4): the refusal
    says samples x starts x points, what the budget allows, and the ways out (the options, the
    environment variable GEARCHAOS_MAX_JOB_STEPS, which the CLI now reads)."""
    monkeypatch.setenv("GEARCHAOS_MAX_JOB_STEPS", "3500000")
    base = ["check", str(design_file), "--speed", "2000:5000", "--speed-points", "2"]
    assert main([*base, "--samples", "512", "--max-probability", "separation=0.01"]) == 2
    err = capsys.readouterr().err
    assert "512 samples x 1 start x 2 points = 1024 runs" in err
    assert "over the budget of 3500000 RK4 steps per job" in err
    assert "the budget allows 64 samples at these points, or 0 points at 512 samples" in err
    for way in ("--speed-points", "--starts", "--samples auto", "GEARCHAOS_MAX_JOB_STEPS=STEPS"):
        assert way in err


def test_samples_auto_reports_the_points_the_budget_leaves_undecided(
    design_file: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--samples auto`` samples each point only until it is decided: 5000 rpm fails at 64
    samples (7 of 8 separate), 2000 rpm (no separation) needs 368 to prove 1 %; a budget of
    3.5e6 RK4 steps (15,360 a sample a point) stops it at 128 samples, undecided, and the gate
    fails: an undecided point does not pass silently."""
    monkeypatch.setenv("GEARCHAOS_MAX_JOB_STEPS", "3500000")
    base = ["check", str(design_file), "--speed", "2000:5000", "--speed-points", "2"]
    assert main([*base, "--samples", "auto", "--max-probability", "separation=0.01"]) == 1
    captured = capsys.readouterr()
    assert (
        "UNDECIDED: speed 2000 rpm (128 samples) [P(separation) undecided: upper bound at 99.3 % "
        "0.0431 > 0.01 (0/128 samples)]" in captured.out
    )
    assert "FAIL: speed 5000 rpm (64 samples) [P(separation) lower bound" in captured.out
    assert "the budget of 3500000 RK4 steps ran out: 1 points undecided after 128" in captured.err
    assert (
        "FAIL: 1 of 2 points over a probability limit (P(separation) <= 0.01), 1 undecided"
        in captured.out
    )


def test_the_api_refuses_a_study_over_the_budget_in_the_same_terms(tmp_path: Path) -> None:
    """One rule for the CLI and the API (``jobs.budget_refusal``): samples x starts x points."""
    from fastapi.testclient import TestClient

    from service.core.config import Settings
    from service.main import create_app

    app = create_app(Settings(data_dir=tmp_path, workers=0, max_job_steps=3_500_000))
    body = {
        "design": DESIGN,
        "samples": 512,
        "settings": ENVELOPE_SETTINGS,
        "axes": [{"parameter": "speed", "start": "2000 rpm", "stop": "5000 rpm", "num": 2}],
    }
    with TestClient(app) as c:
        r = c.post("/v1/robustness", json=body)
    assert r.status_code == 422, r.text
    detail = r.json()["detail"]
    assert "512 samples x 1 start x 2 points = 1024 runs" in detail
    assert "max_job_steps, environment GEARCHAOS_MAX_JOB_STEPS" in detail and "axes[].num" in detail


def test_sequential_looks_share_the_error_of_one_decision() -> None:
    """``--samples auto`` looks at a point up to 7 times (64 ... 4,096 samples): each look at
    95 % would give a point 7 chances to pass by luck (the expert's push on issue 30's auto
    sampling). The 5 % is shared over the looks: 0 events in 368 samples prove P <= 1 % at 95 %
    (one look, --samples N) but not at a look of the sequential study (561 are needed)."""
    from gearengine.studies.robustness.results import Probability, RobustnessPoint
    from gearengine.studies.robustness.sequential import decision_confidence, looks, verdict
    from gearengine.studies.robustness.tolerances import probability, samples_to_prove

    def point(k: int, n: int) -> RobustnessPoint:
        return RobustnessPoint.model_construct(
            probabilities={"chaotic": Probability(**probability(k, n))}
        )

    assert looks() == 7 and decision_confidence() == pytest.approx(1 - 0.05 / 7)
    assert verdict(point(0, 368), {"chaotic": 0.01}) == "pass"
    assert verdict(point(0, 368), {"chaotic": 0.01}, decision_confidence()) == "undecided"
    assert samples_to_prove(0.01, decision_confidence()) == 561
    assert verdict(point(0, 561), {"chaotic": 0.01}, decision_confidence()) == "pass"


def test_samples_and_seed_without_a_probability_limit_are_refused(design_file: Path) -> None:
    """``check --speed ... --samples 64 --seed 3`` ran the ordinary envelope gate and said
    nothing of the two options (new-user review of issue 30): they are refused, naming
    --max-probability."""
    for extra in (["--samples", "64"], ["--seed", "3"]):
        assert main(["check", str(design_file), "--speed", "2000:5000", *extra]) == 2


def test_the_gates_json_is_its_report_at_the_confidence_it_decided_at(
    design_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:  # fmt: skip
    """The probability gate's ``--json`` was the bare robustness result: no verdicts, limits or
    reasons, and 95 % intervals while ``--samples auto`` decided at 99.3 %; its PASS/FAIL line
    went to stderr, the envelope gate's to stdout (review of issue 30). Now the report has per
    point the verdict, the reasons and the interval read at the confidence decided at, the
    limits and the overall verdict, with the robustness result inside."""
    from gearengine.studies.robustness.tolerances import clopper_pearson

    monkeypatch.setenv("GEARCHAOS_MAX_JOB_STEPS", "3500000")
    out = tmp_path / "gate.json"
    base = ["check", str(design_file), "--speed", "2000:5000", "--speed-points", "2"]
    assert main([*base, "--samples", "auto", "--max-probability", "separation=0.01",
                 "--json", str(out)]) == 1  # fmt: skip
    captured = capsys.readouterr()
    assert (
        "FAIL: 1 of 2 points over a probability limit (P(separation) <= 0.01), 1 undecided"
        in captured.out
    )
    assert "points over a probability limit" not in captured.err
    report = json.loads(out.read_text())
    assert (report["passed"], report["limits"]) == (False, {"separation": 0.01})
    assert (report["failing_points"], report["undecided_points"]) == (1, 1)
    assert report["confidence"] == pytest.approx(1 - 0.05 / 7)
    slow, fast = report["verdicts"]
    assert slow["point"] == {"speed": {"value": 2000.0, "unit": "rpm"}}
    assert (slow["verdict"], fast["verdict"]) == ("undecided", "fail")
    assert slow["samples"] == 128 and slow["starts_per_sample"] == 1
    assert slow["reasons"] == [
        "P(separation) undecided: upper bound at 99.3 % 0.0431 > 0.01 (0/128 samples)"
    ]
    read = slow["limits"]["separation"]
    assert (read["count"], read["samples"], read["verdict"]) == (0, 128, "undecided")
    assert read["interval"] == pytest.approx(clopper_pearson(0, 128, 1 - 0.05 / 7))
    kept = report["result"]["points"][0]["probabilities"]["separation"]
    assert kept["interval"][1] < read["interval"][1]  # the result's own 95 % interval, kept
    # said before computing: the budget cannot hold the round that proves 1 % without events
    assert report["notes"][0].startswith("--samples auto: a point with no events needs 561 ")
    assert "every point decided" not in report["notes"][1]
    assert report["notes"][1].startswith("--samples auto: the budget of 3500000 RK4 steps")
    assert main([*base, "--samples", "8", "--max-probability", "back_flank=0.5",
                 "--json", str(out)]) == 0  # fmt: skip
    assert "PASS: 0 of 2 points over a probability limit (P(back_flank) <= 0.5), 0 undecided" in (
        capsys.readouterr().out
    )
    report = json.loads(out.read_text())
    assert report["passed"] and report["confidence"] == 0.95 and report["notes"] == [ONE_START]
    assert [v["verdict"] for v in report["verdicts"]] == ["pass", "pass"]


def test_the_probability_gate_refuses_the_envelope_rules_it_would_ignore(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check --max-probability chaotic=0.1 --max-dte 0.001um --fail-on separation --runup
    1000 --refine 3`` passed: the probability gate read none of the envelope's rules and
    options (new-user review, finding 2). Refused before computing, naming them; a limit given
    twice kept the last one silently, and is refused too."""
    base = ["check", str(design_file), "--speed", "2000:5000", "--speed-points", "2",
            "--samples", "64"]  # fmt: skip
    extra = ["--max-dte", "0.001um", "--fail-on", "separation", "--runup", "1000", "--refine",
             "3", "--max-lle", "0", "--max-dynamic-factor", "1.1", "--min-basin", "0.1",
             "--server", "http://localhost:1", "--min-stability-margin", "0.1"]  # fmt: skip
    assert main([*base, "--max-probability", "chaotic=0.1", *extra]) == 2
    err = capsys.readouterr().err
    for option in extra[::2]:
        assert option in err
    assert "run it as a second check without --max-probability" in err
    twice = ["--max-probability", "chaotic=0.05", "--max-probability", "chaotic=0.5"]
    assert main([*base, *twice]) == 2
    assert "P(chaotic) is limited twice (chaotic=0.05 before)" in capsys.readouterr().err


def test_diverged_samples_never_pass_a_limit_they_could_break() -> None:
    """``robustness --speed 100:100`` had 128 of 128 samples diverged, printed 'chaotic 0.000'
    and the gate passed chaotic=0.05 (new-user review, finding 4): a diverged sample has no
    class or contact. A limit passes when it holds with the diverged samples counted as the
    outcome (a few of many do not matter), else the point is undecided, saying why; the
    lower bound (a fail) counts the followed events alone."""
    from gearengine.gate.probability import point_verdict
    from gearengine.studies.robustness.results import Probability, RobustnessPoint
    from gearengine.studies.robustness.tolerances import probability

    def point(diverged: int, chaotic: int, n: int = 64) -> RobustnessPoint:
        probs = {"chaotic": probability(chaotic, n), "diverged": probability(diverged, n),
                 "melnikov_chaos_possible": probability(0, n)}  # fmt: skip
        shown = {k: Probability(**v) for k, v in probs.items()}
        return RobustnessPoint(values={}, shown={"speed": 100.0}, samples=n, dte_um={},
                               probabilities=shown)  # fmt: skip

    every = point_verdict(point(64, 0), {"chaotic": 0.1}, ONE_LOOK, 1, None)
    assert every.verdict == "undecided" and every.limits["chaotic"].verdict == "undecided"
    assert every.reasons == [
        "P(chaotic) undecided: 64 of 64 samples diverged (the model could not follow them); "
        "counted as chaotic, the upper bound at 95 % is 1 > 0.1"
    ]
    # the verdicts P(diverged) and Melnikov read are known for every sample
    assert point_verdict(point(64, 0), {"melnikov_chaos_possible": 0.1}, ONE_LOOK, 1,
                         None).verdict == "pass"  # fmt: skip
    assert point_verdict(point(64, 0), {"diverged": 0.5}, ONE_LOOK, 1, None).verdict == "fail"
    # one diverged sample of 64 under a 10 % limit: 1/64 still proves it (upper bound 0.084)
    assert point_verdict(point(1, 0), {"chaotic": 0.1}, ONE_LOOK, 1, None).verdict == "pass"
    assert point_verdict(point(1, 20), {"chaotic": 0.1}, ONE_LOOK, 1, None).verdict == "fail"


def test_the_study_text_shows_diverged_samples(
    design_file: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Samples that diverged were left out of the line: 'chaotic 0.000 [0.000, 0.028]' and
    nothing of them (the review's 100 rpm, where every sample diverged because the steps did
    not resolve the contact, test_step_resolution). Divergence is rare now, so the study's
    samples are marked diverged here, and the line must count them."""
    from gearengine.cli import robustness as cli_robustness

    real = cli_robustness.study

    def diverging(args, doc):  # type: ignore[no-untyped-def]
        request, result = real(args, doc)
        p = result.points[0]
        probs = {**p.probabilities}
        probs["diverged"] = probs["diverged"].model_copy(update={"count": p.samples})
        point = p.model_copy(update={"probabilities": probs})
        return request, result.model_copy(update={"points": [point]})

    monkeypatch.setattr(cli_robustness, "study", diverging)
    argv = ["robustness", str(design_file), "--speed", "5000:5000", "--speed-points", "1",
            "--samples", "8"]  # fmt: skip
    assert main(argv) == 0
    assert "diverged 8 of 8 (8 samples" in capsys.readouterr().out


def test_the_gate_refuses_fewer_than_one_sample(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check --max-probability chaotic=0.05 --samples 0`` raised ZeroDivisionError (exit 70,
    a traceback) in samples_needed (new-user review, finding 5): refused by the parser."""
    for count in ("0", "-4"):
        argv = ["check", str(design_file), "--max-probability", "chaotic=0.05",
                f"--samples={count}"]  # fmt: skip
        with pytest.raises(SystemExit) as stopped:
            main(argv)
        assert stopped.value.code == 2
        assert f"argument --samples: '{count}': give a whole number of at least 1" in (
            capsys.readouterr().err
        )


def test_the_envelope_check_says_it_judges_the_nominal_design_of_a_toleranced_one(
    design_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check robustness-gears.json --speed 4000:6000 ...`` passed with notes [] while the
    probability gate failed every point (new-user review, finding 6): the envelope check of a
    design with tolerances says, in its text and its report, that it judged the nominal
    design and which option judges the tolerances."""
    from gearengine.cli.envelope import NOMINAL_ONLY

    out = tmp_path / "e.json"
    argv = ["check", str(design_file), "--speed", "2000:2000", "--speed-points", "1",
            "--starts", "1", "--refine", "0", "--json", str(out)]  # fmt: skip
    main(argv)
    assert f"  note: {NOMINAL_ONLY}" in capsys.readouterr().out
    assert json.loads(out.read_text())["notes"] == [NOMINAL_ONLY]
    nominal = tmp_path / "nominal.json"
    nominal.write_text(json.dumps({"design": {k: v for k, v in DESIGN.items()
                                              if k != "tolerances"}}))  # fmt: skip
    main([*argv[:1], str(nominal), *argv[2:]])
    assert "note:" not in capsys.readouterr().out
    assert json.loads(out.read_text())["notes"] == []


def test_the_help_and_the_refusal_list_the_same_probability_names(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The refusal of a bad --max-probability listed 7 names, --help 3 (new-user review,
    finding 7): both list every name the gate limits."""
    from gearengine.cli.documents import GATED
    from gearengine.cli.main import build_parser

    check = next(a for a in build_parser()._subparsers._group_actions[0].choices.items()
                 if a[0] == "check")[1]  # fmt: skip
    helped = " ".join(check.format_help().split())
    assert f"NAME one of {', '.join(GATED)}" in helped
    assert main(["check", str(design_file), "--max-probability", "nonsense=0.1"]) == 2
    assert f"NAME one of {', '.join(GATED)}" in capsys.readouterr().err


def test_a_gate_on_one_design_names_its_speed_and_torque(
    design_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A gate without --speed/--torque called its point 'operating point' and its report's
    point was {} (new-user review, finding 7): it is the design's own 4000 rpm and 5 N*m."""
    out = tmp_path / "one.json"
    argv = ["check", str(design_file), "--samples", "8", "--max-probability", "back_flank=0.5",
            "--json", str(out), "--junit", str(tmp_path / "j.xml")]  # fmt: skip
    assert main(argv) == 0
    assert "PASS: speed 4000 rpm, torque 5 N*m (8 samples)" in capsys.readouterr().out
    assert json.loads(out.read_text())["verdicts"][0]["point"] == {
        "speed": {"value": 4000.0, "unit": "rpm"},
        "torque": {"value": 5.0, "unit": "N*m"},
    }
    case = ElementTree.parse(tmp_path / "j.xml").getroot().find("testsuite/testcase")
    assert case is not None and case.get("name") == "speed 4000 rpm, torque 5 N*m"


def test_the_gate_reads_the_design_once_through_its_request(
    design_file: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The point a study without axes is named by (``own_point``) is the request's design, not
    the document's design validated a second time after the study."""
    from gearengine.model.design import Design

    calls: list[object] = []
    validate = Design.model_validate

    def counted(data: object, *args: object, **kwargs: object) -> Design:
        calls.append(data)
        return validate(data, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(Design, "model_validate", counted)
    argv = ["check", str(design_file), "--samples", "8", "--max-probability", "back_flank=0.5"]
    assert main(argv) == 0
    assert "PASS: speed 4000 rpm, torque 5 N*m (8 samples)" in capsys.readouterr().out
    assert DESIGN not in calls  # each sample's design is its own tree (model.fields.design_with)


def test_samples_auto_says_before_computing_that_the_budget_cannot_prove_a_limit() -> None:
    """``--samples auto`` on the worked envelope (115 points, P(chaotic) <= 1 %) ran 98 s and
    ended with 104 points undecided, the budget spent: a point with no events needs 561 samples
    at 99.3 %, the round of 1,024, which the budget could not hold at every point, and nothing
    said so before (third new-user review). ``unreachable`` says it from the work alone."""
    from gearengine.studies.robustness.sequential import unreachable
    from gearengine.studies.robustness.study import checked, point_work, robustness_work

    axes = [{"parameter": "speed", "start": "2000 rpm", "stop": "5000 rpm", "num": 3}]
    request = checked(RobustnessRequest.model_validate({"design": DESIGN, "axes": axes,
                                                        "samples": 64}))  # fmt: skip
    per_sample = robustness_work(request.model_copy(update={"samples": 1}))
    unit = point_work(request)
    said = unreachable(unit, {"chaotic": 0.01}, 600 * per_sample)
    assert said is not None
    assert said.startswith("a point with no events needs 561 samples to prove P(chaotic) <= 0.01 "
                           "at 99.3 % (the round of 1024 samples)")  # fmt: skip
    assert "holds 600 samples at each of the 3 points" in said
    assert unreachable(unit, {"chaotic": 0.01}, 1024 * per_sample) is None
    assert unreachable(unit, {"chaotic": 0.05}, 600 * per_sample) is None  # 110: round 128
