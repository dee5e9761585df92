"""The gates' JUnit XML (``gearengine check --junit FILE``): one ``testsuites`` > ``testsuite``
document, one test case per checked item (a torque level of the envelope gate, an operating
point of the probability gate) and at most one ``failure`` element per test case, whose message
joins every reason and whose text lists them one a line.

GitHub's JUnit report actions (mikepenz/action-junit-report, dorny/test-reporter), GitLab and
the Surefire schema read one failure per test case: a second one is dropped or refused, so the
reasons of a test case are gathered into one (``tests/data/junit.xsd`` allows at most one).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from xml.etree import ElementTree

from gearengine.gate.envelope import EnvelopeReport, level_text, window_text
from gearengine.gate.probability import ProbabilityReport


@dataclass(frozen=True)
class Case:
    """One test case: its name and the reasons it fails (none: it passes)."""

    name: str
    reasons: list[str] = field(default_factory=list)
    kinds: list[str] = field(default_factory=list)
    """The rules broken, for the failure's ``type`` (deduplicated, in order)."""


def junit_xml(suites_name: str, suite_name: str, classname: str, cases: Sequence[Case]) -> str:
    """The JUnit document of ``cases`` (see the module's docstring)."""
    suites = ElementTree.Element("testsuites", name=suites_name)
    suite = ElementTree.SubElement(suites, "testsuite", name=suite_name)
    failed = 0
    for c in cases:
        case = ElementTree.SubElement(suite, "testcase", classname=classname, name=c.name,
                                      time="0")  # fmt: skip
        if not c.reasons:
            continue
        failed += 1
        kinds = ", ".join(dict.fromkeys(c.kinds)) or "failure"
        node = ElementTree.SubElement(case, "failure", message="; ".join(c.reasons), type=kinds)
        node.text = "\n".join(c.reasons)
    for node in (suites, suite):
        node.set("tests", str(len(cases)))
        node.set("failures", str(failed))
        node.set("errors", "0")
    return ElementTree.tostring(suites, encoding="unicode", xml_declaration=True) + "\n"


def envelope_junit(report: EnvelopeReport, name: str) -> str:
    """The envelope gate's JUnit: one test case per torque level the text lists (the report's
    windows: the grid's levels and those refined between them, or one "all"), failed once with
    every failing window of the level in words; levels ascending, as the text lists them."""
    levels: list = []
    for level in [w.level for w in report.windows or report.sweep.windows or []] or [{}]:
        if level not in levels:  # dicts: not hashable
            levels.append(level)
    levels += [lv for lv in (w.level for w in report.failures) if lv not in levels]
    levels.sort(key=lambda level: [v.value for v in level.values()])  # as the text: ascending
    cases = []
    for level in levels:
        mine = [w for w in report.failures if w.level == level]
        cases.append(Case(level_text(level), [window_text(w) for w in mine],
                          [w.rule for w in mine]))  # fmt: skip
    return junit_xml("gearchaos envelope", name, "gearchaos.envelope", cases)


def probability_junit(report: ProbabilityReport, name: str) -> str:
    """The probability gate's JUnit: one test case per operating point, failed once with its
    reasons."""
    cases = [Case(level_text(v.point), v.reasons, [r.split(")")[0] + ")" for r in v.reasons])
             for v in report.verdicts]  # fmt: skip
    return junit_xml("gearchaos robustness", name, "robustness", cases)
