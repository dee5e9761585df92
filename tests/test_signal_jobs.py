"""A recording over the synchronous budget runs as a durable job (``POST /v1/signals/jobs``,
kind ``signal``, ``gearengine.rig.SIGNAL_JOB``) on the real queue (SQLite store, a pool
worker), with the numbers and the figure of ``gearengine signal FILE``."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from gearengine.cli.main import main
from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.rig import SIGNAL_JOB, signal_work
from gearengine.signals.series import SYNC_SAMPLES, SignalRequest
from service.core.config import Settings
from service.main import create_app
from tests._polling import poll
from tests.conftest import started
from tests.test_signals_api import RATE, body, mesh_tones

LONG = np.tile(mesh_tones(), math.ceil((SYNC_SAMPLES + 1) / RATE))
"""A mesh recording one second over the synchronous budget (7 s at 20 kHz)."""


@pytest.fixture
def worked(tmp_path: Path) -> TestClient:
    """A client of an app with one pool worker."""
    with started(create_app(Settings(data_dir=tmp_path / "data", workers=1))) as c:
        yield c


def test_a_long_recording_runs_as_a_job_with_the_clis_numbers_and_figure(
    worked: TestClient, tmp_path: Path
) -> None:
    doc = body(LONG)
    refused = worked.post("/v1/signals", json=doc)
    assert refused.status_code == 422
    assert refused.headers["content-type"].startswith("application/problem+json")
    assert refused.json()["type"].endswith("over-budget")
    assert "POST /v1/signals/jobs" in refused.json()["detail"]
    plot_refused = worked.post("/v1/signals/plot", json=doc)
    assert plot_refused.status_code == 422 and "/v1/signals/jobs" in plot_refused.text

    r = worked.post("/v1/signals/jobs", json=doc)
    assert r.status_code == 202, r.text
    url = r.headers["location"]
    assert url.startswith("/v1/signals/jobs/")
    job = poll(lambda: worked.get(url).json())
    assert job["status"] == "succeeded", job
    assert job["progress"] == {"done": LONG.size, "total": LONG.size}

    request = tmp_path / "long.json"
    request.write_text(json.dumps(doc))
    out, figure = tmp_path / "long-reading.json", tmp_path / "long-reading.png"
    assert main(["signal", str(request), "--json", str(out), "--plot", str(figure)]) == 0
    result = worked.get(url + "/result").json()
    assert result == json.loads(out.read_text()) and result["verdict"] == "periodic"
    plot = worked.get(url + "/plot?format=png")
    assert plot.headers["content-type"] == "image/png" and plot.content == figure.read_bytes()
    assert [j["id"] for j in worked.get("/v1/signals/jobs").json()["items"]] == [job["id"]]
    assert worked.get("/v1/basins").json()["total"] == 0  # another kind's listing


def test_bad_input_to_the_job_route_is_refused_before_anything_is_stored(
    tmp_path: Path,
) -> None:
    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0))) as c:
        doc = body(mesh_tones())
        doc["signal"]["sample_rate"] = "500 Hz"  # type: ignore[index]
        r = c.post("/v1/signals/jobs", json=doc)
        assert r.status_code == 422 and r.json()["errors"][0]["path"] == "signal.sample_rate"
        assert c.get("/v1/signals/jobs").json()["total"] == 0
        url = c.post("/v1/signals/jobs", json=body(mesh_tones())).headers["location"]
        r = c.get(url + "/result?partial=true")  # nothing runs (no worker): no chunk yet
        assert r.status_code == 409 and "no finished chunk" in r.json()["detail"]


def test_a_design_costs_the_models_analysis_and_its_lever_trials(tmp_path: Path) -> None:
    plain = SignalRequest.model_validate(body(mesh_tones()))
    with_design = {**body(mesh_tones()), "design": EXAMPLE_DESIGN}
    del with_design["teeth"]
    designed = SignalRequest.model_validate(with_design)
    assert SIGNAL_JOB.work(plain) == 0 and signal_work(designed) > 0
    assert signal_work(designed) % 7 == 0  # the analysis and six lever trials
    settings = Settings(data_dir=tmp_path, workers=0, max_job_steps=signal_work(designed) - 1)
    with TestClient(create_app(settings)) as c:
        r = c.post("/v1/signals/jobs", json=with_design)
        assert r.status_code == 422 and r.json()["errors"][0]["path"] == "design"
        assert "max_job_steps" in r.json()["detail"]
        assert c.post("/v1/signals/jobs", json=body(mesh_tones())).status_code == 202
