"""The gearengine CLI as a user runs it: a real subprocess."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from gearengine.cli.main import main
from gearengine.homoclinic.schemas import MelnikovRequest
from gearengine.homoclinic.verdict import melnikov
from gearengine.jsonio import dumps
from tests.conftest import ROOT

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "paper-4.1.json"


def run(*args: str, stdin: str | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "gearengine.cli", *args],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_melnikov_table() -> None:
    out = run("melnikov", str(EXAMPLE))
    assert out.returncode == 0, out.stderr
    assert "chaos POSSIBLE" in out.stdout
    assert "F_e1" in out.stdout and "0.177953" in out.stdout  # the loaded loops' threshold
    out = run("melnikov", str(EXAMPLE), "--mean-load", "perturbation")
    assert "F_e1" in out.stdout and "0.19588" in out.stdout  # the paper's


def test_melnikov_json_is_the_api_body() -> None:
    out = run("melnikov", str(EXAMPLE), "--json")
    assert out.returncode == 0, out.stderr
    req = MelnikovRequest.model_validate_json(EXAMPLE.read_text())
    assert out.stdout.rstrip("\n") == dumps(melnikov(req.params))
    assert json.loads(out.stdout)["thresholds"]["F_e1"]["nearest"] > 0.177


def test_stdin_and_invalid_input_exit_2_naming_each_field() -> None:
    bad = {"params": {"damping": -1, "transmission_error": {"frequency": 0}, "speed": 1}}
    out = run("melnikov", "-", stdin=json.dumps(bad))
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert lines == [
        "params.damping: Input should be greater than or equal to 0",
        "params.transmission_error.frequency: Input should be greater than or equal to 0.000001",
        "params.speed: Extra inputs are not permitted",
    ]


def test_nan_and_broken_json_are_refused() -> None:
    out = run("melnikov", "-", stdin='{"params": {"damping": NaN}}')
    assert out.returncode == 2 and "params.damping" in out.stderr
    out = run("melnikov", "-", stdin='{"params": ')
    assert out.returncode == 2 and "invalid JSON at line 1" in out.stderr
    out = run("melnikov", "/nonexistent.json")
    assert out.returncode == 2 and "No such file" in out.stderr


def test_empty_input_says_so() -> None:
    for stdin in ("", "  \n"):
        out = run("melnikov", "-", stdin=stdin)
        assert out.returncode == 2 and out.stderr.strip() == "-: empty input"


def pipe(command: str) -> subprocess.CompletedProcess[str]:
    """``command`` run by bash with ``gearengine`` being this interpreter's CLI; prints the CLI's
    exit status (PIPESTATUS[0]) last."""
    cli = f"{sys.executable} -m gearengine.cli"
    script = command.replace("gearengine", cli, 1) + '; echo "status=${PIPESTATUS[0]}"'
    return subprocess.run(
        ["bash", "-c", script], capture_output=True, text=True, timeout=120, cwd=EXAMPLE.parents[1]
    )


def test_a_closed_pipe_ends_quietly() -> None:
    out = pipe("gearengine melnikov examples/paper-4.1.json | head -1")
    assert out.stdout.startswith("Melnikov verdict:") and "Traceback" not in out.stderr
    assert out.stdout.strip().splitlines()[-1] in ("status=0", "status=141")
    # `true` reads nothing and exits at once, long before the CLI has computed: every write fails
    out = pipe("gearengine melnikov examples/paper-4.1.json --json | true")
    assert out.stderr == "" and out.stdout.strip() == "status=141"


def test_convert_prints_readable_text_and_refuses_params() -> None:
    """No Python list or JSON in the text output; a params file is refused (exit 2), not a
    traceback."""
    out = run("convert", str(EXAMPLE.with_name("design-geometry.json")))
    assert out.returncode == 0, out.stderr
    assert "[{" not in out.stdout and "{'" not in out.stdout and '{"' not in out.stdout
    assert "stiffness_harmonics        r=1 1.34463e+08 N/m @ -1.859 rad; r=2" in out.stdout
    assert "  mu~ (damping)              0.04" in out.stdout
    refused = run("convert", str(EXAMPLE))
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert "design: give a design" in refused.stderr


def test_analyze_says_how_many_starts_it_looked_from(capsys: pytest.CaptureFixture) -> None:
    """Without basins the text says the verdict is from the settings' start(s) and names the
    command that searches the others (analyze said periodic where basins found chaos from
    23 % of starts, without saying it looked from one start: a new-user review)."""
    design = str(ROOT / "examples" / "ci" / "design.json")
    assert main(["analyze", design]) == 0
    assert (
        f"from 1 start of the settings: other attractors of this design are not searched "
        f"(gearengine basins {design})" in capsys.readouterr().out
    )
