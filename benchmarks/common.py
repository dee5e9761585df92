"""What several benchmark scripts share: timing a call, an earlier commit's engine, and waiting
for a real server."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
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


def timings(calls: list[Callable[[], object]]) -> list[float]:
    """Wall time of each call, seconds: each call its own input (a varied design), so no cache
    of an earlier call's input flatters the next."""
    times = []
    for call in calls:
        t = time.perf_counter()
        call()
        times.append(time.perf_counter() - t)
    return times


def min_median(times: list[float]) -> tuple[float, float]:
    """(min, median) of ``times``."""
    ordered = sorted(times)
    n = len(ordered)
    return ordered[0], (ordered[n // 2] if n % 2 else 0.5 * (ordered[n // 2 - 1] + ordered[n // 2]))


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
def extracted(commit: str, packages: tuple[str, ...] = ("gearengine",)) -> Iterator[Path]:
    """A temporary directory holding the ``packages`` of ``commit`` (``git archive``): the
    previous implementation, run with ``PYTHONPATH`` set to it and the same dependencies."""
    with tempfile.TemporaryDirectory(prefix="gearchaos-baseline-") as tmp:
        archive = subprocess.run(
            ["git", "archive", commit, *packages], cwd=ROOT, capture_output=True, check=True
        )
        subprocess.run(["tar", "-x", "-C", tmp], input=archive.stdout, check=True)
        yield Path(tmp)


@contextmanager
def served(data_dir: Path, env: dict[str, str], tree: Path = ROOT) -> Iterator[httpx.Client]:
    """A real ``gearengine serve`` of the working tree (or of the source ``tree`` of an earlier
    commit, ``extracted`` with gearengine and service: then on ``PYTHONPATH``) on a free loopback
    port with ``env`` added to this process's environment and its job store in ``data_dir``,
    ready (``wait_ready``); yields a client of it and stops it afterwards (killed if it does not
    stop within 60 s)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    cmd = [sys.executable, "-m", "gearengine.cli", "serve", "--port", str(port),
           "--data-dir", str(data_dir)]  # fmt: skip
    with open(data_dir.parent / "server.log", "w") as log:
        if tree != ROOT:
            env = {**env, "PYTHONPATH": str(tree)}
        proc = subprocess.Popen(
            cmd, cwd=tree, env={**os.environ, **env}, stdout=log, stderr=subprocess.STDOUT
        )
        try:
            with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=600) as client:
                wait_ready(client, 900.0)  # a tree extracted afresh compiles its kernels
                yield client
        finally:
            proc.terminate()
            try:
                proc.wait(timeout=60)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
