"""The uvicorn server of ``gearengine serve``: it says in one line when the service is ready."""

from __future__ import annotations

import socket
from pathlib import Path

import uvicorn

from service.core.config import Settings

EXIT_STARTUP_FAILURE = 3
"""uvicorn could not start (the port is taken, the lifespan failed): uvicorn's own code."""


def ready_line(settings: Settings, port: int) -> str:
    """Where the service answers, where its docs and data are, and how to stop it."""
    data = str(settings.data_dir)
    if not Path(data).is_absolute() and not data.startswith("."):
        data = f"./{data}"
    host = f"[{settings.host}]" if ":" in settings.host else settings.host
    return f"ready on http://{host}:{port}, docs at /docs, data in {data}, Ctrl-C stops"


class AnnouncingServer(uvicorn.Server):
    """Prints ``ready_line`` to standard output once the socket listens. That is after the
    lifespan's start-up (kernels warmed, job store open): uvicorn binds the socket only then,
    so the lifespan itself would say it too early."""

    def __init__(self, config: uvicorn.Config, settings: Settings) -> None:
        super().__init__(config)
        self.settings = settings

    async def startup(self, sockets: list[socket.socket] | None = None) -> None:
        await super().startup(sockets)
        if self.started:
            port = self.servers[0].sockets[0].getsockname()[1]
            print(ready_line(self.settings, port), flush=True)
