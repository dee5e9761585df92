"""The gate states the resolution it checked and refines between grid points: chaos in a narrow
window between two passing grid points next to a point near the chaos limit is found, as a
finer grid finds it (issue 30.4).

The case is the z = 23/67 class-7 pair of ``examples/remedies-z23-67.json`` with the
transmission error lowered to 4.591 µm (the remedy the default 23 x 5 grid accepted): at 5 N*m,
4,500 and 5,000 rpm are periodic, 4,750 rpm is chaotic from about 40 % of the 16 starts, and the
period-2 attractor at 4,500 rpm contracts at half the linear rate (LLE -0.024 at mu = 0.05).
"""

from __future__ import annotations

import json

from gearengine.cli.junit import envelope_junit
from gearengine.gate.envelope import (
    Rules,
    envelope_axis,
    envelope_sweep,
    gate_settings,
    near_limit,
    refined_report,
)
from gearengine.studies.sweep import run_local, validated
from tests.conftest import ROOT

DESIGN = ROOT / "examples" / "remedies-z23-67.json"


def sweep(te_um: float, speed: str, num: int) -> object:
    design = json.loads(DESIGN.read_text())["design"]
    design["transmission_error"]["harmonics"][0]["amplitude"] = f"{te_um} um"
    axes = [envelope_axis("speed", speed, "rpm", num), envelope_axis("torque", "5:5", "N*m", 1)]
    return validated(envelope_sweep(design, gate_settings({}, None), axes, "resolution test"))


def test_refinement_finds_chaos_between_passing_grid_points() -> None:
    request = sweep(4.591, "4500:5000", 2)
    result = run_local(request, chunk_points=1)
    rules = Rules()
    coarse = refined_report(request, result, rules, refine=0)
    assert coarse.passed and coarse.points == 2
    assert coarse.resolution is not None and coarse.resolution.starts == 16
    assert coarse.resolution.speed_step_rpm == 500.0
    assert "not refined between grid points" in coarse.resolution.text()
    assert any(near_limit(p, rules) for p in result.points)

    fine = refined_report(request, result, rules, refine=1)
    assert not fine.passed and fine.points == 3 and fine.failing_points == 1
    assert fine.resolution is not None and fine.resolution.refined_points == 1
    assert fine.resolution.finest_speed_step_rpm == 250.0
    assert "refined to 250 rpm" in fine.resolution.text()
    (window,) = fine.failures
    assert window.rule == "chaotic" and window.speeds_rpm == [4750.0, 4750.0]
    assert window.attractors and "% of starts" in window.attractors[0]
    assert "<failure " in envelope_junit(fine, "envelope")


def test_a_point_far_from_every_limit_is_not_refined() -> None:
    """Two passing grid points, both contracting near the linear rate: nothing is inserted."""
    request = sweep(4.591, "4500:4625", 2)
    result = run_local(request, chunk_points=1)
    rules = Rules(fail_on=["diverged"])  # the chaos limit is not a rule: LLEs are not near it
    report = refined_report(request, result, rules, refine=2)
    assert report.passed and report.resolution is not None
    assert report.resolution.refined_points == 0 and report.points == 2


def test_windows_are_the_failures_points_and_levels_ascend() -> None:
    """One source for the check's windows: the report's windows (text and JSON) are drawn from
    the grid and the refined points its failures come from, at every torque level, ascending
    (the windows said chaotic 4500-5000 rpm at 2 N*m beside a failure at 4500-5250 rpm, left out
    the refined 6.75 N*m level, and the failures listed 2, 11.5, then 6.75 N*m)."""
    from gearengine.cli.envelope import windows_summary
    from gearengine.gate.envelope import EnvelopeReport, envelope_report

    golden = EnvelopeReport.model_validate_json((ROOT / "tests/golden/check-envelope.json")
                                                .read_text())  # fmt: skip
    report = envelope_report(golden.sweep, golden.rules, golden.refined, golden.resolution)
    torques = [w.level["torque"].value for w in report.windows]
    assert torques == sorted(torques) == [2.0, 6.75, 11.5]
    failing = [f.level["torque"].value for f in report.failures]
    assert failing == sorted(failing)
    for f in report.failures:
        (w,) = [w for w in report.windows if w.level == f.level]
        lo, hi = f.speeds_rpm
        assert any(a <= lo and hi <= b for a, b in w.response[f.rule]), (f, w.response)
    assert len(windows_summary(report.windows)) == 3


def test_junit_cases_come_in_ascending_torque() -> None:
    """The JUnit report lists its torque levels as the text does, ascending: a refined level
    with failures (6.75 N*m) stands between the grid's 2 and 11.5 N*m, not after them."""
    from xml.etree import ElementTree

    from gearengine.gate.envelope import EnvelopeReport, envelope_report

    golden = EnvelopeReport.model_validate_json((ROOT / "tests/golden/check-envelope.json")
                                                .read_text())  # fmt: skip
    report = envelope_report(golden.sweep, golden.rules, golden.refined, golden.resolution)
    root = ElementTree.fromstring(envelope_junit(report, "envelope"))
    names = [c.get("name") for c in root.iter("testcase")]
    assert names == ["torque 2 N*m", "torque 6.75 N*m", "torque 11.5 N*m"]


def test_a_one_point_check_says_there_is_nothing_to_refine() -> None:
    """One operating point has no neighbours: the resolution says so (it printed "refined to
    where" with nothing between "to" and "where")."""
    from gearengine.gate.resolution import resolution

    text = resolution(sweep(4.591, "4500:4500", 1), 1).text()
    assert text == "1 speed (one point), 16 starts a point; no neighbours to refine between"
