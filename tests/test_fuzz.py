"""Schemathesis over every operation of the OpenAPI document, in process against the ASGI app.

Checks: no 5xx, status codes / content types / bodies as documented, invalid data refused, and
valid data accepted (positive_data_acceptance), under the repository's ``schemathesis.toml``: the
same configuration as the documented ``st run`` against a server (README, "Testing"), which
accepts a 422 to schema-valid data only on the operations whose rules across fields it lists
(``tests/test_fuzz_config.py``). Job routes are reached through the OpenAPI links from each
submit (``service.api.links``): the stateful test follows them, and
``test_every_job_route_is_reached_through_its_links`` checks that each one answers for the job.
Examples per operation are bounded (GEARCHAOS_FUZZ_EXAMPLES, default 20) to keep CI short.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest
import schemathesis
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, settings
from schemathesis.checks import not_a_server_error
from schemathesis.config import SchemathesisConfig
from schemathesis.specs.openapi.checks import (
    content_type_conformance,
    negative_data_rejection,
    positive_data_acceptance,
    response_schema_conformance,
    status_code_conformance,
)

from service.core.config import Settings
from service.main import create_app
from tests.conftest import ROOT, started
from tests.test_robustness import DESIGN as ROBUST_DESIGN

CHECKS = [
    not_a_server_error,
    status_code_conformance,
    content_type_conformance,
    response_schema_conformance,
    negative_data_rejection,
    positive_data_acceptance,
]
EXAMPLES = int(os.environ.get("GEARCHAOS_FUZZ_EXAMPLES", "20"))

# a small synchronous budget keeps generated analyses cheap; over it is a documented 422
APP = create_app(
    Settings(
        data_dir=Path(tempfile.mkdtemp(prefix="gearchaos-fuzz-")),
        workers=0,
        max_sync_steps=100_000,
        max_curve_points=50,
        max_queued_jobs=100_000,  # no workers: every generated job stays queued (README)
        max_status_wait_s=0.0,  # so a status request with ?wait answers at once
    )
)
CONFIG = SchemathesisConfig.from_path(ROOT / "schemathesis.toml")
schema = schemathesis.openapi.from_asgi("/openapi.json", APP, config=CONFIG)


@pytest.fixture(scope="module", autouse=True)
def lifespan() -> Iterator[None]:
    """Run the app's start-up (kernel warm-up, job store) once for all generated calls.

    The kernels warm up in a thread after start-up; until they are warm ``GET /v1/ready`` is a
    documented 503, which the no-5xx check would count, so the calls wait for the warm-up.
    """
    with started(APP):
        yield


@schema.parametrize()
@settings(
    max_examples=EXAMPLES,
    deadline=None,
    suppress_health_check=list(HealthCheck),
    derandomize=True,
)
def test_every_operation_as_documented(case: schemathesis.Case) -> None:
    case.call_and_validate(checks=CHECKS)


Stateful = schema.as_state_machine()
TestStateful = Stateful.TestCase
TestStateful.settings = settings(
    max_examples=max(1, EXAMPLES // 4),
    stateful_step_count=10,
    deadline=None,
    suppress_health_check=list(HealthCheck),
    derandomize=True,
)


def test_every_job_route_is_reached_through_its_links() -> None:
    """Submit each kind of job with its documented example, then call every operation its 202
    response links to with the ``job_id`` the link names (``$response.body#/id``): each one
    answers for the job (never 404: the stateful phase reaches it the same way)."""
    spec = APP.openapi()
    by_id = {op["operationId"]: (method, path) for path, ops in spec["paths"].items()
             for method, op in ops.items()}  # fmt: skip
    client = TestClient(APP)  # the module's app, started once by ``lifespan``
    submitted_kinds = set()
    for path, ops in spec["paths"].items():
        links = ops.get("post", {}).get("responses", {}).get("202", {}).get("links")
        if not links:
            continue
        body = ops["post"]["requestBody"]["content"]["application/json"]
        schema_ref = body["schema"]["$ref"].rsplit("/", 1)[-1]
        example = spec["components"]["schemas"][schema_ref].get("examples", [None])[0]
        example = example or {"design": ROBUST_DESIGN, "samples": 8}  # no model example
        submitted = client.post(path, json=example)
        assert submitted.status_code == 202, (path, submitted.text)
        submitted_kinds.add(path)
        for name, link in links.items():
            assert link["parameters"] == {"job_id": "$response.body#/id"}
            method, target = by_id[link["operationId"]]
            url = target.replace("{job_id}", submitted.json()["id"])
            answer = client.request(method.upper(), url)
            assert answer.status_code != 404, (name, url, answer.text)
    assert submitted_kinds == {"/v1/basins", "/v1/remedies", "/v1/robustness", "/v1/runups",
                               "/v1/signals/jobs", "/v1/sweeps"}  # fmt: skip
