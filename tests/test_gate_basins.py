"""The envelope gate with basins: every attractor of every operating point is checked.

``tests/data/gate-starts-1/`` holds the report and JUnit XML of the gate before basins (branch
main without them) on a small envelope of examples/envelope-map.json; ``--starts 1`` gives them
byte for byte. With the default basin sample, the points that fail are exactly those where an
attractor found independently (``gearengine.attractors`` at each point) is chaotic, and the
report names it with its basin fraction.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import gearengine
from gearengine.cli import main
from gearengine.gate.envelope import ENVELOPE_SETTINGS, GATE_STARTS
from tests.conftest import ROOT

GOLDEN = ROOT / "tests" / "data" / "gate-starts-1"
ENVELOPE = ROOT / "examples" / "envelope-map.json"
SMALL = ["--speed", "4500:6000", "--speed-points", "4", "--torque", "2:21", "--torque-points", "2"]


@pytest.fixture
def envelope(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    shutil.copy(ENVELOPE, tmp_path / "envelope-map.json")
    return tmp_path


def test_one_start_gives_the_report_of_before_basins(
    envelope: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["check", "envelope-map.json", *SMALL, "--starts", "1", "--junit", "j.xml",
                 "--refine", "0"])  # fmt: skip
    assert code == 1
    out = capsys.readouterr().out.splitlines(keepends=True)
    assert out.pop(1).startswith("  resolution: 4 x 2 grid (500 rpm x 19 N*m), 1 start a point")
    assert "".join(out) == (GOLDEN / "report.txt").read_text()
    assert (envelope / "j.xml").read_text() == (GOLDEN / "junit.xml").read_text()


def test_the_default_gate_fails_where_any_attractor_is_chaotic_and_names_it(
    envelope: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["check", "envelope-map.json", *SMALL, "--json", "r.json", "--junit", "j.xml",
                 "--refine", "0"])  # the grid's points (test_gate_resolution refines)  # fmt: skip
    out = capsys.readouterr().out
    report = json.loads((envelope / "r.json").read_text())
    design = json.loads(ENVELOPE.read_text())["design"]
    expected = set()
    for rpm in (4500, 5000, 5500, 6000):
        for torque in (2, 21):
            point = {**design, "speed": f"{rpm} rpm", "torque": f"{torque} N*m"}
            found, _ = gearengine.attractors({"design": point}, ENVELOPE_SETTINGS,
                                             starts=GATE_STARTS)  # fmt: skip
            chaotic = [a for a in found if a.classification in ("chaotic", "diverged")]
            if chaotic:
                expected.add((rpm, torque))
                assert f"{rpm} rpm: {chaotic[0].label} from" in out
    failing = {
        (int(p["physical"]["speed"]["value"]), int(p["physical"]["torque"]["value"]))
        for p in report["sweep"]["points"]
        if any(a["classification"] in ("chaotic", "diverged") for a in p["attractors"])
    }
    assert failing == expected and report["failing_points"] == len(expected)
    assert code == (1 if expected else 0)
    # the gate with basins fails at least where the single start did, and names who failed
    assert len(expected) >= 3
    assert "% of starts" in (envelope / "j.xml").read_text()
    for w in report["failures"]:
        assert w["attractors"] and all("% of starts" in a for a in w["attractors"])
    # --min-basin 0.99: only attractors reached from (nearly) every start are checked
    large = sum(
        any(a["classification"] == "chaotic" and a["fraction"] > 0.99 for a in p["attractors"])
        for p in report["sweep"]["points"]
    )
    assert large < len(expected)
    main(["check", "envelope-map.json", *SMALL, "--min-basin", "0.99", "--json", "m.json",
          "--refine", "0"])  # fmt: skip
    assert json.loads((envelope / "m.json").read_text())["failing_points"] == large


def test_continuation_names_the_attractors_beside_the_followed_branch() -> None:
    from gearengine.studies.sweep.compute import run_local
    from gearengine.studies.sweep.request import validated

    design = json.loads(ENVELOPE.read_text())["design"]
    doc = {"design": {**design, "torque": "2 N*m"},
           "settings": {**ENVELOPE_SETTINGS, "basins": {"starts": 16}},
           "axes": [{"parameter": "speed", "start": "5750 rpm", "stop": "6000 rpm", "num": 2}],
           "continuation": True, "direction": "both"}  # fmt: skip
    result = run_local(validated(doc))
    assert [p.branch for p in result.points] == ["up", "up", "down", "down"]
    for p in result.points:
        assert p.attractors is not None and p.coexisting is not None
        names = {f"{a.label} from" for a in p.attractors}
        # every other attractor is named, the followed one (its class among them) is not
        assert len(p.coexisting) == len(p.attractors) - 1 or (
            len(p.coexisting) == len(p.attractors)
            and p.classification not in {a.classification for a in p.attractors}
        )
        assert all(any(c.startswith(n) for n in names) for c in p.coexisting)
    assert any(p.coexisting for p in result.points)  # 5,750 rpm: several attractors


def test_the_envelope_map_hatches_where_attractors_coexist() -> None:
    from matplotlib.patches import Rectangle

    from gearengine.plots.envelope import COEXIST_COLOUR, envelope_map
    from gearengine.studies.sweep.compute import run_local
    from gearengine.studies.sweep.request import validated

    design = json.loads(ENVELOPE.read_text())["design"]
    axes = [{"parameter": "speed", "start": "5750 rpm", "stop": "6000 rpm", "num": 2},
            {"parameter": "torque", "start": "2 N*m", "stop": "21 N*m", "num": 2}]  # fmt: skip
    doc = {"design": design, "settings": {**ENVELOPE_SETTINGS, "basins": {"starts": 16}},
           "axes": axes}  # fmt: skip
    request = validated(doc)
    result = run_local(request)
    several = sum(len(p.attractors or []) > 1 for p in result.points)
    assert several >= 1
    ax = envelope_map(request, result.points).axes[0]
    hatched = [r for r in ax.patches if isinstance(r, Rectangle) and r.get_hatch()]
    assert len(hatched) == several
    assert all(r.get_edgecolor()[:3] == pytest.approx((0x6A / 255, 0x3D / 255, 0x9A / 255))
               for r in hatched) and COEXIST_COLOUR == "#6a3d9a"  # fmt: skip
