"""The embedded job store database: one SQLite file (WAL) in the data directory.

One connection per thread; every write is one ``BEGIN IMMEDIATE`` transaction, which excludes
every other writer (processes on this machine included), so no row lock clauses are needed.
The file must stay on a local disk of one machine (SQLite over NFS is not safe).
"""

from __future__ import annotations

import sqlite3
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from service.jobs.database import Migration, Tx, statements

TABLES = (
    """CREATE TABLE IF NOT EXISTS jobs (
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
)""",
    "CREATE INDEX IF NOT EXISTS jobs_owner ON jobs(owner, created_at)",
    "CREATE INDEX IF NOT EXISTS jobs_status ON jobs(status, created_at)",
    """CREATE TABLE IF NOT EXISTS chunks (
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
)""",
    "CREATE INDEX IF NOT EXISTS chunks_status ON chunks(status, lease_expires)",
    """CREATE TABLE IF NOT EXISTS commits (
    job_id TEXT NOT NULL,
    idx INTEGER NOT NULL,
    owner TEXT NOT NULL,
    at REAL NOT NULL
)""",
    """CREATE TABLE IF NOT EXISTS job_events (
    job_id TEXT NOT NULL,
    owner TEXT,
    status TEXT NOT NULL,
    created_at REAL,
    started_at REAL,
    finished_at REAL,
    error TEXT
)""",
    """CREATE TRIGGER IF NOT EXISTS job_submitted AFTER INSERT ON jobs BEGIN
    INSERT INTO job_events VALUES (NEW.id, NEW.owner, NEW.status, NEW.created_at,
                                   NEW.started_at, NEW.finished_at, NEW.error);
END""",
    """CREATE TRIGGER IF NOT EXISTS job_transition AFTER UPDATE OF status ON jobs
WHEN NEW.status != OLD.status BEGIN
    INSERT INTO job_events VALUES (NEW.id, NEW.owner, NEW.status, NEW.created_at,
                                   NEW.started_at, NEW.finished_at, NEW.error);
END""",
)
"""Version 1: the tables (``IF NOT EXISTS``: a file from before versioned migrations already
has them, perhaps without ``jobs.kind``, which version 2 adds). ``commits`` is ordered by
SQLite's implicit ``rowid``."""


def _job_kinds(tx: Tx) -> None:
    """Version 2: jobs of several kinds. A store from before kinds gains the column, and every
    job in it is a sweep."""
    columns = {r["name"] for r in tx.execute("PRAGMA table_info(jobs)")}
    if "kind" not in columns:
        tx.execute("ALTER TABLE jobs ADD COLUMN kind TEXT NOT NULL DEFAULT 'sweep'")
    tx.execute("CREATE INDEX IF NOT EXISTS jobs_kind ON jobs(kind, owner, created_at)")


MIGRATIONS = (
    Migration(1, "jobs, chunks, commits and job events", statements(*TABLES)),
    Migration(2, "job kinds", _job_kinds),
)


class SqliteDatabase:
    """The store file at ``path``; one connection per thread."""

    migrations = MIGRATIONS
    lock_rows = skip_locked = skip_locked_claim = ""
    migration_lock = serialize_submits = ""
    retryable: tuple[type[BaseException], ...] = ()
    errors: tuple[type[BaseException], ...] = (sqlite3.Error,)
    notify_work = ""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.location = str(self.path)
        self._local = threading.local()

    def listen(self, wake: Callable[[], None]) -> Callable[[], None]:
        """Nothing to listen to: dispatchers on one machine poll the file."""
        return lambda: None

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
    def transaction(self) -> Iterator[sqlite3.Connection]:
        db = self._db()
        db.execute("BEGIN IMMEDIATE")
        try:
            yield db
        except BaseException:
            db.execute("ROLLBACK")
            raise
        db.execute("COMMIT")

    @contextmanager
    def reading(self, timeout: float | None = None) -> Iterator[sqlite3.Connection]:
        yield self._db()

    def now(self, tx: Tx) -> float:
        return time.time()

    def close(self) -> None:
        db = getattr(self._local, "db", None)
        if db is not None:
            db.close()
            self._local.db = None

    shutdown = close
