"""The server's log lines survive a stopping signal (service.server.log_to_stderr)."""

from __future__ import annotations

import subprocess
import sys

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
