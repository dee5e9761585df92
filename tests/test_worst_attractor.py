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
    assert "The simulated response is chaotic (chaotic, double-sided impacts from 56 %" in summary
    assert "the recorded run from the settings' start is periodic (1T)" in summary
    # each LLE beside the response it belongs to: the chaotic attractor's in its parenthesis,
    # the recorded periodic run's with that run's contact, DTE and dynamic factor
    worst, run = analysis.numerics.attractors[0].lle, analysis.numerics.lle
    assert worst > 0.0 > run
    head, tail = summary.split("the recorded run from the settings' start")
    assert f"({worst:+.3g} per unit tau)" in head and f"({run:+.3g} per unit tau)" in tail
    line = analysis.summary()
    assert line.startswith("chaotic (chaotic, double-sided impacts from 56 % of starts)")


def test_the_one_line_summary_gives_the_worst_attractors_dte_and_dynamic_factor(analysis):
    """The headline's DTE and dynamic factor sit beside the chaotic attractor's LLE: they are
    that attractor's, not the periodic settings' start's (which read 'chaotic ... DTE 62 um')"""
    worst, run = analysis.numerics.attractors[0], analysis.engineering.response
    assert f"{worst.dte_um:.3g}" != f"{run.dte_peak_to_peak_um:.3g}"  # the premise
    line = analysis.summary()
    assert f"; DTE {worst.dte_um:.3g} µm, dynamic factor {worst.dynamic_factor:.3g}" in line


def test_sweep_point_and_windows_follow_the_worst_attractor(sweep):
    (p,) = sweep.points
    worst = p.attractors[0]
    assert (p.classification, p.period) == ("chaotic", None)
    assert p.lle == worst.lle and p.impact_regime == worst.impact_regime
    assert p.decided_by == f"{worst.label} from 56 % of starts"
    assert p.decided_fraction == worst.fraction == 9 / 16
    assert list(sweep.windows[0].response) == ["chaotic"]


def test_csv_and_dataframe_rows_have_the_verdict_and_every_attractor(sweep):
    rows = list(to_csv(sweep, design=True))
    header = rows[0].strip().split(",")
    assert header[-4:] == ["decided_by", "decided_fraction", "basin_starts", "attractors"]
    frame = sweep.to_pandas()
    row = frame.iloc[0]
    assert row["classification"] == "chaotic"
    assert row["decided_by"] == sweep.points[0].decided_by
    assert row["decided_fraction"] == pytest.approx(9 / 16)
    assert row["basin_starts"] == 16
    listed = [part.rsplit(": ", 1) for part in row["attractors"].split("; ")]
    assert [(label, float(f)) for label, f in listed] == [
        (a.label, pytest.approx(a.fraction)) for a in sweep.points[0].attractors
    ]


def test_csv_and_dataframe_dte_and_dynamic_factor_are_the_worst_attractors(sweep):
    """The DTE and dynamic-factor columns belong to the attractor whose verdict heads the row
    (decided_by), not to the settings' own periodic start (a new-user review of issue 30)."""
    (p,) = sweep.points
    worst = p.attractors[0]
    assert p.physical["dte"].value == pytest.approx(worst.dte_um)
    assert p.physical["dynamic_factor"].value == pytest.approx(worst.dynamic_factor)
    row = sweep.to_pandas().iloc[0]
    assert row["dte [um]"] == pytest.approx(worst.dte_um)
    assert row["dynamic_factor"] == pytest.approx(worst.dynamic_factor)
