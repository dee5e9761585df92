"""The dispatcher: claims chunks from the store, runs them on a backend, commits the results.

One loop (``run``) does everything, so the store sees one connection per dispatcher:

1. commit finished chunks (only while their lease is still held; the last one finishes the job),
   or record a failed attempt: a ``ValueError`` from the computation is deterministic and fails
   the job at once, anything else (a dead worker, a lost Dask task) is retried up to
   ``max_retries`` times;
2. renew the leases of running chunks every ``lease_seconds / 3`` (heartbeat); a chunk whose
   job was cancelled is dropped;
3. claim as many chunks as the backend has free slots.

Leases name their holder, the dispatcher's ``owner``: ``host:pid:random``. A lease of a holder
that is known to be dead is ended at once instead of after ``lease_seconds`` (so a server
restarted after a crash resumes its chunks immediately), at start and then with every heartbeat.
Known dead (``holder_is_dead``): same host name, and either this process's pid but not one of its
live dispatchers (a restart that got the same pid, as PID 1 in a container does), or a pid with
no process (``os.kill(pid, 0)`` raises ProcessLookupError). Every other holder (another host, a
live or reused pid, an owner string of another form) keeps its lease until it expires. Should the
rule ever misjudge (two machines with one host name sharing a data directory), no result is
committed twice: a commit needs the lease, and the old holder's next heartbeat drops the chunk.

``stop`` is graceful: no new claims, running chunks get ``grace`` seconds to finish and be
committed, the rest are released unfinished (without counting an attempt).
"""

from __future__ import annotations

import logging
import os
import socket
import threading
import time
import uuid
from concurrent.futures import CancelledError
from dataclasses import dataclass, field
from typing import Any

from service.jobs.backends import Backend
from service.jobs.store import Claim, JobStore

log = logging.getLogger("gearchaos.jobs")

IDLE_POLL = 0.5
"""Seconds between looks at the store when nothing wakes the dispatcher: a submission to this
process, a finished chunk, or (PostgreSQL) another process's notification (``store.listen``)
wake it at once; polling is the fallback."""

HOST = socket.gethostname()
_LIVE_OWNERS: set[str] = set()
"""Owners of this process's dispatchers that have not finished running."""


def new_owner() -> str:
    """A dispatcher's instance id: ``host:pid:random``."""
    return f"{HOST}:{os.getpid()}:{uuid.uuid4().hex[:8]}"


def holder_is_dead(owner: str) -> bool:
    """Whether the dispatcher ``owner`` is known to have died (see the module's docstring)."""
    host, _, rest = owner.rpartition(":")
    host, _, pid_text = host.rpartition(":")
    if host != HOST or not pid_text.isdigit() or not rest:
        return False
    pid = int(pid_text)
    if pid == os.getpid():
        return owner not in _LIVE_OWNERS
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:  # PermissionError: the pid exists, owned by someone else
        return False
    return False


@dataclass
class Dispatcher:
    """Feeds one backend from one store."""

    store: JobStore
    backend: Backend
    lease_seconds: float = 30.0
    max_retries: int = 3
    owner: str = field(default_factory=new_owner)

    def __post_init__(self) -> None:
        self._running: dict[tuple[str, int], tuple[Claim, Any]] = {}
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._last_beat = 0.0
        self._last_reclaim = -float("inf")
        self._grace_until = 0.0
        _LIVE_OWNERS.add(self.owner)

    # --- control --------------------------------------------------------------------------

    def wake(self) -> None:
        """Look at the store now (a job was submitted or a chunk finished)."""
        self._wake.set()

    def start(self) -> None:
        """Run the loop in a daemon thread."""
        self._thread = threading.Thread(target=self.run, name="job-dispatcher", daemon=True)
        self._thread.start()

    def request_stop(self, grace: float = 5.0) -> None:
        """Ask ``run`` to stop (safe from a signal handler): no new claims, running chunks get
        ``grace`` seconds to finish and be committed, the rest are released."""
        self._grace_until = time.monotonic() + grace
        self._stop.set()
        self._wake.set()

    def stop(self, grace: float = 5.0) -> None:
        """``request_stop`` and wait for the loop's thread to end."""
        self.request_stop(grace)
        if self._thread is not None:
            self._thread.join()

    @property
    def running(self) -> list[tuple[str, int]]:
        """(job id, chunk index) of the chunks in flight."""
        return list(self._running)

    # --- the loop -------------------------------------------------------------------------

    def run(self) -> None:
        """Dispatch until ``stop``; then drain gracefully."""
        log.info("dispatcher %s started on %s", self.owner, self.backend.name)
        unlisten = self.store.listen(self.wake)  # other replicas' submissions wake it at once
        while not self._stop.is_set():
            try:
                self.step()
            except Exception:
                log.exception("dispatcher step failed; retrying")
                time.sleep(1.0)
            self._wake.wait(min(IDLE_POLL, self.lease_seconds / 3.0))
            self._wake.clear()
        unlisten()
        self._drain()
        self.store.close()
        _LIVE_OWNERS.discard(self.owner)
        log.info("dispatcher %s stopped", self.owner)

    def step(self, claim: bool = True) -> None:
        """One round: collect finished chunks, heartbeat, claim new ones."""
        for key, (c, future) in list(self._running.items()):
            if future.done():
                del self._running[key]
                self._finish(c, future)
        now = time.monotonic()
        if self._running and now - self._last_beat >= self.lease_seconds / 3.0:
            held = self.store.heartbeat(self.owner, self.lease_seconds, list(self._running))
            for key in set(self._running) - held:
                _, future = self._running.pop(key)
                future.cancel()
                log.info("chunk %s/%d dropped (job cancelled or lease lost)", *key)
            self._last_beat = now
        if claim and now - self._last_reclaim >= self.lease_seconds / 3.0:
            self.reclaim_dead_leases()
            self._last_reclaim = now
        free = self.backend.capacity() - len(self._running)
        if claim and free > 0:
            for c in self.store.claim(self.owner, self.lease_seconds, self.max_retries, free):
                try:
                    future = self.backend.submit(c)
                except Exception as exc:
                    self._lost(c, exc)
                    continue
                future.add_done_callback(lambda _: self._wake.set())
                self._running[c.key] = (c, future)

    def reclaim_dead_leases(self) -> int:
        """End the leases of dispatchers known to be dead; returns the chunks freed."""
        dead = {o for o in self.store.lease_holders() if holder_is_dead(o)}
        freed = self.store.expire_leases(dead)
        if freed:
            log.info("reclaimed %d chunk(s) leased by dead dispatcher(s) %s", freed, sorted(dead))
        return freed

    def _finish(self, c: Claim, future: Any) -> None:
        try:
            result = future.result()
        except CancelledError:
            self.store.release(self.owner, [c.key])
            return
        except ValueError as exc:
            self.store.fail(self.owner, c.job_id, c.index, str(exc), False, self.max_retries)
            log.warning("job %s chunk %d invalid: %s", c.job_id, c.index, exc)
            return
        except Exception as exc:
            self._lost(c, exc)
            return
        if self.store.commit(self.owner, c.job_id, c.index, result):
            log.info("job %s chunk %d committed", c.job_id, c.index)
        else:  # fenced: another dispatcher holds (or committed) the chunk, or it was cancelled
            log.info("job %s chunk %d not committed: lease lost", c.job_id, c.index)

    def _lost(self, c: Claim, exc: Exception) -> None:
        """An attempt failed for a reason outside the computation: retry (bounded)."""
        reason = f"{type(exc).__name__}: {exc}".rstrip(": ")
        self.store.fail(self.owner, c.job_id, c.index, reason, True, self.max_retries)
        log.warning("job %s chunk %d attempt %d lost: %s", c.job_id, c.index, c.attempt, reason)
        self.backend.recover(exc)

    def _drain(self) -> None:
        while self._running and time.monotonic() < self._grace_until:
            self.step(claim=False)
            self._wake.wait(0.05)
            self._wake.clear()
        self.store.release(self.owner, list(self._running))
        self._running.clear()
        self.backend.close()
