"""Where chunks run: a local process pool or a Dask distributed cluster.

Both hand back futures with ``done()``, ``result()`` and ``add_done_callback``; the dispatcher
treats them alike. Workers only compute (``gearengine.studies.jobs.compute_chunk_json`` with the
claim's kind, whatever the kind); they never touch the store, so a worker that dies or hangs
cannot corrupt it.
"""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Protocol

from gearengine.studies.jobs import compute_chunk_json
from service.jobs.store import Claim
from service.lifetime import exit_with_parent


class Backend(Protocol):
    """A place to run chunks."""

    name: str

    def capacity(self) -> int:
        """How many chunks may run at once."""

    def submit(self, claim: Claim) -> Any:
        """Start computing a chunk; returns a future of its JSON array."""

    def recover(self, error: BaseException) -> None:
        """Called after a future failed with ``error``; repair the backend if it broke."""

    def close(self) -> None:
        """Stop every worker, dropping unfinished work."""


def _init_worker(threads: int, parent: int) -> None:
    """Pool worker start-up: end with the server (``parent``: a kill -9 of it must not leave
    this process, and the resource tracker it holds open, behind), share the cores fairly and
    load the kernels once."""
    exit_with_parent(parent)
    import numba

    from gearengine.numerics.simulation import warm_up

    numba.set_num_threads(threads)
    warm_up()


def _ready() -> int:
    return os.getpid()


class LocalPool:
    """``workers`` spawned processes on this machine (numba threads: cores / workers)."""

    name = "local"

    def __init__(self, workers: int) -> None:
        self.workers = workers
        self._pool = self._start()

    def _start(self) -> ProcessPoolExecutor:
        threads = max(1, (os.cpu_count() or 1) // self.workers)
        pool = ProcessPoolExecutor(
            self.workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_init_worker,
            initargs=(threads, os.getpid()),
        )
        # the workers start and warm up in the background (the server is ready meanwhile);
        # capacity() stays 0, so no chunk is claimed, until every one of them has answered
        self._warming = [pool.submit(_ready) for _ in range(self.workers)]
        return pool

    def capacity(self) -> int:
        if self._warming:
            if not all(f.done() for f in self._warming):
                return 0
            warming, self._warming = self._warming, []
            try:
                for f in warming:
                    f.result()
            except BrokenProcessPool as exc:  # a worker died while starting: a fresh pool
                self.recover(exc)
                return 0
        return self.workers

    def submit(self, claim: Claim) -> Future[str]:
        return self._pool.submit(
            compute_chunk_json, claim.kind, claim.request_json, claim.index, claim.chunk_points
        )

    def recover(self, error: BaseException) -> None:
        """Replace the pool once after a worker died (every chunk of the old pool fails)."""
        if not isinstance(error, BrokenProcessPool):
            return
        try:
            self._pool.submit(_ready)
        except BrokenProcessPool:
            self.close()
            self._pool = self._start()

    def close(self) -> None:
        processes = list((self._pool._processes or {}).values())  # no public API before 3.14
        self._pool.shutdown(wait=False, cancel_futures=True)
        for p in processes:
            p.terminate()
        for p in processes:
            p.join(timeout=5)


class DaskCluster:
    """A Dask distributed scheduler at ``address``; keeps no state the store does not have."""

    name = "dask"

    def __init__(self, address: str) -> None:
        from distributed import Client

        self.client = Client(address, timeout=30)

    def capacity(self) -> int:
        return max(1, sum(self.client.nthreads().values()))

    def submit(self, claim: Claim) -> Any:
        return self.client.submit(
            compute_chunk_json,
            claim.kind,
            claim.request_json,
            claim.index,
            claim.chunk_points,
            key=f"{claim.kind}-{claim.job_id}-{claim.index}-{claim.attempt}",
            pure=False,
        )

    def recover(self, error: BaseException) -> None:
        """Dask reschedules lost tasks itself and reconnects on its own."""

    def close(self) -> None:
        self.client.close()


def make_backend(workers: int, dask_address: str | None) -> Backend | None:
    """Dask if an address is given, else a local pool of ``workers`` (None when 0)."""
    if dask_address:
        return DaskCluster(dask_address)
    return LocalPool(workers) if workers > 0 else None
