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

import pytest

from gearengine.gate.envelope import envelope_axis, envelope_sweep, gate_settings, refined_report
from gearengine.gate.junit import envelope_junit
from gearengine.gate.rules import Rules, near_limit
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
    """Two passing grid points, both contracting near the linear rate: nothing is inserted for
    the limits (their attractor sets differ, 2T beside 1T: the gate refines there for that)."""
    from gearengine.gate.resolution import refine
    from gearengine.gate.rules import attractor_failures

    request = sweep(4.591, "4500:4625", 2)
    result = run_local(request, chunk_points=1)
    rules = Rules(fail_on=["diverged"])  # the chaos limit is not a rule: LLEs are not near it
    fails = lambda p: bool(attractor_failures(p, rules))  # noqa: E731
    assert refine(request, result.points, fails, lambda p: near_limit(p, rules), 2) == []
    report = refined_report(request, result, rules, refine=2)
    assert report.passed and report.resolution is not None
    assert report.resolution.refined_points == 2 and report.points == 4


def test_windows_are_the_failures_points_and_levels_ascend() -> None:
    """One source for the check's windows: the report's windows (text and JSON) are drawn from
    the grid and the refined points its failures come from, at every torque level, ascending
    (the windows said chaotic 4500-5000 rpm at 2 N*m beside a failure at 4500-5250 rpm, left out
    the refined 6.75 N*m level, and the failures listed 2, 11.5, then 6.75 N*m)."""
    from gearengine.gate.envelope import EnvelopeReport, envelope_report
    from gearengine.gate.envelope_text import windows_summary

    golden = EnvelopeReport.model_validate_json((ROOT / "tests/golden/check-envelope.json")
                                                .read_text())  # fmt: skip
    report = envelope_report(golden.sweep, golden.rules, golden.refined, golden.resolution)
    torques = [w.level["torque"].value for w in report.windows]
    assert torques == sorted(torques) == [2.0, 4.375, 6.75, 9.125, 11.5]
    failing = [f.level["torque"].value for f in report.failures]
    assert failing == sorted(failing)
    for f in report.failures:
        (w,) = [w for w in report.windows if w.level == f.level]
        lo, hi = f.speeds_rpm
        assert any(a <= lo and hi <= b for a, b in w.response[f.rule]), (f, w.response)
    assert len(windows_summary(report.windows)) == 5


def test_junit_cases_come_in_ascending_torque() -> None:
    """The JUnit report lists its torque levels as the text does, ascending: refined levels
    (4.375, 6.75, 9.125 N*m) stand between the grid's 2 and 11.5 N*m, not after them."""
    from xml.etree import ElementTree

    from gearengine.gate.envelope import EnvelopeReport, envelope_report

    golden = EnvelopeReport.model_validate_json((ROOT / "tests/golden/check-envelope.json")
                                                .read_text())  # fmt: skip
    report = envelope_report(golden.sweep, golden.rules, golden.refined, golden.resolution)
    root = ElementTree.fromstring(envelope_junit(report, "envelope"))
    names = [c.get("name") for c in root.iter("testcase")]
    assert names == [f"torque {t} N*m" for t in ("2", "4.375", "6.75", "9.125", "11.5")]


def test_a_one_point_check_says_there_is_nothing_to_refine() -> None:
    """One operating point has no neighbours: the resolution says so (it printed "refined to
    where" with nothing between "to" and "where")."""
    from gearengine.gate.resolution import resolution

    text = resolution(sweep(4.591, "4500:4500", 1), 1).text()
    assert text == "1 speed (one point), 16 starts a point; no neighbours to refine between"


def test_the_default_refinement_finds_chaos_next_to_a_refined_point_near_the_limit() -> None:
    """The z = 23/67 pair (TE 11.3 µm) at 5 N*m: 3,500 and 3,727 rpm (grid neighbours of the
    default 23 x 5 grid) and their midpoint 3,614 rpm pass, all near the chaos limit; 3,557 rpm
    is chaotic from 19 % of starts. One halving (main's default) passed it; ``--refine 2``
    found it (review of issue 30, item 5), now the default."""
    request = sweep(11.3, "3500:3727.2727272727", 2)
    result = run_local(request, chunk_points=1)
    report = refined_report(request, result, Rules())
    assert report.resolution is not None and report.resolution.depth == 2
    assert not report.passed
    spans = [[round(v, 2) for v in w.speeds_rpm] for w in report.failures]
    assert spans == [[3556.82, 3556.82], [3670.45, 3670.45]]


def test_neighbours_whose_attractor_sets_differ_are_refined() -> None:
    """Two passing points far from every limit are refined between when their attractor sets
    differ (a bifurcation lies between them, where a window may hide)."""
    from gearengine.gate.resolution import refine

    request = sweep(4.591, "4500:4625", 2)
    result = run_local(request, chunk_points=1)
    never = lambda p: False  # noqa: E731
    assert refine(request, result.points, never, never, 1) == []
    added = refine(request, result.points, never, never, 1, kind=lambda p: p.values["speed"])
    assert [round(p.physical["speed"].value, 2) for p in added] == [4562.5]


def test_refined_levels_say_where_they_were_checked_and_each_is_a_junit_case() -> None:
    """A torque level refined between the grid's was printed as if checked over the whole speed
    range, and JUnit had a case for the grid's levels alone (6 cases for 8 levels in the text):
    the text names the speeds checked there and JUnit has one case per level of the text."""
    from xml.etree import ElementTree

    from gearengine.gate.envelope import EnvelopeReport, envelope_report
    from gearengine.gate.envelope_text import windows_summary

    golden = EnvelopeReport.model_validate_json((ROOT / "tests/golden/check-envelope.json")
                                                .read_text())  # fmt: skip
    report = envelope_report(golden.sweep, Rules(fail_on=["diverged"]), golden.refined,
                             golden.resolution)  # fmt: skip
    assert report.passed and len(report.windows) == 5
    lines = windows_summary(report.windows, report=report)
    for line, torque in zip(lines[1:4], ("4.375", "6.75", "9.125"), strict=True):
        assert line.startswith(f"windows at torque {torque} N*m (refined level, checked at ")
    assert "(refined level" not in lines[0] + lines[4]
    root = ElementTree.fromstring(envelope_junit(report, "envelope"))
    names = [c.get("name") for c in root.iter("testcase")]
    assert names == [f"torque {t} N*m" for t in ("2", "4.375", "6.75", "9.125", "11.5")]


def test_refinement_reaches_inside_a_cell() -> None:
    """The damping remedy of the z = 23/67 pair (0.1672; the TE 11.3 µm design) passed its
    45 x 9 verification: every corner of the cell 5,432-5,545 rpm x 5-11.9 N*m passes, and so
    did every edge midpoint main refined, but 5,489 rpm / 6.72 N*m, inside the cell, is chaotic
    from every start (found by check on the 89 x 17 grid). Splitting cells (edge midpoints and
    centre, twice) reaches it."""
    design = json.loads(DESIGN.read_text())["design"]
    design["mesh"]["damping_ratio"] = 0.1672
    axes = [envelope_axis("speed", f"{1000 + 39 * 5000 / 44!r}:{1000 + 40 * 5000 / 44!r}",
                          "rpm", 2), envelope_axis("torque", "5:11.875", "N*m", 2)]  # fmt: skip
    request = validated(envelope_sweep(design, gate_settings({}, None), axes, "cell test"))
    result = run_local(request, chunk_points=1)
    report = refined_report(request, result, Rules())
    assert all(p.classification != "chaotic" for p in result.points)
    assert not report.passed, report.resolution
    (window,) = report.failures
    assert window.level["torque"].value == 6.71875
    assert [round(v, 2) for v in window.speeds_rpm] == [5488.64, 5488.64]


def test_a_refinement_for_pass_or_fail_stops_at_its_first_failure(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Where only pass or fail is needed (a remedies bisection step), the refinement stops at
    the first batch with a failing point, the points expected to fail (``first``) first; one
    that does not stop computes the points of the full refinement, the same bits, however it
    is batched; a failing point is found from its grid cell alone (``fails_toward``). The case
    of the test above: 3,613.6 rpm (level 1) passes, 3,556.8 and 3,670.5 rpm (level 2)
    fail."""
    from gearengine.gate import resolution
    from gearengine.gate.envelope import fails_toward
    from gearengine.gate.rules import attractor_failures

    request = sweep(11.3, "3500:3727.2727272727", 2)
    result = run_local(request, chunk_points=1)
    rules = Rules()
    fails = lambda p: bool(attractor_failures(p, rules))  # noqa: E731
    near = lambda p: near_limit(p, rules)  # noqa: E731
    full = resolution.refine(request, result.points, fails, near, 2)
    assert [round(p.physical["speed"].value, 1) for p in full] == [3613.6, 3556.8, 3670.5]
    assert [fails(p) for p in full] == [False, True, True]
    monkeypatch.setattr(resolution, "STOP_BATCH", 1)
    stopped = resolution.refine(request, result.points, fails, near, 2, stop=fails)
    assert [p.model_dump_json() for p in stopped] == [p.model_dump_json() for p in full[:2]]
    hinted = resolution.refine(request, result.points, fails, near, 2, stop=fails,
                               first=[full[2].values])  # fmt: skip
    assert [p.model_dump_json() for p in hinted] == [full[0].model_dump_json(),
                                                     full[2].model_dump_json()]  # fmt: skip
    never = resolution.refine(request, result.points, fails, near, 2, stop=lambda p: False)
    assert [p.model_dump_json() for p in never] == [p.model_dump_json() for p in full]
    # from the failing point's grid cell alone, before the rest of the grid: found
    assert fails_toward(request, rules, 2, [full[2].values])
    assert not fails_toward(request, Rules(fail_on=["diverged"]), 2, [full[2].values])


def test_a_check_with_nothing_to_refine_says_so() -> None:
    """It read 'refined to 62.5 rpm x ...: 0 points added' when nothing was refined (second
    new-user review)."""
    from gearengine.gate.resolution import Resolution

    text = Resolution(speed_points=5, torque_points=1, speed_step_rpm=250.0, starts=16,
                      depth=2, finest_speed_step_rpm=62.5, refined_points=0).text()  # fmt: skip
    assert "0 points added" not in text and "refined to" not in text
    assert text.endswith("nothing to refine (up to 2 halvings)")
