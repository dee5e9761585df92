"""OpenAPI links from every job submit operation to the operations on the job (issue 30 item
7): schemathesis' stateful phase, and client generators, follow a submitted job's ``id`` to its
status, result, figure and cancel routes instead of calling them with made-up ids."""

from __future__ import annotations

import json
import re

from tests.conftest import ROOT

SPEC = json.loads((ROOT / "openapi.json").read_text())


def job_operations() -> dict[str, set[str]]:
    """Per job collection ``/v1/<kind>``, the operation ids under ``/v1/<kind>/{job_id}``."""
    out: dict[str, set[str]] = {}
    for path, ops in SPEC["paths"].items():
        if m := re.fullmatch(r"(/v1/[^{}]+?)/\{job_id\}(/.*)?", path):
            out.setdefault(m.group(1), set()).update(op["operationId"] for op in ops.values())
    return out


def test_every_submit_links_to_every_operation_on_its_job() -> None:
    jobs = job_operations()
    assert set(jobs) == {"/v1/sweeps", "/v1/runups", "/v1/robustness", "/v1/remedies",
                         "/v1/basins", "/v1/signals/jobs"}  # fmt: skip
    for base, ids in jobs.items():
        links = SPEC["paths"][base]["post"]["responses"]["202"]["links"]
        assert {link["operationId"] for link in links.values()} == ids, base
        for link in links.values():
            assert link["parameters"] == {"job_id": "$response.body#/id"}
        assert {"GetJob", "GetResult", "CancelJob"} <= set(links), base


def test_the_linked_parameter_is_the_submitted_job_id() -> None:
    """The 202 body is a Job, whose id the links read."""
    for base in job_operations():
        body = SPEC["paths"][base]["post"]["responses"]["202"]["content"]["application/json"]
        assert body["schema"] == {"$ref": "#/components/schemas/Job"}
    assert "id" in SPEC["components"]["schemas"]["Job"]["required"]


def test_a_405_allows_every_documented_method_of_the_path(tmp_path) -> None:
    """Starlette's 405 named only the first matching route's methods (``Allow: POST`` on
    /v1/sweeps, which also lists jobs with GET); schemathesis' ST205 found it."""
    from fastapi.testclient import TestClient

    from service.core.config import Settings
    from service.main import create_app

    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0, api_keys=""))) as client:
        cases = [("/v1/sweeps", "GET, POST"), ("/v1/runups/0", "DELETE, GET"),
                 ("/v1/sweeps/0/result", "GET"), ("/v1/melnikov", "POST")]  # fmt: skip
        for path, allowed in cases:
            response = client.request("OPTIONS", path)
            assert response.status_code == 405
            assert response.headers["allow"] == allowed, path
            assert response.headers["content-type"] == "application/problem+json"
