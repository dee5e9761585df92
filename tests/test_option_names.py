"""A refusal of ``remedies`` and ``robustness`` names what the user wrote: the CLI option
(``--speed (its high end)``, ``--samples``, ``--lever ... (its low end)``), not the request's
internal path (``axes[0].stop``, ``envelope.speed``), and the API the JSON field itself
(issue 30 item 7)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gearengine.cli.main import main
from tests.test_robustness import DESIGN


@pytest.fixture()
def design_file(tmp_path: Path) -> Path:
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": DESIGN}))
    return path


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (["--speed", "1000:abc"], "--speed (its high end): cannot read 'abc'"),
        (["--speed", "1000:2000", "--torque", "x:5"], "--torque (its low end): cannot read 'x'"),
        (["--speed", "1000:2000", "--speed-points", "0"], "--speed-points: "),
        (["--speed", "1000:2000", "--samples", "0"], "--samples: "),
        (["--speed", "1000:2000", "--torque", "1:2", "--torque-points", "0"], "--torque-points: "),
    ],
)
def test_robustness_names_the_option(
    design_file: Path, capsys: pytest.CaptureFixture[str], options: list[str], named: str
) -> None:
    assert main(["robustness", str(design_file), *options]) == 2
    err = capsys.readouterr().err
    assert named in err
    assert "axes[" not in err and "samples:" not in err.replace("--samples:", "")


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (["--speed", "1000:abc"], "--speed: cannot read 'abc'"),
        (["--speed", "1000:2000", "--torque", "5:x"], "--torque: cannot read 'x'"),
        (["--speed", "1000:2000", "--speed-points", "0"], "--speed-points: "),
        (["--speed", "1000:2000", "--lever", "mesh.half_backlash=5:1"],
         "--lever mesh.half_backlash (its low end): 5 m is outside"),
        (["--speed", "1000:2000", "--lever", "foo.bar=1:2"],
         "--lever foo.bar: the design has no numeric field foo.bar"),
    ],
)  # fmt: skip
def test_remedies_names_the_option(
    design_file: Path, capsys: pytest.CaptureFixture[str], options: list[str], named: str
) -> None:
    assert main(["remedies", str(design_file), *options]) == 2
    err = capsys.readouterr().err
    assert named in err
    assert "envelope." not in err and "levers[" not in err


def test_the_api_names_a_lever_s_bound_by_its_own_path(client) -> None:
    body = {"design": DESIGN, "envelope": {"speed": "1000:2000"},
            "levers": [{"lever": "mesh.half_backlash", "bounds": ["5 um", 1]}]}  # fmt: skip
    answer = client.post("/v1/remedies", json=body)
    assert answer.status_code == 422
    (error,) = answer.json()["errors"]
    assert error["path"] == "levers[0].bounds[1]"
    assert error["pointer"] == "/levers/0/bounds/1"
    assert error["message"].startswith("1 m is outside the plausible range of a half backlash")


def test_wording_of_refusals_new_user_review(
    design_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Four refusals a new user met (issue 30 review): "plausible range of a angle"; --starts 0
    named settings.basins.starts; --torque -5:60 got argparse's "expected one argument" (the
    range taken for an option), where its end is refused with its reason; --max-lle 1/s was
    "not a number" beside a help saying check prints the LLE in 1/s too."""
    from gearengine.model.design import EXAMPLE_DESIGN, Design

    driver = {**EXAMPLE_DESIGN["driver"], "pressure_angle": "50 deg"}
    with pytest.raises(ValueError, match="plausible range of an angle"):
        Design.model_validate({**EXAMPLE_DESIGN, "driver": driver})
    for command in (
        ["check", str(design_file), "--speed", "1000:2000"],
        ["basins", str(design_file)],
    ):
        assert main([*command, "--starts", "0"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("--starts: ") and "settings.basins" not in err
    assert main(["check", str(design_file), "--speed", "1000:2000", "--torque", "-5:60"]) == 2
    assert "--torque (its low end): -5 N*m is negative; a mean torque" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["check", str(design_file), "--max-lle", "1/s"])
    assert "per unit tau (tau = omega_n t), a plain number" in capsys.readouterr().err
