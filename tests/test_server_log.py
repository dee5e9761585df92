"""The server's log lines survive a stopping signal (service.server.log_to_stderr)."""

from __future__ import annotations

import io
import logging
import queue
import subprocess
import sys
import time

import pytest

from service.server import RecordQueue, flush_log, log_to_stderr

PROGRAM = """
import logging, signal
from service.server import flush_log, log_to_stderr
log_to_stderr()
for i in range(20000):
    logging.getLogger("gearchaos.access").info('{"event": "request", "n": %d}', i)
{end}
signal.raise_signal(signal.SIGTERM)  # as uvicorn does after its shutdown
"""


def lines_written(end: str) -> int:
    run = subprocess.run(
        [sys.executable, "-c", PROGRAM.replace("{end}", end)], capture_output=True, text=True
    )
    assert run.returncode == -15  # killed by the re-raised SIGTERM, as a server is
    return run.stderr.count('"event": "request"')


def test_queued_lines_are_written_before_the_signal_ends_the_process() -> None:
    """20,000 lines queued at once (a loaded server stopping) all reach stderr: the servers'
    shutdown calls ``flush_log``, as here; atexit does not run once the signal is re-raised."""
    assert lines_written("flush_log()") == 20000


class CountingStream(io.StringIO):
    """stderr that counts its writes."""

    writes = 0

    def write(self, text: str) -> int:
        self.writes += 1
        return super().write(text)


def test_lines_are_written_in_batches(monkeypatch: pytest.MonkeyPatch) -> None:
    """Lines logged one at a time, as requests come, are written whole and in order, many to a
    write: a wake-up of the log thread and a write a line took the GIL from the event loop
    once a request."""
    stream = CountingStream()
    monkeypatch.setattr(sys, "stderr", stream)
    root = logging.getLogger()
    handlers, level = root.handlers[:], root.level
    try:
        log_to_stderr()
        for i in range(50):
            logging.getLogger("gearchaos.access").info('{"event": "request", "n": %d}', i)
            time.sleep(0.001)
        flush_log()
    finally:
        root.handlers[:], root.level = handlers, level
    assert stream.getvalue().splitlines() == [
        f'{{"event": "request", "n": {i}}}' for i in range(50)
    ]
    assert stream.writes <= 5


def test_a_plain_record_is_queued_as_it_is() -> None:
    """An access line (a str message, no arguments) goes on the queue without the format and
    copy of ``QueueHandler.prepare`` (a fifth of a health check's middleware CPU); a record
    with arguments or an exception is still prepared, its line formatted where it was logged."""
    handler = RecordQueue(queue.SimpleQueue())
    plain = logging.LogRecord("gearchaos.access", logging.INFO, __file__, 1, '{"a": 1}', (), None)
    assert handler.prepare(plain) is plain
    with_args = logging.LogRecord("gearchaos", logging.INFO, __file__, 1, "job %s", ("x",), None)
    prepared = handler.prepare(with_args)
    assert prepared is not with_args and (prepared.msg, prepared.args) == ("job x", None)
    try:
        raise ValueError("boom")
    except ValueError:
        failed = logging.LogRecord(
            "gearchaos", logging.ERROR, __file__, 1, "failed", (), sys.exc_info()
        )
    prepared = handler.prepare(failed)
    assert prepared.exc_info is None and "ValueError: boom" in prepared.msg
