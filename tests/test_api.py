"""The HTTP API in process: contracts, errors, caching, auth, docs."""

from __future__ import annotations

import hashlib
import json
import logging
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from gearengine.homoclinic.verdict import melnikov
from gearengine.jsonio import dumps
from gearengine.model.params import GearParams
from service.core.config import Settings
from service.main import create_app
from service.openapi import document
from tests.conftest import PAPER_PARAMS, ROOT


def test_melnikov_body_is_the_engine_result(client: TestClient) -> None:
    r = client.post("/v1/melnikov", json={"params": PAPER_PARAMS})
    assert r.status_code == 200
    assert r.headers["content-type"] == "application/json"
    assert r.content == dumps(melnikov(GearParams.model_validate(PAPER_PARAMS))).encode()
    assert r.json()["thresholds"]["F_e1"]["nearest"] == pytest.approx(0.177953, abs=5e-6)
    paper = client.post("/v1/melnikov", json={"params": PAPER_PARAMS, "mean_load": "perturbation"})
    assert paper.json()["thresholds"]["F_e1"]["nearest"] == pytest.approx(0.19588, abs=5e-5)


def test_same_canonical_request_same_bytes_and_etag(client: TestClient) -> None:
    a = client.post("/v1/melnikov", json={"params": PAPER_PARAMS})
    reordered = json.dumps({"params": dict(reversed(list(PAPER_PARAMS.items())))}, indent=3)
    b = client.post("/v1/melnikov", content=reordered, headers={"content-type": "application/json"})
    assert a.content == b.content and a.headers["etag"] == b.headers["etag"]
    assert (a.headers["x-cache"], b.headers["x-cache"]) == ("miss", "hit")
    c = client.post(
        "/v1/melnikov", json={"params": PAPER_PARAMS}, headers={"if-none-match": a.headers["etag"]}
    )
    assert c.status_code == 304 and c.content == b""
    other = client.post("/v1/melnikov", json={"params": {**PAPER_PARAMS, "damping": 0.08}})
    assert other.headers["etag"] != a.headers["etag"]


@pytest.mark.parametrize(
    ("body", "path"),
    [
        ({"params": {**PAPER_PARAMS, "damping": "NaN"}}, "params.damping"),
        ({"params": {**PAPER_PARAMS, "damping": "Infinity"}}, "params.damping"),
        ({"params": {**PAPER_PARAMS, "damping": -0.1}}, "params.damping"),
        (
            {
                "params": {
                    **PAPER_PARAMS,
                    "transmission_error": {"frequency": 0.5, "harmonics": [{}] * 40},
                }
            },
            "params.transmission_error.harmonics",
        ),
        (
            {"params": {**PAPER_PARAMS, "backlash": {"model": "cubic", "a": "x"}}},
            "params.backlash.cubic.a",
        ),
        ({"params": PAPER_PARAMS, "methd": "x"}, "methd"),
        ({}, "params"),
    ],
)
def test_bad_input_is_problem_json_naming_the_field(
    client: TestClient, body: dict, path: str
) -> None:
    r = client.post("/v1/melnikov", json=body)
    assert r.status_code == 422
    assert r.headers["content-type"] == "application/problem+json"
    problem = r.json()
    assert {"type", "title", "status", "detail", "errors"} <= problem.keys()
    assert problem["status"] == 422
    assert path in [e["path"] for e in problem["errors"]], problem


def test_broken_json_and_wrong_method(client: TestClient) -> None:
    r = client.post(
        "/v1/melnikov", content=b'{"params": ', headers={"content-type": "application/json"}
    )
    assert r.status_code == 422 and r.headers["content-type"] == "application/problem+json"
    # the location is the body, not a character offset dressed up as a path (found in review)
    assert r.json()["errors"][0]["path"] == "" and "at character 11" in r.json()["detail"]
    r = client.get("/v1/melnikov")
    assert r.status_code == 405 and r.json()["status"] == 405


@pytest.mark.parametrize(
    "headers",
    [{"content-type": "application/x-www-form-urlencoded"}, {}, {"content-type": "text/plain"}],
)
def test_json_body_without_json_content_type_is_415_with_a_hint(
    client: TestClient, headers: dict[str, str]
) -> None:
    body = json.dumps({"params": PAPER_PARAMS})  # what `curl -d` sends as form data
    r = client.post("/v1/melnikov", content=body, headers=headers)
    assert r.status_code == 415 and r.headers["content-type"] == "application/problem+json"
    assert "send Content-Type: application/json" in r.json()["detail"]
    assert "valid dictionary" not in r.text
    # JSON that is not an object, sent as JSON, is still a validation problem
    r = client.post("/v1/melnikov", content=b"[1]", headers={"content-type": "application/json"})
    assert r.status_code == 422


def test_body_limit_counts_streamed_bytes(tmp_path: Path) -> None:
    app = create_app(Settings(data_dir=tmp_path, max_body_bytes=4096))
    with TestClient(app) as c:
        big = json.dumps({"params": PAPER_PARAMS, "pad": "x" * 5000})
        r = c.post("/v1/melnikov", content=big, headers={"content-type": "application/json"})
        assert r.status_code == 413 and "4096" in r.json()["detail"]

        def chunks():  # no Content-Length: counted while streaming
            for _ in range(10):
                yield b" " * 1000

        r = c.post("/v1/melnikov", content=chunks(), headers={"content-type": "application/json"})
        assert r.status_code == 413 and r.headers["content-type"] == "application/problem+json"


def test_conversion_endpoint(client: TestClient) -> None:
    example = {
        "inertia_a": 2e-3,
        "inertia_b": 8e-3,
        "base_radius_a": 0.03,
        "base_radius_b": 0.05,
        "teeth_a": 18,
        "teeth_b": 30,
        "shaft_speed_a": 157.0,
        "mesh_stiffness": 1e8,
        "mesh_damping": 200.0,
        "half_backlash": 1e-4,
        "torque_a_mean": 24.0,
        "torque_b_mean": 40.0,
    }
    r = client.post("/v1/conversions/physical", json=example)
    assert r.status_code == 200, r.text
    out = r.json()
    assert out["natural_frequency"] > 0 and out["params"]["damping"] > 0
    bad = client.post("/v1/conversions/physical", json={**example, "inertia_a": -1})
    assert bad.status_code == 422 and bad.json()["errors"][0]["path"] == "inertia_a"


def test_threshold_curve_endpoint(client: TestClient) -> None:
    body = {"params": PAPER_PARAMS, "parameter": "F_e1", "start": 0.1, "stop": 2.0, "num": 20}
    r = client.post("/v1/thresholds", json=body)
    assert r.status_code == 200
    curve = r.json()
    assert len(curve["frequencies"]) == 20 and len(curve["no_chaos"]) == 20
    r = client.post("/v1/thresholds", json={**body, "num": 10_000})
    assert r.status_code == 422 and "max_curve_points" in r.json()["detail"]
    assert r.json()["errors"][0]["path"] == "num"
    # no rule joins start and stop (the schema could not say it): downwards is the same curve
    down = client.post("/v1/thresholds", json={**body, "start": 2.0, "stop": 0.1}).json()
    assert down["frequencies"] == pytest.approx(curve["frequencies"][::-1])
    assert down["no_chaos"][0] == curve["no_chaos"][-1]  # the ends are exact
    assert down["no_chaos"][-1] == curve["no_chaos"][0]
    # the schema's bounds are validation's: below the engine's lowest frequency, and 2.0 as num
    r = client.post("/v1/thresholds", json={**body, "start": 1e-9})
    assert r.status_code == 422 and r.json()["errors"][0]["path"] == "start"
    assert client.post("/v1/thresholds", json={**body, "num": 20.0}).json() == curve


@pytest.mark.parametrize(
    ("patch", "path"),
    [
        ({"frequency_parameter": "Omega_k"}, "frequency_parameter"),
        (
            {"params": {**PAPER_PARAMS, "backlash": {"model": "cubic", "a": -1.0}}},
            "params.backlash",
        ),
    ],
)
def test_threshold_refusals_name_the_request_field(
    client: TestClient, patch: dict, path: str
) -> None:
    r = client.post("/v1/thresholds", json={"params": PAPER_PARAMS, **patch})
    assert r.status_code == 422
    assert [e["path"] for e in r.json()["errors"]] == [path]


def test_api_keys(tmp_path: Path) -> None:
    app = create_app(Settings(data_dir=tmp_path, api_keys="alpha-key,beta-key"))
    with TestClient(app) as c:
        r = c.post("/v1/melnikov", json={"params": PAPER_PARAMS})
        assert r.status_code == 401 and r.headers["content-type"] == "application/problem+json"
        r = c.post("/v1/melnikov", json={"params": PAPER_PARAMS}, headers={"x-api-key": "nope"})
        assert r.status_code == 401 and "not valid" in r.json()["detail"]
        ok = {"authorization": "Bearer alpha-key"}
        assert c.post("/v1/melnikov", json={"params": PAPER_PARAMS}, headers=ok).status_code == 200
        ok = {"x-api-key": "beta-key"}
        assert c.post("/v1/melnikov", json={"params": PAPER_PARAMS}, headers=ok).status_code == 200
        assert c.get("/v1/health").status_code == 200 and c.get("/metrics").status_code == 200


def test_keys_file_holds_only_hashes(tmp_path: Path) -> None:
    import hashlib

    (tmp_path / "api_keys.sha256").write_text(
        "# team A\n" + hashlib.sha256(b"team-a-secret").hexdigest() + "\n"
    )
    with TestClient(create_app(Settings(data_dir=tmp_path))) as c:
        r = c.post(
            "/v1/melnikov", json={"params": PAPER_PARAMS}, headers={"x-api-key": "team-a-secret"}
        )
        assert r.status_code == 200
        assert c.post("/v1/melnikov", json={"params": PAPER_PARAMS}).status_code == 401


def test_health_ready_metrics(client: TestClient) -> None:
    assert client.get("/v1/health").json()["status"] == "ok"
    ready = client.get("/v1/ready").json()
    assert ready["status"] == "ok" and all(ready["checks"].values())
    client.post("/v1/melnikov", json={"params": PAPER_PARAMS})
    text = client.get("/metrics").text
    assert 'gearchaos_requests_total{method="POST",route="/v1/melnikov",status="200"}' in text
    assert "gearchaos_request_duration_seconds_bucket" in text


def test_access_log_line_and_counts(client: TestClient, caplog: pytest.LogCaptureFixture) -> None:
    """Each request logs one JSON line (with its key id under auth) and counts once per route,
    method and status: the middleware keeps the metrics' children, so a second status of the
    same route has its own count."""
    with caplog.at_level(logging.INFO, logger="gearchaos.access"):
        for _ in range(2):
            client.post("/v1/melnikov", json={"params": PAPER_PARAMS})
        client.post("/v1/melnikov", json={"params": {"damping": -1}})
    lines = [json.loads(r.getMessage()) for r in caplog.records if r.name == "gearchaos.access"]
    assert [(x["route"], x["method"], x["status"]) for x in lines] == [
        ("/v1/melnikov", "POST", 200),
        ("/v1/melnikov", "POST", 200),
        ("/v1/melnikov", "POST", 422),
    ]
    assert all(x["event"] == "request" and x["duration_ms"] >= 0.0 for x in lines)
    assert all(x["key_id"] is None for x in lines)
    text = client.get("/metrics").text
    assert 'gearchaos_requests_total{method="POST",route="/v1/melnikov",status="200"} 2.0' in text
    assert 'gearchaos_requests_total{method="POST",route="/v1/melnikov",status="422"} 1.0' in text


ONE = (
    '{"damping": 0.05, "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]}}'
)
VERDICT_BODIES = [
    '{"params": ' + ONE + "}",
    '{"params": ' + ONE + ', "params": {"damping": 0.07}}',  # a duplicate key
    '{"params": {"damping": 1, "torque": {"frequency": 1, "harmonics": [{"amplitude": -0}]}}}',
    '{"params": ' + ONE + ', "method": "quadrature"}',
    '{"params": ' + ONE + ', "extra": 1}',
    '{"params": {"damping": 1e400}}',
    '{"params": {"damping": NaN}}',
    '{"params": {"damping": "0.05"}}',
    "[]",
    "",
    '{"params": {"damping": 0.05}, "design": {}}',
]  # fmt: skip


@pytest.mark.parametrize("body", VERDICT_BODIES)
@pytest.mark.parametrize("key", [None, "team-a-secret", "wrong"])
def test_verdict_route_answers_as_fastapi(tmp_path: Path, body: str, key: str | None) -> None:
    """POST /v1/melnikov takes a short path for an application/json body that validates
    (``VerdictLane``); every body answers as FastAPI's own handler does (here under a +json
    media type, which only FastAPI's handler reads): status, problem and verdict bytes, with
    and without a valid API key."""
    (tmp_path / "api_keys.sha256").write_text(hashlib.sha256(b"team-a-secret").hexdigest())
    keys = {"x-api-key": key} if key else {}
    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0))) as c:
        answers = [
            c.post("/v1/melnikov", content=body.encode(), headers={"content-type": media, **keys})
            for media in ("application/json", "application/vnd.gearchaos+json")
        ]
    short, fastapi = ((r.status_code, r.content) for r in answers)
    assert short == fastapi


def test_committed_openapi_matches_the_app() -> None:
    committed = (ROOT / "openapi.json").read_text()
    assert committed == document(), "openapi.json is stale: run python -m service.openapi"


def test_request_fields_have_descriptions_and_examples() -> None:
    spec = json.loads(document())
    schemas = spec["components"]["schemas"]
    request_models = [
        "MelnikovRequest", "ThresholdsRequest", "GearParams", "Excitation", "Harmonic",
        "CubicBacklash", "PiecewiseBacklash", "PhysicalGearData",
    ]  # fmt: skip

    def has_example(prop: dict) -> bool:
        if "$ref" in prop:  # a nested model: its own schema carries the examples
            return "examples" in schemas[prop["$ref"].rsplit("/", 1)[1]]
        return any(k in prop for k in ("examples", "example", "default"))

    missing = [
        f"{name}.{field}"
        for name in request_models
        for field, prop in schemas[name]["properties"].items()
        if "description" not in prop or not has_example(prop)
    ]
    assert not missing, missing


def test_docs_work_offline(client: TestClient) -> None:
    page = client.get("/docs").text
    assert "cdn" not in page.lower() and "/static-offline-docs/swagger-ui-bundle.js" in page
    assert client.get("/static-offline-docs/swagger-ui-bundle.js").status_code == 200
    redoc = client.get("/redoc").text
    assert "/static-offline-docs/redoc.standalone.js" in redoc
    assert client.get("/static-offline-docs/redoc.standalone.js").status_code == 200
