"""Chunks on a real Dask distributed cluster (LocalCluster, threads): the embedded dispatcher
and the ``gearengine worker --dask`` command, with the SQLite store as the source of truth."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from distributed import LocalCluster

from gearengine.studies.sweep import SweepPlan, run_local, validated
from service.jobs.backends import DaskCluster
from service.jobs.dispatcher import Dispatcher
from service.jobs.store import JobStore
from tests._polling import UNFINISHED, poll
from tests.conftest import PAPER_PARAMS

DOC = {
    "params": PAPER_PARAMS,
    "settings": {"transient_periods": 50, "record_periods": 50, "steps_per_period": 64},
    "axes": [
        {"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 5},
        {"parameter": "Omega_e", "start": 0.4, "stop": 0.8, "num": 3},
    ],
}


@pytest.fixture(scope="module")
def cluster() -> Iterator[LocalCluster]:
    with LocalCluster(
        n_workers=1,
        threads_per_worker=2,
        processes=False,
        protocol="tcp://",
        host="127.0.0.1",
        dashboard_address=None,
    ) as c:
        yield c


def submit(store: JobStore, chunk_points: int = 4) -> str:
    req = validated(DOC)
    plan = SweepPlan(req, chunk_points)
    return store.submit(None, req.model_dump_json(), plan.point_counts(), chunk_points, 10).id


def wait_done(store: JobStore, job_id: str, timeout: float = 60.0) -> str:
    return poll(lambda: store.get(job_id, None).status, lambda s: s not in UNFINISHED, timeout)


def stored_result(store: JobStore, job_id: str) -> list[str]:
    return list(store.chunk_results(job_id))


def test_dispatcher_on_dask_equals_run_local(cluster: LocalCluster, tmp_path: Path) -> None:
    store = JobStore.in_dir(tmp_path)
    job = submit(store)
    dispatcher = Dispatcher(store, DaskCluster(cluster.scheduler_address), lease_seconds=5.0)
    dispatcher.start()
    try:
        assert wait_done(store, job) == "succeeded"
    finally:
        dispatcher.stop()
    points = [p for arr in stored_result(store, job) for p in json.loads(arr)]
    assert points == run_local(validated(DOC), chunk_points=4).model_dump(mode="json")["points"]
    assert sorted(i for i, _ in store.commit_log(job)) == list(range(4))


def test_worker_command_on_dask_stops_gracefully(cluster: LocalCluster, tmp_path: Path) -> None:
    store = JobStore.in_dir(tmp_path)
    job = submit(store, chunk_points=2)
    cmd = [sys.executable, "-m", "gearengine.cli", "worker", "--data-dir", str(tmp_path)]
    proc = subprocess.Popen([*cmd, "--dask", cluster.scheduler_address], stderr=subprocess.PIPE)
    try:
        assert wait_done(store, job) == "succeeded"
        assert len(stored_result(store, job)) == 8
    finally:
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=30)
    assert proc.returncode == 0, err.decode()
    assert b"stopped" in err
