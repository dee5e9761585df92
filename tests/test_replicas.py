"""Several replicas on one PostgreSQL job store, with real parts: a throwaway PostgreSQL server,
real ``gearengine serve`` replicas and ``gearengine worker`` processes, each with its own data
directory (the database is the only state they share).

A replica killed with -9 mid-job, and a worker whose heartbeat stops while its chunk computes
(SIGSTOP), lose only their chunk's lease: another replica finishes the job with the numbers of
an uninterrupted run, and every chunk has exactly one stored result. A job is cancelled through
the replica that did not take it; 200 submissions at once across two replicas are all stored
once and all run.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import httpx
import pytest

from gearengine.studies.sweep import run_local, validated
from service.jobs.store import JobStore
from tests._polling import finished, poll
from tests._postgres import PostgresCluster
from tests.conftest import PAPER_PARAMS, Server
from tests.test_faults import CHUNK_POINTS, N_CHUNKS, SWEEP, kill9, poll_url, pool_workers

LEASE_SECONDS = 2


def env(database_url: str, **extra: str) -> dict[str, str]:
    """A replica's environment: the shared store, one HTTP process, one pool worker, short
    leases and 2-point chunks (as ``tests.test_faults``)."""
    return {
        "GEARCHAOS_DATABASE_URL": database_url,
        "GEARCHAOS_HTTP_PROCESSES": "1",
        "GEARCHAOS_WORKERS": "1",
        "GEARCHAOS_LEASE_SECONDS": str(LEASE_SECONDS),
        "GEARCHAOS_SWEEP_CHUNK_POINTS": str(CHUNK_POINTS),
        **extra,
    }


@pytest.fixture(scope="module")
def reference() -> dict[str, Any]:
    """The uninterrupted run, in this process."""
    return run_local(validated(SWEEP), chunk_points=CHUNK_POINTS).model_dump(mode="json")


@pytest.fixture
def store(database_url: str) -> Iterator[JobStore]:
    s = JobStore.open(database_url)
    yield s
    s.shutdown()


@pytest.fixture(scope="module")
def pair(
    tmp_path_factory: pytest.TempPathFactory, postgres: PostgresCluster
) -> Iterator[tuple[Server, Server, JobStore]]:
    """Two replicas on one fresh database, shared by the tests that kill nothing (each works
    on jobs of its own), and the store they share."""
    url = postgres.new_database()
    shared = JobStore.open(url)
    tmp = tmp_path_factory.mktemp("pair")
    with replicas(tmp, url, 2, GEARCHAOS_MAX_QUEUED_JOBS="1000") as (a, b):
        yield a, b, shared
    shared.shutdown()


@contextlib.contextmanager
def replicas(tmp_path: Path, database_url: str, n: int, **extra: str) -> Iterator[list[Server]]:
    """``n`` ``gearengine serve`` replicas on the store, each with its own data directory."""
    started: list[Server] = []
    try:
        for i in range(n):
            started.append(Server(tmp_path / f"replica-{i}", env(database_url, **extra)))
        yield started
    finally:
        for s in started:
            s.stop()


class Worker:
    """A ``gearengine worker`` process (a dispatcher and one pool worker) on the store."""

    def __init__(self, database_url: str) -> None:
        self.log = tempfile.NamedTemporaryFile("w+", prefix="gearchaos-worker-", suffix=".log")  # noqa: SIM115
        cmd = [sys.executable, "-m", "gearengine.cli", "worker", "--workers", "1"]
        cmd += ["--data-dir", tempfile.mkdtemp(prefix="gearchaos-worker-")]
        self.proc = subprocess.Popen(
            cmd, env={**os.environ, **env(database_url)}, stdout=self.log,
            stderr=subprocess.STDOUT, start_new_session=True,
        )  # fmt: skip

    def output(self) -> str:
        return Path(self.log.name).read_text()

    def stop(self) -> None:
        with contextlib.suppress(ProcessLookupError):
            os.kill(self.proc.pid, signal.SIGCONT)
        self.proc.terminate()
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        self.log.close()


def leases(store: JobStore, job_id: str) -> dict[int, int]:
    """Chunk index -> pid of the dispatcher holding its lease, for the job's leased chunks
    (lease owners are ``host:pid:random``)."""
    with store.db.reading() as db:
        rows = db.execute(
            "SELECT idx, lease_owner FROM chunks WHERE job_id = ? AND status = 'leased'",
            (job_id,),
        ).fetchall()
    return {r[0]: int(r[1].split(":")[-2]) for r in rows}


def committers(store: JobStore, job_id: str) -> dict[int, int]:
    """Chunk index -> pid of its committer; asserts that every chunk was committed once."""
    log = store.commit_log(job_id)
    assert sorted(idx for idx, _ in log) == list(range(N_CHUNKS)), log
    return {idx: int(owner.split(":")[-2]) for idx, owner in log}


def test_a_replica_killed_mid_job_loses_only_its_chunk(
    tmp_path: Path, database_url: str, store: JobStore, reference: dict[str, Any]
) -> None:
    with replicas(tmp_path, database_url, 2) as (a, b):
        job = httpx.post(a.url + "/v1/sweeps", json=SWEEP, timeout=30).json()
        poll(lambda: store.commit_log(job["id"]), lambda log: len(log) >= 2)
        interrupted = stopped_holding_leases(a, store, job["id"])
        children = pool_workers(a)
        os.kill(a.proc.pid, signal.SIGKILL)
        a.proc.wait()
        kill9(children)
        before = store.commit_log(job["id"])
        url = f"{b.url}/v1/sweeps/{job['id']}"
        assert poll_url(url, finished)["status"] == "succeeded"
        assert httpx.get(url + "/result", timeout=30).json() == reference
    by = committers(store, job["id"])
    assert store.commit_log(job["id"])[: len(before)] == before
    assert all(by[idx] == b.proc.pid for idx in interrupted)
    assert {by[idx] for idx, _ in before} <= {a.proc.pid, b.proc.pid}
    assert all(store.attempts(job["id"])[idx] == 2 for idx in interrupted)


def stopped_holding_leases(worker: Worker | Server, store: JobStore, job_id: str) -> list[int]:
    """SIGSTOP ``worker``'s dispatcher at a moment it holds chunk leases (chunks computing in
    its pool process); returns their indices. Read after the stop, so none of them can still be
    committed by it (a lease read before the stop may be committed before a kill lands)."""
    while True:
        poll(lambda: leases(store, job_id), lambda held: worker.proc.pid in held.values())
        os.kill(worker.proc.pid, signal.SIGSTOP)
        held = [i for i, pid in leases(store, job_id).items() if pid == worker.proc.pid]
        if held:
            return held
        os.kill(worker.proc.pid, signal.SIGCONT)  # it committed in between: try again


def test_a_worker_whose_heartbeat_stops_mid_chunk_loses_the_lease_and_cannot_commit(
    tmp_path: Path, database_url: str, store: JobStore, reference: dict[str, Any]
) -> None:
    """SIGSTOP freezes a worker's dispatcher (and so its heartbeats) while its pool process
    computes a chunk. The lease expires, another worker computes the chunk again and commits
    it; the frozen worker, resumed, finds its lease gone (or its connection ended, had it been
    frozen inside a transaction) and stores nothing."""
    with replicas(tmp_path, database_url, 1, GEARCHAOS_WORKERS="0") as (api,):
        job = httpx.post(api.url + "/v1/sweeps", json=SWEEP, timeout=30).json()
        frozen, other = Worker(database_url), None
        try:
            poll(lambda: store.commit_log(job["id"]), lambda log: len(log) >= 1)
            stalled = stopped_holding_leases(frozen, store, job["id"])[0]
            other = Worker(database_url)
            url = f"{api.url}/v1/sweeps/{job['id']}"
            assert poll_url(url, finished)["status"] == "succeeded"
            os.kill(frozen.proc.pid, signal.SIGCONT)
            acted = (f"chunk {stalled} not committed: lease lost", f"/{stalled} dropped",
                     "dispatcher step failed")  # fmt: skip
            poll(frozen.output, lambda text: any(line in text for line in acted))
            assert httpx.get(url + "/result", timeout=30).json() == reference
        finally:
            frozen.stop()
            if other is not None:
                other.stop()
    by = committers(store, job["id"])
    assert by[stalled] == other.proc.pid and store.attempts(job["id"])[stalled] == 2


def test_a_job_is_cancelled_through_the_replica_that_did_not_take_it(
    pair: tuple[Server, Server, JobStore],
) -> None:
    a, b, store = pair
    job = httpx.post(a.url + "/v1/sweeps", json=SWEEP, timeout=30).json()
    poll_url(f"{a.url}/v1/sweeps/{job['id']}", lambda j: j["progress"]["done"] >= 2)
    r = httpx.delete(f"{b.url}/v1/sweeps/{job['id']}", timeout=10)
    assert r.status_code == 200 and r.json()["status"] == "cancelled"
    commits = len(store.commit_log(job["id"]))
    poll(lambda: leases(store, job["id"]), lambda held: not held, timeout=30)
    seen = httpx.get(f"{a.url}/v1/sweeps/{job['id']}", timeout=10).json()
    assert seen["status"] == "cancelled" and seen["progress"]["done"] < seen["progress"]["total"]
    small = {**SWEEP, "settings": {"transient_periods": 10, "record_periods": 10}}
    nxt = httpx.post(b.url + "/v1/sweeps", json=small, timeout=10).json()
    assert poll_url(f"{a.url}/v1/sweeps/{nxt['id']}", finished)["status"] == "succeeded"
    assert len(store.commit_log(job["id"])) == commits


TINY = {
    "params": PAPER_PARAMS,
    "settings": {"transient_periods": 10, "record_periods": 10, "steps_per_period": 64},
    "axes": [{"parameter": "F_e1", "start": 0.15, "stop": 0.3, "num": CHUNK_POINTS}],
}
"""A one-chunk sweep."""


def test_200_submissions_at_once_across_two_replicas_are_each_stored_and_run_once(
    pair: tuple[Server, Server, JobStore],
) -> None:
    n, servers, store = 200, pair[:2], pair[2]
    with httpx.Client(timeout=60) as http, ThreadPoolExecutor(32) as pool:
        answers = list(
            pool.map(
                lambda i: http.post(
                    servers[i % 2].url + "/v1/sweeps", json={**TINY, "label": f"burst-{i}"}
                ),
                range(n),
            )
        )
    assert [r.status_code for r in answers] == [202] * n
    ids = [r.json()["id"] for r in answers]
    assert len(set(ids)) == n

    def listed(server: Server) -> dict[str, Any]:
        """The burst's jobs as the replica lists them (other tests' jobs left out)."""
        jobs: dict[str, Any] = {}
        offset: int | None = 0
        while offset is not None:
            page = httpx.get(
                f"{server.url}/v1/sweeps", params={"limit": 100, "offset": offset}, timeout=30
            ).json()
            jobs |= {j["id"]: j for j in page["items"] if (j["label"] or "").startswith("burst-")}
            offset = page["next_offset"]
        return jobs

    for server in servers:
        assert poll(
            lambda s=server: listed(s), lambda jobs: all(map(finished, jobs.values()))
        ).keys() == set(ids)
    jobs = listed(servers[0])
    assert {j["status"] for j in jobs.values()} == {"succeeded"}
    assert sorted(j["label"] for j in jobs.values()) == sorted(f"burst-{i}" for i in range(n))
    assert all([idx for idx, _ in store.commit_log(job_id)] == [0] for job_id in ids)
