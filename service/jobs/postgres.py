"""The shared job store database: PostgreSQL, for several API replicas and dispatchers on any
number of hosts (``GEARCHAOS_DATABASE_URL=postgresql://...``).

psycopg 3 with a connection pool (``psycopg_pool``) per process; every statement runs in
autocommit unless inside ``transaction()``. Writers are ordered so that none waits in a cycle:
a transaction that changes a job locks its ``jobs`` row first, then its chunks in index order;
claims lock chunks and their jobs with ``SKIP LOCKED`` and so never wait. Should PostgreSQL's
deadlock detector still abort a transaction (a heartbeat's and a cancel's chunk locks), the
store runs it again (``retryable``). The clock of leases is the server's
(``clock_timestamp()``), one for every replica.

Dispatchers wake at once on work another replica made: every transaction that makes chunks
claimable (a submission, chunks released by a stopping dispatcher, an attempt to retry) runs
``pg_notify`` on ``CHANNEL``, which PostgreSQL delivers to every ``LISTEN``ing session when it
commits; each dispatcher's ``Listener`` (its own connection, outside the pool, in a thread)
wakes its loop. Polling every ``IDLE_POLL`` stays as the fallback (a lost notification, a
connection being re-opened, a pooler such as PgBouncer in transaction mode that cannot
``LISTEN``: ``database_listen = false``).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from functools import lru_cache
from typing import Any

import psycopg
from psycopg import errors as pg_errors
from psycopg.conninfo import conninfo_to_dict, make_conninfo
from psycopg_pool import ConnectionPool

from service.jobs.database import Migration, Tx, statements

IDLE_IN_TRANSACTION_MS = 10_000
"""A session idle inside a transaction this long is ended by the server, its row locks freed: a
process frozen mid-transaction (SIGSTOP, a paused VM, a stalled pod) would otherwise hold its
job's row and stall every dispatcher's claims and commits of that job. The store's own
transactions never wait for anything but the database."""
CHANNEL = "gearchaos_work"
"""The notification channel of claimable work."""
LISTEN_POLL = 1.0
"""Seconds a listener waits for notifications before looking whether it should stop."""
LISTEN_RETRY = 1.0
"""Seconds before a listener whose connection failed connects again."""
LOCK_KEY = 0x6765_6172
"""Advisory lock namespace of gearchaos ("gear"); the second key picks the lock."""

TABLES = (
    """CREATE TABLE jobs (
    id TEXT PRIMARY KEY,
    kind TEXT NOT NULL DEFAULT 'sweep',
    owner TEXT,
    status TEXT NOT NULL,
    request_json TEXT NOT NULL,
    chunk_points INTEGER NOT NULL,
    total_chunks INTEGER NOT NULL,
    total_points INTEGER NOT NULL,
    created_at DOUBLE PRECISION NOT NULL,
    started_at DOUBLE PRECISION,
    finished_at DOUBLE PRECISION,
    error TEXT
)""",
    "CREATE INDEX jobs_owner ON jobs(owner, created_at)",
    "CREATE INDEX jobs_status ON jobs(status, created_at)",
    "CREATE INDEX jobs_kind ON jobs(kind, owner, created_at)",
    """CREATE TABLE chunks (
    job_id TEXT NOT NULL REFERENCES jobs(id),
    idx INTEGER NOT NULL,
    n_points INTEGER NOT NULL,
    status TEXT NOT NULL,
    lease_owner TEXT,
    lease_expires DOUBLE PRECISION,
    attempts INTEGER NOT NULL DEFAULT 0,
    error TEXT,
    result_json BYTEA,
    committed_at DOUBLE PRECISION,
    PRIMARY KEY (job_id, idx)
)""",
    "CREATE INDEX chunks_status ON chunks(status, lease_expires)",
    """CREATE TABLE commits (
    rowid BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    job_id TEXT NOT NULL,
    idx INTEGER NOT NULL,
    owner TEXT NOT NULL,
    at DOUBLE PRECISION NOT NULL
)""",
    """CREATE TABLE job_events (
    job_id TEXT NOT NULL,
    owner TEXT,
    status TEXT NOT NULL,
    created_at DOUBLE PRECISION,
    started_at DOUBLE PRECISION,
    finished_at DOUBLE PRECISION,
    error TEXT
)""",
    """CREATE FUNCTION job_event() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    INSERT INTO job_events VALUES (NEW.id, NEW.owner, NEW.status, NEW.created_at,
                                   NEW.started_at, NEW.finished_at, NEW.error);
    RETURN NULL;
END $$""",
    "CREATE TRIGGER job_submitted AFTER INSERT ON jobs FOR EACH ROW EXECUTE FUNCTION job_event()",
    "CREATE TRIGGER job_transition AFTER UPDATE OF status ON jobs FOR EACH ROW "
    "WHEN (NEW.status IS DISTINCT FROM OLD.status) EXECUTE FUNCTION job_event()",
)
"""Version 1: the schema of SQLite's versions 1 and 2 (job kinds included). ``commits.rowid``
orders the commit log as SQLite's implicit rowid does. ``job_events`` rows live only inside
the transaction that wrote them (it reads and deletes them before committing), so no other
transaction ever sees one."""

MIGRATIONS = (Migration(1, "jobs, chunks, commits, job events and kinds", statements(*TABLES)),)


@lru_cache(maxsize=256)
def to_pyformat(sql: str) -> str:
    """The store's SQL for psycopg: ``?`` placeholders as ``%s``."""
    return sql.replace("?", "%s")


class Row(tuple):
    """A result row indexed by position or by column name (as ``sqlite3.Row``)."""

    names: dict[str, int]

    def __new__(cls, values: Sequence[Any], names: dict[str, int]) -> Row:
        row = super().__new__(cls, values)
        row.names = names
        return row

    def __getitem__(self, key: Any) -> Any:
        return super().__getitem__(self.names[key] if isinstance(key, str) else key)


def rows(cursor: psycopg.Cursor[Any]) -> Any:
    """psycopg row factory making ``Row``s."""
    names = {c.name: i for i, c in enumerate(cursor.description or ())}
    return lambda values: Row(values, names)


class PgTx:
    """A pooled connection speaking the store's SQL (``to_pyformat``)."""

    def __init__(self, conn: psycopg.Connection[Any]) -> None:
        self.conn = conn

    def execute(self, sql: str, args: Sequence[object] = ()) -> psycopg.Cursor[Any]:
        return self.conn.execute(to_pyformat(sql), args)  # type: ignore[arg-type]

    def executemany(self, sql: str, args: Sequence[Sequence[object]]) -> None:
        with self.conn.cursor() as cur:
            cur.executemany(to_pyformat(sql), args)  # type: ignore[arg-type]


def redacted(url: str) -> str:
    """``url`` without its password (for logs and ``location``)."""
    params = conninfo_to_dict(url)
    params.pop("password", None)
    return make_conninfo("", **params)


log = logging.getLogger("gearchaos.jobs")


class Listener:
    """A thread holding one connection that ``LISTEN``s on ``CHANNEL`` and calls ``wake()``
    for each notification; it calls ``wake()`` too each time it (re)connects, for the work
    committed while it was not listening. A failed connection is opened again after
    ``LISTEN_RETRY`` seconds (the dispatcher polls meanwhile)."""

    def __init__(self, url: str, wake: Callable[[], None]) -> None:
        self.url = url
        self.wake = wake
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="job-listener", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                with psycopg.connect(self.url, autocommit=True) as conn:
                    conn.execute(f"LISTEN {CHANNEL}")
                    self.wake()
                    while not self._stop.is_set():
                        for _ in conn.notifies(timeout=LISTEN_POLL):
                            self.wake()
            except psycopg.Error as exc:
                log.warning("job listener lost its connection (%s); polling meanwhile", exc)
                self._stop.wait(LISTEN_RETRY)

    def stop(self) -> None:
        """Stop listening (within ``LISTEN_POLL`` seconds) and close the connection."""
        self._stop.set()
        self._thread.join(timeout=LISTEN_POLL + 5.0)


class PostgresDatabase:
    """The database at ``url`` (``postgresql://user:pass@host:port/db``), ``pool_size``
    connections at most in this process."""

    migrations = MIGRATIONS
    lock_rows = " FOR UPDATE"
    skip_locked = " FOR UPDATE SKIP LOCKED"
    skip_locked_claim = " FOR UPDATE OF c, j SKIP LOCKED"
    migration_lock = f"SELECT pg_advisory_xact_lock({LOCK_KEY}, 1)"
    serialize_submits = f"SELECT pg_advisory_xact_lock({LOCK_KEY}, 2)"
    retryable: tuple[type[BaseException], ...] = (
        pg_errors.DeadlockDetected,
        pg_errors.SerializationFailure,
    )
    errors: tuple[type[BaseException], ...] = (psycopg.Error,)
    notify_work = f"SELECT pg_notify('{CHANNEL}', '')"

    def __init__(self, url: str, pool_size: int = 8) -> None:
        self.url = url
        self.location = redacted(url)
        self.pool = ConnectionPool(
            url,
            min_size=1,
            max_size=pool_size,
            kwargs={
                "autocommit": True,
                "row_factory": rows,
                "options": f"-c idle_in_transaction_session_timeout={IDLE_IN_TRANSACTION_MS}",
            },
            check=ConnectionPool.check_connection,  # a connection broken by a restart is replaced
            name="gearchaos-jobs",
            open=True,
        )

    def listen(self, wake: Callable[[], None]) -> Callable[[], None]:
        return Listener(self.url, wake).stop

    @contextmanager
    def transaction(self) -> Iterator[Tx]:
        with self.pool.connection() as conn, conn.transaction():
            yield PgTx(conn)

    @contextmanager
    def reading(self, timeout: float | None = None) -> Iterator[Tx]:
        with self.pool.connection(timeout) as conn:
            yield PgTx(conn)

    def now(self, tx: Tx) -> float:
        (seconds,) = tx.execute("SELECT EXTRACT(EPOCH FROM clock_timestamp())").fetchone()
        return float(seconds)

    def close(self) -> None:
        """Nothing is held per thread: a connection goes back to the pool after each use."""

    def shutdown(self) -> None:
        self.pool.close()
