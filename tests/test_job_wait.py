"""``GET /v1/<kind>/{id}?wait=S``: a status request held until the job finishes (at most S
seconds), one request where a client polled every few milliseconds (issue 31: a served map's
10 ms polls took about 0.25 s of the server's CPU on the cores computing the map)."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from service.api.routes.jobs import JobRoutes
from service.core.config import Settings
from service.main import create_app
from tests.conftest import ROOT, started


def chaos_map(num: int) -> dict:
    """The chaos map of the examples at ``num`` x ``num`` points: a job of a second or two."""
    doc = json.loads((ROOT / "examples" / "chaos-map.json").read_text())
    for axis in doc["axes"]:
        axis["num"] = num
    return doc


@pytest.fixture(scope="module")
def working(tmp_path_factory: pytest.TempPathFactory) -> Iterator[TestClient]:
    settings = Settings(data_dir=tmp_path_factory.mktemp("jobs"), workers=1)
    with started(create_app(settings)) as c:
        yield c


def test_a_status_request_with_wait_answers_when_the_job_finishes(working: TestClient) -> None:
    """One request right after the submission gets the finished job and its result follows;
    without ``wait`` the same request would have seen it queued or running."""
    job_id = working.post("/v1/sweeps", json=chaos_map(45)).json()["id"]
    r = working.get(f"/v1/sweeps/{job_id}?wait=30")
    assert r.status_code == 200 and r.json()["status"] == "succeeded", r.text
    assert "Retry-After" not in r.headers
    assert working.get(f"/v1/sweeps/{job_id}/result").status_code == 200


def reads(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The job ids a status request reads from the store, in order."""
    seen: list[str] = []
    read = JobRoutes.job_or_404

    def counted(self: JobRoutes, jobs: object, job_id: str, owner: str | None) -> object:
        seen.append(job_id)
        return read(self, jobs, job_id, owner)  # type: ignore[arg-type]

    monkeypatch.setattr(JobRoutes, "job_or_404", counted)
    return seen


def test_an_unfinished_job_is_answered_after_wait_with_retry_after(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """No worker: the job stays queued; a held request reads it again while it waits and
    answers it queued, with Retry-After."""
    seen = reads(monkeypatch)
    with started(create_app(Settings(data_dir=tmp_path, workers=0))) as c:
        job_id = c.post("/v1/sweeps", json=chaos_map(4)).json()["id"]
        r = c.get(f"/v1/sweeps/{job_id}?wait=0.1")
        assert r.status_code == 200 and r.json()["status"] == "queued"
        assert r.headers["Retry-After"] == "5"
        assert seen.count(job_id) > 1  # read again while held
        for bad in ("31", "nan", "inf", "-1"):
            r = c.get(f"/v1/sweeps/{job_id}?wait={bad}")
            assert r.status_code == 422, (bad, r.text)
            assert r.headers["content-type"].startswith("application/problem+json")
            assert "wait" in r.text
        assert c.get("/v1/sweeps/no-such-job?wait=1").status_code == 404


def test_the_settings_cap_the_wait(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``max_status_wait_s`` 0 (a fuzzing run, whose jobs never finish) answers a status with
    ``?wait=30`` at once: the job is read once."""
    seen = reads(monkeypatch)
    settings = Settings(data_dir=tmp_path, workers=0, max_status_wait_s=0.0)
    with started(create_app(settings)) as c:
        job_id = c.post("/v1/sweeps", json=chaos_map(4)).json()["id"]
        r = c.get(f"/v1/sweeps/{job_id}?wait=30")
        assert r.json()["status"] == "queued" and seen.count(job_id) == 1
