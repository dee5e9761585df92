"""What the job store needs of a SQL database, and the versioned migrations of its schema.

``service.jobs.store.JobStore`` holds the queue's logic once, written in SQL that SQLite and
PostgreSQL both run (``?`` placeholders, row values in ``IN``). A ``Database`` carries what
differs: how a connection and a transaction are had, the clock, the row-locking clauses, which
errors mean "run the transaction again", and the schema.

Migrations are numbered; ``migrate`` applies, in one transaction, those a database has not yet
recorded in its ``schema_migrations`` table, so replicas that start together migrate once.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import Any, Protocol


class Cursor(Protocol):
    """The part of a DB-API cursor the store uses; rows index by position and by column name."""

    rowcount: int

    def fetchone(self) -> Any: ...

    def fetchall(self) -> list[Any]: ...

    def __iter__(self) -> Iterator[Any]: ...


class Tx(Protocol):
    """A connection inside a transaction (or, for reads, in autocommit)."""

    def execute(self, sql: str, args: Sequence[object] = ()) -> Cursor: ...

    def executemany(self, sql: str, rows: Sequence[Sequence[object]]) -> Any: ...


@dataclass(frozen=True)
class Migration:
    """Version ``version`` of a schema: ``apply`` runs its statements in the migrating
    transaction (a function, so a step may look at what is there first)."""

    version: int
    name: str
    apply: Callable[[Tx], None]


def statements(*sql: str) -> Callable[[Tx], None]:
    """A migration step that executes ``sql`` in order (one statement each)."""

    def apply(tx: Tx) -> None:
        for s in sql:
            tx.execute(s)

    return apply


class Database(Protocol):
    """One SQL database holding the job store."""

    location: str
    """Where it is: a file path (SQLite) or a URL without its password (PostgreSQL)."""
    migrations: tuple[Migration, ...]
    lock_rows: str
    """Clause appended to a SELECT that is about to update the rows it read (`` FOR UPDATE``),
    empty where a write transaction already excludes every other writer (SQLite)."""
    skip_locked_claim: str
    """Clause of the claim query: lock the chunks and their jobs, skip rows another
    transaction holds (PostgreSQL ``FOR UPDATE OF c, j SKIP LOCKED``)."""
    skip_locked: str
    """As ``lock_rows``, skipping rows another transaction holds."""
    migration_lock: str
    """A statement run first by ``migrate``, making replicas that start together take turns
    (PostgreSQL: an advisory lock); empty on SQLite, whose write transactions exclude others."""
    serialize_submits: str
    """A statement that makes concurrent submissions take turns, so the cap on unfinished jobs
    holds (PostgreSQL: a transaction-level advisory lock); empty on SQLite."""
    retryable: tuple[type[BaseException], ...]
    """Errors after which a transaction is run again from the start (deadlock, serialization
    failure); PostgreSQL's deadlock detector may abort one of two writers."""
    errors: tuple[type[BaseException], ...]
    """Errors meaning the database does not answer (readiness)."""
    notify_work: str
    """A statement telling every listening process that there are chunks to claim, delivered
    when the transaction commits (PostgreSQL: ``pg_notify``); empty on SQLite, whose
    dispatchers share one machine and poll."""

    def listen(self, wake: Callable[[], None]) -> Callable[[], None]:
        """Call ``wake()`` whenever another process commits a ``notify_work`` (and once when
        listening starts or resumes after a lost connection); returns the function that stops
        listening. A no-op on SQLite."""

    def transaction(self) -> AbstractContextManager[Tx]:
        """A write transaction: committed when the block ends, rolled back on an exception."""

    def reading(self, timeout: float | None = None) -> AbstractContextManager[Tx]:
        """A connection for reads (each statement sees the latest committed state); waiting
        at most ``timeout`` seconds for one where connections are pooled."""

    def now(self, tx: Tx) -> float:
        """The store's clock, POSIX seconds (PostgreSQL: the server's, one clock for every
        replica, so leases do not depend on the hosts' clocks)."""

    def close(self) -> None:
        """Give back what this thread holds (a connection)."""

    def shutdown(self) -> None:
        """Close every connection (the process stops using the store)."""


MIGRATIONS_TABLE = (
    "CREATE TABLE IF NOT EXISTS schema_migrations (version INTEGER PRIMARY KEY, "
    "name TEXT NOT NULL, applied_at DOUBLE PRECISION NOT NULL)"
)


def migrate(db: Database) -> list[int]:
    """Apply the migrations ``db`` has not recorded, in version order, in one transaction.
    Returns the versions applied."""
    with db.transaction() as tx:
        if db.migration_lock:
            tx.execute(db.migration_lock)
        tx.execute(MIGRATIONS_TABLE)
        done = {r[0] for r in tx.execute("SELECT version FROM schema_migrations")}
        applied = []
        for m in sorted(db.migrations, key=lambda m: m.version):
            if m.version in done:
                continue
            m.apply(tx)
            tx.execute(
                "INSERT INTO schema_migrations (version, name, applied_at) VALUES (?, ?, ?)",
                (m.version, m.name, time.time()),
            )
            applied.append(m.version)
    return applied
