"""The uvicorn server of ``gearengine serve``: it says in one line when the service is ready."""

from __future__ import annotations

import asyncio
import atexit
import contextlib
import ctypes
import json
import logging
import logging.handlers
import os
import queue
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import uvicorn

from service.core.config import Settings
from service.lifetime import exit_with_parent

EXIT_STARTUP_FAILURE = 3
"""uvicorn could not start (the port is taken, the lifespan failed): uvicorn's own code."""


LOG_BATCH_SECONDS = 0.1
"""How long the log thread gathers records after the first before writing them all at once."""


class LineWriter:
    """The log thread of ``log_to_stderr``: it wakes on a record, gathers what else arrives in
    ``LOG_BATCH_SECONDS``, and writes the formatted lines in one write. A wake-up and a write a
    line took the GIL from the event loop once a request: 0.06 ms of the median of a served
    request (GET /v1/health 0.19 against 0.13 ms without the line; benchmarks/README.md)."""

    def __init__(
        self, records: queue.SimpleQueue[logging.LogRecord | None], out: logging.StreamHandler
    ) -> None:
        self.records, self.out = records, out
        self.handlers: list[logging.Handler] = [out]  # flush_log goes back to writing with them
        self._thread = threading.Thread(target=self._run, name="log-writer", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        """Write every record queued so far, then end the thread."""
        self.records.put(None)
        self._thread.join()

    def _run(self) -> None:
        while True:
            batch = [self.records.get()]
            if batch[0] is not None:
                time.sleep(LOG_BATCH_SECONDS)
            with contextlib.suppress(queue.Empty):
                while batch[-1] is not None:
                    batch.append(self.records.get_nowait())
            self._write([r for r in batch if r is not None])
            if batch[-1] is None:
                return

    def _write(self, records: list[logging.LogRecord]) -> None:
        """The records' lines in one write (``StreamHandler.emit`` for many)."""
        if not records:
            return
        out = self.out
        try:
            text = "".join(out.format(r) + out.terminator for r in records)
            with out.lock:
                out.stream.write(text)
                out.flush()
        except Exception:  # as emit: logging never raises into the program
            out.handleError(records[0])


_LISTENER: list[LineWriter] = []
"""The log thread of this process, once ``log_to_stderr`` started it."""


class RecordQueue(logging.handlers.QueueHandler):
    """``QueueHandler`` that queues a plain record (a str message without arguments, exception
    or stack, such as every access line) as it is: its line is its message, which the writer
    formats the same later. ``QueueHandler.prepare`` formats and copies every record for a
    queue that may cross processes; for the log thread of this process that cost 7 us of the
    CPU of each request (a fifth of a health check's middleware). Other records are prepared
    as before."""

    def prepare(self, record: logging.LogRecord) -> logging.LogRecord:
        plain = isinstance(record.msg, str) and not record.args
        if plain and not record.exc_info and not record.stack_info:
            return record
        return super().prepare(record)


def log_to_stderr() -> None:
    """The server's log (a JSON line per request and per job transition) on stderr, written by
    a background thread: a request only puts its record on a queue (``RecordQueue``), and the
    ``LineWriter`` thread formats and writes the lines in batches. A write and flush per line on
    the event loop cost about 15 % of a Melnikov verdict's throughput (benchmarks/load.py).
    ``flush_log`` ends it; a normal exit (a start-up failure) does too, through ``atexit``."""
    records: queue.SimpleQueue[logging.LogRecord | None] = queue.SimpleQueue()
    out = logging.StreamHandler(sys.stderr)
    out.setFormatter(logging.Formatter("%(message)s"))
    writer = LineWriter(records, out)
    root = logging.getLogger()
    root.handlers[:] = [RecordQueue(records)]
    root.setLevel(logging.INFO)
    writer.start()
    _LISTENER.append(writer)
    atexit.register(flush_log)


def flush_log() -> None:
    """Write every queued log line and go back to writing lines directly. The servers call it
    at the end of their shutdown: uvicorn re-raises a stopping signal (SIGTERM from ``docker
    stop``, or from the parent to a peer) after it, so an ``atexit`` hook would not run."""
    while _LISTENER:
        writer = _LISTENER.pop()
        writer.stop()
        logging.getLogger().handlers[:] = list(writer.handlers)


def ready_line(settings: Settings, port: int) -> str:
    """Where the service answers, where its docs and data are, and how to stop it."""
    data = str(settings.data_dir)
    if not Path(data).is_absolute() and not data.startswith("."):
        data = f"./{data}"
    host = f"[{settings.host}]" if ":" in settings.host else settings.host
    return f"ready on http://{host}:{port}, docs at /docs, data in {data}, Ctrl-C stops"


PR_SET_PDEATHSIG = 1
"""prctl option: the signal a process gets when its parent dies (Linux)."""
PEER_START_SECONDS = 300.0
"""How long the first process waits for the others to accept before it says ready anyway."""
PEER_ENV = "GEARCHAOS_PEER"
"""Environment variable handing a peer (``python -m service.peer``) its socket and settings."""


@dataclass
class Peers:
    """The other HTTP processes of ``gearengine serve --http-processes N`` (N > 1), each a
    ``python -m service.peer`` subprocess sharing the listening socket. Each writes one byte to
    the ``up`` pipe once it accepts connections and its kernels are warm (``service.warmup``);
    when all have (``wait``), this process writes one byte to each peer's ``go`` pipe and
    ``all_up`` is set: ``GET /v1/ready`` of every process answers 200 only then, so a client
    that waited for ready finds all accepting and warm."""

    processes: list[subprocess.Popen]
    up: int
    go: list[int]
    all_up: threading.Event = field(default_factory=threading.Event)

    @classmethod
    def start(cls, n: int, sock: socket.socket, settings: Settings) -> Peers:
        up_r, up_w = os.pipe()
        os.set_blocking(up_r, False)
        processes, go = [], []
        for _ in range(n):
            go_r, go_w = os.pipe()
            spec = {
                "socket": sock.fileno(),
                "up": up_w,
                "go": go_r,
                "parent": os.getpid(),
                "settings": settings.model_dump(mode="json"),
            }
            processes.append(
                subprocess.Popen(
                    [sys.executable, "-m", "service.peer"],
                    env={**os.environ, PEER_ENV: json.dumps(spec)},
                    pass_fds=(sock.fileno(), up_w, go_r),
                )
            )
            os.close(go_r)
            go.append(go_w)
        os.close(up_w)
        return cls(processes, up_r, go)

    async def wait(self, server: uvicorn.Server) -> None:
        """Until every peer accepts (or one died, or the server stops, or PEER_START_SECONDS);
        then tell them all (``go``) and set ``all_up``."""
        deadline = time.monotonic() + PEER_START_SECONDS
        count = 0
        while count < len(self.processes) and time.monotonic() < deadline:
            if server.should_exit or any(p.poll() is not None for p in self.processes):
                break
            with contextlib.suppress(OSError):  # BlockingIOError: nothing yet
                count += len(os.read(self.up, 64))
            await asyncio.sleep(0.05)
        if count < len(self.processes) and not server.should_exit:
            logging.getLogger("gearchaos").warning(
                "only %d of %d extra HTTP processes ready", count, len(self.processes)
            )
        for fd in self.go:
            with contextlib.suppress(OSError):
                os.write(fd, b"1")
        self.all_up.set()

    def terminate(self) -> None:
        """SIGTERM every peer still running: uvicorn's graceful shutdown."""
        for p in self.processes:
            if p.poll() is None:
                p.terminate()

    def stop(self, grace: float = 10.0) -> None:
        """``terminate``, then SIGKILL what is left after ``grace`` seconds."""
        self.terminate()
        deadline = time.monotonic() + grace
        for p in self.processes:
            try:
                p.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        for fd in [self.up, *self.go]:  # once: a second stop must not close reused numbers
            if fd >= 0:
                with contextlib.suppress(OSError):
                    os.close(fd)
        self.up, self.go = -1, []


class AnnouncingServer(uvicorn.Server):
    """Prints ``ready_line`` to standard output once the socket listens. That is after the
    lifespan's start-up (job store open; the kernels warm up in the background after it,
    ``service.warmup``): uvicorn binds the socket only then, so the lifespan itself would say
    it too early. With ``peers``, it then waits for them (``Peers.wait``)."""

    def __init__(
        self, config: uvicorn.Config, settings: Settings, peers: Peers | None = None
    ) -> None:
        super().__init__(config)
        self.settings = settings
        self.peers = peers

    async def startup(self, sockets: list[socket.socket] | None = None) -> None:
        await super().startup(sockets)
        if self.started:
            port = self.servers[0].sockets[0].getsockname()[1]
            print(ready_line(self.settings, port), flush=True)
            if self.peers is not None:
                await self.peers.wait(self)

    async def shutdown(self, sockets: list[socket.socket] | None = None) -> None:
        """Peers shut down alongside this process, and are gone before it exits (uvicorn
        re-raises the stopping signal after its shutdown)."""
        if self.peers is not None:
            self.peers.terminate()
        await super().shutdown(sockets)
        if self.peers is not None:
            await asyncio.to_thread(self.peers.stop)
        flush_log()


class _PeerServer(uvicorn.Server):
    """A peer's uvicorn server: writes to its ``up`` pipe once it accepts connections and its
    kernels are warm."""

    def __init__(self, config: uvicorn.Config, up: int) -> None:
        super().__init__(config)
        self.up = up

    async def startup(self, sockets: list[socket.socket] | None = None) -> None:
        await super().startup(sockets)
        if self.started:
            warm = self.config.app.state.warm_up.done
            threading.Thread(target=lambda: warm.wait() and os.write(self.up, b"1"),
                             name="peer-up", daemon=True).start()  # fmt: skip

    async def shutdown(self, sockets: list[socket.socket] | None = None) -> None:
        """The queued log lines are written before uvicorn re-raises the parent's SIGTERM."""
        await super().shutdown(sockets)
        flush_log()


def serve_peer() -> None:
    """One more HTTP process (``python -m service.peer``, started by ``serve_processes``): the
    same app on the listening socket of ``gearengine serve``, without a sweep dispatcher
    (``workers=0``: store only; the first process's dispatcher picks submitted jobs up within
    its idle poll). It stops with uvicorn's signals, and at once when its parent dies (no
    orphan keeps the port)."""
    from service.main import create_app

    spec = json.loads(os.environ[PEER_ENV])
    parent = spec["parent"]
    with contextlib.suppress(OSError, AttributeError):  # Linux: killed when the parent dies
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)

    all_up = threading.Event()

    def wait_go() -> None:
        with contextlib.suppress(OSError):
            os.read(spec["go"], 1)
        all_up.set()

    exit_with_parent(parent)  # elsewhere, and if the parent died before prctl
    threading.Thread(target=wait_go, name="all-up", daemon=True).start()
    log_to_stderr()
    settings = Settings.model_validate(spec["settings"])
    app = create_app(settings.model_copy(update={"workers": 0, "dask_scheduler": None}))
    app.state.ready_checks["http_processes"] = all_up.is_set
    config = uvicorn.Config(
        app, log_level="warning", access_log=False, timeout_keep_alive=settings.keep_alive_seconds
    )
    sock = socket.socket(fileno=spec["socket"])
    _PeerServer(config, spec["up"]).run(sockets=[sock])


def serve_processes(config: uvicorn.Config, settings: Settings) -> bool:
    """``http_processes`` HTTP processes on one socket: this one (the sweep dispatcher, the
    ready line) and ``http_processes - 1`` peers (``serve_peer``); the kernel hands each new
    connection to whichever process accepts it first. True if this one started."""
    try:
        sock = config.bind_socket()
    except SystemExit:  # uvicorn could not bind (the port is taken) and logged why
        return False
    peers = Peers.start(settings.http_processes - 1, sock, settings)
    config.app.state.ready_checks["http_processes"] = peers.all_up.is_set
    server = AnnouncingServer(config, settings, peers)
    try:
        server.run(sockets=[sock])
    finally:
        peers.stop()
        sock.close()
    return server.started
