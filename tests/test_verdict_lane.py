"""POST /v1/melnikov's lane (``service.api.routes.melnikov.VerdictLane``): a JSON body that
validates is answered without the router, everything else by the route with the body replayed,
and every answer is the bytes the route gave before the lane.

``data/melnikov_responses.json`` holds 60 requests (one and three excitations, loads of both
signs, quadrature, perturbation load, not applicable, incommensurate, designs, refusals) with
the status, media type, ETag and sha256 of the body that main answered before the lane
(``benchmarks/melnikov_identity.py --store``; the script compares 514 requests with any tree).
"""

from __future__ import annotations

import asyncio
import hashlib
import json
from collections.abc import Callable
from pathlib import Path

import pytest
from fastapi import FastAPI
from fastapi.routing import APIRoute
from fastapi.testclient import TestClient
from opentelemetry import _logs, metrics, trace

from service.core.config import Settings
from service.main import create_app

STORED = json.loads((Path(__file__).parent / "data" / "melnikov_responses.json").read_text())
ONE = {"params": {"damping": 0.05, "transmission_error": {"frequency": 0.5, "harmonics": [
    {"amplitude": 0.2}]}}}  # fmt: skip


@pytest.fixture
def routed(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The paths of the requests the router's routes handle."""
    handled: list[str] = []
    handle = APIRoute.handle

    async def counting(self: APIRoute, scope: dict, receive: object, send: object) -> None:
        handled.append(self.path)
        await handle(self, scope, receive, send)

    monkeypatch.setattr(APIRoute, "handle", counting)
    return handled


def test_responses_equal_the_stored_ones(tmp_path: Path) -> None:
    client = TestClient(create_app(Settings(data_dir=tmp_path, workers=0)))
    got = []
    for row in STORED:
        r = client.post("/v1/melnikov", content=row["body"], headers={"content-type": row["media"]})
        got.append(
            (r.status_code, r.headers["content-type"], r.headers.get("etag", ""),
             hashlib.sha256(r.content).hexdigest())
        )  # fmt: skip
    assert got == [(x["status"], x["content_type"], x["etag"], x["sha256"]) for x in STORED]


def test_a_verdict_skips_the_router_and_a_refusal_takes_it(
    tmp_path: Path, routed: list[str]
) -> None:
    client = TestClient(create_app(Settings(data_dir=tmp_path, workers=0)))
    ok = client.post("/v1/melnikov", json=ONE)
    bad = client.post("/v1/melnikov", json={"params": {"damping": -1}})
    assert (ok.status_code, bad.status_code) == (200, 422)
    assert ok.json()["chaos_possible"] is True
    assert routed == ["/v1/melnikov"]  # the refused body only


def call(app: FastAPI, chunks: list[bytes], length: bool = True) -> tuple[int, bytes]:
    """(status, body) of POST /v1/melnikov whose body arrives in ``chunks`` (ASGI messages),
    with or without a Content-Length header."""
    headers = [(b"content-type", b"application/json")]
    if length:
        headers.append((b"content-length", str(sum(map(len, chunks))).encode()))
    scope = {"type": "http", "asgi": {"version": "3.0"}, "http_version": "1.1", "method": "POST",
             "scheme": "http", "path": "/v1/melnikov", "raw_path": b"/v1/melnikov",
             "query_string": b"", "root_path": "", "headers": headers,
             "client": ("127.0.0.1", 50000), "server": ("127.0.0.1", 8000)}  # fmt: skip
    messages = [
        {"type": "http.request", "body": c, "more_body": k < len(chunks) - 1}
        for k, c in enumerate(chunks)
    ]
    out: dict = {"body": b""}

    async def receive() -> dict:
        return messages.pop(0) if messages else {"type": "http.disconnect"}

    async def send(message: dict) -> None:
        if message["type"] == "http.response.start":
            out["status"] = message["status"]
        else:
            out["body"] += message.get("body", b"")

    asyncio.run(app(scope, receive, send))
    return out["status"], out["body"]


@pytest.mark.parametrize("doc", [ONE, {"params": {"damping": -1}}])
def test_a_body_in_pieces_answers_as_in_one(tmp_path: Path, routed: list[str], doc: dict) -> None:
    """The lane reads every message of the body, and replays them all to the route when it
    does not answer; a body without Content-Length goes to the route unread."""
    body = json.dumps(doc).encode()
    app = create_app(Settings(data_dir=tmp_path, workers=0))
    whole = call(app, [body])
    assert whole[0] == (200 if doc is ONE else 422)
    assert call(app, [body[:10], body[10:25], body[25:]]) == whole
    assert call(app, [body[:10], body[10:]], length=False) == whole
    assert routed == ["/v1/melnikov"] * (1 if doc is ONE else 3)


def test_a_request_does_not_look_up_opentelemetry(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """FastAPI's native OpenTelemetry is off (the service has its own metrics and access log):
    with it on, every request looked up the global tracer, meter and logger providers, which
    read the environment each time."""
    asked: list[str] = []

    def counted(name: str, getter: Callable[[], object]) -> Callable[[], object]:
        def get() -> object:
            asked.append(name)
            return getter()

        return get

    for module, name in ((trace, "tracer"), (metrics, "meter"), (_logs, "logger")):
        getter = f"get_{name}_provider"
        monkeypatch.setattr(module, getter, counted(name, getattr(module, getter)))
    client = TestClient(create_app(Settings(data_dir=tmp_path, workers=0)))
    assert client.post("/v1/melnikov", json=ONE).status_code == 200
    assert client.get("/v1/health").status_code == 200
    assert asked == []


def test_a_refused_verdict_is_computed_once_and_answered_as_the_route_would(
    tmp_path: Path, routed: list[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The lane suppressed every exception of the verdict and let the route compute it again:
    a refusal found while computing (a ValueError of the engine) ran twice. It runs once and is
    answered with the app's problem+json (422 naming the field); an unexpected error is the
    server-error handler's 500, also computed once."""
    import service.api.routes.melnikov as route

    calls: list[str] = []

    def refused(body: object) -> object:
        calls.append("verdict")
        raise ValueError("params.damping: refused by the engine")

    monkeypatch.setattr(route, "answer_melnikov", refused)
    app = create_app(Settings(data_dir=tmp_path, workers=0))
    r = TestClient(app).post("/v1/melnikov", json=ONE)
    assert r.status_code == 422 and r.headers["content-type"] == "application/problem+json"
    assert "refused by the engine" in r.text and calls == ["verdict"] and routed == []

    def crash(body: object) -> object:
        calls.append("crash")
        raise RuntimeError("a bug")

    monkeypatch.setattr(route, "answer_melnikov", crash)
    r = TestClient(app, raise_server_exceptions=False).post("/v1/melnikov", json=ONE)
    assert r.status_code == 500 and r.json()["title"] == "Internal error"
    assert calls == ["verdict", "crash"]
