"""The durable job store: jobs and the results of finished chunks, in SQLite or PostgreSQL.

Tables: ``jobs`` (one row per job, of any kind of ``gearengine.studies.jobs.KINDS``: its ``kind``
column names it), ``chunks`` (one row per chunk: status pending | leased | done | failed |
cancelled, lease owner and expiry, attempts, result) and ``commits`` (an append-only log of
chunk commits, for audits and the fault tests). A chunk's result JSON is stored
zlib-compressed (``pack``/``unpack``), read back one chunk at a time.

The logic is written once here; ``service.jobs.sqlite`` (the embedded default, a file in the
data directory) and ``service.jobs.postgres`` (``GEARCHAOS_DATABASE_URL``, shared by replicas on
many hosts) supply connections, row locks, the clock and the versioned schema
(``service.jobs.database``). Every state change is one transaction. A chunk is leased for
``lease_seconds`` and the lease is renewed by heartbeats; a chunk whose lease expired is claimed
again (its attempt counts). A result is committed only while the committer still holds the
lease (fencing by holder), so no chunk is committed twice. Times are POSIX seconds of the
database's clock.
"""

from __future__ import annotations

import functools
import json
import logging
import time
import uuid
import zlib
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ParamSpec, TypeVar

from service.core.config import Settings
from service.jobs.database import Database, Tx, migrate
from service.jobs.models import Job, JobAxis, JobStatus, Progress, utc
from service.jobs.sqlite import SqliteDatabase

P = ParamSpec("P")
T = TypeVar("T")

log = logging.getLogger("gearchaos.jobs")

DB_FILE = "jobs.sqlite3"
"""Name of the store in the data directory."""
COMPRESS_LEVEL = 1
"""zlib level of stored chunk results (JSON of verdicts shrinks about 5 times). On the 100 x 100
chaos map's 4.0 MB JSON: level 1 21 ms and 862 kB, level 6 93 ms and 775 kB; a served map
stores about 16.5 MB of chunk results, so level 6 cost about 0.3 s of CPU a map on the cores
that compute it (issue 31, wt-map3) for 10 % less storage."""


def pack(result_json: str) -> bytes:
    """A chunk's result JSON as stored: zlib-compressed UTF-8."""
    return zlib.compress(result_json.encode(), COMPRESS_LEVEL)


def unpack(stored: bytes | str) -> str:
    """A stored chunk result as JSON text (rows written before compression are text)."""
    return stored if isinstance(stored, str) else zlib.decompress(stored).decode()


class QueueFullError(Exception):
    """The number of unfinished jobs reached the cap."""


@dataclass(frozen=True)
class Claim:
    """A leased chunk: what a worker needs to compute it."""

    job_id: str
    index: int
    request_json: str
    chunk_points: int
    attempt: int
    kind: str
    """The job's kind (``gearengine.studies.jobs.KINDS``): what computes the chunk."""

    @property
    def key(self) -> tuple[str, int]:
        return (self.job_id, self.index)


PING_SECONDS = 2.0
"""Longest wait of the readiness check for a pooled connection (PostgreSQL down: not ready)."""
RETRIES = 5
"""Runs of a transaction that the database aborted to break a deadlock (``Database.retryable``)."""


def retried(method: Callable[P, T]) -> Callable[P, T]:
    """Run a store method (one transaction) again when the database aborted it to break a
    deadlock or a serialization conflict; it changed nothing then."""

    @functools.wraps(method)
    def run(*args: P.args, **kwargs: P.kwargs) -> T:
        store = args[0]
        assert isinstance(store, JobStore)
        for attempt in range(RETRIES):
            try:
                return method(*args, **kwargs)
            except store.db.retryable:
                if attempt == RETRIES - 1:
                    raise
                time.sleep(0.01 * (attempt + 1))
        raise AssertionError("unreachable")

    return run


class JobStore:
    """The job queue's state in one database (``service.jobs.database.Database``)."""

    def __init__(self, db: Database, listening: bool = True) -> None:
        self.db = db
        self.listening = listening
        migrate(db)

    @classmethod
    def open(cls, location: str | Path, pool_size: int = 8, listening: bool = True) -> JobStore:
        """The store at ``location``: a ``postgresql://`` URL (``pool_size`` connections at
        most; ``listening``: dispatchers woken by notifications, ``listen``), else a SQLite
        file path."""
        if str(location).startswith(("postgresql://", "postgres://")):
            from service.jobs.postgres import PostgresDatabase

            return cls(PostgresDatabase(str(location), pool_size), listening)
        return cls(SqliteDatabase(Path(location)))

    @classmethod
    def in_dir(cls, data_dir: Path) -> JobStore:
        """The SQLite store of a data directory."""
        return cls.open(Path(data_dir) / DB_FILE)

    @classmethod
    def configured(cls, settings: Settings) -> JobStore:
        """The store the settings name: ``database_url`` when set, else the data directory's."""
        if settings.database_url:
            return cls.open(
                settings.database_url, settings.database_pool_size, settings.database_listen
            )
        return cls.in_dir(Path(settings.data_dir))

    @contextmanager
    def _tx(self) -> Iterator[Tx]:
        """One write transaction; the job transitions it made (recorded by triggers in
        ``job_events``) are logged once it has committed."""
        with self.db.transaction() as db:
            yield db
            events = db.execute("DELETE FROM job_events RETURNING *").fetchall()
        for event in events:
            log_transition(event)

    def _lock_job(self, db: Tx, job_id: str) -> None:
        """Lock the job's row before its chunks (the order every writer keeps)."""
        db.execute(f"SELECT id FROM jobs WHERE id = ?{self.db.lock_rows}", (job_id,))

    def listen(self, wake: Callable[[], None]) -> Callable[[], None]:
        """Call ``wake()`` when another process makes chunks claimable (PostgreSQL
        ``LISTEN/NOTIFY``; nothing on SQLite or with ``listening`` off); returns the stop."""
        if not self.listening:
            return lambda: None
        return self.db.listen(wake)

    def _notify(self, db: Tx) -> None:
        """Tell the listening dispatchers, at commit, that there are chunks to claim."""
        if self.db.notify_work:
            db.execute(self.db.notify_work)

    def close(self) -> None:
        """Give back what this thread holds (its SQLite connection)."""
        self.db.close()

    def shutdown(self) -> None:
        """Close every connection of this process."""
        self.db.shutdown()

    def ping(self) -> bool:
        """The database answers a query."""
        try:
            with self.db.reading(timeout=PING_SECONDS) as db:
                db.execute("SELECT 1 FROM jobs LIMIT 1").fetchall()
        except self.db.errors:
            return False
        return True

    # --- the API's side -------------------------------------------------------------------

    @retried
    def submit(
        self, owner: str | None, request_json: str, chunk_counts: list[int], chunk_points: int,
        max_unfinished: int, kind: str = "sweep",
    ) -> Job:  # fmt: skip
        """Store a job of ``kind`` and its chunks; raises ``QueueFullError`` at
        ``max_unfinished`` jobs (of every kind)."""
        job_id = uuid.uuid4().hex
        with self._tx() as db:
            db.execute(
                "INSERT INTO jobs (id, kind, owner, status, request_json, chunk_points, "
                "total_chunks, total_points, created_at) VALUES (?, ?, ?, 'queued', ?, ?, ?, ?, ?)",
                (job_id, kind, owner, request_json, chunk_points, len(chunk_counts),
                 sum(chunk_counts), self.db.now(db)),
            )  # fmt: skip
            db.executemany(
                "INSERT INTO chunks (job_id, idx, n_points, status) VALUES (?, ?, ?, 'pending')",
                [(job_id, i, n) for i, n in enumerate(chunk_counts)],
            )
            # counted after the inserts (this job included), so that concurrent submissions
            # take turns (serialize_submits) only for the count and the commit
            if self.db.serialize_submits:
                db.execute(self.db.serialize_submits)
            (n,) = db.execute(
                "SELECT COUNT(*) FROM jobs WHERE status IN ('queued', 'running')"
            ).fetchone()
            if n > max_unfinished:
                raise QueueFullError(f"{n - 1} unfinished jobs, the limit is {max_unfinished}")
            self._notify(db)
        job = self.get(job_id, owner)
        assert job is not None
        return job

    def get(self, job_id: str, owner: str | None, kind: str | None = None) -> Job | None:
        """The job if it exists, belongs to ``owner`` (None: auth off) and, when ``kind`` is
        given, is of that kind."""
        where, args = _of("j.id = ?", [job_id], owner, kind)
        with self.db.reading() as db:
            row = db.execute(f"{_JOB_SELECT} WHERE {where}", args).fetchone()
        return None if row is None else _job(row)

    def request_json(self, job_id: str) -> str:
        """The stored request document of a job."""
        with self.db.reading() as db:
            (text,) = db.execute("SELECT request_json FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return text

    def list(
        self, owner: str | None, status: JobStatus | None, limit: int, offset: int,
        kind: str | None = None,
    ) -> tuple[list[Job], int]:  # fmt: skip
        """A page of ``owner``'s jobs (of ``kind`` when given), newest first, and the number
        matching."""
        where, args = _of("TRUE", [], owner, kind)
        if status is not None:
            where += " AND j.status = ?"
            args.append(status)
        with self.db.reading() as db:
            (total,) = db.execute(f"SELECT COUNT(*) FROM jobs j WHERE {where}", args).fetchone()
            rows = db.execute(
                f"{_JOB_SELECT} WHERE {where} ORDER BY j.created_at DESC, j.id LIMIT ? OFFSET ?",
                [*args, limit, offset],
            ).fetchall()
        return [_job(r) for r in rows], total

    @retried
    def cancel(self, job_id: str, owner: str | None, kind: str | None = None) -> Job | None:
        """Cancel an unfinished job: no new chunk starts. Finished jobs are left as they are."""
        where, args = _of("id = ?", [job_id], owner, kind, table="")
        with self._tx() as db:
            self._lock_job(db, job_id)
            hit = db.execute(
                "UPDATE jobs SET status = 'cancelled', finished_at = ? "
                f"WHERE {where} AND status IN ('queued', 'running')",
                [self.db.now(db), *args],
            ).rowcount
            if hit:
                self._cancel_chunks(db, job_id)
        return self.get(job_id, owner, kind)

    def chunk_results(self, job_id: str) -> Iterator[str]:
        """JSON arrays of the committed chunks, in chunk order, one query each (so the
        iteration may move between threads, as a streamed response does)."""
        with self.db.reading() as db:
            (n,) = db.execute("SELECT total_chunks FROM jobs WHERE id = ?", (job_id,)).fetchone()
        for idx in range(n):
            with self.db.reading() as db:
                row = db.execute(
                    "SELECT result_json FROM chunks WHERE job_id = ? AND idx = ? "
                    "AND status = 'done'",
                    (job_id, idx),
                ).fetchone()
            if row is not None:
                yield unpack(row[0])

    # --- the dispatcher's side ------------------------------------------------------------

    @retried
    def claim(self, owner: str, lease_seconds: float, max_retries: int, limit: int) -> list[Claim]:
        """Lease up to ``limit`` chunks, oldest job first: pending ones, or leased ones whose
        lease expired (their worker is gone). A chunk out of attempts fails its job. Chunks
        another transaction holds (PostgreSQL) are skipped, not waited for."""
        claims: list[Claim] = []
        with self._tx() as db:
            now = self.db.now(db)
            rows = db.execute(
                "SELECT c.job_id, c.idx, c.attempts, c.status, c.error, j.request_json, "
                "j.chunk_points, j.kind FROM chunks c JOIN jobs j ON j.id = c.job_id "
                "WHERE j.status IN ('queued', 'running') AND (c.status = 'pending' "
                "OR (c.status = 'leased' AND c.lease_expires < ?)) "
                f"ORDER BY j.created_at, j.id, c.idx LIMIT ?{self.db.skip_locked_claim}",
                (now, limit),
            ).fetchall()
            failed: set[str] = set()
            for r in rows:
                if r["job_id"] in failed:
                    continue
                if r["attempts"] > max_retries:
                    reason = r["error"] or "its worker stopped answering (lease expired)"
                    self._fail_job(db, r["job_id"], r["idx"], r["attempts"], reason, now)
                    failed.add(r["job_id"])
                    continue
                db.execute(
                    "UPDATE chunks SET status = 'leased', lease_owner = ?, lease_expires = ?, "
                    "attempts = attempts + 1 WHERE job_id = ? AND idx = ?",
                    (owner, now + lease_seconds, r["job_id"], r["idx"]),
                )
                db.execute(
                    "UPDATE jobs SET status = 'running', started_at = ? "
                    "WHERE id = ? AND status = 'queued'",
                    (now, r["job_id"]),
                )
                claims.append(
                    Claim(r["job_id"], r["idx"], r["request_json"], r["chunk_points"],
                          r["attempts"] + 1, r["kind"])
                )  # fmt: skip
        return claims

    @retried
    def heartbeat(
        self, owner: str, lease_seconds: float, keys: list[tuple[str, int]]
    ) -> set[tuple[str, int]]:
        """Extend the leases of ``keys``; returns those still held (not cancelled or lost)."""
        held = set()
        with self._tx() as db:
            expires = self.db.now(db) + lease_seconds
            for job_id, idx in sorted(keys):
                if db.execute(
                    "UPDATE chunks SET lease_expires = ? WHERE job_id = ? AND idx = ? "
                    "AND status = 'leased' AND lease_owner = ?",
                    (expires, job_id, idx, owner),
                ).rowcount:
                    held.add((job_id, idx))
        return held

    @retried
    def commit(self, owner: str, job_id: str, idx: int, result_json: str) -> bool:
        """Store a chunk's result if ``owner`` still holds its lease; the last chunk finishes
        the job. Returns whether the result was committed."""
        with self._tx() as db:
            now = self.db.now(db)
            self._lock_job(db, job_id)
            if not db.execute(
                "UPDATE chunks SET status = 'done', result_json = ?, committed_at = ?, "
                "lease_owner = NULL, lease_expires = NULL, error = NULL "
                "WHERE job_id = ? AND idx = ? AND status = 'leased' AND lease_owner = ?",
                (pack(result_json), now, job_id, idx, owner),
            ).rowcount:
                return False
            db.execute(
                "INSERT INTO commits (job_id, idx, owner, at) VALUES (?, ?, ?, ?)",
                (job_id, idx, owner, now),
            )
            (left,) = db.execute(
                "SELECT COUNT(*) FROM chunks WHERE job_id = ? AND status != 'done'", (job_id,)
            ).fetchone()
            if left == 0:
                db.execute(
                    "UPDATE jobs SET status = 'succeeded', finished_at = ? "
                    "WHERE id = ? AND status = 'running'",
                    (now, job_id),
                )
        return True

    @retried
    def fail(
        self, owner: str, job_id: str, idx: int, reason: str, retry: bool, max_retries: int
    ) -> None:
        """A chunk's attempt failed: back to pending if ``retry`` and attempts remain, else the
        job fails with ``reason``."""
        with self._tx() as db:
            now = self.db.now(db)
            self._lock_job(db, job_id)
            row = db.execute(
                "SELECT attempts FROM chunks WHERE job_id = ? AND idx = ? "
                "AND status = 'leased' AND lease_owner = ?",
                (job_id, idx, owner),
            ).fetchone()
            if row is None:
                return
            if retry and row["attempts"] <= max_retries:
                db.execute(
                    "UPDATE chunks SET status = 'pending', lease_owner = NULL, "
                    "lease_expires = NULL, error = ? WHERE job_id = ? AND idx = ?",
                    (reason, job_id, idx),
                )
                self._notify(db)
            else:
                self._fail_job(db, job_id, idx, row["attempts"], reason, now)

    @retried
    def release(self, owner: str, keys: list[tuple[str, int]]) -> None:
        """Give leased chunks back unfinished (graceful stop); the attempt is not counted."""
        with self._tx() as db:
            db.executemany(
                "UPDATE chunks SET status = 'pending', lease_owner = NULL, lease_expires = NULL, "
                "attempts = CASE WHEN attempts > 0 THEN attempts - 1 ELSE 0 END "
                "WHERE job_id = ? AND idx = ? AND status = 'leased' AND lease_owner = ?",
                [(job_id, idx, owner) for job_id, idx in sorted(keys)],
            )
            if keys:
                self._notify(db)

    def lease_holders(self) -> set[str]:
        """Owners of the leases that have not expired."""
        with self.db.reading() as db:
            rows = db.execute(
                "SELECT DISTINCT lease_owner FROM chunks WHERE status = 'leased' "
                "AND lease_owner IS NOT NULL AND lease_expires >= ?",
                (self.db.now(db),),
            ).fetchall()
        return {r[0] for r in rows}

    @retried
    def expire_leases(self, owners: set[str]) -> int:
        """End the leases of ``owners`` now (their holders are known to be dead), so the next
        claim takes those chunks at once, as after an expiry (the attempt counts). Returns how
        many chunks were freed (a chunk another transaction holds is left for the next call)."""
        if not owners:
            return 0
        marks = ", ".join("?" * len(owners))
        with self._tx() as db:
            return db.execute(
                "UPDATE chunks SET lease_expires = ? WHERE (job_id, idx) IN (SELECT job_id, idx "
                f"FROM chunks WHERE status = 'leased' AND lease_owner IN ({marks})"
                f"{self.db.skip_locked})",
                (self.db.now(db), *sorted(owners)),
            ).rowcount

    def commit_log(self, job_id: str) -> list[tuple[int, str]]:
        """(chunk index, committer) of every commit of a job, in commit order."""
        with self.db.reading() as db:
            rows = db.execute(
                "SELECT idx, owner FROM commits WHERE job_id = ? ORDER BY rowid", (job_id,)
            ).fetchall()
        return [(r["idx"], r["owner"]) for r in rows]

    def attempts(self, job_id: str) -> list[int]:
        """Attempts of each chunk of a job, in chunk order."""
        with self.db.reading() as db:
            rows = db.execute(
                "SELECT attempts FROM chunks WHERE job_id = ? ORDER BY idx", (job_id,)
            ).fetchall()
        return [r[0] for r in rows]

    def _cancel_chunks(self, db: Tx, job_id: str) -> None:
        """The job's unfinished chunks are cancelled, locked in index order."""
        db.execute(
            "UPDATE chunks SET status = 'cancelled', lease_owner = NULL "
            "WHERE (job_id, idx) IN (SELECT job_id, idx FROM chunks WHERE job_id = ? "
            f"AND status IN ('pending', 'leased') ORDER BY idx{self.db.lock_rows})",
            (job_id,),
        )

    def _fail_job(
        self, db: Tx, job_id: str, idx: int, attempts: int, reason: str, now: float
    ) -> None:
        """Chunk ``idx`` failed for good: the job fails, its unfinished chunks are cancelled."""
        db.execute(
            "UPDATE chunks SET status = 'failed', lease_owner = NULL, error = ? "
            "WHERE job_id = ? AND idx = ?",
            (reason, job_id, idx),
        )
        self._cancel_chunks(db, job_id)
        db.execute(
            "UPDATE jobs SET status = 'failed', finished_at = ?, error = ? "
            "WHERE id = ? AND status IN ('queued', 'running')",
            (now, f"chunk {idx} failed after {attempts} attempt(s): {reason}", job_id),
        )


_JOB_SELECT = (
    "SELECT j.*, (SELECT CAST(COALESCE(SUM(n_points), 0) AS INTEGER) FROM chunks c "
    "WHERE c.job_id = j.id AND c.status = 'done') AS done_points FROM jobs j"
)


def _of(
    where: str, args: list[object], owner: str | None, kind: str | None, table: str = "j."
) -> tuple[str, list[object]]:
    """``where`` narrowed to the jobs of ``owner`` (None: those stored without one, auth off)
    and of ``kind`` (None: every kind); ``table``: the prefix of the jobs table's columns.
    ``IS NULL`` or ``=``, never ``IS ?``: PostgreSQL's ``IS NOT DISTINCT FROM`` uses no index."""
    if owner is None:
        where += f" AND {table}owner IS NULL"
    else:
        where, args = f"{where} AND {table}owner = ?", [*args, owner]
    return (where, args) if kind is None else (f"{where} AND {table}kind = ?", [*args, kind])


def _job(row: Any) -> Job:
    request = json.loads(row["request_json"])
    return Job(
        id=row["id"],
        label=request.get("label"),
        status=row["status"],
        progress=Progress(done=row["done_points"], total=row["total_points"]),
        axes=[
            JobAxis(**{k: a[k] for k in ("parameter", "start", "stop", "num")})
            for a in request.get("axes", [])
        ],
        created_at=utc(row["created_at"]),
        started_at=utc(row["started_at"]),
        finished_at=utc(row["finished_at"]),
        error=row["error"],
    )


def log_transition(event: Any) -> None:
    """One structured line per job transition: job id, key id, status and durations (s)."""
    created, started, finished = event["created_at"], event["started_at"], event["finished_at"]
    line = {
        "event": "job",
        "job_id": event["job_id"],
        "key_id": event["owner"],
        "status": event["status"],
        "queued_s": None if started is None else round(started - created, 3),
        "run_s": None if finished is None or started is None else round(finished - started, 3),
        "error": event["error"],
    }
    log.info(json.dumps(line))
