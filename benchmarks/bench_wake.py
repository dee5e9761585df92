"""Submit -> claim latency across replicas on one PostgreSQL job store: dispatchers that poll
every 0.5 s against dispatchers woken by LISTEN/NOTIFY (``GEARCHAOS_DATABASE_LISTEN``).

    .venv/bin/python benchmarks/bench_wake.py [--jobs 30] [--seed 0]

A throwaway PostgreSQL cluster (``tests/_postgres.py``, Debian's binaries). For each setting a
fresh database, one ``gearengine worker`` process (one pool worker: the dispatcher of another
replica) and this process as the replica that takes the submissions (its own ``JobStore``, its
own connection pool; no dispatcher here, so only the other replica can claim). After a warm-up
job, ``--jobs`` one-point sweeps are submitted one at a time, each after the previous one
finished and a random pause of 0.2 to 0.9 s (seeded), so the claim never waits for a busy
worker: the latency is the time the other replica takes to notice. Latency = ``started_at -
created_at`` of each job, both stamped by the database's clock (``clock_timestamp()``) in the
submitting and the claiming transaction, so no two hosts' clocks are compared. Results go to the
"wake" section of benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from report import write_section  # benchmarks/report.py

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from gearengine.model.examples import PAPER_SECTION_41  # noqa: E402
from gearengine.studies import jobs  # noqa: E402
from service.jobs.store import JobStore  # noqa: E402
from tests._postgres import PostgresCluster, binaries  # noqa: E402
from tests.conftest import free_port  # noqa: E402

SWEEP = {
    "params": PAPER_SECTION_41,
    "settings": {"transient_periods": 20, "record_periods": 20, "steps_per_period": 64},
    "axes": [{"parameter": "F_e1", "start": 0.2, "stop": 0.2, "num": 1}],
}
"""A job that computes in milliseconds: the claim, not the work, is timed."""


def submit_and_wait(store: JobStore, request_json: str) -> str:
    job = store.submit(None, request_json, [1], 1, 64, kind="sweep")
    deadline = time.monotonic() + 120.0
    while (j := store.get(job.id, None)) is not None and j.status in ("queued", "running"):
        if time.monotonic() > deadline:
            raise TimeoutError(f"job {job.id} still {j.status}")
        time.sleep(0.02)
    return job.id


def latencies(url: str, listen: bool, n: int, seed: int, log: Path) -> np.ndarray:
    """Seconds from commit of the submission to the claim, for ``n`` jobs."""
    env = {**os.environ, "GEARCHAOS_DATABASE_LISTEN": "true" if listen else "false"}
    cmd = [sys.executable, "-m", "gearengine.cli", "worker", "--database-url", url,
           "--workers", "1"]  # fmt: skip
    store = JobStore.open(url)
    with open(log, "w") as out:
        worker = subprocess.Popen(cmd, env=env, stdout=out, stderr=subprocess.STDOUT, cwd=ROOT)
    try:
        request_json = jobs.kind("sweep").request.model_validate(SWEEP).model_dump_json()
        submit_and_wait(store, request_json)  # the worker's pool is up and its kernels loaded
        rng = random.Random(seed)
        ids = []
        for _ in range(n):
            time.sleep(rng.uniform(0.2, 0.9))
            ids.append(submit_and_wait(store, request_json))
        with store.db.reading() as db:
            rows = db.execute(
                "SELECT started_at - created_at FROM jobs WHERE id = ANY(?)", (ids,)
            ).fetchall()
        return np.array([float(r[0]) for r in rows])
    finally:
        worker.terminate()
        worker.wait(timeout=30)
        store.shutdown()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--jobs", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    bin_dir = binaries()
    if bin_dir is None:
        raise SystemExit("no PostgreSQL binaries: apt-get install postgresql")
    cluster = PostgresCluster(bin_dir, free_port())
    rows = []
    try:
        with tempfile.TemporaryDirectory() as tmp:
            for listen in (False, True):
                url = cluster.new_database()
                s = latencies(url, listen, args.jobs, args.seed, Path(tmp) / "worker.log")
                label = "LISTEN/NOTIFY" if listen else "polling every 0.5 s"
                rows.append((label, s))
                print(label, np.round(np.percentile(s, [50, 90, 100]) * 1e3, 1), flush=True)
    finally:
        cluster.stop()
    load = os.getloadavg()[0]
    table = "\n".join(
        f"| {label} | {s.size} | {np.median(s) * 1e3:.1f} | {np.percentile(s, 90) * 1e3:.1f} | "
        f"{s.max() * 1e3:.1f} | {s.mean() * 1e3:.1f} |"
        for label, s in rows
    )
    (_, off), (_, on) = rows
    write_section(
        "wake",
        f"""### Submit -> claim across replicas: polling against LISTEN/NOTIFY

Reproduce: `.venv/bin/python benchmarks/bench_wake.py --jobs {args.jobs} --seed {args.seed}`.
One replica takes the submissions (no dispatcher), a `gearengine worker` (one pool worker) on
the same PostgreSQL database claims them; one one-point sweep at a time, each after the
previous one finished and a random pause of 0.2-0.9 s. Latency: `started_at - created_at`, both
from the database's clock.

| dispatcher wakes by | jobs | median ms | p90 ms | max ms | mean ms |
|---|---|---|---|---|---|
{table}

Median {np.median(off) / np.median(on):.0f}x lower with LISTEN/NOTIFY in this run (load average
{load:.1f} on 2 cores, shared with other work).""",
    )


if __name__ == "__main__":
    main()
