"""Bounded load test: a real `gearengine serve` on loopback, N concurrent keep-alive clients.

    .venv/bin/python benchmarks/load.py [--clients 50] [--seconds 60] [--mixes mixed,melnikov]
        [--baseline REV]     (make load)

Each mix runs against a fresh server from the source of commit REV (``git archive``, the
previous implementation) and then from the working tree, in one run.

Clients mix Melnikov verdicts (half of them repeated designs that hit the cache), short
analyses and small sweep submissions. The queue cap is set low so the run also shows that a full
queue answers 429 with Retry-After and accepts work again once it drains. Any 5xx or transport
error fails the run (exit 1). Results go to the "load" section of benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import random
import resource
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
ROOT = Path(__file__).resolve().parents[1]
BASELINE = "2216844"
"""The implementation before issue 13 (the issue's "today"), served for comparison."""


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


MIXES = {"mixed": [6, 3, 1], "melnikov": [1, 0, 0], "sweeps": [0, 0, 1]}
"""Weights of (melnikov, analysis, sweep) per mix: mixed, Melnikov verdicts only, or sweep
submissions only (benchmarks/load_replicas.py)."""


class Connection:
    """One keep-alive HTTP/1.1 connection on asyncio streams, what each client drives.

    httpx costs the driver about as much CPU per request as the server spends answering it, and
    driver and server share this machine's two cores; this bare client costs a fraction of that,
    so the numbers say more about the server. Responses must carry Content-Length (the API's do).
    """

    def __init__(self, host: str, port: int) -> None:
        self.host, self.port = host, port
        self.reader: asyncio.StreamReader | None = None
        self.writer: asyncio.StreamWriter | None = None

    async def post(self, path: str, body: bytes) -> tuple[int, dict[bytes, bytes]]:
        """(status, lower-cased headers) of a POST; raises OSError or asyncio errors."""
        if self.writer is None:
            self.reader, self.writer = await asyncio.open_connection(self.host, self.port)
        assert self.reader is not None
        head = (
            f"POST {path} HTTP/1.1\r\nHost: {self.host}:{self.port}\r\n"
            f"Content-Type: application/json\r\nContent-Length: {len(body)}\r\n\r\n"
        )
        self.writer.write(head.encode() + body)
        lines = (await self.reader.readuntil(b"\r\n\r\n")).split(b"\r\n")
        headers = {}
        for line in lines[1:]:
            if b":" in line:
                key, value = line.split(b":", 1)
                headers[key.strip().lower()] = value.strip()
        if b"content-length" not in headers:
            raise ConnectionError("response without Content-Length")
        await self.reader.readexactly(int(headers[b"content-length"]))
        if headers.get(b"connection", b"").lower() == b"close":
            self.close()
        return int(lines[0].split()[1]), headers

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()
        self.reader = self.writer = None


async def client(
    url: str,
    seed: int,
    deadline: float,
    log: dict[str, list],
    codes: dict,
    mix: str = "mixed",
) -> None:
    rng = random.Random(seed)
    host, port = url.removeprefix("http://").rsplit(":", 1)
    conn = Connection(host, int(port))
    try:
        while time.monotonic() < deadline:
            op = rng.choices(["melnikov", "analysis", "sweep"], weights=MIXES[mix])[0]
            path, body = request_for(op, rng)
            start = time.perf_counter()
            try:
                status, headers = await asyncio.wait_for(
                    conn.post(path, json.dumps(body).encode()), 120.0
                )
                codes[(op, status)] += 1
                if status == 429:
                    assert b"retry-after" in headers, "429 without Retry-After"
            except (TimeoutError, OSError, asyncio.IncompleteReadError) as exc:
                codes[(op, type(exc).__name__)] += 1
                conn.close()
                continue
            log[op].append(time.perf_counter() - start)
    finally:
        conn.close()


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


def cpu_seconds(pid: int) -> float:
    """User + system CPU seconds of a process and its children (Linux /proc; 0 elsewhere)."""
    found = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True)
    total = 0.0
    for p in [pid, *(int(w) for w in found.stdout.split())]:
        try:
            fields = Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    return total


def own_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


async def run(clients: int, seconds: float, url: str, mix: str, pid: int) -> dict:
    """One load run of ``mix`` against the server at ``url`` (process ``pid``): its numbers."""
    log: dict[str, list] = defaultdict(list)
    codes: dict = defaultdict(int)
    limits = httpx.Limits(max_connections=clients, keepalive_expiry=2.0)
    async with httpx.AsyncClient(base_url=url, timeout=120.0, limits=limits) as http:
        deadline = time.monotonic() + seconds
        cpu0, own0, started = cpu_seconds(pid), own_cpu(), time.perf_counter()
        await asyncio.gather(*(client(url, i, deadline, log, codes, mix) for i in range(clients)))
        wall = time.perf_counter() - started
        server_cpu, driver_cpu = (cpu_seconds(pid) - cpu0) / wall, (own_cpu() - own0) / wall
        drained, retry = await drain_and_retry(http) if MIXES[mix][2] else (0.0, None)
    bad = sum(n for (_, code), n in codes.items() if not isinstance(code, int) or code >= 500)
    full = sum(n for (op, code), n in codes.items() if code == 429)
    return {
        "mix": mix,
        "wall": wall,
        "log": dict(log),
        "codes": dict(codes),
        "bad": bad,
        "full": full,
        "drained": drained,
        "retry": retry,
        "server_cpu": server_cpu,
        "driver_cpu": driver_cpu,
        "ok": bad == 0 and (retry is None or (full > 0 and retry == 202)),
    }


def details(label: str, r: dict, clients: int) -> str:
    """The per-operation table and status codes of one run."""
    rows = ["| operation | requests | p50 ms | p99 ms | per second |", "|---|---:|---:|---:|---:|"]
    for op, lat in sorted(r["log"].items()):
        rows.append(
            f"| {op} | {len(lat)} | {percentile(lat, 50):.1f} | {percentile(lat, 99):.1f} "
            f"| {len(lat) / r['wall']:.1f} |"
        )
    total = sum(len(v) for v in r["log"].values())
    status = ", ".join(f"{op} {code}: {n}" for (op, code), n in sorted(r["codes"].items(), key=str))
    text = (
        f"### {label}, {r['mix']}\n\n" + "\n".join(rows) + f"\n\nAll operations: {total} requests "
        f"in {r['wall']:.1f} s = {total / r['wall']:.1f} per second, {clients} concurrent "
        f"clients. Status codes: {status}. Errors (5xx or transport): {r['bad']}."
    )
    if r["retry"] is not None:
        text += (
            f" Sweep submissions refused with 429 while the queue (cap {QUEUE_CAP}) was full: "
            f"{r['full']}; after it drained ({r['drained']:.0f} s) a new submission got "
            f"{r['retry']}."
        )
    return text


def summary_row(label: str, r: dict) -> str:
    total = sum(len(v) for v in r["log"].values())
    mel = r["log"].get("melnikov", [])
    return (
        f"| {label} | {r['mix']} | {total / r['wall']:.0f} | {len(mel) / r['wall']:.0f} "
        f"| {percentile(mel, 50):.1f} | {percentile(mel, 99):.1f} | {r['bad']} "
        f"| {r['server_cpu']:.2f} | {r['driver_cpu']:.2f} |"
    )


def targets(results: list[tuple[str, dict]]) -> str:
    """The issue's load targets on the working tree's default server, judged against the
    previous implementation run in the same process with the same driver."""
    now = [r for label, r in results if label == "now"]
    mel = [r for r in now if r["mix"] == "melnikov"]
    old = [r for label, r in results if not label.startswith("now") and r["mix"] == "melnikov"]
    if not mel or not old:
        return "Targets (issue 13): not judged (run both mixes, with the baseline)."
    rate, p99 = (
        len(mel[0]["log"]["melnikov"]) / mel[0]["wall"],
        percentile(mel[0]["log"]["melnikov"], 99),
    )
    old_rate = len(old[0]["log"]["melnikov"]) / old[0]["wall"]
    errors = sum(x["bad"] for x in now)
    met = rate >= 4 * old_rate and p99 < 250.0 and errors == 0
    return (
        f"Targets (issue 13): 0 errors and 0 5xx in every run of the working tree (measured "
        f"{errors}); Melnikov-only throughput at least 4 x that of the previous implementation "
        f"in this run, 4 x {old_rate:.0f} = {4 * old_rate:.0f} requests/s (measured {rate:.0f}, "
        f"{rate / old_rate:.1f}x); p99 below 250 ms (measured {p99:.0f} ms): "
        f"{'met' if met else 'NOT met'}."
    )


def serve_and_run(
    tree: Path, tmp: Path, args: argparse.Namespace, mix: str, extra: list[str]
) -> dict:
    """Start ``gearengine serve`` from the source tree ``tree`` on a free loopback port, run
    one load run of ``mix`` against it, stop it."""
    port = 18000 + (os.getpid() + 7 * len(list(tmp.iterdir()))) % 1000
    data = tmp / f"data-{port}-{mix}"
    env = {
        **os.environ,
        "GEARCHAOS_MAX_QUEUED_JOBS": str(QUEUE_CAP),
        "PYTHONPATH": str(tree),
    }
    cmd = [sys.executable, "-m", "gearengine.cli", "serve", "--port", str(port), *extra]
    with open(tmp / f"server-{port}.log", "w") as log:
        server = subprocess.Popen(
            [*cmd, "--data-dir", str(data)], env=env, cwd=tree, stdout=log, stderr=log
        )
        url = f"http://127.0.0.1:{port}"
        try:
            for _ in range(1500):  # bounded: a fresh tree compiles its kernels first
                if server.poll() is not None:
                    tail = (tmp / f"server-{port}.log").read_text()[-2000:]
                    raise RuntimeError(f"server from {tree} exited:\n{tail}")
                try:
                    if httpx.get(url + "/v1/ready", timeout=1.0).status_code == 200:
                        break
                except httpx.HTTPError:
                    pass
                time.sleep(0.2)
            return asyncio.run(run(args.clients, args.seconds, url, mix, server.pid))
        finally:
            server.terminate()
            server.wait(timeout=60)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument(
        "--mixes", default="mixed,melnikov", help="comma-separated: " + ", ".join(MIXES)
    )
    parser.add_argument(
        "--baseline",
        default=BASELINE,
        help="git revision to run first, for comparison ('' for none)",
    )
    parser.add_argument(
        "--processes",
        default="default,1",
        help="HTTP processes of the working tree's server, one run each ('default': no flag)",
    )
    args = parser.parse_args()
    mixes = args.mixes.split(",")
    results: list[tuple[str, dict]] = []
    with tempfile.TemporaryDirectory(prefix="gearchaos-load-") as name:
        tmp = Path(name)
        trees = [
            ("now", ROOT, [])
            if n == "default"
            else (f"now, --http-processes {n}", ROOT, ["--http-processes", n])
            for n in args.processes.split(",")
        ]
        if args.baseline:
            old = tmp / "baseline"
            old.mkdir()
            archive = subprocess.run(
                ["git", "archive", args.baseline, "gearengine", "service"],
                cwd=ROOT,
                capture_output=True,
                check=True,
            )
            subprocess.run(["tar", "-x", "-C", str(old)], input=archive.stdout, check=True)
            for name in ("httptools", "uvloop"):  # its dependencies: uvicorn falls back to h11
                (old / f"{name}.py").write_text(f"raise ImportError('{name}: not a dependency')\n")
            trees.insert(0, (args.baseline, old, []))
        for label, tree, extra in trees:
            for mix in mixes:
                results.append((label, serve_and_run(tree, tmp, args, mix, extra)))
                print(summary_row(*results[-1]), flush=True)
    head = (
        "| server | mix | requests/s | Melnikov/s | Melnikov p50 ms | Melnikov p99 ms | errors "
        "| server CPU, cores | driver CPU, cores |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|---:|"
    )
    section = "\n\n".join(
        [
            "## Load",
            "Reproduce: `make load` (`.venv/bin/python benchmarks/load.py --clients "
            f"{args.clients} --seconds {args.seconds:g}`): a real `gearengine serve` with its "
            "defaults on loopback, started afresh for each run, first from the source of "
            f"commit {args.baseline or '(none)'} (`git archive`, the previous implementation, "
            "with its dependencies: uvicorn on the pure-Python h11 parser and the asyncio loop, "
            "as httptools and uvloop are hidden from it), then from the working tree (httptools, "
            "uvloop; by default one HTTP process per core, also run with `--http-processes 1`), "
            "in one run. Mixes: `mixed` (Melnikov verdicts, half of "
            "them repeated designs that hit the cache; short analyses; small sweep "
            "submissions, 6 : 3 : 1) and `melnikov` (verdicts only, the same designs). CPU is "
            "measured from /proc over the run: the server with its child processes, and the "
            "load driver (one process, bare asyncio HTTP/1.1 keep-alive connections, one per "
            "client: `Connection`; httpx cost as much CPU per request as the server) on the "
            "same 2-core machine, which other work may share: the load average is printed.",
            head + "\n" + "\n".join(summary_row(label, r) for label, r in results),
            targets(results) + f" Load average after the runs: {os.getloadavg()[0]:.1f}.",
            *(details(label, r, args.clients) for label, r in results),
        ]
    )
    print(section)
    write_section("load", section)
    sys.exit(0 if all(r["ok"] for _, r in results) else 1)


if __name__ == "__main__":
    main()
