"""Compact sweep results: ``outputs`` keeps only the named point fields in the chunk JSON, the
result and the CSV; chunk results are stored zlib-compressed; a map's result streams."""

from __future__ import annotations

import csv
import io
import json
import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from pydantic import ValidationError

from gearengine.studies.sweep import compute_chunk_json, csv_rows, run_local, validated
from service.core.config import Settings
from service.jobs.store import DB_FILE, pack, unpack
from service.main import create_app
from tests._polling import poll
from tests.conftest import PAPER_PARAMS, started

SHORT = {"transient_periods": 50, "record_periods": 50, "steps_per_period": 64}


def body(**extra: Any) -> dict[str, Any]:
    axes = [{"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 5},
            {"parameter": "Omega_e", "start": 0.4, "stop": 0.6, "num": 2}]  # fmt: skip
    return {"params": PAPER_PARAMS, "settings": SHORT, "axes": axes, **extra}


def test_outputs_keep_only_the_named_fields() -> None:
    req = validated(body(outputs=["classification", "period"]))
    points = json.loads(compute_chunk_json(req.model_dump_json(), 0, 4))
    assert [sorted(p) for p in points] == [["branch", "classification", "period", "values"]] * 4
    full = run_local(validated(body()))
    compact = run_local(req)
    assert [(p.classification, p.period) for p in compact.points] == [
        (p.classification, p.period) for p in full.points
    ]
    assert all(p.poincare_x is None and p.lle is None for p in compact.points)
    rows = list(csv.reader(io.StringIO("".join(csv_rows(req.axes, compact.points, req.outputs)))))
    assert rows[0] == ["F_e1", "Omega_e", "branch", "classification", "period"]
    assert len(rows) == 11


def test_outputs_are_validated() -> None:
    with pytest.raises(ValidationError, match="outputs"):
        validated(body(outputs=["classification", "no_such_field"]))
    with pytest.raises(ValidationError, match="outputs"):
        validated(body(outputs=[]))


def test_pack_round_trip_and_old_text_rows() -> None:
    text = json.dumps([{"values": {"F_e1": 0.1}, "classification": "periodic"}] * 100)
    packed = pack(text)
    assert isinstance(packed, bytes) and len(packed) < len(text) // 10
    assert unpack(packed) == text and unpack(text) == text


@pytest.fixture(scope="module")
def working(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[TestClient, Path]]:
    data = tmp_path_factory.mktemp("jobs")
    settings = Settings(data_dir=data, workers=1, sweep_chunk_points=4)
    with started(create_app(settings)) as c:
        yield c, data


def test_service_stores_compressed_chunks_and_streams_compact_results(working) -> None:
    c, data = working
    doc = body(outputs=["classification", "period", "lle"])
    job_id = c.post("/v1/sweeps", json=doc).json()["id"]
    poll(lambda: c.get(f"/v1/sweeps/{job_id}").json())
    result = c.get(f"/v1/sweeps/{job_id}/result").json()
    assert len(result["points"]) == 10 and result["windows"] is None
    assert all(sorted(p) == ["branch", "classification", "lle", "period", "values"]
               for p in result["points"])  # fmt: skip
    keep = {"points": {"__all__": {"values", "branch", *doc["outputs"]}}}
    local = run_local(validated(doc)).model_dump(mode="json", include=keep)
    assert result["points"] == local["points"]
    text = c.get(f"/v1/sweeps/{job_id}/result?format=csv").text
    assert text.splitlines()[0] == "F_e1,Omega_e,branch,classification,period,lle [1/tau]"
    with sqlite3.connect(data / DB_FILE) as db:
        stored = db.execute("SELECT result_json FROM chunks WHERE job_id = ?", (job_id,)).fetchall()
    assert stored and all(isinstance(row[0], bytes) for row in stored)
