"""What several benchmark scripts share: timing a call, an earlier commit's engine, and waiting
for a real server."""

from __future__ import annotations

import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx

ROOT = Path(__file__).resolve().parents[1]


def best_of(fn: Callable[[], object], repeats: int) -> float:
    """Smallest wall time of ``repeats`` calls of ``fn``, seconds."""
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def wait_ready(client: httpx.Client, seconds: float = 120.0) -> None:
    """Poll ``/v1/ready`` until it answers 200 (kernels warm, job store open) or time runs out."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            if client.get("/v1/ready").status_code == 200:
                return
        except httpx.HTTPError:
            pass
        time.sleep(0.1)
    raise TimeoutError(f"the server was not ready within {seconds:g} s")


@contextmanager
def extracted(commit: str) -> Iterator[Path]:
    """A temporary directory holding the ``gearengine`` package of ``commit`` (``git archive``):
    the previous implementation, run with ``PYTHONPATH`` set to it and the same dependencies."""
    with tempfile.TemporaryDirectory(prefix="gearchaos-baseline-") as tmp:
        archive = subprocess.run(
            ["git", "archive", commit, "gearengine"], cwd=ROOT, capture_output=True, check=True
        )
        subprocess.run(["tar", "-x", "-C", tmp], input=archive.stdout, check=True)
        yield Path(tmp)
