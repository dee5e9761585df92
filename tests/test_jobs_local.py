"""``jobs.run_local``: the progress callback hears of each chunk as it completes, and the result
is assembled in index order whatever the order of completion."""

from __future__ import annotations

import threading

import pytest
from pydantic import BaseModel

from gearengine.studies import jobs


class Request(BaseModel):
    """A job of two chunks: chunk 0 of 1 unit of work, chunk 1 of 10."""

    chunks: int = 2


class Result(BaseModel):
    """The chunks' outputs as assembled."""

    outputs: list[str]


REPORTED = threading.Event()
"""Set by the test's progress callback once it has heard of chunk 1."""
WAIT_S = 20.0
"""Longest wait of chunk 0 for that [s] (a safety net: run_local awaiting chunks in index order
never reports chunk 1 before chunk 0 ends, and would wait forever)."""


def _chunk(request: Request, index: int, chunk_points: int) -> str:
    if index == 0:  # the slow first chunk: done only after chunk 1 was reported
        REPORTED.wait(WAIT_S)
    return f"chunk {index}"


SLOW_FIRST = jobs.JobKind(
    name="slow-first",
    request=Request,
    chunk_points=1,
    chunk_counts=lambda request, size: [1, 10],
    work=lambda request: 0,
    compute_chunk=_chunk,
    assemble=lambda request, chunks: Result(outputs=chunks),
)


def test_progress_as_chunks_complete(monkeypatch: pytest.MonkeyPatch) -> None:
    """Chunk 1 ends first and is reported first (before: the callback waited for chunk 0, and
    the remedies CLI printed all six searches at the end); the outputs stay in index order."""
    monkeypatch.setitem(jobs.KINDS, "slow-first", "tests.test_jobs_local:SLOW_FIRST")
    REPORTED.clear()
    seen: list[tuple[int, int]] = []

    def callback(done: int, total: int) -> None:
        seen.append((done, total))
        if done == 10:
            REPORTED.set()

    result = jobs.run_local("slow-first", Request(), callback, workers=2)
    assert seen == [(10, 11), (11, 11)]
    assert isinstance(result, Result) and result.outputs == ["chunk 0", "chunk 1"]
