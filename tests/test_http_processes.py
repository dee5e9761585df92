"""`gearengine serve --http-processes N`: N HTTP processes on one port, one sweep dispatcher.

Speed is measured in benchmarks/load.py, never asserted here."""

from __future__ import annotations

import os
import signal
import socket
from pathlib import Path

import httpx
import psutil

from tests._polling import UNFINISHED, poll
from tests.conftest import PAPER_PARAMS, Server


def peers(server: Server) -> list[psutil.Process]:
    kids = psutil.Process(server.proc.pid).children()
    return [p for p in kids if "service.peer" in " ".join(p.cmdline())]


def wait_gone(processes: list[psutil.Process], timeout: float = 20.0) -> bool:
    _, alive = psutil.wait_procs(processes, timeout=timeout)
    return not alive


def port_free(port: int) -> bool:
    with socket.socket() as s:
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
        return True


def test_three_processes_answer_on_one_port_and_stop_together(tmp_path: Path) -> None:
    srv = Server(tmp_path / "data", None, "--http-processes", "3")
    try:
        others = peers(srv)
        assert len(others) == 2
        ready = httpx.get(srv.url + "/v1/ready", timeout=10).json()
        assert ready["checks"]["http_processes"] is True
        assert srv.output().count("ready on http://127.0.0.1") == 1
        for k in range(12):  # a new connection each: whichever process accepts it answers
            params = {**PAPER_PARAMS, "mean_force": 0.001 * k}
            r = httpx.post(srv.url + "/v1/melnikov", json={"params": params}, timeout=60)
            assert r.status_code == 200 and r.json()["chaos_possible"] is True
        axis = {"parameter": "F_e1", "start": 0.1, "stop": 0.2, "num": 2}
        sweep = {
            "params": PAPER_PARAMS,
            "axes": [axis],
            "settings": {"transient_periods": 10, "record_periods": 10},
        }
        jobs = [
            httpx.post(srv.url + "/v1/sweeps", json=sweep, timeout=60).json()["id"]
            for _ in range(4)
        ]
        states = poll(  # submitted to any process, run by the one dispatcher
            lambda: {httpx.get(f"{srv.url}/v1/sweeps/{j}", timeout=10).json()["status"]
                     for j in jobs},
            lambda s: not s & set(UNFINISHED), interval=0.3,
        )  # fmt: skip
        assert states == {"succeeded"}
    finally:
        srv.stop()
    assert srv.proc.returncode in (0, -signal.SIGTERM)  # uvicorn re-raises the signal
    assert wait_gone(others, timeout=0.5)  # stopped before the first process exits
    assert port_free(srv.port)


def test_killing_the_first_process_takes_the_others_with_it(tmp_path: Path) -> None:
    """kill -9 of `gearengine serve` leaves no peer holding the port, and no process at all."""
    srv = Server(tmp_path / "data", None, "--http-processes", "2")
    try:
        others = peers(srv)
        assert len(others) == 1
        os.kill(srv.proc.pid, signal.SIGKILL)
        srv.proc.wait(timeout=20)
        assert wait_gone(others)
        assert port_free(srv.port)
    finally:
        srv.stop()
    # the pool workers and the resource tracker end too (they used to live on, ~220 MB each)
    assert srv.orphans == []
