"""What the benchmarks that start a real ``gearengine serve`` share."""

from __future__ import annotations

import time

import httpx


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
