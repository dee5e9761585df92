"""End to end: a real `gearengine serve` (uvicorn) on a free loopback port, called with httpx."""

from __future__ import annotations

import concurrent.futures

import httpx
import pytest

from tests.conftest import PAPER_PARAMS, Server


def test_every_endpoint_answers(server: Server) -> None:
    with httpx.Client(base_url=server.url, timeout=60) as c:
        assert c.get("/v1/health").json()["status"] == "ok"
        assert c.get("/v1/ready").status_code == 200
        r = c.post("/v1/melnikov", json={"params": PAPER_PARAMS})
        assert r.status_code == 200 and r.json()["chaos_possible"] is True
        r = c.post("/v1/thresholds", json={"params": PAPER_PARAMS, "parameter": "mu", "num": 10})
        assert r.status_code == 200 and len(r.json()["frequencies"]) == 10
        assert "gearchaos_requests_total" in c.get("/metrics").text
        assert c.get("/docs").status_code == 200 and c.get("/openapi.json").status_code == 200


def test_server_timing_header_reports_compute(server: Server) -> None:
    """Every fresh computation says how long it took (Server-Timing); cache hits do not.

    The time itself is measured in benchmarks/, never asserted here."""
    with httpx.Client(base_url=server.url, timeout=60) as c:
        params = {**PAPER_PARAMS, "damping": 0.0513}
        fresh = c.post("/v1/melnikov", json={"params": params})
        again = c.post("/v1/melnikov", json={"params": params})
    assert fresh.headers["x-cache"] == "miss"
    assert float(fresh.headers["server-timing"].split("dur=")[1]) > 0.0
    assert again.headers["x-cache"] == "hit" and "server-timing" not in again.headers


@pytest.mark.parametrize(
    ("content", "status", "path"),
    [
        (b'{"params": {"damping": NaN}}', 422, "params.damping"),
        (b'{"params": {"damping": 1e400}}', 422, "params.damping"),
        (
            b'{"params": {"damping": 0.1, "torque": {"frequency": -1}}}',
            422,
            "params.torque.frequency",
        ),
        (b'{"params": ', 422, None),
        (b'{"params": {"damping": 0.1}, "pad": "' + b"x" * (2 << 20) + b'"}', 413, None),
    ],
)
def test_bad_input_over_http(server: Server, content: bytes, status: int, path: str | None) -> None:
    r = httpx.post(
        server.url + "/v1/melnikov",
        content=content,
        headers={"content-type": "application/json"},
        timeout=60,
    )
    assert r.status_code == status
    assert r.headers["content-type"] == "application/problem+json"
    if path:
        assert path in [e["path"] for e in r.json()["errors"]]


def test_concurrent_requests(server: Server) -> None:
    def ask(k: int) -> int:
        params = {**PAPER_PARAMS, "mean_force": 0.001 * k}
        return httpx.post(
            server.url + "/v1/melnikov", json={"params": params}, timeout=60
        ).status_code

    with concurrent.futures.ThreadPoolExecutor(8) as pool:
        assert set(pool.map(ask, range(40))) == {200}
