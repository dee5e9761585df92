"""Bounded load test: a real `gearengine serve` on loopback, N concurrent httpx clients.

    .venv/bin/python benchmarks/load.py [--clients 50] [--seconds 60]     (make load)

Clients mix Melnikov verdicts (half of them repeated designs that hit the cache), short
analyses and small sweep submissions. The queue cap is set low so the run also shows that a full
queue answers 429 with Retry-After and accepts work again once it drains. Any 5xx or transport
error fails the run (exit 1). Results go to the "load" section of benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import random
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import httpx
import numpy as np
from report import write_section  # benchmarks/report.py (the script's own folder)

PARAMS = {
    "damping": 0.07,
    "mean_force": 0.01,
    "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]},
}
SHORT = {"transient_periods": 100, "record_periods": 100, "steps_per_period": 100}
QUEUE_CAP = 8


def design(rng: random.Random, fresh: bool) -> dict:
    fe = rng.uniform(0.0, 0.3) if fresh else rng.choice([0.1, 0.2, 0.25])
    return {**PARAMS, "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": fe}]}}


def request_for(op: str, rng: random.Random) -> tuple[str, dict]:
    if op == "melnikov":
        return "/v1/melnikov", {"params": design(rng, rng.random() < 0.5)}
    if op == "analysis":
        return "/v1/analyses", {"params": design(rng, True), "settings": SHORT}
    axis = {"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 16}
    return "/v1/sweeps", {"params": PARAMS, "settings": SHORT, "axes": [axis]}


async def client(
    http: httpx.AsyncClient, seed: int, deadline: float, log: dict[str, list], codes: dict
) -> None:
    rng = random.Random(seed)
    while time.monotonic() < deadline:
        op = rng.choices(["melnikov", "analysis", "sweep"], weights=[6, 3, 1])[0]
        path, body = request_for(op, rng)
        start = time.perf_counter()
        try:
            r = await http.post(path, json=body)
            codes[(op, r.status_code)] += 1
            if r.status_code == 429:
                assert "retry-after" in r.headers, "429 without Retry-After"
        except httpx.HTTPError as exc:
            codes[(op, type(exc).__name__)] += 1
            continue
        log[op].append(time.perf_counter() - start)


async def drain_and_retry(http: httpx.AsyncClient, timeout: float = 600.0) -> tuple[float, int]:
    """Wait until no sweep is queued or running, then submit one more: (seconds, status)."""
    start = time.monotonic()
    while time.monotonic() - start < timeout:
        busy = 0
        for status in ("queued", "running"):
            r = await http.get("/v1/sweeps", params={"status": status, "limit": 100})
            busy += len(r.json()["items"])
        if busy == 0:
            break
        await asyncio.sleep(1.0)
    path, body = request_for("sweep", random.Random(0))
    r = await http.post(path, json=body)
    return time.monotonic() - start, r.status_code


def percentile(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) * 1e3 if values else float("nan")


async def run(clients: int, seconds: float, url: str) -> tuple[str, bool]:
    log: dict[str, list] = defaultdict(list)
    codes: dict = defaultdict(int)
    limits = httpx.Limits(max_connections=clients, keepalive_expiry=2.0)
    async with httpx.AsyncClient(base_url=url, timeout=120.0, limits=limits) as http:
        deadline = time.monotonic() + seconds
        started = time.perf_counter()
        await asyncio.gather(*(client(http, i, deadline, log, codes) for i in range(clients)))
        wall = time.perf_counter() - started
        drained, retry = await drain_and_retry(http)
    rows = ["| operation | requests | p50 ms | p99 ms | per second |", "|---|---:|---:|---:|---:|"]
    for op, lat in sorted(log.items()):
        rows.append(
            f"| {op} | {len(lat)} | {percentile(lat, 50):.1f} | {percentile(lat, 99):.1f} "
            f"| {len(lat) / wall:.1f} |"
        )
    total = sum(len(v) for v in log.values())
    status = ", ".join(f"{op} {code}: {n}" for (op, code), n in sorted(codes.items(), key=str))
    bad = sum(n for (_, code), n in codes.items() if not isinstance(code, int) or code >= 500)
    full = sum(n for (op, code), n in codes.items() if code == 429)
    ok = bad == 0 and full > 0 and retry == 202
    table = "\n".join(rows)
    text = (
        f"{table}\n\nAll operations: {total} requests in {wall:.1f} s = {total / wall:.1f} "
        f"per second, {clients} concurrent clients.\n\n"
        f"Status codes: {status}.\n\n"
        f"Errors (5xx or transport): {bad}. Sweep submissions refused with 429 while the queue "
        f"(cap {QUEUE_CAP}) was full: {full}; after it drained ({drained:.0f} s) a new "
        f"submission got {retry}."
    )
    return text, ok


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=60.0)
    args = parser.parse_args()
    port = 18000 + os.getpid() % 1000
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "GEARCHAOS_MAX_QUEUED_JOBS": str(QUEUE_CAP)}
        cmd = [sys.executable, "-m", "gearengine.cli", "serve", "--port", str(port)]
        log = open(Path(tmp) / "server.log", "w")  # noqa: SIM115
        server = subprocess.Popen(
            [*cmd, "--data-dir", str(Path(tmp) / "data")], env=env, stdout=log, stderr=log
        )
        url = f"http://127.0.0.1:{port}"
        try:
            for _ in range(600):
                try:
                    if httpx.get(url + "/v1/ready", timeout=1.0).status_code == 200:
                        break
                except httpx.HTTPError:
                    pass
                time.sleep(0.2)
            text, ok = asyncio.run(run(args.clients, args.seconds, url))
        finally:
            server.terminate()
            server.wait(timeout=60)
            log.close()
    section = (
        "## Load\n\nReproduce: `make load` (`.venv/bin/python benchmarks/load.py --clients "
        f"{args.clients} --seconds {args.seconds:g}`) against a real `gearengine serve` on "
        f"loopback with its default workers.\n\n{text}\n"
    )
    print(section)
    write_section("load", section)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
