"""Load on one and on two API replicas sharing one PostgreSQL job store, on this machine.

    .venv/bin/python benchmarks/load_replicas.py [--clients 32] [--seconds 20]
        [--database-url postgresql://...]

Without ``--database-url`` a throwaway PostgreSQL cluster is started from Debian's binaries
(``tests/_postgres.py``; apt-get install postgresql). Each configuration gets a fresh database
and fresh ``gearengine serve`` replicas (one HTTP process each, no workers: submissions are
stored, not computed, so the numbers are the API's and the store's); the rows:

* ``sqlite, 1 replica``: the embedded store, for reference;
* ``postgres, 1 replica`` and ``postgres, 2 replicas``: client i talks to replica i mod n.

Two runs per configuration, with ``--clients`` keep-alive clients (``load.Connection``) for
``--seconds`` each: sweep submissions (``POST /v1/sweeps``, a 16-point sweep) and Melnikov
verdicts (``POST /v1/melnikov``, half repeated designs). After the submission run the store is
counted: every 202 must be one stored job (none lost, none twice). The replicas, PostgreSQL and
the load driver share the machine's cores (and other work may too: the load average is
printed). Results go to the "replicas" section of benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import os
import socket
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path

import httpx
from common import wait_ready  # benchmarks/common.py
from load import client, percentile  # benchmarks/load.py
from report import write_section  # benchmarks/report.py

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests._postgres import PostgresCluster, binaries  # noqa: E402 (the tests' throwaway server)

CONFIGS = (("sqlite, 1 replica", 1, False), ("postgres, 1 replica", 1, True),
           ("postgres, 2 replicas", 2, True))  # fmt: skip
"""The rows: (label, replicas, on PostgreSQL)."""
OPS = {"sweeps": "sweep", "melnikov": "melnikov"}
"""Mix of ``load.MIXES`` -> the operation it times."""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def replicas(n: int, database_url: str | None, tmp: Path) -> Iterator[list[str]]:
    """``n`` ``gearengine serve`` replicas (one HTTP process, no workers) on the store; yields
    their URLs once all are ready."""
    procs, urls = [], []
    tmp.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, "GEARCHAOS_WORKERS": "0", "GEARCHAOS_HTTP_PROCESSES": "1",
           "GEARCHAOS_MAX_QUEUED_JOBS": str(10**7), "PYTHONPATH": str(ROOT)}  # fmt: skip
    if database_url:
        env["GEARCHAOS_DATABASE_URL"] = database_url
    try:
        for _ in range(n):
            port = free_port()
            data = tmp / f"replica-{port}"
            cmd = [sys.executable, "-m", "gearengine.cli", "serve", "--port", str(port),
                   "--data-dir", str(data)]  # fmt: skip
            log = open(tmp / f"replica-{port}.log", "w")  # noqa: SIM115
            procs.append(subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=log, stderr=log))
            urls.append(f"http://127.0.0.1:{port}")
        for url in urls:
            with httpx.Client(base_url=url, timeout=30) as c:
                wait_ready(c, 300.0)
        yield urls
    finally:
        for p in procs:
            p.terminate()
        for p in procs:
            p.wait(timeout=60)


async def measure(urls: list[str], clients: int, seconds: float, mix: str) -> dict:
    """``clients`` clients of ``mix`` for ``seconds``, client i on replica i mod n."""
    log: dict[str, list] = defaultdict(list)
    codes: dict = defaultdict(int)
    deadline = time.monotonic() + seconds
    started = time.perf_counter()
    await asyncio.gather(
        *(client(urls[i % len(urls)], i, deadline, log, codes, mix) for i in range(clients))
    )
    wall = time.perf_counter() - started
    times = log[OPS[mix]]
    bad = sum(n for (_, code), n in codes.items() if not isinstance(code, int) or code >= 300)
    return {"rate": len(times) / wall, "p50": percentile(times, 50),
            "p99": percentile(times, 99), "n": len(times), "bad": bad,
            "accepted": codes.get(("sweep", 202), 0)}  # fmt: skip


def stored_jobs(url: str) -> int:
    return httpx.get(url + "/v1/sweeps", params={"limit": 1}, timeout=60).json()["total"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=32)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--database-url", default=None)
    parser.add_argument(
        "--only", type=lambda s: s.split(";"), default=None,
        help="run only these rows (;-separated labels); the README is not rewritten",
    )  # fmt: skip
    args = parser.parse_args()
    cluster = None
    if args.database_url is None:
        bin_dir = binaries() or sys.exit("no PostgreSQL binaries: apt-get install postgresql")
        cluster = PostgresCluster(bin_dir, free_port())
    rows: list[tuple[str, str, dict, int]] = []
    try:
        with tempfile.TemporaryDirectory(prefix="gearchaos-replicas-") as name:
            tmp = Path(name)
            for label, n, pg in CONFIGS:
                if args.only and label not in args.only:
                    continue
                url = None
                if pg:
                    url = cluster.new_database() if cluster else args.database_url
                with replicas(n, url, tmp / label.replace(", ", "-").replace(" ", "-")) as urls:
                    for mix in OPS:
                        r = asyncio.run(measure(urls, args.clients, args.seconds, mix))
                        stored = stored_jobs(urls[-1]) if mix == "sweeps" else -1
                        rows.append((label, mix, r, stored))
                        print(label, mix, r, stored, flush=True)
                        if mix == "sweeps" and stored != r["accepted"]:
                            sys.exit(f"{label}: {r['accepted']} accepted but {stored} stored")
    finally:
        if cluster is not None:
            cluster.stop()
    if not args.only:
        write_section("replicas", report(rows, args))


def report(rows: list[tuple[str, str, dict, int]], args: argparse.Namespace) -> str:
    table = [
        "| store, replicas | requests | per second | p50 ms | p99 ms | non-2xx or errors "
        "| stored jobs |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for label, mix, r, stored in rows:
        what = "sweep submissions" if mix == "sweeps" else "Melnikov verdicts"
        table.append(
            f"| {label} | {what} | {r['rate']:.0f} | {r['p50']:.1f} | {r['p99']:.1f} | "
            f"{r['bad']} | {stored if stored >= 0 else ''} |"
        )
    rate = {(label, mix): r["rate"] for label, mix, r, _ in rows}
    one, two = "postgres, 1 replica", "postgres, 2 replicas"
    ratios = ", ".join(f"{OPS[m]} {rate[(two, m)] / rate[(one, m)]:.2f}x" for m in OPS)
    return "\n\n".join(
        [
            "## Replicas on one PostgreSQL job store",
            f"Reproduce: `.venv/bin/python benchmarks/load_replicas.py --clients {args.clients} "
            f"--seconds {args.seconds:g}` (a throwaway PostgreSQL 15 cluster, fsync off, from "
            "Debian's binaries; each row a fresh database and fresh `gearengine serve` replicas "
            "with one HTTP process and no workers, so submissions are stored, not computed). "
            f"{args.clients} keep-alive clients, client i on replica i mod n. Stored jobs: the "
            "store's count after the submission run, equal to the 202s (none lost or doubled).",
            "\n".join(table),
            f"Two replicas over one: {ratios}. This machine has 2 cores, shared by both "
            "replicas, PostgreSQL and the load driver, and was shared with other work during "
            f"the run (load average after the runs {os.getloadavg()[0]:.1f}): a second replica "
            "here can only use the core the first left idle; on separate hosts each replica "
            "brings its own.",
        ]
    )


if __name__ == "__main__":
    main()
