"""A robustness job survives kill -9 of its server: restarted, it resumes from the committed
chunks and its result equals an uninterrupted run (chunks depend only on (request, index))."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest

from gearengine.studies.robustness.study import RobustnessRequest, run_local
from service.jobs.store import JobStore
from tests.test_faults import crash_and_resume, data_dir  # noqa: F401
from tests.test_robustness import DESIGN

STUDY: dict[str, Any] = {
    "design": DESIGN,
    # long transients make each 16-sample chunk take a few tenths of a second
    "settings": {"transient_periods": 3000, "record_periods": 100},
    "samples": 64,
}
N_CHUNKS = 4


@pytest.fixture(scope="module")
def reference() -> dict[str, Any]:
    request = RobustnessRequest.model_validate(copy.deepcopy(STUDY))
    return run_local(request).model_dump(mode="json")


def test_kill9_server_mid_study_then_restart_gives_the_same_numbers(
    data_dir: Path,  # noqa: F811
    reference: dict[str, Any],
) -> None:
    job_id, before = crash_and_resume(data_dir, "/v1/robustness", STUDY, 16, reference, 300.0)
    assert 1 <= len(before) < N_CHUNKS
    log = JobStore.in_dir(data_dir).commit_log(job_id)
    assert sorted(idx for idx, _ in log) == list(range(N_CHUNKS))
    assert log[: len(before)] == before
