"""The service's commands, ``gearengine serve`` and ``gearengine worker``.

The engine's command line knows nothing of the service: it loads the entry points of the group
``gearengine.commands`` (declared in ``pyproject.toml``), and ``register`` here adds these two
commands. At import time this module needs only the engine's command line: the settings
(pydantic-settings), fastapi and uvicorn are imported when a command runs.
"""

from __future__ import annotations

import argparse
import ipaddress
from pathlib import Path

from gearengine.cli.documents import EXIT_OK, InvalidInputError


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def cmd_serve(args: argparse.Namespace) -> int:
    """Start uvicorn with the API (imports the service only here: the engine has no web deps)."""
    import uvicorn

    from service.api.deps import load_key_hashes
    from service.core.config import Settings
    from service.main import create_app
    from service.server import (
        EXIT_STARTUP_FAILURE,
        AnnouncingServer,
        log_to_stderr,
        serve_processes,
    )

    flags = {
        "host": args.host,
        "port": args.port,
        "data_dir": args.data_dir,
        "workers": args.workers,
        "http_processes": args.http_processes,
        "dask_scheduler": args.dask,
        "database_url": args.database_url,
        "insecure": args.insecure or None,
    }
    settings = Settings(**{k: v for k, v in flags.items() if v is not None})
    try:
        keys = load_key_hashes(settings)
    except ValueError as exc:
        raise InvalidInputError([str(exc)]) from None
    if not _is_loopback(settings.host) and not keys and not settings.insecure:
        raise InvalidInputError(
            [
                f"refusing to serve on {settings.host} without API keys: set "
                "GEARCHAOS_API_KEYS, or put key digests in the data directory's "
                "api_keys.sha256, or pass --insecure"
            ]
        )
    try:
        Path(settings.data_dir).mkdir(parents=True, exist_ok=True)
        probe = Path(settings.data_dir) / ".write-probe"
        probe.write_text("ok")
        probe.unlink()
    except OSError as exc:
        raise InvalidInputError(
            [f"data directory {settings.data_dir} is not writable: {exc.strerror}"]
        ) from None
    log_to_stderr()
    config = uvicorn.Config(
        create_app(settings),
        host=settings.host,
        port=settings.port,
        log_level="info",
        access_log=False,  # the app logs each request once, as a JSON line (AccessLog)
        timeout_keep_alive=settings.keep_alive_seconds,
    )
    if settings.http_processes > 1:  # several HTTP processes, one dispatcher
        return EXIT_OK if serve_processes(config, settings) else EXIT_STARTUP_FAILURE
    server = AnnouncingServer(config, settings)  # prints the one "ready on ..." line
    server.run()
    return EXIT_OK if server.started else EXIT_STARTUP_FAILURE


def cmd_worker(args: argparse.Namespace) -> int:
    """Run sweep workers on the data directory's job store (``service.jobs.worker``)."""
    from service.core.config import Settings
    from service.jobs.worker import run_worker

    flags = {
        "data_dir": args.data_dir,
        "workers": args.workers,
        "dask_scheduler": args.dask,
        "database_url": args.database_url,
    }
    return run_worker(Settings(**{k: v for k, v in flags.items() if v is not None}))


DATABASE_URL_HELP = (
    "PostgreSQL job store shared by replicas (postgresql://...; default: SQLite in the data dir)"
)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``serve`` and ``worker`` to the ``gearengine`` command line (entry point)."""
    p = sub.add_parser("serve", help="start the HTTP API and the sweep workers")
    p.add_argument("--host", default=None, help="bind address (default 127.0.0.1)")
    p.add_argument("--port", type=int, default=None, help="TCP port (default 8000)")
    p.add_argument("--data-dir", default=None, help="directory holding all state (default ./data)")
    p.add_argument("--workers", type=int, default=None, help="sweep worker processes")
    p.add_argument(
        "--http-processes",
        type=int,
        default=None,
        help="HTTP server processes on the one port (default: cores)",
    )
    p.add_argument("--dask", default=None, metavar="ADDRESS", help="Dask scheduler for sweeps")
    p.add_argument("--database-url", default=None, metavar="URL", help=DATABASE_URL_HELP)
    p.add_argument(
        "--insecure", action="store_true", help="allow a non-loopback bind without API keys"
    )
    p.set_defaults(func=cmd_serve)

    p = sub.add_parser("worker", help="run sweep workers on a data directory's job store")
    p.add_argument("--data-dir", default=None, help="directory holding the job store")
    p.add_argument("--workers", type=int, default=None, help="worker processes (default: cores)")
    p.add_argument("--dask", default=None, metavar="ADDRESS", help="Dask scheduler to run on")
    p.add_argument("--database-url", default=None, metavar="URL", help=DATABASE_URL_HELP)
    p.set_defaults(func=cmd_worker)
