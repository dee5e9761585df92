"""``gearengine worker``: a dispatcher without the API, on a process pool or a Dask cluster."""

from __future__ import annotations

import logging
import signal
from types import FrameType

from service.core.config import Settings
from service.jobs.backends import make_backend
from service.jobs.dispatcher import Dispatcher
from service.jobs.store import JobStore


def run_worker(settings: Settings) -> int:
    """Run a dispatcher on the configured store (``database_url``, else the data directory's)
    until SIGTERM or SIGINT (graceful)."""
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s %(message)s")
    backend = make_backend(max(1, settings.workers), settings.dask_scheduler)
    assert backend is not None
    store = JobStore.configured(settings)
    dispatcher = Dispatcher(store, backend, settings.lease_seconds, settings.max_retries)

    def on_signal(signum: int, _: FrameType | None) -> None:
        logging.getLogger("gearchaos.jobs").info("signal %d: stopping", signum)
        dispatcher.request_stop()

    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    dispatcher.run()
    store.shutdown()
    return 0
