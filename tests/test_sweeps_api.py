"""/v1/sweeps over the in-process client: submission, polling, listing, ownership, cancel,
limits, results, CSV and figures (the last with a real embedded dispatcher and worker pool)."""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from gearengine.studies.sweep import compute_chunk_json, run_local, to_csv, validated
from service.core.config import Settings
from service.main import create_app
from tests._polling import poll
from tests.conftest import PAPER_PARAMS, started

SHORT = {"transient_periods": 50, "record_periods": 50, "steps_per_period": 64}


def body(num: int = 11, **extra: Any) -> dict[str, Any]:
    return {
        "params": PAPER_PARAMS,
        "settings": SHORT,
        "axes": [{"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": num}],
        **extra,
    }


def test_submit_answers_202_with_location_and_the_job(client: TestClient) -> None:
    r = client.post("/v1/sweeps", json=body())
    assert r.status_code == 202
    job = r.json()
    assert r.headers["location"] == f"/v1/sweeps/{job['id']}"
    assert job["status"] == "queued" and job["progress"] == {"done": 0, "total": 11}
    assert job["started_at"] is None and job["error"] is None
    r = client.get(r.headers["location"])
    assert r.status_code == 200 and r.json() == job and r.headers["retry-after"]


def test_listing_is_paginated_and_filtered(client: TestClient) -> None:
    ids = [client.post("/v1/sweeps", json=body()).json()["id"] for _ in range(3)]
    client.delete(f"/v1/sweeps/{ids[1]}")
    page = client.get("/v1/sweeps", params={"limit": 2}).json()
    assert page["total"] == 3 and [j["id"] for j in page["items"]] == ids[::-1][:2]
    assert page["next_offset"] == 2
    last = client.get("/v1/sweeps", params={"limit": 2, "offset": 2}).json()
    assert [j["id"] for j in last["items"]] == [ids[0]] and last["next_offset"] is None
    cancelled = client.get("/v1/sweeps", params={"status": "cancelled"}).json()
    assert [j["id"] for j in cancelled["items"]] == [ids[1]]
    assert client.get("/v1/sweeps", params={"status": "done"}).status_code == 422


def test_cancel_is_immediate_and_idempotent(client: TestClient) -> None:
    job = client.post("/v1/sweeps", json=body()).json()
    r = client.delete(f"/v1/sweeps/{job['id']}")
    assert r.status_code == 200 and r.json()["status"] == "cancelled"
    assert r.json()["finished_at"] is not None and "retry-after" not in r.headers
    assert client.delete(f"/v1/sweeps/{job['id']}").json()["status"] == "cancelled"
    r = client.get(f"/v1/sweeps/{job['id']}/result")
    assert r.status_code == 409 and r.headers["content-type"] == "application/problem+json"


def test_unfinished_result_is_409_with_retry_after(client: TestClient) -> None:
    job = client.post("/v1/sweeps", json=body()).json()
    for path in ("result", "plot"):
        r = client.get(f"/v1/sweeps/{job['id']}/{path}")
        assert r.status_code == 409 and r.headers["retry-after"]


def test_unknown_job_is_404(client: TestClient) -> None:
    for method, path in (("GET", ""), ("GET", "/result"), ("GET", "/plot"), ("DELETE", "")):
        r = client.request(method, f"/v1/sweeps/{'0' * 32}{path}")
        assert r.status_code == 404 and r.json()["status"] == 404


@pytest.mark.parametrize(
    ("change", "path"),
    [
        ({"axes": [{"parameter": "F_e1", "start": 0, "stop": 0.3, "num": 0}]}, "axes[0].num"),
        (
            {
                "axes": [
                    {"parameter": "F_e1", "start": 0, "stop": 0.3, "num": 3},
                    {"parameter": "F_e1", "start": 0, "stop": 0.3, "num": 3},
                ]
            },
            "axes[1].parameter",
        ),
        ({"axes": [{"parameter": "mu", "start": -1, "stop": 0.3, "num": 3}]}, "axes[0].start"),
        ({"axes": []}, "axes"),
        ({"direction": "both"}, "direction"),
        ({"settings": {"steps_per_period": 2}}, "settings.steps_per_period"),
        ({"axes": [{"parameter": "F_e1", "start": 0, "stop": 0.3, "num": 50_000}]}, "axes"),
        # one point over a range is its start alone (a new-user review: a gate passed on it)
        ({"axes": [{"parameter": "F_e1", "start": 0, "stop": 0.3, "num": 1}]}, "axes[0].num"),
    ],
)
def test_invalid_sweeps_are_422_naming_the_field(
    client: TestClient, change: dict[str, Any], path: str
) -> None:
    r = client.post("/v1/sweeps", json={**body(), **change})
    assert r.status_code == 422 and r.headers["content-type"] == "application/problem+json"
    assert path in [e["path"] for e in r.json()["errors"]], r.json()
    assert client.get("/v1/sweeps").json()["total"] == 0  # nothing stored


def test_sweep_over_the_compute_budget_is_refused_before_it_is_stored(tmp_path: Path) -> None:
    app = create_app(Settings(data_dir=tmp_path, workers=0, max_job_steps=1_000_000))
    with TestClient(app) as c:
        r = c.post("/v1/sweeps", json=body(num=200))  # 200 points x 100 periods x 64 steps
        assert r.status_code == 422
        assert "max_job_steps" in r.json()["detail"] and "1280000" in r.json()["detail"]
        assert c.get("/v1/sweeps").json()["total"] == 0
        assert c.post("/v1/sweeps", json=body(num=100)).status_code == 202


@pytest.mark.parametrize("variable", ["GEARCHAOS_MAX_JOB_POINTS", "GEARCHAOS_MAX_SWEEP_POINTS"])
def test_the_job_point_cap_is_read_from_its_variable_or_its_old_alias(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, variable: str
) -> None:
    monkeypatch.setenv(variable, "150")
    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0))) as c:
        r = c.post("/v1/sweeps", json=body(num=200))
        assert r.status_code == 422 and "150" in r.json()["detail"], r.json()
        assert c.post("/v1/sweeps", json=body(num=150)).status_code == 202


def test_queue_cap_answers_429_with_retry_after(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path, workers=0, max_queued_jobs=2)
    with started(create_app(settings)) as c:
        assert all(c.post("/v1/sweeps", json=body()).status_code == 202 for _ in range(2))
        r = c.post("/v1/sweeps", json=body())
        assert r.status_code == 429 and int(r.headers["retry-after"]) > 0
        assert "max_queued_jobs" in r.json()["detail"]


def test_jobs_are_owned_by_the_api_key(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path, workers=0, api_keys="key-a,key-b")
    with started(create_app(settings)) as c:
        a, b = {"X-API-Key": "key-a"}, {"Authorization": "Bearer key-b"}
        assert c.post("/v1/sweeps", json=body()).status_code == 401
        job = c.post("/v1/sweeps", json=body(), headers=a).json()
        for method, path in (("GET", ""), ("GET", "/result"), ("GET", "/plot"), ("DELETE", "")):
            r = c.request(method, f"/v1/sweeps/{job['id']}{path}", headers=b)
            assert r.status_code == 404, (method, path)
        assert c.get("/v1/sweeps", headers=b).json()["total"] == 0
        assert c.get("/v1/sweeps", headers=a).json()["items"][0]["id"] == job["id"]
        assert c.get(f"/v1/sweeps/{job['id']}", headers=a).json()["status"] == "queued"


def test_ready_checks_the_job_store(client: TestClient) -> None:
    assert client.get("/v1/ready").json()["checks"]["job_store"] is True


@pytest.fixture(scope="module")
def working(tmp_path_factory: pytest.TempPathFactory) -> Iterator[TestClient]:
    """An app with an embedded dispatcher and one worker process."""
    settings = Settings(data_dir=tmp_path_factory.mktemp("jobs"), workers=1, sweep_chunk_points=4)
    with started(create_app(settings)) as c:
        yield c


def wait(c: TestClient, job_id: str, timeout: float = 60.0) -> dict[str, Any]:
    return poll(lambda: c.get(f"/v1/sweeps/{job_id}").json(), timeout=timeout)


def test_a_sweep_runs_to_the_same_result_as_run_local(working: TestClient) -> None:
    doc = {
        **body(),
        "axes": [
            {"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 6},
            {"parameter": "Omega_e", "start": 0.4, "stop": 0.8, "num": 3},
        ],
    }
    job = wait(working, working.post("/v1/sweeps", json=doc).json()["id"])
    assert job["status"] == "succeeded" and job["progress"] == {"done": 18, "total": 18}
    assert job["started_at"] <= job["finished_at"]
    r = working.get(f"/v1/sweeps/{job['id']}/result")
    assert r.status_code == 200 and "retry-after" not in r.headers
    assert r.json() == run_local(validated(doc), chunk_points=4).model_dump(mode="json")
    r = working.get(f"/v1/sweeps/{job['id']}/result", params={"format": "csv"})
    assert r.headers["content-type"].startswith("text/csv")
    rows = list(csv.DictReader(io.StringIO(r.text)))
    assert len(rows) == 18 and list(rows[0])[:2] == ["F_e1", "Omega_e"]


def test_plots_negotiate_png_and_svg(working: TestClient) -> None:
    job = wait(working, working.post("/v1/sweeps", json=body(num=8)).json()["id"])
    url = f"/v1/sweeps/{job['id']}/plot"
    r = working.get(url)
    assert r.headers["content-type"] == "image/png" and r.content.startswith(b"\x89PNG")
    r = working.get(url, headers={"Accept": "image/svg+xml"})
    assert r.headers["content-type"] == "image/svg+xml" and b"<svg" in r.content[:500]
    assert working.get(url, params={"format": "svg"}).headers["content-type"] == "image/svg+xml"
    assert working.get(url, headers={"Accept": "text/html"}).status_code == 406


def test_continuation_both_branches_over_http(working: TestClient) -> None:
    doc = body(num=4, continuation=True, direction="both")
    job = wait(working, working.post("/v1/sweeps", json=doc).json()["id"])
    points = working.get(f"/v1/sweeps/{job['id']}/result").json()["points"]
    assert [p["branch"] for p in points] == ["up"] * 4 + ["down"] * 4


def test_jobs_show_their_axes_and_label(client: TestClient) -> None:
    job = client.post("/v1/sweeps", json=body(label="stage 1: F_e1")).json()
    assert job["label"] == "stage 1: F_e1"
    assert job["axes"] == [{"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 11}]
    (listed,) = client.get("/v1/sweeps").json()["items"]
    assert listed["label"] == "stage 1: F_e1" and listed["axes"] == job["axes"]
    assert client.post("/v1/sweeps", json=body()).json()["label"] is None
    r = client.post("/v1/sweeps", json=body(label="x" * 201))
    assert r.status_code == 422 and r.json()["errors"][0]["path"] == "label"


def test_a_cancelled_jobs_finished_chunks_are_a_partial_result(tmp_path: Path) -> None:
    """Chunk 51 of 4 points holds F_e1 = 0.204, which numpy.linspace makes 0.20400000000000001:
    the CSV writes the decimal."""
    app = create_app(Settings(data_dir=tmp_path, workers=0, sweep_chunk_points=4))
    with TestClient(app) as c:
        job = c.post("/v1/sweeps", json=body(num=301)).json()
        store = app.state.jobs.store
        url = f"/v1/sweeps/{job['id']}"
        assert c.get(url + "/result", params={"partial": True}).json()["points"] == []
        # a worker leases chunks 0..51 and finishes only chunk 51; then the job is cancelled
        claims = store.claim("test-worker", 60.0, 3, 52)
        assert [cl.index for cl in claims] == list(range(52))
        done = compute_chunk_json(claims[51].request_json, 51, 4)
        assert store.commit("test-worker", job["id"], 51, done)
        assert c.delete(url).json()["status"] == "cancelled"
        assert c.get(url + "/result").status_code == 409
        r = c.get(url + "/result", params={"partial": True})
        assert r.status_code == 200 and r.headers["x-partial-result"] == "true"
        result = r.json()
        assert result["partial"] is True
        assert [p["values"]["F_e1"] for p in result["points"]] == pytest.approx(
            [0.204, 0.205, 0.206, 0.207]
        )
        r = c.get(url + "/result", params={"partial": True, "format": "csv"})
        assert r.headers["x-partial-result"] == "true"
        rows = list(csv.DictReader(io.StringIO(r.text)))
        assert [row["F_e1"] for row in rows] == ["0.204", "0.205", "0.206", "0.207"]


def test_openapi_declares_the_headers_it_sends(client: TestClient) -> None:
    paths = client.get("/openapi.json").json()["paths"]
    submit = paths["/v1/sweeps"]["post"]["responses"]["202"]["headers"]
    assert {"Location", "Retry-After"} <= set(submit)
    assert "Retry-After" in paths["/v1/sweeps/{job_id}"]["get"]["responses"]["200"]["headers"]
    result = paths["/v1/sweeps/{job_id}/result"]["get"]["responses"]
    assert "Retry-After" in result["409"]["headers"]
    assert "X-Partial-Result" in result["200"]["headers"]
    for path in ("/v1/melnikov", "/v1/analyses", "/v1/thresholds", "/v1/analyses/plot"):
        responses = paths[path]["post"]["responses"]
        assert "ETag" in responses["200"]["headers"] and "304" in responses, path


def test_a_design_sweep_csv_from_the_service_is_in_gear_units(working: TestClient) -> None:
    """The stored points are read back unvalidated: the CSV's gear-unit cells still come out,
    equal to the JSON's ``physical`` and to what the CLI writes for the same sweep."""
    doc = json.loads((Path(__file__).parents[1] / "examples" / "envelope-map.json").read_text())
    doc["settings"] = SHORT
    doc["axes"][0]["num"], doc["axes"][1]["num"] = 3, 2
    job = wait(working, working.post("/v1/sweeps", json=doc).json()["id"])
    assert job["status"] == "succeeded"
    text = working.get(f"/v1/sweeps/{job['id']}/result", params={"format": "csv"}).text
    rows = list(csv.DictReader(io.StringIO(text)))
    points = working.get(f"/v1/sweeps/{job['id']}/result").json()["points"]
    assert len(rows) == 6
    for row, point in zip(rows, points, strict=True):
        for key, title in (("speed", "speed [rpm]"), ("dte", "dte [um]")):
            assert float(row[title]) == point["physical"][key]["value"]
    request = validated(doc)
    local = "".join(to_csv(run_local(request), request.outputs, design=True))
    assert text == local


@pytest.mark.parametrize(("setting", "stored"), [(None, 1000), (4, 4)])
def test_a_sweep_is_chunked_for_its_workers_unless_the_size_is_set(
    tmp_path: Path, setting: int | None, stored: int
) -> None:
    """Unset, about four chunks per worker (balanced_chunk_points; no embedded worker counts as
    one): 4000 points in chunks of 1000. The size is stored with the job, so a resumed job keeps
    its chunks."""
    app = create_app(Settings(data_dir=tmp_path, workers=0, sweep_chunk_points=setting))
    with TestClient(app) as c:
        assert c.post("/v1/sweeps", json=body(num=4000)).status_code == 202
        claims = app.state.jobs.store.claim("test-worker", 60.0, 3, 10_000)
    assert {cl.chunk_points for cl in claims} == {stored} and len(claims) == 4000 // stored


def test_a_basins_sweep_csv_from_the_service_has_each_attractors_columns(
    working: TestClient,
) -> None:
    """With settings.basins each attractor has its own columns (class, period, fraction with
    its interval, LLE per unit tau, magnitudes in gear units), as many as a point has at most:
    the service reads its stored points once for that count, and writes the CLI's CSV."""
    doc = json.loads((Path(__file__).parents[1] / "examples" / "envelope-map.json").read_text())
    doc["settings"] = {**SHORT, "basins": {"starts": 4}}
    doc["axes"][0]["num"], doc["axes"][1]["num"] = 2, 1
    doc["axes"][1]["stop"] = doc["axes"][1]["start"]  # one torque
    job = wait(working, working.post("/v1/sweeps", json=doc).json()["id"])
    assert job["status"] == "succeeded"
    text = working.get(f"/v1/sweeps/{job['id']}/result", params={"format": "csv"}).text
    points = working.get(f"/v1/sweeps/{job['id']}/result").json()["points"]
    most = max(len(p["attractors"]) for p in points)
    header = text.splitlines()[0].split(",")
    assert f"attractor_{most - 1}_class" in header and f"attractor_{most}_class" not in header
    assert "attractor_0_lle [1/tau]" in header and "attractor_0_dte [um]" in header
    request = validated(doc)
    assert text == "".join(to_csv(run_local(request), request.outputs, design=True))
