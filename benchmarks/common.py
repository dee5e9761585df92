"""What several benchmark scripts share: timing a call, and waiting for a real server."""

from __future__ import annotations

import time
from collections.abc import Callable

import httpx


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
