"""Every verdict of an ensemble is its worst attractor's (issue 30 item 1, docs/basins.md): the
sweep point, its speed windows, CSV and DataFrame rows, and the analysis' summary sentences.

The pair of ``examples/basins-5750rpm.json`` at 5,750 rpm / 2 N*m: from the settings' own start
it settles on a period-1 orbit, while 9 of 16 basin starts reach a chaotic attractor."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.studies.sweep import SweepRequest, run_local
from gearengine.studies.sweep.export import csv_rows
from gearengine.studies.sweep.results import to_csv

ROOT = Path(__file__).resolve().parents[1]
DOC = json.loads((ROOT / "examples" / "basins-5750rpm.json").read_text())
BASINS = {"starts": 16, "box": [["-30 um", "30 um"], ["-250 mm/s", "250 mm/s"]]}
SETTINGS = {**DOC["settings"], "basins": BASINS}


@pytest.fixture(scope="module")
def analysis():
    return analyze(AnalysisRequest.model_validate({**DOC, "settings": SETTINGS}))


@pytest.fixture(scope="module")
def sweep():
    request = SweepRequest.model_validate(
        {
            "design": DOC["design"],
            "settings": SETTINGS,
            "axes": [{"parameter": "speed", "start": "5750 rpm", "stop": "5750 rpm", "num": 1}],
        }
    )
    return run_local(request)


def test_the_recorded_run_and_the_worst_attractor_differ(analysis):
    """The premise: the settings' start is periodic, the worst attractor chaotic."""
    assert analysis.numerics.classification == "periodic"
    assert analysis.numerics.attractors[0].classification == "chaotic"
    assert analysis.verdict.chaotic


def test_summaries_name_the_worst_attractor(analysis):
    summary = analysis.engineering.summary
    assert "The simulated response is chaotic (chaotic, back-flank impacts from 56 %" in summary
    assert "the recorded run from the settings' start is periodic (1T)" in summary
    # each LLE beside the response it belongs to: the chaotic attractor's in its parenthesis,
    # the recorded periodic run's with that run's contact, DTE and dynamic factor
    worst, run = analysis.numerics.attractors[0].lle, analysis.numerics.lle
    assert worst > 0.0 > run
    head, tail = summary.split("the recorded run from the settings' start")
    assert f"({worst:+.3g} per unit tau)" in head and f"({run:+.3g} per unit tau)" in tail
    line = analysis.summary()
    assert line.startswith("chaotic (chaotic, back-flank impacts from 56 % of starts)")


def _largest(found, field):
    """The largest value of ``field`` over the attractors above min_fraction 0, and its owner."""
    return max(((getattr(a, field), a) for a in found), key=lambda va: va[0])


def test_the_one_line_summary_gives_the_largest_dte_and_dynamic_factor_named(analysis):
    """The verdict is the worst attractor's by class (chaotic, 56 %), the DTE and dynamic factor
    the largest over the attractors: the 25 % periodic one's 45.3 µm, named, not the chaotic
    one's 32.6 µm (which the line gave while the DTE gate failed on 45.3 µm; decision on
    issue 30's review, finding 1)."""
    found = analysis.numerics.attractors
    dte, owner = _largest(found, "dte_um")
    assert owner is not found[0] and dte > found[0].dte_um  # the premise: another attractor
    factor, same = _largest(found, "dynamic_factor")
    assert same is owner
    line = analysis.summary()
    named = f"{owner.label} from {100 * owner.fraction:.0f} % of starts"
    assert f"; DTE {dte:.3g} µm, dynamic factor {factor:.3g} ({named})" in line
    assert line.startswith("chaotic (chaotic, back-flank impacts from 56 % of starts)")
    worst = analysis.engineering.most_adverse
    assert worst["dte"].value == dte and worst["dte"].label == owner.label
    assert worst["dte"].attractor == found.index(owner) and worst["dte"].fraction == 0.25
    assert worst["force_max"].value == max(a.force_max_n for a in found)
    assert worst["force_min"].value == min(a.force_min_n for a in found)
    summary = analysis.engineering.summary
    assert f"the largest dynamic transmission error {dte:.3g} µm peak to peak ({named})" in summary


def test_the_single_point_check_judges_what_the_summary_says(analysis):
    """``gearengine check FILE`` on a file with basins: the verdict is the worst attractor's
    (chaotic), the DTE the largest over the attractors; it judged the settings' periodic start
    (PASS under --fail-on chaotic while the line it printed said chaotic)."""
    from gearengine.cli.analyze import failures
    from gearengine.gate.rules import Rules

    dte = _largest(analysis.numerics.attractors, "dte_um")[0]
    assert failures(analysis, Rules()) == ["chaotic"]
    rules = Rules(fail_on=["diverged"], max_dte_um=float(f"{dte:.3g}") - 0.5)
    assert failures(analysis, rules) == [f"DTE > {rules.max_dte_um:g} µm"]
    assert failures(analysis, rules.model_copy(update={"max_dte_um": dte + 0.1})) == []


def test_sweep_point_and_windows_follow_the_worst_attractor(sweep):
    (p,) = sweep.points
    worst = p.attractors[0]
    assert (p.classification, p.period) == ("chaotic", None)
    assert p.lle == worst.lle and p.impact_regime == worst.impact_regime
    assert p.decided_by == f"{worst.label} from 56 % of starts"
    assert p.decided_fraction == worst.fraction == 9 / 16
    assert list(sweep.windows[0].response) == ["chaotic"]


def test_csv_and_dataframe_rows_have_the_verdict_and_every_attractor(sweep):
    """Every attractor in its own columns, worst first, with units where they have them: the
    CSV had one ``attractors`` string of labels and bare fractions (review of issue 30)."""
    rows = list(to_csv(sweep, design=True))
    header = rows[0].strip().split(",")
    found = sweep.points[0].attractors
    assert len(found) == 3
    first = header.index("attractor_0_class")
    assert header[first - 8 : first] == [
        "dte_from",
        "dynamic_factor_from",
        "force_max_from",
        "force_min_from",
        "decided_by",
        "decided_fraction",
        "basin_starts",
        "record_from",
    ]
    each = ["class", "period", "impact_regime", "fraction", "fraction_low", "fraction_high",
            "lle [1/tau]", "dte [um]", "dynamic_factor", "force_max [N]",
            "force_min [N]"]  # fmt: skip
    assert header[first:] == [f"attractor_{k}_{name}" for k in (0, 1, 2) for name in each]
    assert "attractors" not in header
    frame = sweep.to_pandas()
    assert list(frame.columns) == header
    row = frame.iloc[0]
    assert row["classification"] == "chaotic"
    assert row["decided_by"] == sweep.points[0].decided_by
    assert row["decided_fraction"] == pytest.approx(9 / 16)
    assert row["basin_starts"] == 16
    # the record columns are the settings' start's run, in half backlashes, and say so
    assert row["record_from"] == "worst of the settings' own starts"
    assert row["x_peak_to_peak [b]"] == sweep.points[0].x_peak_to_peak
    assert row["poincare_x [b]"] == sweep.points[0].poincare_x
    # one numbering: magnitudes_from's attractor k is the CSV's attractor_k group
    dte_from = sweep.points[0].magnitudes_from["dte"]
    assert row[f"attractor_{dte_from.attractor}_dte [um]"] == row["dte [um]"]
    assert row[f"attractor_{dte_from.attractor}_class"] == found[dte_from.attractor].classification
    for k, a in enumerate(found):
        assert row[f"attractor_{k}_class"] == a.classification
        assert row[f"attractor_{k}_fraction"] == a.fraction
        assert [row[f"attractor_{k}_fraction_{e}"] for e in ("low", "high")] == a.interval
        assert row[f"attractor_{k}_lle [1/tau]"] == a.lle
        assert row[f"attractor_{k}_dte [um]"] == a.dte_um
        assert row[f"attractor_{k}_force_min [N]"] == a.force_min_n
    assert found[0].period is None and row.isna()["attractor_0_period"]
    assert row["attractor_1_period"] == found[1].period
    assert row["attractor_1_impact_regime"] == found[1].impact_regime


def test_csv_and_dataframe_magnitudes_are_the_largest_over_the_attractors_named(sweep):
    """The DTE, dynamic-factor and force columns are the most adverse over the attractors
    (largest, force_min smallest; the periodic 25 % attractor's 45.3 µm beside the chaotic
    verdict), each named in a *_from column; the unitless force_max, force_min (another start's)
    are gone beside force_max [N] (a new-user review of issue 30, finding 1 and item 7)."""
    (p,) = sweep.points
    found = p.attractors
    dte, owner = _largest(found, "dte_um")
    assert owner is not found[0]  # the premise: not the attractor that decided the verdict
    assert p.physical["dte"].value == dte
    assert p.physical["dynamic_factor"].value == _largest(found, "dynamic_factor")[0]
    assert p.physical["force_max"].value == _largest(found, "force_max_n")[0]
    assert p.physical["force_min"].value == min(a.force_min_n for a in found)
    assert p.magnitudes_from["dte"].label == owner.label
    assert p.magnitudes_from["dte"].attractor == found.index(owner)
    assert p.magnitudes_from["dte"].fraction == owner.fraction
    header = next(iter(to_csv(sweep, design=True))).strip().split(",")
    assert "force_max [N]" in header and "force_max" not in header and "force_min" not in header
    row = sweep.to_pandas().iloc[0]
    assert row["dte [um]"] == pytest.approx(dte)
    assert row["force_min [N]"] == pytest.approx(p.physical["force_min"].value)
    assert row["dte_from"] == f"{owner.label} from {100 * owner.fraction:.0f} % of starts"
    assert row["classification"] == "chaotic" and row["decided_fraction"] == pytest.approx(9 / 16)
    # the service writes the CSV from stored points (JSON objects): the same rows
    stored = [json.loads(q.model_dump_json()) for q in sweep.points]
    rows = csv_rows(sweep.axes, stored, None, True, True, len(found))
    assert list(rows) == list(to_csv(sweep, design=True))


def test_the_z23_67_point_gives_one_dte_in_headline_check_json_and_gate():
    """The worked example of issue 30 (examples/remedies-z23-67.json at 5,000 rpm / 10 N*m, 16
    starts): the verdict is the chaotic attractor's (31 %), the DTE shown in the check JSON is
    the periodic attractor's 62 µm (69 %), on which --max-dte 30um fails; it showed the chaotic
    one's 20.4 µm, and the settings' start's force_max."""
    from gearengine.gate.envelope import check_envelope, envelope_sweep, gate_settings
    from gearengine.gate.rules import Rules

    design = json.loads((ROOT / "examples" / "remedies-z23-67.json").read_text())["design"]
    axes = [{"parameter": "speed", "start": "5000 rpm", "stop": "5000 rpm", "num": 1},
            {"parameter": "torque", "start": "10 N*m", "stop": "10 N*m", "num": 1}]  # fmt: skip
    doc = envelope_sweep(design, gate_settings({}, 16), axes, "z = 23/67")
    report = check_envelope(SweepRequest.model_validate(doc), Rules(max_dte_um=30.0), refine=0)
    (p,) = report.sweep.points
    assert (p.classification, p.decided_by) == ("chaotic", "chaotic, tooth separation from "
                                                "31 % of starts")  # fmt: skip
    periodic = next(a for a in p.attractors if a.classification == "periodic")
    assert periodic.fraction == 11 / 16 and round(periodic.dte_um) == 62
    assert p.physical["dte"].value == periodic.dte_um
    assert p.physical["force_max"].value == max(a.force_max_n for a in p.attractors)
    assert p.magnitudes_from["dte"].label == periodic.label
    assert [(w.rule, w.attractors) for w in report.failures] == [
        ("chaotic", ["5000 rpm: chaotic, tooth separation from 31 % of starts"]),
        ("DTE > 30 µm", ["5000 rpm: periodic 1T, tooth separation from 69 % of starts"]),
    ]


def test_the_numerics_say_they_are_the_settings_starts_answer(analysis, tmp_path, capsys):
    """numerics.classification, worst_case and the Floquet block are the settings' periodic
    start's under verdict.chaotic (decided by another attractor); the JSON and the text say
    whose they are, and which attractor decided (issue 30 review, finding 2)."""
    from gearengine.cli.main import main

    assert analysis.numerics.worst_case.classification == "periodic" and analysis.verdict.chaotic
    assert analysis.verdict.decided_attractor == 0
    note = analysis.numerics.notes[-1]
    assert "worst_case, floquet" in note and "settings' own start's answer (periodic (1T))" in note
    assert "the verdict is another attractor's above basins.min_fraction: " in note
    assert note.endswith(f"{analysis.verdict.decided_by} (verdict.decided_by)")
    path = tmp_path / "doc.json"
    path.write_text(json.dumps({**DOC, "settings": SETTINGS}))
    assert main(["analyze", str(path)]) == 0
    text = capsys.readouterr().out
    assert "of the settings' start: Floquet multipliers" in text
    assert f"note: {note}" in text


def test_the_gates_min_basin_is_the_threshold_of_the_points_it_shows(tmp_path):
    """check --min-basin X checked the attractors above X while each point's verdict and
    magnitudes came from those above the file's basins.min_fraction (0): a 10 % attractor's DTE
    was shown on a point the gate passed. The gate's threshold is now the points' too (CLI and
    the remedies' envelope)."""
    from gearengine.cli.envelope import envelope_request
    from gearengine.cli.main import build_parser
    from gearengine.gate.envelope import gate_settings

    assert gate_settings({}, 16, 0.2)["basins"] == {"starts": 16, "grid": True, "min_fraction": 0.2}
    assert gate_settings({"basins": {"starts": 8}}, None, 0.3)["basins"]["min_fraction"] == 0.3
    assert gate_settings({"record_periods": 60}, 1, 0.2) == {"record_periods": 60}
    assert "min_fraction" not in gate_settings({}, 16)["basins"]
    args = build_parser().parse_args(["check", "design.json", "--speed", "5000:6000",
                                      "--speed-points", "2", "--min-basin", "0.2"])  # fmt: skip
    doc = {"design": DOC["design"]}
    assert envelope_request(args, doc).settings.basins.min_fraction == 0.2


def test_the_te_with_static_and_contact_forces_are_over_the_attractors_too(analysis):
    """The magnitudes read from a time history (the TE an encoder sees, the contact force) are
    the most adverse over the attractors as well, each attractor run again from a start that
    reached it; engineering.response stays the settings' start's, one of them."""
    worst, run = analysis.engineering.most_adverse, analysis.engineering.response
    assert set(worst) == {"dte", "dynamic_factor", "force_max", "force_min", "te_with_static",
                          "contact_force_max", "contact_force_min"}  # fmt: skip
    assert worst["te_with_static"].value >= run.te_with_static_peak_to_peak_um
    assert worst["contact_force_max"].value >= run.contact_force_max_n
    assert worst["contact_force_min"].value <= run.contact_force_min_n
    # the contact force is the model's force where a flank touches: within its extremes
    assert worst["force_min"].value <= worst["contact_force_min"].value
    assert worst["contact_force_max"].value <= worst["force_max"].value
    assert {w.unit for k, w in worst.items() if k.startswith("contact")} == {"N"}


def test_a_robustness_sample_counts_the_largest_dte_and_dynamic_factor():
    """With basins a robustness sample counts as its worst attractor by class, and its DTE and
    dynamic factor (P(dynamic_factor_above_limit), the DTE statistics and their Sobol indices)
    are the largest over the attractors, as a sweep point shows them: it took the chaotic
    attractor's 20.4 µm beside a 69 % periodic one of 62 µm."""
    from gearengine.numerics.results import Attractor, BasinCounts
    from gearengine.studies.robustness.study import CLASSES, _worst

    def attractor(kind: str, count: int, dte: float, factor: float) -> Attractor:
        return Attractor.model_construct(
            label=kind,
            classification=kind,
            period=None,
            impact_regime="single_sided",
            fraction=count / 16,
            count=count,
            dte_um=dte,
            dynamic_factor=factor,
        )

    found = [attractor("chaotic", 5, 20.4, 7.15), attractor("periodic", 11, 62.0, 9.92)]
    counts = BasinCounts.model_construct(starts=16, diverged=0, unsettled=0)
    run = _worst([0, 0, True, 62.0, 9.92], found, counts, 0.0)
    assert run == [CLASSES.index("chaotic"), 1, True, 62.0, 9.92]
    assert _worst([0, 0, True, 1.0, 1.0], found, counts, 0.5)[3:] == [62.0, 9.92]


def test_a_sweep_keeping_some_outputs_keeps_whose_they_are():
    """A sweep whose outputs keep classification and physical kept the worst attractor's class
    and the largest DTE without decided_by or magnitudes_from: numbers without their owner."""
    request = SweepRequest.model_validate(
        {"design": DOC["design"], "settings": SETTINGS, "outputs": ["classification", "physical"],
         "axes": [{"parameter": "speed", "start": "5750 rpm", "stop": "5750 rpm", "num": 1}]}
    )  # fmt: skip
    (p,) = run_local(request).points
    assert p.classification == "chaotic" and p.decided_by.startswith("chaotic")
    assert p.magnitudes_from["dte"].classification == "periodic" and p.lle is None
