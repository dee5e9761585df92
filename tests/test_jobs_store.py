"""The job store on each of its databases (SQLite, and PostgreSQL on a throwaway server):
ownership, the queue cap, leases, commits, retries, cancellation; the same tests for both."""

from __future__ import annotations

import json
import multiprocessing
import sqlite3
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import psycopg
import pytest

from service.jobs.store import DB_FILE, JobStore, QueueFullError
from tests._polling import poll

LEASE = 60.0


@pytest.fixture(params=["sqlite", "postgres"])
def location(request: pytest.FixtureRequest, tmp_path: Path) -> str:
    """Where the store is: the SQLite file of a data directory, or a fresh PostgreSQL
    database."""
    if request.param == "postgres":
        return request.getfixturevalue("database_url")
    return str(tmp_path / DB_FILE)


@pytest.fixture
def store(location: str) -> Iterator[JobStore]:
    s = JobStore.open(location)
    yield s
    s.shutdown()


def submit(store: JobStore, owner: str | None = None, chunks: int = 3, cap: int = 10) -> str:
    return store.submit(owner, '{"doc": 1}', [2] * chunks, 2, cap).id


def test_jobs_belong_to_their_owner(store: JobStore) -> None:
    a, b = submit(store, "alice"), submit(store, "bob")
    assert store.get(a, "alice") is not None and store.get(a, "bob") is None
    assert store.get(a, None) is None
    jobs, total = store.list("bob", None, 10, 0)
    assert total == 1 and [j.id for j in jobs] == [b]
    assert store.cancel(a, "bob") is None and store.get(a, "alice").status == "queued"


def test_listing_pages_newest_first_and_filters(store: JobStore) -> None:
    ids = [submit(store) for _ in range(5)]
    page, total = store.list(None, None, 2, 0)
    assert total == 5 and [j.id for j in page] == ids[::-1][:2]
    store.cancel(ids[0], None)
    page, total = store.list(None, "cancelled", 10, 0)
    assert total == 1 and page[0].id == ids[0] and page[0].finished_at is not None


def test_queue_cap_counts_unfinished_jobs(store: JobStore) -> None:
    first = submit(store, cap=2)
    submit(store, cap=2)
    with pytest.raises(QueueFullError):
        submit(store, cap=2)
    store.cancel(first, None)
    submit(store, cap=2)


def test_claim_commit_and_progress(store: JobStore) -> None:
    job = submit(store, chunks=3)
    claims = store.claim("w1", LEASE, 3, 2)
    assert [(c.job_id, c.index, c.attempt) for c in claims] == [(job, 0, 1), (job, 1, 1)]
    assert store.get(job, None).status == "running"
    assert [c.index for c in store.claim("w2", LEASE, 3, 5)] == [2]
    assert store.claim("w3", LEASE, 3, 5) == []
    assert not store.commit("w2", job, 0, "[1]")  # not w2's lease
    for idx, owner in ((0, "w1"), (2, "w2")):
        assert store.commit(owner, job, idx, f"[{idx}]")
    assert not store.commit("w1", job, 0, "[9]")  # already committed
    j = store.get(job, None)
    assert j.status == "running" and (j.progress.done, j.progress.total) == (4, 6)
    assert store.commit("w1", job, 1, "[1]")
    assert store.get(job, None).status == "succeeded"
    assert list(store.chunk_results(job)) == ["[0]", "[1]", "[2]"]
    assert store.commit_log(job) == [(0, "w1"), (2, "w2"), (1, "w1")]


def test_an_expired_lease_is_claimed_again_and_the_old_owner_cannot_commit(
    store: JobStore,
) -> None:
    job = submit(store, chunks=1)
    store.claim("dead", 0.05, 3, 1)
    time.sleep(0.1)
    (again,) = store.claim("alive", LEASE, 3, 1)
    assert again.attempt == 2
    assert store.heartbeat("dead", LEASE, [(job, 0)]) == set()
    assert not store.commit("dead", job, 0, "[]")
    assert store.commit("alive", job, 0, "[]")
    assert store.commit_log(job) == [(0, "alive")]


def test_retries_are_bounded_then_the_job_fails_with_the_reason(store: JobStore) -> None:
    job = submit(store, chunks=2)
    for attempt in (1, 2, 3):
        c = store.claim("w", LEASE, 2, 1)[0]
        assert (c.index, c.attempt) == (0, attempt)
        store.fail("w", job, 0, "BrokenProcessPool: worker died", True, 2)
    j = store.get(job, None)
    assert j.status == "failed"
    assert j.error == "chunk 0 failed after 3 attempt(s): BrokenProcessPool: worker died"
    assert store.claim("w", LEASE, 2, 5) == []


def test_a_deterministic_error_fails_at_once(store: JobStore) -> None:
    job = submit(store, chunks=1)
    store.claim("w", LEASE, 3, 1)
    store.fail("w", job, 0, "steps_per_period: over the cap", False, 3)
    assert store.get(job, None).error.endswith("steps_per_period: over the cap")


def test_leases_lost_too_often_fail_the_job(store: JobStore) -> None:
    job = submit(store, chunks=1)
    for _ in range(2):
        store.claim("w", 0.01, 1, 1)
        time.sleep(0.03)
    assert store.claim("w", 0.01, 1, 1) == []
    assert "lease expired" in store.get(job, None).error


def test_cancel_stops_claims_and_heartbeats(store: JobStore) -> None:
    job = submit(store, chunks=3)
    store.claim("w", LEASE, 3, 1)
    assert store.cancel(job, None).status == "cancelled"
    assert store.heartbeat("w", LEASE, [(job, 0)]) == set()
    assert store.claim("w", LEASE, 3, 5) == []
    assert not store.commit("w", job, 0, "[]")


def test_release_gives_chunks_back_without_counting_the_attempt(store: JobStore) -> None:
    job = submit(store, chunks=1)
    store.claim("w", LEASE, 3, 1)
    store.release("w", [(job, 0)])
    (c,) = store.claim("v", LEASE, 3, 1)
    assert c.attempt == 1 and store.attempts(job) == [1]


def _claim_all(
    location: str, owner: str, out: multiprocessing.Queue, total: Any, chunks: int
) -> None:
    """Claim one chunk at a time until the dispatchers together hold ``chunks`` claims.

    An empty claim does not mean the queue is empty: PostgreSQL's claim skips a job row that
    another claimer holds locked for a moment (``FOR UPDATE OF c, j SKIP LOCKED``), and a
    dispatcher then simply polls again; so each process stops on the shared count, or after
    60 s, and the test then checks that no chunk was claimed twice or left out."""
    store = JobStore.open(location)
    got = []
    deadline = time.monotonic() + 60.0
    while total.value < chunks and time.monotonic() < deadline:
        claims = store.claim(owner, LEASE, 3, 1)
        with total.get_lock():
            total.value += len(claims)
        got += [c.key for c in claims]
        if not claims:
            time.sleep(0.01)
    out.put(got)
    store.shutdown()


def test_concurrent_dispatchers_never_claim_a_chunk_twice(store: JobStore, location: str) -> None:
    job = submit(store, chunks=60, cap=10)
    ctx = multiprocessing.get_context("spawn")
    out, total = ctx.Queue(), ctx.Value("i", 0)
    procs = [
        ctx.Process(target=_claim_all, args=(location, f"p{i}", out, total, 60)) for i in range(4)
    ]
    for p in procs:
        p.start()
    claimed = [key for _ in procs for key in out.get(timeout=90)]
    for p in procs:
        p.join()
    assert sorted(claimed) == [(job, i) for i in range(60)]


def test_every_job_transition_is_one_structured_log_line(
    store: JobStore, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level("INFO", logger="gearchaos.jobs")
    job = submit(store, owner="key-a1b2", chunks=1)
    (claim,) = store.claim("w1", LEASE, 3, 5)
    assert store.commit("w1", job, claim.index, "[]")
    lines = [json.loads(r.message) for r in caplog.records if r.message.startswith("{")]
    assert [(e["job_id"], e["key_id"], e["status"]) for e in lines] == [
        (job, "key-a1b2", "queued"),
        (job, "key-a1b2", "running"),
        (job, "key-a1b2", "succeeded"),
    ]
    assert lines[-1]["run_s"] >= 0.0 and lines[1]["queued_s"] >= 0.0
    other = submit(store)
    store.cancel(other, None)
    assert json.loads(caplog.records[-1].message)["status"] == "cancelled"


def test_a_locked_database_makes_writers_wait_not_fail(tmp_path: Path) -> None:
    """Another process holding the write lock (concurrent writer): the submit waits for it."""
    store = JobStore.in_dir(tmp_path)
    submit(store)
    holder = sqlite3.connect(
        tmp_path / "jobs.sqlite3", isolation_level=None, check_same_thread=False
    )
    holder.execute("BEGIN EXCLUSIVE")
    release = threading.Timer(1.0, lambda: holder.execute("COMMIT"))
    release.start()
    start = time.monotonic()
    job = submit(JobStore.in_dir(tmp_path))
    waited = time.monotonic() - start
    release.join()
    holder.close()
    assert waited >= 0.9 and store.get(job, None).status == "queued"


def test_a_store_from_before_job_kinds_gains_the_kind_column(tmp_path: Path) -> None:
    """An existing jobs.sqlite3 without ``kind``: opened, every old job is a sweep and is
    claimed as one; jobs of another kind are told apart by every read."""
    old = sqlite3.connect(tmp_path / "jobs.sqlite3")
    old.executescript(
        "CREATE TABLE jobs (id TEXT PRIMARY KEY, owner TEXT, status TEXT NOT NULL, "
        "request_json TEXT NOT NULL, chunk_points INTEGER NOT NULL, total_chunks INTEGER NOT "
        "NULL, total_points INTEGER NOT NULL, created_at REAL NOT NULL, started_at REAL, "
        "finished_at REAL, error TEXT);"
        "INSERT INTO jobs VALUES ('old', NULL, 'queued', '{}', 2, 1, 2, 1.0, NULL, NULL, NULL);"
    )
    old.close()
    store = JobStore.in_dir(tmp_path)
    with store.db.transaction() as db:
        db.execute(
            "INSERT INTO chunks (job_id, idx, n_points, status) VALUES ('old', 0, 2, 'pending')"
        )
    other = store.submit(None, '{"doc": 2}', [1], 1, 10, kind="robustness").id
    assert (
        store.get("old", None, "sweep") is not None and store.get("old", None, "robustness") is None
    )
    assert store.get(other, None, "sweep") is None and store.get(other, None).id == other
    assert [j.id for j in store.list(None, None, 10, 0, "robustness")[0]] == [other]
    assert store.cancel(other, None, "sweep") is None and store.get(other, None).status == "queued"
    assert [(c.job_id, c.kind) for c in store.claim("w", LEASE, 3, 5)] == [
        ("old", "sweep"),
        (other, "robustness"),
    ]


def _open_and_report(location: str, out: multiprocessing.Queue) -> None:
    store = JobStore.open(location)
    with store.db.reading() as db:
        out.put(sorted(r[0] for r in db.execute("SELECT version FROM schema_migrations")))
    store.shutdown()


def test_migrations_are_versioned_and_applied_once_by_stores_opened_together(
    location: str,
) -> None:
    """Four processes open a new store at the same moment (replicas starting together): each
    sees every version recorded once, and none fails on a half-made schema."""
    ctx = multiprocessing.get_context("spawn")
    out = ctx.Queue()
    procs = [ctx.Process(target=_open_and_report, args=(location, out)) for _ in range(4)]
    for p in procs:
        p.start()
    seen = [out.get(timeout=60) for _ in procs]
    for p in procs:
        p.join()
    store = JobStore.open(location)
    expected = sorted(m.version for m in store.db.migrations)
    assert seen == [expected] * 4
    assert store.list(None, None, 1, 0) == ([], 0)
    store.shutdown()


def _commit_together(store: JobStore, commits: list[tuple[str, str, int]]) -> list[bool]:
    """Run ``store.commit(owner, job, idx, ...)`` for each entry in its own thread, released at
    the same instant; returns whether each was committed."""
    start, done = threading.Barrier(len(commits)), [False] * len(commits)

    def one(i: int, owner: str, job: str, idx: int) -> None:
        start.wait()
        done[i] = store.commit(owner, job, idx, f"[{idx}]")

    threads = [threading.Thread(target=one, args=(i, *c)) for i, c in enumerate(commits)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return done


def test_the_last_two_chunks_committed_at_once_finish_the_job(store: JobStore) -> None:
    """Two dispatchers commit a job's last two chunks in the same instant: whichever commits
    second sees the other's chunk done and finishes the job (every time)."""
    jobs = [submit(store, chunks=2, cap=100) for _ in range(15)]
    for job in jobs:
        claims = store.claim("a", LEASE, 3, 1) + store.claim("b", LEASE, 3, 1)
        assert [c.job_id for c in claims] == [job, job]
        assert _commit_together(store, [("a", job, 0), ("b", job, 1)]) == [True, True]
    assert {store.get(job, None).status for job in jobs} == {"succeeded"}


def test_the_queue_cap_holds_under_concurrent_submissions(store: JobStore) -> None:
    results: list[str] = []

    def one() -> None:
        try:
            results.append(submit(store, cap=5))
        except QueueFullError:
            results.append("full")

    threads = [threading.Thread(target=one) for _ in range(12)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results.count("full") == 7 and store.list(None, None, 100, 0)[1] == 5


def test_a_postgres_store_cut_off_is_not_ready_and_recovers(database_url: str) -> None:
    """The database refuses connections and drops the pool's: the readiness check says so
    (within its timeout, not the pool's 30 s) and answers again once connections are back."""
    store = JobStore.open(database_url)
    name = database_url.rsplit("/", 1)[1]
    admin = psycopg.connect(database_url.rsplit("/", 1)[0] + "/postgres", autocommit=True)

    def allow(yes: bool) -> None:
        admin.execute(f"ALTER DATABASE {name} ALLOW_CONNECTIONS {str(yes).lower()}")

    try:
        assert store.ping()
        allow(False)
        admin.execute(
            "SELECT pg_terminate_backend(pid) FROM pg_stat_activity WHERE datname = %s", (name,)
        )
        assert not store.ping()
        allow(True)
        assert poll(store.ping, bool, timeout=30)
        assert submit(store) and store.ping()
    finally:
        allow(True)
        admin.close()
        store.shutdown()


def test_a_submission_on_one_replica_notifies_the_others_listeners(database_url: str) -> None:
    """PostgreSQL LISTEN/NOTIFY: a store listening is woken by a submission committed through
    another store (another replica's pool), and by chunks released; not by a submission
    rolled back (queue full), and never when listening is off."""
    a, b = JobStore.open(database_url), JobStore.open(database_url)
    deaf = JobStore.open(database_url, listening=False)
    woken, deaf_woken = threading.Event(), threading.Event()
    stop, stop_deaf = b.listen(woken.set), deaf.listen(deaf_woken.set)
    try:
        poll(woken.is_set, bool, timeout=30.0)  # connected: one wake for what came before
        woken.clear()
        job = submit(a, cap=1)
        poll(woken.is_set, bool, timeout=30.0)
        woken.clear()
        with pytest.raises(QueueFullError):
            submit(a, cap=1)
        (claim,) = b.claim("b:1:x", LEASE, 3, 1)
        b.release("b:1:x", [claim.key])
        poll(woken.is_set, bool, timeout=30.0)
        assert b.claim("b:1:y", LEASE, 3, 1)[0].key == (job, 0)
        assert not deaf_woken.is_set()
    finally:
        stop()
        stop_deaf()
        for s in (a, b, deaf):
            s.shutdown()


def test_a_dispatcher_that_never_polls_claims_another_replicas_submission(
    database_url: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With polling off (IDLE_POLL an hour, leases of an hour), only the notification can
    wake the dispatcher after its first look at the empty store: the job submitted through
    another store is claimed all the same."""
    from service.jobs import dispatcher as dispatching
    from service.jobs.backends import LocalPool

    monkeypatch.setattr(dispatching, "IDLE_POLL", 3600.0)
    here, there = JobStore.open(database_url), JobStore.open(database_url)
    pool = LocalPool(1)
    poll(pool.capacity, bool, timeout=300)  # its worker has started: it can take a chunk
    d = dispatching.Dispatcher(there, pool, lease_seconds=3 * 3600.0)
    d.start()
    try:
        time.sleep(0.5)  # the dispatcher's first round has found nothing; now it waits
        job = submit(here, chunks=1)
        claimed = poll(lambda: here.get(job, None), lambda j: j.status != "queued", timeout=60)
        assert claimed.status in ("running", "failed")  # '{"doc": 1}' is no sweep: it fails
    finally:
        d.stop(grace=0.0)
        here.shutdown()
