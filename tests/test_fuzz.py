"""Schemathesis over every operation of the OpenAPI document, in process against the ASGI app.

Checks: no 5xx, status codes / content types / bodies as documented, and invalid data refused.
Examples per operation are bounded (GEARCHAOS_FUZZ_EXAMPLES, default 20) to keep CI short.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from schemathesis.checks import not_a_server_error
from schemathesis.specs.openapi.checks import (
    content_type_conformance,
    negative_data_rejection,
    response_schema_conformance,
    status_code_conformance,
)

from service.core.config import Settings
from service.main import create_app
from tests.conftest import started

CHECKS = [
    not_a_server_error,
    status_code_conformance,
    content_type_conformance,
    response_schema_conformance,
    negative_data_rejection,
]
EXAMPLES = int(os.environ.get("GEARCHAOS_FUZZ_EXAMPLES", "20"))

# a small synchronous budget keeps generated analyses cheap; over it is a documented 422
APP = create_app(
    Settings(
        data_dir=Path(tempfile.mkdtemp(prefix="gearchaos-fuzz-")),
        workers=0,
        max_sync_steps=100_000,
        max_curve_points=50,
    )
)
schema = schemathesis.openapi.from_asgi("/openapi.json", APP)


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
