"""Analyses over HTTP and the CLI gate: the paper's cases classify the same everywhere."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import httpx
import pytest
from fastapi.testclient import TestClient

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.jsonio import dumps
from tests.conftest import PAPER_PARAMS, Server


def fe(amplitude: float, omega: float = 0.5, mu: float = 0.07) -> dict:
    return {
        **PAPER_PARAMS,
        "damping": mu,
        "transmission_error": {"frequency": omega, "harmonics": [{"amplitude": amplitude}]},
    }


# (params, classification, period): paper section 4.1, Figs. 6 and 13
PAPER_CASES = [
    (fe(0.2), "periodic", 1),
    (fe(0.22), "periodic", 2),
    (fe(0.23), "periodic", 4),
    (fe(0.28), "chaotic", None),
    (fe(0.3, 0.7, 0.15), "periodic", 1),
    (fe(0.3, 0.7, 0.135), "periodic", 2),
    (fe(0.3, 0.7, 0.12), "chaotic", None),
]


@pytest.mark.parametrize(("params", "classification", "period"), PAPER_CASES)
def test_paper_cases_over_http_match_the_engine(
    server: Server, params: dict, classification: str, period: int | None
) -> None:
    r = httpx.post(server.url + "/v1/analyses", json={"params": params}, timeout=120)
    assert r.status_code == 200, r.text
    body = r.json()
    assert (body["numerics"]["classification"], body["numerics"]["period"]) == (
        classification,
        period,
    )
    engine = analyze(AnalysisRequest.model_validate({"params": params}))
    assert r.content == dumps(engine).encode()


def test_budget_refusal_points_to_sweeps(client: TestClient) -> None:
    body = {"params": PAPER_PARAMS, "settings": {"record_periods": 50000, "steps_per_period": 400}}
    r = client.post("/v1/analyses", json=body)
    assert r.status_code == 422
    problem = r.json()
    assert "max_sync_steps" in problem["detail"] and "/v1/sweeps" in problem["detail"]
    assert problem["errors"][0]["path"] == "settings"


@pytest.mark.parametrize(
    ("settings", "path"),
    [
        ({"transient_periods": -1}, "settings.transient_periods"),
        ({"steps_per_period": 2}, "settings.steps_per_period"),
        ({"initial_state": [0.0, float("nan")]}, "settings.initial_state[1]"),
        ({"initial_states": [[0.0, 0.0]] * 500}, "settings.initial_states"),
    ],
)
def test_bad_settings_name_the_field(client: TestClient, settings: dict, path: str) -> None:
    content = json.dumps({"params": PAPER_PARAMS, "settings": settings}).replace("NaN", "NaN")
    r = client.post("/v1/analyses", content=content, headers={"content-type": "application/json"})
    assert r.status_code == 422
    assert any(e["path"].startswith(path) for e in r.json()["errors"]), r.json()


def test_figures(client: TestClient) -> None:
    r = client.post("/v1/analyses/plot", json={"params": fe(0.28)})
    assert r.status_code == 200 and r.headers["content-type"] == "image/png"
    assert r.content[:8] == b"\x89PNG\r\n\x1a\n"
    r = client.post("/v1/analyses/plot?format=svg", json={"params": fe(0.28)})
    assert r.headers["content-type"] == "image/svg+xml" and b"<svg" in r.content[:500]
    again = client.post("/v1/analyses/plot?format=svg", json={"params": fe(0.28)})
    assert again.content == r.content
    r = client.post(
        "/v1/thresholds/plot", json={"params": PAPER_PARAMS}, headers={"accept": "image/svg+xml"}
    )
    assert r.headers["content-type"] == "image/svg+xml"
    assert (
        client.post("/v1/thresholds/plot?format=gif", json={"params": PAPER_PARAMS}).status_code
        == 422
    )


def test_metrics_count_analyses_by_classification(client: TestClient) -> None:
    client.post("/v1/analyses", json={"params": fe(0.28)})
    assert 'gearchaos_analyses_total{classification="chaotic"} 1.0' in client.get("/metrics").text


def gate(tmp_path: Path, params: dict, *flags: str) -> subprocess.CompletedProcess[str]:
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"params": params}))
    return subprocess.run(
        [sys.executable, "-m", "gearengine.cli", "check", str(path), *flags],
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_check_gate_exit_codes(tmp_path: Path) -> None:
    chaotic = gate(tmp_path, fe(0.28))
    assert chaotic.returncode == 1 and chaotic.stdout.startswith("FAIL: chaotic")
    periodic = gate(tmp_path, fe(0.2))
    assert periodic.returncode == 0 and periodic.stdout.startswith("PASS: periodic 1T")
    assert len(periodic.stdout.strip().splitlines()) == 1
    assert gate(tmp_path, fe(0.2), "--fail-on", "melnikov").returncode == 1
    assert gate(tmp_path, fe(0.2), "--max-lle", "-0.1").returncode == 1
    assert gate(tmp_path, fe(0.2), "--max-lle", "0").returncode == 0
    # a bare limit adds to the default --fail-on chaotic: a chaotic design fails even when its
    # LLE is below the limit (it used to replace the rule, and a chaotic design passed)
    assert gate(tmp_path, fe(0.28), "--max-lle", "0.1").returncode == 1
    assert gate(tmp_path, fe(0.28), "--fail-on", "diverged", "--max-lle", "0.1").returncode == 0
    assert gate(tmp_path, fe(0.28), "--max-lle", "0.01").returncode == 1
    bad = gate(tmp_path, {**PAPER_PARAMS, "damping": "x"})
    assert bad.returncode == 2 and "params.damping" in bad.stderr


def test_analyze_json_is_the_api_body(tmp_path: Path, client: TestClient) -> None:
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"params": fe(0.23)}))
    out = subprocess.run(
        [sys.executable, "-m", "gearengine.cli", "analyze", str(path), "--json"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    assert (
        out.stdout.rstrip("\n").encode()
        == client.post("/v1/analyses", json={"params": fe(0.23)}).content
    )
