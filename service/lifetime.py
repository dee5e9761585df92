"""A child process of ``gearengine serve`` that outlives it is an orphan holding memory (a pool
worker keeps ~220 MB of compiled kernels) or the port (an HTTP peer): each child watches its
parent and ends itself when the parent is gone, kill -9 included."""

from __future__ import annotations

import os
import signal
import threading
import time

PARENT_POLL_SECONDS = 0.5
"""How often a child checks that its parent still lives."""


def exit_with_parent(parent: int) -> None:
    """Start a daemon thread that kills this process (SIGKILL, no clean-up: the parent that
    would receive its results is dead) once it is no longer the child of ``parent``.

    Polling ``os.getppid`` works everywhere and whichever thread of the parent started the
    child; Linux's ``PR_SET_PDEATHSIG`` fires when that *thread* ends, so a pool worker started
    from a short-lived thread would die with it.
    """

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_POLL_SECONDS)
        os.kill(os.getpid(), signal.SIGKILL)

    threading.Thread(target=watch, name="parent-watch", daemon=True).start()
