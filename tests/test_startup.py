"""Start-up faults: a bad data directory or an unsafe bind is refused at once, clearly."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from service.core.config import Settings
from service.jobs.runtime import JobQueue
from service.main import create_app
from service.speed import KernelSpeed
from service.warmup import KernelWarmUp
from tests.conftest import Server, free_port, started


def serve(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-m", "gearengine.cli", "serve", "--port", str(free_port()), *args]
    return subprocess.run(
        cmd, capture_output=True, text=True, timeout=60, env={**os.environ, **(env or {})}
    )


@pytest.fixture
def read_only_dir(tmp_path: Path) -> Iterator[Path]:
    """A directory nobody can write to (root ignores modes, so use a kernel filesystem)."""
    if os.geteuid() == 0:
        yield Path("/sys/kernel")
        return
    path = tmp_path / "ro"
    path.mkdir()
    path.chmod(0o500)
    yield path
    path.chmod(0o700)


def test_read_only_data_dir_is_refused_at_start(read_only_dir: Path) -> None:
    out = serve("--data-dir", str(read_only_dir))
    assert out.returncode == 2
    assert f"data directory {read_only_dir} is not writable" in out.stderr


def test_data_dir_under_a_file_is_refused(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    out = serve("--data-dir", str(blocker / "data"))
    assert out.returncode == 2 and "is not writable" in out.stderr


def test_missing_data_dir_is_created(tmp_path: Path) -> None:
    data = tmp_path / "new" / "nested" / "data"
    srv = Server(data)
    try:
        assert httpx.get(srv.url + "/v1/ready", timeout=5).status_code == 200
        assert data.is_dir()
    finally:
        srv.stop()


def test_public_bind_needs_keys_or_insecure(tmp_path: Path) -> None:
    out = serve("--host", "0.0.0.0", "--data-dir", str(tmp_path))
    assert out.returncode == 2 and "without API keys" in out.stderr
    assert "--insecure" in out.stderr


def test_sigterm_shuts_down_gracefully(tmp_path: Path) -> None:
    """uvicorn finishes the lifespan shutdown, then re-raises SIGTERM (exit -15) by design."""
    srv = Server(tmp_path / "data")
    srv.proc.terminate()
    assert srv.proc.wait(timeout=30) in (0, -15)
    srv.stop()
    log = srv.output()
    assert "Application shutdown complete" in log and "Traceback" not in log


def test_keys_file_without_keys_does_not_count_as_auth(tmp_path: Path) -> None:
    """A comment-only keys file must not let a public bind start without authentication."""
    (tmp_path / "api_keys.sha256").write_text("# keys go here\n\n")
    out = serve("--host", "0.0.0.0", "--data-dir", str(tmp_path))
    assert out.returncode == 2 and "without API keys" in out.stderr


def test_malformed_keys_file_is_refused_naming_the_line(tmp_path: Path) -> None:
    (tmp_path / "api_keys.sha256").write_text("# team A\nmy-plain-secret\n")
    out = serve("--data-dir", str(tmp_path))
    assert out.returncode == 2
    assert "api_keys.sha256:2: not a sha256 hex digest" in out.stderr


def test_the_ready_line_does_not_wait_for_the_kernels(tmp_path: Path) -> None:
    """The lifespan's start-up only opens the store: the warm-up and then the dispatcher run
    in the background (``service.warmup``); ``kernels`` turns true once both happened."""
    app = create_app(Settings(data_dir=tmp_path, workers=1))
    with started(app) as c:
        assert app.state.jobs.dispatcher is not None
        assert c.get("/v1/ready").json()["checks"] == {"job_store": True, "kernels": True}


def test_no_dispatcher_starts_once_the_service_stops(tmp_path: Path) -> None:
    """A service stopped while its kernels warm up never starts its pool workers."""
    settings = Settings(data_dir=tmp_path, workers=1)
    jobs = JobQueue.open(settings)
    warming = KernelWarmUp(jobs, settings, KernelSpeed(settings))
    warming.stop()
    warming.start()
    warming._thread.join()
    assert jobs.dispatcher is None and not warming.done.is_set()
    jobs.close()
