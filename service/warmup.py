"""The kernels warm up after the ready line: ``gearengine serve`` answers as soon as its socket
listens and the job store is open, while a background thread compiles (fresh clone: about a
minute and a half on a loaded 2-core machine) or loads from numba's cache (a few seconds) every
kernel, then starts the sweep dispatcher, whose pool workers then load the kernels this thread
has just cached instead of compiling them too. ``GET /v1/ready`` says ``kernels: false`` (503)
until then; a request meanwhile is answered, the first of its kind after numba compiled what it
needs (numba's compiler lock serialises the two threads' compilations).
"""

from __future__ import annotations

import logging
import threading
import time

from service.core.config import Settings
from service.jobs.runtime import JobQueue
from service.speed import KernelSpeed

log = logging.getLogger("gearchaos.startup")


def warm_up_kernels() -> None:
    """Compile or load every numba kernel once, so the first request is fast."""
    from gearengine.homoclinic.batch import warm_up as warm_up_melnikov
    from gearengine.numerics import warm_up

    warm_up()
    warm_up_melnikov()


class KernelWarmUp:
    """A daemon thread: ``warm_up_kernels``, the measurement of the kernels' speed (``speed``,
    which sets the synchronous budget), then the sweep dispatcher of ``jobs``; ``done`` is set
    when all happened (the ``kernels`` readiness check)."""

    def __init__(self, jobs: JobQueue, settings: Settings, speed: KernelSpeed) -> None:
        self.jobs = jobs
        self.settings = settings
        self.speed = speed
        self.done = threading.Event()
        self._lock = threading.Lock()
        self._stopping = False
        self._thread = threading.Thread(target=self._run, name="kernel-warm-up", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        """No dispatcher is started after this (the service is shutting down)."""
        with self._lock:
            self._stopping = True

    def _run(self) -> None:
        start = time.monotonic()
        try:
            warm_up_kernels()
            self.speed.measure()  # before the dispatcher's workers load the cores
        except Exception:  # a bug: every request would meet it too; stay not ready
            log.exception("kernel warm-up failed")
            return
        with self._lock:
            if self._stopping:
                return
            self.jobs.start_dispatcher(self.settings)
        log.info("kernels ready in %.1f s, sweep dispatcher started", time.monotonic() - start)
        self.done.set()
