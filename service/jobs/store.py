"""The durable job store: one SQLite file (WAL) holding jobs and the results of finished chunks.

Tables: ``jobs`` (one row per job, of any kind of ``gearengine.studies.jobs.KINDS``: its ``kind``
column names it; a store written before kinds existed gains the column, every old job a sweep),
``chunks`` (one row per chunk: status pending | leased |
done | failed | cancelled, lease owner and expiry, attempts, result JSON) and ``commits`` (an
append-only log of chunk commits, for audits and the fault tests). A chunk's result JSON is
stored zlib-compressed (a BLOB in ``result_json``; ``pack``/``unpack``), read back one chunk at
a time.

Every state change is one ``BEGIN IMMEDIATE`` transaction, so several dispatchers (processes
on this machine) can share the file. A chunk is leased for ``lease_seconds`` and the lease is
renewed by heartbeats; a chunk whose lease expired is claimed again (its attempt counts). A
result is committed only while the committer still holds the lease, so no chunk is committed
twice. Times are POSIX seconds (``time.time()``).
"""

from __future__ import annotations

import json
import logging
import sqlite3
import threading
import time
import uuid
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from service.jobs.models import Job, JobAxis, JobStatus, Progress, utc

log = logging.getLogger("gearchaos.jobs")

DB_FILE = "jobs.sqlite3"
"""Name of the store in the data directory."""
COMPRESS_LEVEL = 6
"""zlib level of stored chunk results (JSON of verdicts shrinks about 5 to 10 times)."""


def pack(result_json: str) -> bytes:
    """A chunk's result JSON as stored: zlib-compressed UTF-8."""
    return zlib.compress(result_json.encode(), COMPRESS_LEVEL)


def unpack(stored: bytes | str) -> str:
    """A stored chunk result as JSON text (rows written before compression are text)."""
    return stored if isinstance(stored, str) else zlib.decompress(stored).decode()


SCHEMA = """
CREATE TABLE IF NOT EXISTS jobs (
    id TEXT PRIMARY KEY,
    kind TEXT NOT NULL DEFAULT 'sweep',
    owner TEXT,
    status TEXT NOT NULL,
    request_json TEXT NOT NULL,
    chunk_points INTEGER NOT NULL,
    total_chunks INTEGER NOT NULL,
    total_points INTEGER NOT NULL,
    created_at REAL NOT NULL,
    started_at REAL,
    finished_at REAL,
    error TEXT
);
CREATE INDEX IF NOT EXISTS jobs_owner ON jobs(owner, created_at);
CREATE INDEX IF NOT EXISTS jobs_status ON jobs(status, created_at);
CREATE TABLE IF NOT EXISTS chunks (
    job_id TEXT NOT NULL REFERENCES jobs(id),
    idx INTEGER NOT NULL,
    n_points INTEGER NOT NULL,
    status TEXT NOT NULL,
    lease_owner TEXT,
    lease_expires REAL,
    attempts INTEGER NOT NULL DEFAULT 0,
    error TEXT,
    result_json TEXT,
    committed_at REAL,
    PRIMARY KEY (job_id, idx)
);
CREATE INDEX IF NOT EXISTS chunks_status ON chunks(status, lease_expires);
CREATE TABLE IF NOT EXISTS commits (
    job_id TEXT NOT NULL,
    idx INTEGER NOT NULL,
    owner TEXT NOT NULL,
    at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS job_events (
    job_id TEXT NOT NULL,
    owner TEXT,
    status TEXT NOT NULL,
    created_at REAL,
    started_at REAL,
    finished_at REAL,
    error TEXT
);
CREATE TRIGGER IF NOT EXISTS job_submitted AFTER INSERT ON jobs BEGIN
    INSERT INTO job_events VALUES (NEW.id, NEW.owner, NEW.status, NEW.created_at,
                                   NEW.started_at, NEW.finished_at, NEW.error);
END;
CREATE TRIGGER IF NOT EXISTS job_transition AFTER UPDATE OF status ON jobs
WHEN NEW.status != OLD.status BEGIN
    INSERT INTO job_events VALUES (NEW.id, NEW.owner, NEW.status, NEW.created_at,
                                   NEW.started_at, NEW.finished_at, NEW.error);
END;
"""


KIND_COLUMN = """
ALTER TABLE jobs ADD COLUMN kind TEXT NOT NULL DEFAULT 'sweep';
"""
"""Migration of a store from before job kinds: every job in it is a sweep."""
KIND_INDEX = "CREATE INDEX IF NOT EXISTS jobs_kind ON jobs(kind, owner, created_at);"


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


class JobStore:
    """Access to the store file; one SQLite connection per thread."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._local = threading.local()
        db = self._db()
        db.executescript(SCHEMA)
        columns = {r["name"] for r in db.execute("PRAGMA table_info(jobs)")}
        if "kind" not in columns:
            db.executescript(KIND_COLUMN)
        db.executescript(KIND_INDEX)

    @classmethod
    def in_dir(cls, data_dir: Path) -> JobStore:
        """The store of a data directory."""
        return cls(Path(data_dir) / DB_FILE)

    def _db(self) -> sqlite3.Connection:
        db = getattr(self._local, "db", None)
        if db is None:
            db = sqlite3.connect(self.path, isolation_level=None, timeout=30.0)
            db.row_factory = sqlite3.Row
            db.execute("PRAGMA journal_mode=WAL")
            db.execute("PRAGMA synchronous=FULL")
            db.execute("PRAGMA busy_timeout=30000")
            self._local.db = db
        return db

    @contextmanager
    def _tx(self) -> Iterator[sqlite3.Connection]:
        """One BEGIN IMMEDIATE transaction; the job transitions it made (recorded by triggers in
        ``job_events``) are logged once it has committed."""
        db = self._db()
        db.execute("BEGIN IMMEDIATE")
        try:
            yield db
            events = db.execute("SELECT * FROM job_events").fetchall()
            if events:
                db.execute("DELETE FROM job_events")
        except BaseException:
            db.execute("ROLLBACK")
            raise
        db.execute("COMMIT")
        for event in events:
            log_transition(event)

    def close(self) -> None:
        """Close this thread's connection."""
        db = getattr(self._local, "db", None)
        if db is not None:
            db.close()
            self._local.db = None

    def ping(self) -> bool:
        """The file answers a query."""
        try:
            self._db().execute("SELECT 1 FROM jobs LIMIT 1").fetchall()
        except sqlite3.Error:
            return False
        return True

    # --- the API's side -------------------------------------------------------------------

    def submit(
        self, owner: str | None, request_json: str, chunk_counts: list[int], chunk_points: int,
        max_unfinished: int, kind: str = "sweep",
    ) -> Job:  # fmt: skip
        """Store a job of ``kind`` and its chunks; raises ``QueueFullError`` at
        ``max_unfinished`` jobs (of every kind)."""
        job_id, now = uuid.uuid4().hex, time.time()
        with self._tx() as db:
            (n,) = db.execute(
                "SELECT COUNT(*) FROM jobs WHERE status IN ('queued', 'running')"
            ).fetchone()
            if n >= max_unfinished:
                raise QueueFullError(f"{n} unfinished jobs, the limit is {max_unfinished}")
            db.execute(
                "INSERT INTO jobs (id, kind, owner, status, request_json, chunk_points, "
                "total_chunks, total_points, created_at) VALUES (?, ?, ?, 'queued', ?, ?, ?, ?, ?)",
                (job_id, kind, owner, request_json, chunk_points, len(chunk_counts),
                 sum(chunk_counts), now),
            )  # fmt: skip
            db.executemany(
                "INSERT INTO chunks (job_id, idx, n_points, status) VALUES (?, ?, ?, 'pending')",
                [(job_id, i, n) for i, n in enumerate(chunk_counts)],
            )
        job = self.get(job_id, owner)
        assert job is not None
        return job

    def get(self, job_id: str, owner: str | None, kind: str | None = None) -> Job | None:
        """The job if it exists, belongs to ``owner`` (None: auth off) and, when ``kind`` is
        given, is of that kind."""
        where, args = _of("j.id = ? AND j.owner IS ?", [job_id, owner], kind)
        row = self._db().execute(f"{_JOB_SELECT} WHERE {where}", args).fetchone()
        return None if row is None else _job(row)

    def request_json(self, job_id: str) -> str:
        """The stored request document of a job."""
        (text,) = (
            self._db().execute("SELECT request_json FROM jobs WHERE id = ?", (job_id,)).fetchone()
        )
        return text

    def list(
        self, owner: str | None, status: JobStatus | None, limit: int, offset: int,
        kind: str | None = None,
    ) -> tuple[list[Job], int]:  # fmt: skip
        """A page of ``owner``'s jobs (of ``kind`` when given), newest first, and the number
        matching."""
        where, args = _of("j.owner IS ?", [owner], kind)
        if status is not None:
            where += " AND j.status = ?"
            args.append(status)
        db = self._db()
        (total,) = db.execute(f"SELECT COUNT(*) FROM jobs j WHERE {where}", args).fetchone()
        rows = db.execute(
            f"{_JOB_SELECT} WHERE {where} ORDER BY j.created_at DESC, j.id LIMIT ? OFFSET ?",
            [*args, limit, offset],
        ).fetchall()
        return [_job(r) for r in rows], total

    def cancel(self, job_id: str, owner: str | None, kind: str | None = None) -> Job | None:
        """Cancel an unfinished job: no new chunk starts. Finished jobs are left as they are."""
        where, args = _of("id = ? AND owner IS ?", [job_id, owner], kind, column="kind")
        with self._tx() as db:
            hit = db.execute(
                "UPDATE jobs SET status = 'cancelled', finished_at = ? "
                f"WHERE {where} AND status IN ('queued', 'running')",
                [time.time(), *args],
            ).rowcount
            if hit:
                db.execute(
                    "UPDATE chunks SET status = 'cancelled', lease_owner = NULL "
                    "WHERE job_id = ? AND status IN ('pending', 'leased')",
                    (job_id,),
                )
        return self.get(job_id, owner, kind)

    def chunk_results(self, job_id: str) -> Iterator[str]:
        """JSON arrays of the committed chunks, in chunk order, one query each (so the
        iteration may move between threads, as a streamed response does)."""
        (n,) = (
            self._db().execute("SELECT total_chunks FROM jobs WHERE id = ?", (job_id,)).fetchone()
        )
        for idx in range(n):
            row = (
                self._db()
                .execute(
                    "SELECT result_json FROM chunks WHERE job_id = ? AND idx = ? "
                    "AND status = 'done'",
                    (job_id, idx),
                )
                .fetchone()
            )
            if row is not None:
                yield unpack(row[0])

    # --- the dispatcher's side ------------------------------------------------------------

    def claim(self, owner: str, lease_seconds: float, max_retries: int, limit: int) -> list[Claim]:
        """Lease up to ``limit`` chunks, oldest job first: pending ones, or leased ones whose
        lease expired (their worker is gone). A chunk out of attempts fails its job."""
        now = time.time()
        claims: list[Claim] = []
        with self._tx() as db:
            rows = db.execute(
                "SELECT c.job_id, c.idx, c.attempts, c.status, c.error, j.request_json, "
                "j.chunk_points, j.kind FROM chunks c JOIN jobs j ON j.id = c.job_id "
                "WHERE j.status IN ('queued', 'running') AND (c.status = 'pending' "
                "OR (c.status = 'leased' AND c.lease_expires < ?)) "
                "ORDER BY j.created_at, j.id, c.idx LIMIT ?",
                (now, limit),
            ).fetchall()
            failed: set[str] = set()
            for r in rows:
                if r["job_id"] in failed:
                    continue
                if r["attempts"] > max_retries:
                    reason = r["error"] or "its worker stopped answering (lease expired)"
                    _fail_job(db, r["job_id"], r["idx"], r["attempts"], reason, now)
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

    def heartbeat(
        self, owner: str, lease_seconds: float, keys: list[tuple[str, int]]
    ) -> set[tuple[str, int]]:
        """Extend the leases of ``keys``; returns those still held (not cancelled or lost)."""
        held = set()
        with self._tx() as db:
            for job_id, idx in keys:
                if db.execute(
                    "UPDATE chunks SET lease_expires = ? WHERE job_id = ? AND idx = ? "
                    "AND status = 'leased' AND lease_owner = ?",
                    (time.time() + lease_seconds, job_id, idx, owner),
                ).rowcount:
                    held.add((job_id, idx))
        return held

    def commit(self, owner: str, job_id: str, idx: int, result_json: str) -> bool:
        """Store a chunk's result if ``owner`` still holds its lease; the last chunk finishes
        the job. Returns whether the result was committed."""
        now = time.time()
        with self._tx() as db:
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

    def fail(
        self, owner: str, job_id: str, idx: int, reason: str, retry: bool, max_retries: int
    ) -> None:
        """A chunk's attempt failed: back to pending if ``retry`` and attempts remain, else the
        job fails with ``reason``."""
        now = time.time()
        with self._tx() as db:
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
            else:
                _fail_job(db, job_id, idx, row["attempts"], reason, now)

    def release(self, owner: str, keys: list[tuple[str, int]]) -> None:
        """Give leased chunks back unfinished (graceful stop); the attempt is not counted."""
        with self._tx() as db:
            db.executemany(
                "UPDATE chunks SET status = 'pending', lease_owner = NULL, lease_expires = NULL, "
                "attempts = MAX(attempts - 1, 0) "
                "WHERE job_id = ? AND idx = ? AND status = 'leased' AND lease_owner = ?",
                [(job_id, idx, owner) for job_id, idx in keys],
            )

    def lease_holders(self) -> set[str]:
        """Owners of the leases that have not expired."""
        rows = self._db().execute(
            "SELECT DISTINCT lease_owner FROM chunks WHERE status = 'leased' "
            "AND lease_owner IS NOT NULL AND lease_expires >= ?",
            (time.time(),),
        )
        return {r[0] for r in rows}

    def expire_leases(self, owners: set[str]) -> int:
        """End the leases of ``owners`` now (their holders are known to be dead), so the next
        claim takes those chunks at once, as after an expiry (the attempt counts). Returns how
        many chunks were freed."""
        if not owners:
            return 0
        marks = ", ".join("?" * len(owners))
        with self._tx() as db:
            return db.execute(
                f"UPDATE chunks SET lease_expires = ? WHERE status = 'leased' "
                f"AND lease_owner IN ({marks})",
                (time.time(), *sorted(owners)),
            ).rowcount

    def commit_log(self, job_id: str) -> list[tuple[int, str]]:
        """(chunk index, committer) of every commit of a job, in commit order."""
        rows = self._db().execute(
            "SELECT idx, owner FROM commits WHERE job_id = ? ORDER BY rowid", (job_id,)
        )
        return [(r["idx"], r["owner"]) for r in rows]

    def attempts(self, job_id: str) -> list[int]:
        """Attempts of each chunk of a job, in chunk order."""
        rows = self._db().execute(
            "SELECT attempts FROM chunks WHERE job_id = ? ORDER BY idx", (job_id,)
        )
        return [r[0] for r in rows]


_JOB_SELECT = (
    "SELECT j.*, (SELECT COALESCE(SUM(n_points), 0) FROM chunks c "
    "WHERE c.job_id = j.id AND c.status = 'done') AS done_points FROM jobs j"
)


def _of(
    where: str, args: list[object], kind: str | None, column: str = "j.kind"
) -> tuple[str, list[object]]:
    """``where`` narrowed to jobs of ``kind`` (None: every kind)."""
    return (where, args) if kind is None else (f"{where} AND {column} = ?", [*args, kind])


def _job(row: sqlite3.Row) -> Job:
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


def log_transition(event: sqlite3.Row) -> None:
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


def _fail_job(
    db: sqlite3.Connection, job_id: str, idx: int, attempts: int, reason: str, now: float
) -> None:
    db.execute(
        "UPDATE chunks SET status = 'failed', lease_owner = NULL, error = ? "
        "WHERE job_id = ? AND idx = ?",
        (reason, job_id, idx),
    )
    db.execute(
        "UPDATE chunks SET status = 'cancelled', lease_owner = NULL "
        "WHERE job_id = ? AND status IN ('pending', 'leased')",
        (job_id,),
    )
    db.execute(
        "UPDATE jobs SET status = 'failed', finished_at = ?, error = ? "
        "WHERE id = ? AND status IN ('queued', 'running')",
        (now, f"chunk {idx} failed after {attempts} attempt(s): {reason}", job_id),
    )
