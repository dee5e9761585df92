"""``gearengine robustness`` and the probability gate of ``gearengine check``: the CLI's JSON is
the API's document, the gate fails on the 95 % upper bound and JUnit names the points."""

from __future__ import annotations

import json
from pathlib import Path
from xml.etree import ElementTree

import pytest

from gearengine.cli.main import main
from gearengine.gate.envelope import ENVELOPE_SETTINGS
from gearengine.studies.robustness.study import RobustnessRequest, run_local
from tests.test_robustness import DESIGN


@pytest.fixture(scope="module")
def design_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("cli") / "design.json"
    path.write_text(json.dumps({"design": DESIGN}))
    return path


def test_cli_json_is_the_api_document_and_the_map_is_a_png(design_file: Path) -> None:
    out, png = design_file.with_name("r.json"), design_file.with_name("r.png")
    args = [str(design_file), "--speed", "2000:5000", "--speed-points", "2", "--samples", "8"]
    assert main(["robustness", *args, "--json", str(out), "--plot", str(png)]) == 0
    document = json.loads(out.read_text())
    request = RobustnessRequest.model_validate(
        {"design": DESIGN, "samples": 8, "settings": ENVELOPE_SETTINGS,
         "axes": [{"parameter": "speed", "start": "2000 rpm", "stop": "5000 rpm", "num": 2}]}
    )  # fmt: skip
    assert out.read_text() == run_local(request).model_dump_json()
    assert [p["shown"] for p in document["points"]] == [{"speed": 2000.0}, {"speed": 5000.0}]
    assert png.read_bytes().startswith(b"\x89PNG")


def test_the_gate_fails_on_the_upper_bound_and_names_the_points(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    junit = design_file.with_name("junit.xml")
    base = ["check", str(design_file), "--speed", "2000:5000", "--speed-points", "2"]
    # 8 samples: even with no impact the upper bound is 0.31, above 0.01
    assert main([*base, "--samples", "8", "--max-probability", "back_flank=0.01",
                 "--junit", str(junit)]) == 1  # fmt: skip
    cases = ElementTree.parse(junit).getroot().findall("testcase")
    assert [c.get("name") for c in cases] == ["speed 2000 rpm", "speed 5000 rpm"]
    assert all(c.find("failure") is not None for c in cases)
    assert "upper bound" in capsys.readouterr().out
    assert main([*base, "--samples", "8", "--max-probability", "back_flank=0.5"]) == 0
    assert main([*base, "--max-probability", "nonsense=0.1"]) == 2
