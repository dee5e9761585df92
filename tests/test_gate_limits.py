"""Every limit of ``gearengine check`` on one design and on an envelope, or refused: none may be
ignored (issue 26, items 2, 5 and 8)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from gearengine.cli.documents import InvalidInputError, read_document
from gearengine.cli.envelope import envelope_request
from gearengine.cli.main import build_parser, main
from gearengine.gate.envelope_text import windows_summary
from gearengine.gate.rules import Rules, attractor_failures, point_failures, verdict_failures
from gearengine.gate.runup import bin_failures
from gearengine.studies.runup.results import RunupBin
from gearengine.studies.sweep.points import PhysicalValue, SpeedWindows, SweepPoint
from tests.conftest import PAPER_PARAMS, ROOT

LIGHT = {"transient_periods": 60, "record_periods": 60, "steps_per_period": 128}


@pytest.fixture(scope="module")
def geometry(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The README's geometry-form design (18/30 teeth, 3 mm, ISO 6336 stiffness) at 3000 rpm:
    periodic 1T, teeth always in contact, DTE about 5 µm, dynamic factor about 1.07."""
    doc = json.loads((ROOT / "examples" / "design-geometry.json").read_text())
    path = tmp_path_factory.mktemp("gate") / "geometry.json"
    path.write_text(json.dumps({**doc, "settings": LIGHT}))
    return path


def test_physical_limits_judge_one_design(geometry: Path, capsys: pytest.CaptureFixture) -> None:
    """--max-dynamic-factor used to be ignored on one design (PASS with 1.07 > 1.01) and
    --max-dte refused it (exit 2); both now judge the design's own response."""
    assert main(["check", str(geometry)]) == 0
    out, err = capsys.readouterr()
    # the settings it ran, and why an envelope check's DTE at this point can differ (5.02 here,
    # 5.0096 µm there: a limit between them passed one and failed the other, unsaid)
    assert "settings: <= 60 + 60 periods (ended when settled), 128 steps a period (as" in err
    assert "an envelope check runs the light settings where the file sets none" in err
    factor = float(out.split("dynamic factor ")[1].split(";")[0])
    dte = float(out.split("DTE ")[1].split(" µm")[0])
    assert 1.01 < factor < 1.2 and 2.0 < dte < 20.0
    assert main(["check", str(geometry), "--max-dynamic-factor", "1.01"]) == 1
    assert "[dynamic factor > 1.01]" in capsys.readouterr().out
    assert main(["check", str(geometry), "--max-dynamic-factor", "1.5"]) == 0
    assert main(["check", str(geometry), "--max-dte", "2um"]) == 1
    assert "[DTE > 2 µm]" in capsys.readouterr().out
    assert main(["check", str(geometry), "--max-dte", "0.02mm"]) == 0


def test_limits_that_cannot_apply_are_refused(
    geometry: Path, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """Refused before any compute (exit 2), never silently ignored."""
    params = tmp_path / "params.json"
    params.write_text(json.dumps({"params": PAPER_PARAMS}))
    assert main(["check", str(params), "--max-dynamic-factor", "1.5"]) == 2
    assert "--max-dynamic-factor need a design in physical units" in capsys.readouterr().err
    assert main(["check", str(params), "--max-dte", "2um"]) == 2
    # the stability margin used to be dropped without a word on an envelope (exit 0)
    argv = ["check", str(geometry), "--speed", "1000:2000", "--min-stability-margin", "0.9"]
    assert main(argv) == 2
    assert "--min-stability-margin checks one design" in capsys.readouterr().err


def test_separation_fails_drive_flank_impacts() -> None:
    """--fail-on back_flank counts back-flank contact only; separation counts every regime in
    which the teeth come apart (drive-flank impacts too)."""

    def point(regime: str) -> SweepPoint:
        return SweepPoint(values={}, branch=None, classification="periodic", impact_regime=regime)

    separation = Rules(fail_on=["diverged", "separation"])
    back = Rules(fail_on=["diverged", "back_flank"])
    assert point_failures(point("single_sided"), separation) == ["tooth separation"]
    assert point_failures(point("double_sided"), separation) == ["tooth separation"]
    assert point_failures(point("no_impact"), separation) == []
    assert point_failures(point("single_sided"), back) == []
    args = build_parser().parse_args(["check", "x.json", "--fail-on", "separation"])
    assert args.fail_on == ["separation"]


def test_one_verdict_is_judged_by_the_rules_of_a_point() -> None:
    """One analysis is judged by the gate's rule for one verdict (``verdict_failures``), with no
    sweep point made for it; a sweep point is judged by the same rule."""
    rules = Rules(fail_on=["chaotic", "melnikov"], max_lle=0.0, max_dte_um=20.0,
                  max_dynamic_factor=1.5)  # fmt: skip
    verdict = ("chaotic", 0.05, "double_sided", True)
    # the LLE limit names its unit: '[LLE > -1000]' said none (new-user review, finding 7)
    expected = ["chaotic", "Melnikov: chaos possible", "LLE > 0 per unit tau", "DTE > 20 µm"]
    assert verdict_failures(rules, *verdict, dte_um=25.0, dynamic_factor=1.2) == expected
    # a limit on a value the verdict does not have (dimensionless, diverged) fails
    assert verdict_failures(rules, "periodic", -0.1, "no_impact", False)[-2:] == [
        "DTE > 20 µm",
        "dynamic factor > 1.5",
    ]
    physical = {"dte": PhysicalValue(value=25.0, unit="um"),
                "dynamic_factor": PhysicalValue(value=1.2, unit="1")}  # fmt: skip
    point = SweepPoint(values={}, branch=None, classification="chaotic", lle=0.05,
                       impact_regime="double_sided", melnikov_chaos_possible=True,
                       physical=physical)  # fmt: skip
    assert point_failures(point, rules) == expected


def test_envelope_pass_line_names_impact_and_melnikov_windows(
    geometry: Path, capsys: pytest.CaptureFixture
) -> None:
    argv = ["check", str(geometry), "--speed", "1000:3000", "--speed-points", "3",
            "--fail-on", "separation"]  # fmt: skip
    assert main(argv) == 0
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert lines[0].startswith("PASS: 0 of 3 operating points")
    # the geometry design's load is above its critical torque: the criterion does not apply
    assert lines[1] == (
        "  resolution: 3 speeds (1000 rpm), 16 starts a point; no neighbours "
        "differ and no point is near a limit: nothing to refine (up to 2 halvings)"
    )
    assert lines[2] == (
        "  windows: teeth always in contact; "
        "Melnikov: not applicable at 1000-3000 rpm (above T_crit)"
    )
    assert "settings: <= 60 + 60 periods (ended when settled), 128 steps a period" in captured.err


def test_envelope_settings_merge_over_the_light_defaults(tmp_path: Path) -> None:
    """A settings block used to replace the light defaults with the full analysis ones (500 +
    500 periods per start) when it gave only random starts."""
    doc = json.loads((ROOT / "examples" / "design-geometry.json").read_text())
    starts = {"count": 4, "box": [[-1.5, 1.5], [-0.5, 0.5]], "seed": 3}
    path = tmp_path / "starts.json"
    path.write_text(json.dumps({**doc, "settings": {"random_initial_states": starts}}))
    args = argparse.Namespace(file=str(path), speed="1000:2000", speed_points=3, torque=None,
                              torque_points=None, starts=1)  # fmt: skip
    settings = envelope_request(args, read_document(str(path))).settings
    assert (settings.transient_periods, settings.record_periods) == (60, 60)
    assert settings.steps_per_period == 128 and settings.random_initial_states.count == 4
    path.write_text(json.dumps({**doc, "settings": [1]}))
    with pytest.raises(InvalidInputError, match="settings must be an object"):
        envelope_request(args, read_document(str(path)))


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (["--speed", "4000:nan"], "--speed (its high end): 'nan rpm' is not a finite shaft speed"),
        (["--speed", "4000:5000", "--speed-points", "0"], "--speed-points: "),
        (["--speed", "4000:5000", "--torque", "5N:10N"], "--torque (its low end): '5N' has"),
    ],
)
def test_a_bad_option_is_named_by_the_option(
    options: list[str], named: str, capsys: pytest.CaptureFixture
) -> None:
    """What the options build (the sweep's axes) is refused naming the option the user typed,
    not the internal path (axes[0].stop), found by a new-user review."""
    assert main(["check", str(ROOT / "examples" / "ci" / "design.json"), *options]) == 2
    err = capsys.readouterr().err
    assert named in err and "axes[" not in err


def _diverged_point(attractors: list | None) -> SweepPoint:
    """The point the review found: 16 basin starts, every one diverged (no attractor)."""
    return SweepPoint(values={"speed": 31.4}, branch=None, classification="diverged",
                      attractors=attractors, decided_by="diverged from 100 % of starts",
                      physical={"speed": PhysicalValue(value=300.0, unit="rpm")})  # fmt: skip


def test_a_point_whose_every_start_diverged_fails_the_envelope() -> None:
    """With basins the gate checked each attractor above --min-basin, and a point where every
    start diverged has none: it passed ('PASS: 0 of 1' at 300 rpm of design-geometry.json, its
    classification diverged), where --starts 1 failed it. It is judged by its own verdict,
    and a diverged verdict fails whatever --fail-on says."""
    point = _diverged_point([])
    for rules in (Rules(), Rules(fail_on=["separation"]), Rules(fail_on=["back_flank"])):
        assert attractor_failures(point, rules) == [("diverged", "diverged from 100 % of starts")]
        assert point_failures(_diverged_point(None), rules) == ["diverged"]
    # the single-design check judges the same verdict words
    assert verdict_failures(Rules(fail_on=["separation"]), "diverged", None, None, None) == [
        "diverged"
    ]


def test_the_windows_never_call_a_diverged_speed_in_contact() -> None:
    """'teeth always in contact' was printed for a level whose one point diverged."""
    level = {"torque": PhysicalValue(value=60.0, unit="N*m")}
    w = SpeedWindows(level=level, response={"diverged": [[300.0, 300.0]]}, contact={},
                     melnikov=[])  # fmt: skip
    (line,) = windows_summary([w])
    assert "teeth always in contact" not in line
    assert "diverged (contact unknown) 300 rpm" in line


def test_a_diverged_runup_bin_fails_whatever_the_rules() -> None:
    """A bin where a member diverged (no LLE, no contact) failed only a chaos rule, and only
    after 0.05 s of them: under --fail-on separation it passed."""
    values = dict.fromkeys(RunupBin.model_fields)
    diverged = RunupBin(**{**values, "speed_rpm": [300.0, 350.0], "time_s": [0.0, 0.1]})
    assert bin_failures(diverged, Rules(fail_on=["separation"])) == ["diverged"]
    followed = diverged.model_copy(update={"lle": -0.1, "contact": "drive_flank",
                                           "separation_fraction": 0.0})  # fmt: skip
    assert bin_failures(followed, Rules(fail_on=["separation"])) == []


@pytest.mark.parametrize(
    "option",
    ["--max-dynamic-factor", "--max-lle", "--max-dte", "--min-basin", "--min-stability-margin",
     "--runup"],
)  # fmt: skip
def test_non_finite_limits_are_refused_naming_the_option(
    option: str, capsys: pytest.CaptureFixture
) -> None:
    """``check --max-dynamic-factor nan`` passed (no comparison with nan is true) and
    ``--max-dte nan`` printed '(--max-dte nan µm)' (new-user review, finding 3): nan and inf
    are refused by the parser (exit 2), naming the option; the library's Rules refuse them."""
    for value in ("nan", "inf", "-inf"):
        with pytest.raises(SystemExit) as stopped:
            build_parser().parse_args(["check", "x.json", f"{option}={value}"])
        assert stopped.value.code == 2
        assert f"argument {option}: '{value}': give a finite number" in capsys.readouterr().err
    field = {"--max-dynamic-factor": "max_dynamic_factor", "--max-lle": "max_lle",
             "--max-dte": "max_dte_um"}.get(option)  # fmt: skip
    if field is not None:
        with pytest.raises(ValueError, match="finite number"):
            Rules(**{field: float("nan")})


def test_no_melnikov_window_reads_nowhere_in_the_scanned_range(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """The summary said 'Melnikov chaos possible at nowhere rpm' (new-user review, finding 7)
    for the robustness example, whose criterion allows chaos at no speed it scanned."""
    doc = json.loads((ROOT / "examples" / "robustness-gears.json").read_text())
    path = tmp_path / "gears.json"
    path.write_text(json.dumps({**doc, "settings": LIGHT}))
    main(["check", str(path), "--max-lle", "-1000"])
    out = capsys.readouterr().out
    assert "Melnikov chaos possible nowhere in 10-18,000 rpm (scanned)" in out
    assert "nowhere rpm" not in out and "[LLE > -1000 per unit tau]" in out


def test_rules_that_leave_chaos_out_say_so_when_points_are_chaotic() -> None:
    """``--fail-on melnikov`` replaces the default ``chaotic``: an envelope passed three points
    chaotic from 50-100 % of starts and its text never said "chaotic" (second new-user
    review). The report notes the chaotic points the rules do not judge; none when they do."""
    from gearengine.gate.envelope import unjudged_chaos

    chaotic = SweepPoint(values={"speed": 500.0}, branch=None, classification="chaotic",
                         physical={"speed": PhysicalValue(value=4775.0, unit="rpm")})  # fmt: skip
    calm = chaotic.model_copy(update={"classification": "periodic"})
    (note,) = unjudged_chaos([chaotic, calm], Rules(fail_on=["melnikov"]))
    assert note.startswith("1 of 2 points are chaotic, which these rules do not judge")
    assert "fail_on: melnikov" in note and "add chaotic" in note
    assert unjudged_chaos([chaotic, calm], Rules()) == []
    assert unjudged_chaos([chaotic], Rules(fail_on=["quasi_periodic"])) == []
    assert unjudged_chaos([calm], Rules(fail_on=["separation"])) == []


def test_a_report_says_when_points_left_basin_starts_unsettled() -> None:
    """A check passed a point where 8 of 16 basin starts were unsettled (the attractors'
    fractions summing to 0.5) and its text never said so (fourth new-user review): the report
    notes the points with unsettled starts and the worst of them."""
    from gearengine.gate.envelope import unsettled_starts
    from gearengine.numerics.results import BasinCounts

    half = BasinCounts(
        starts=16,
        diverged=0,
        unsettled=8,
        labels=[0] * 8 + [-2] * 8,
        grid=None,
        box=[[-1.5, 1.5], [-0.5, 0.5]],
    )
    at = {"speed": PhysicalValue(value=5659.09, unit="rpm"),
          "torque": PhysicalValue(value=18.75, unit="N*m")}  # fmt: skip
    open_ = SweepPoint(values={"speed": 592.6}, branch=None, classification="periodic",
                       physical=at, basins=half)  # fmt: skip
    settled = open_.model_copy(update={"basins": half.model_copy(update={"unsettled": 0})})
    (note,) = unsettled_starts([open_, settled])
    assert note.startswith("1 of 2 points left basin starts unsettled")
    assert "up to 8 of 16 at speed 5659.09 rpm, torque 18.75 N*m" in note
    assert unsettled_starts([settled]) == []


@pytest.mark.parametrize(
    "option",
    [
        ["--refine", "1"],
        ["--runup", "100"],
        ["--starts", "4"],
        ["--speed-points", "5"],
        ["--torque-points", "3"],
    ],
)
def test_a_one_design_check_refuses_the_envelope_options_it_would_ignore(
    option: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """``check FILE --refine 1`` and ``--runup 100`` without --speed or --torque passed (exit 0)
    having run neither, while --starts and --json were refused (second new-user review)."""
    from gearengine.cli.main import main

    design = str(ROOT / "examples" / "design-geometry.json")
    assert main(["check", design, *option]) == 2
    assert f"{option[0]} checks an envelope" in capsys.readouterr().err


def test_one_point_over_a_range_is_refused(capsys: pytest.CaptureFixture) -> None:
    """``check --speed 1000:6000 --torque 5:60 --speed-points 1 --torque-points 1`` printed
    "PASS: 0 of 1 operating points" having checked 1,000 rpm / 5 N*m alone, 6,000 rpm and
    60 N*m unsaid (third new-user review): one point over a range is its start alone, so it is
    refused in the gate, the study and the sweep (``SweepAxis.count_problem``)."""
    from gearengine.cli.main import main

    design = str(ROOT / "examples" / "design-geometry.json")
    said = "1 point over 1000 rpm:6000 rpm is its start alone: give at least 2 points"
    assert main(["check", design, "--speed", "1000:6000", "--speed-points", "1"]) == 2
    assert f"--speed-points: {said}" in capsys.readouterr().err
    assert main(["robustness", design, "--speed", "1000:6000", "--speed-points", "1"]) == 2
    assert f"--speed-points: {said}" in capsys.readouterr().err
    assert main(["check", design, "--speed", "1000:1000", "--speed-points", "3"]) == 2
    # said as the one value it is, with the option that gives it (fourth new-user review)
    assert "stop equals start, which is one value: give 1 point (num 1; --speed-points 1" in (
        capsys.readouterr().err)  # fmt: skip


@pytest.mark.parametrize("axis", ["speed", "torque"])
def test_a_grid_without_its_range_is_refused(axis: str, capsys: pytest.CaptureFixture) -> None:
    """``check FILE --torque 5:20 --speed-points 5`` checked the torque levels at the design's
    speed and passed with the 5 speeds unrun, unsaid (third stop-39 leftover): a grid's point
    count without its range is refused in check, remedies and robustness alike."""
    from gearengine.cli.main import main

    design = str(ROOT / "examples" / "design-geometry.json")
    other = {"speed": ["--torque", "5:20"], "torque": ["--speed", "1000:2000"]}[axis]
    for command in (["check", design, *other], ["remedies", design, *other],
                    ["robustness", design]):  # fmt: skip
        if command[0] == "remedies" and axis == "speed":
            continue  # remedies require --speed
        assert main([*command, f"--{axis}-points", "3"]) == 2
        err = capsys.readouterr().err
        assert f"--{axis}-points: counts the points of a {axis} range, and none is given" in err


@pytest.mark.parametrize(
    "option",
    [
        "--max-dte=-1um",
        "--max-dte=0",
        "--max-dynamic-factor=0",
        "--max-dynamic-factor=0.5",
        "--max-dynamic-factor=1",
    ],
)
def test_a_limit_no_point_can_meet_is_refused_naming_the_option(
    option: str, capsys: pytest.CaptureFixture
) -> None:
    """``--max-dte=-1um`` failed every point ('DTE > -1 µm', second new-user review): a DTE
    peak to peak or a dynamic factor is never below 0, so a limit at or under 0 is refused
    (``Rules``), named by its option, before computing (it was an internal error once Rules
    refused it, a ValidationError the CLI did not read)."""
    from gearengine.cli.main import main

    assert main(["check", str(ROOT / "examples" / "design-geometry.json"), option]) == 2
    floor = "1" if option.startswith("--max-dynamic-factor") else "0"
    assert f"{option.split('=')[0]}: Input should be greater than {floor}" in (
        capsys.readouterr().err)  # fmt: skip


@pytest.mark.parametrize("rate", ["0", "-500"])
def test_a_bad_runup_rate_is_refused_before_the_envelope_is_computed(
    rate: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check --speed --torque --runup 0`` computed the whole envelope sweep and its refinement
    before the run-up request refused its rate as "rate" and "bin_rpm" (noticed in the walk of
    issue 29): the parser refuses a rate that is not positive, and any other bad ramp is
    refused before the envelope, naming --runup; no point is computed."""
    import gearengine.cli.envelope as envelope

    def no_sweep(*args: object, **kwargs: object) -> None:
        raise AssertionError("the envelope was computed before the ramp was checked")

    monkeypatch.setattr(envelope, "sweep_here", no_sweep)
    design = str(ROOT / "examples" / "ci" / "design.json")
    with pytest.raises(SystemExit) as stopped:
        main(["check", design, "--speed", "3500:4500", "--torque", "20:40", f"--runup={rate}"])
    assert stopped.value.code == 2
    err = capsys.readouterr().err
    assert f"argument --runup: '{rate}': give a positive rate in rpm/s" in err, err
    # a ramp the run-up refuses for another reason (its work budget) is refused before the
    # envelope too, naming --runup
    monkeypatch.setattr("gearengine.studies.runup.profile.MAX_RUNUP_STEPS", 1)
    assert main(["check", design, "--speed", "3500:4500", "--torque", "20:40", "--runup=500"]) == 2
    err = capsys.readouterr().err
    assert "--runup" in err and "over the budget" in err, err
