"""Basins as a durable job (``POST /v1/basins``, kind ``basins``): what the synchronous
analysis refuses for its size runs as a job on the workers, with the CLI's numbers and
picture."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from gearengine.cli import main
from service.core.config import Settings
from service.main import create_app
from tests._polling import poll
from tests.conftest import started
from tests.test_attractors import SMALL


@pytest.fixture
def worked(tmp_path: Path) -> TestClient:
    """A client of an app with one pool worker, and a synchronous budget below SMALL's work
    (16 starts x 200 periods x 128 steps = 409 600 steps), so only the job route runs it."""
    settings = Settings(data_dir=tmp_path / "data", workers=1, max_sync_steps=100_000)
    with started(create_app(settings)) as c:
        yield c


def test_basins_over_the_synchronous_budget_run_as_a_job_with_the_clis_numbers_and_picture(
    worked: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    refused = worked.post("/v1/analyses", json=SMALL)
    assert refused.status_code == 422 and "POST /v1/basins" in refused.json()["detail"]
    r = worked.post("/v1/basins", json=SMALL)
    assert r.status_code == 202, r.text
    url = r.headers["location"]
    job = poll(lambda: worked.get(url).json())
    assert job["status"] == "succeeded" and job["progress"] == {"done": 16, "total": 16}
    doc = tmp_path / "small.json"
    doc.write_text(json.dumps(SMALL))
    picture = tmp_path / "basins.png"
    assert main(["basins", str(doc), "--json", "--plot", str(picture)]) == 0
    assert worked.get(url + "/result").json() == json.loads(capsys.readouterr().out)
    plot = worked.get(url + "/plot?format=png")
    assert plot.headers["content-type"] == "image/png" and plot.content == picture.read_bytes()
    assert [j["id"] for j in worked.get("/v1/basins").json()["items"]] == [job["id"]]
    assert worked.get("/v1/sweeps").json()["total"] == 0


def test_a_basins_job_over_the_job_budget_is_refused_naming_the_starts(tmp_path: Path) -> None:
    app = create_app(Settings(data_dir=tmp_path, workers=0, max_job_steps=100_000))
    with TestClient(app) as c:
        r = c.post("/v1/basins", json=SMALL)
        assert r.status_code == 422 and r.json()["errors"][0]["path"] == "settings.basins.starts"
        assert "max_job_steps" in r.json()["detail"] and c.get("/v1/basins").json()["total"] == 0


def test_a_running_basins_job_has_no_partial_result_and_says_so(tmp_path: Path) -> None:
    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0))) as c:
        url = c.post("/v1/basins", json=SMALL).headers["location"]
        r = c.get(url + "/result?partial=true")
        assert r.status_code == 409 and "no finished chunk" in r.json()["detail"]
        assert c.get(url + "/result").status_code == 409
