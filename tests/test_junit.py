"""The gates' JUnit XML (issue 30 item 8): every test case carries at most one ``failure``
element (GitHub's report actions and the Surefire schema read one), holding every reason of the
test case, and the document validates against ``tests/data/junit.xsd``."""

from __future__ import annotations

import json
from pathlib import Path
from xml.etree import ElementTree

import xmlschema

from gearengine.gate.junit import Case, junit_xml
from tests.conftest import ROOT
from tests.test_envelope import LIGHT, gearengine, rattling

SCHEMA = xmlschema.XMLSchema(ROOT / "tests" / "data" / "junit.xsd")


def test_a_level_breaking_two_rules_has_one_failure_naming_both(tmp_path: Path) -> None:
    """The rattling pair breaks 'chaotic' and 'tooth separation' at one torque level: two
    failing windows, one failure element."""
    design = tmp_path / "rattling.json"
    design.write_text(json.dumps({"design": rattling(), "settings": LIGHT}))
    junit = tmp_path / "envelope.xml"
    out = gearengine("check", str(design), "--speed", "1000:2000", "--speed-points", "4",
                     "--torque", "1:1", "--torque-points", "1", "--starts", "1",
                     "--fail-on", "chaotic", "--fail-on", "separation",
                     "--junit", str(junit))  # fmt: skip
    assert out.returncode == 1, out.stderr
    SCHEMA.validate(junit)
    (case,) = ElementTree.parse(junit).getroot().iter("testcase")
    (failure,) = case.findall("failure")
    lines = failure.text.splitlines()
    assert len(lines) >= 2
    assert {"chaotic", "tooth separation"} <= set(failure.get("type").split(", "))
    assert failure.get("message") == "; ".join(lines)


def test_the_writer_gathers_reasons_and_counts_failed_cases() -> None:
    text = junit_xml("s", "suite", "c", [Case("a"), Case("b", ["x > 1", "y > 2"], ["x", "y"])])
    root = ElementTree.fromstring(text)
    SCHEMA.validate(root)
    suite = root.find("testsuite")
    assert (suite.get("tests"), suite.get("failures")) == ("2", "1")
    assert [len(c.findall("failure")) for c in suite.iter("testcase")] == [0, 1]


def test_the_schema_refuses_two_failures_in_one_case() -> None:
    two = (
        '<testsuites><testsuite name="s" tests="1"><testcase name="a">'
        '<failure message="1"/><failure message="2"/></testcase></testsuite></testsuites>'
    )
    assert not SCHEMA.is_valid(two)
