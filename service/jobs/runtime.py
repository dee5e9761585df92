"""The job queue of one process (jobs of every kind): the store and, when there are workers, a
dispatcher."""

from __future__ import annotations

from dataclasses import dataclass

from service.core.config import Settings
from service.jobs.backends import make_backend
from service.jobs.dispatcher import Dispatcher
from service.jobs.store import JobStore


@dataclass
class JobQueue:
    """The job store (PostgreSQL at ``database_url``, else the data directory's SQLite file)
    and this process's dispatcher (None: store only)."""

    store: JobStore
    dispatcher: Dispatcher | None

    @classmethod
    def open(cls, settings: Settings) -> JobQueue:
        """Open the configured store; no dispatcher until ``start_dispatcher``
        (``service.warmup`` starts it once the kernels are compiled)."""
        return cls(JobStore.configured(settings), None)

    def start_dispatcher(self, settings: Settings) -> None:
        """Start a dispatcher on Dask (``dask_scheduler``) or on a pool of ``workers``
        processes (none when workers == 0 and no Dask)."""
        backend = make_backend(settings.workers, settings.dask_scheduler)
        if backend is not None:
            dispatcher = Dispatcher(self.store, backend, settings.lease_seconds,
                                    settings.max_retries)  # fmt: skip
            dispatcher.start()
            self.dispatcher = dispatcher

    def wake(self) -> None:
        """Tell the local dispatcher that there is work."""
        if self.dispatcher is not None:
            self.dispatcher.wake()

    def ready(self) -> bool:
        """The store answers."""
        return self.store.ping()

    def close(self, grace: float = 5.0) -> None:
        """Stop the dispatcher gracefully and close the store's connections."""
        if self.dispatcher is not None:
            self.dispatcher.stop(grace)
        self.store.shutdown()
