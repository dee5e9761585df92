"""Waiting on a job, once for every test: ``poll`` a fetch until its answer says done."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any, TypeVar

T = TypeVar("T")

UNFINISHED = ("queued", "running")
"""Job states that are not yet final."""


def finished(job: dict[str, Any]) -> bool:
    """A job document whose status is final (succeeded, failed, cancelled)."""
    return job["status"] not in UNFINISHED


def poll(
    fetch: Callable[[], T],
    until: Callable[[T], bool] = finished,  # type: ignore[assignment]
    timeout: float = 120.0,
    interval: float = 0.05,
) -> T:
    """``fetch()`` every ``interval`` seconds until ``until`` holds for its answer, which is
    returned; TimeoutError (with the last answer) after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        answer = fetch()
        if until(answer):
            return answer
        if time.monotonic() > deadline:
            raise TimeoutError(f"still not done after {timeout:g} s: {answer!r}"[:500])
        time.sleep(interval)
