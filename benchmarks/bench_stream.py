"""Streaming a big map's CSV and JSON: through ``gearengine serve`` and the CLI's CSV writer.

Run:  .venv/bin/python benchmarks/bench_stream.py [--num 300]
A real ``gearengine serve`` (limits raised to admit the map, chunks of 1024 points) computes the
num x num map of examples/chaos-map.json at 10 + 10 periods x 16 RK4 steps, once with
``"outputs": ["classification", "period"]`` (the big-map benchmark's columns) and once with
every output (64 Poincare numbers a row); each result is then streamed as CSV and as JSON
(``GET /v1/sweeps/{id}/result``, httpx, written to a file), MB/s = bytes / seconds from request
to last byte, best of 2. The CLI row writes the CSV of the full result in process as
``gearengine sweep`` does (``"".join(to_csv(result))``). Target (issue 20): >= 10 MB/s.
Prints the load average; writes its section of benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import httpx
from bench_big_map import MB  # benchmarks/bench_big_map.py
from common import served  # benchmarks/common.py
from report import write_section  # benchmarks/report.py (the script's own folder)

from gearengine.numerics.simulation import warm_up
from gearengine.studies.sweep.results import SweepResult, to_csv

ROOT = Path(__file__).resolve().parents[1]


def map_doc(num: int, outputs: list[str] | None) -> dict:
    doc = json.loads((ROOT / "examples" / "chaos-map.json").read_text())
    doc["settings"] = {"transient_periods": 10, "record_periods": 10, "steps_per_period": 16}
    if outputs is not None:
        doc["outputs"] = outputs
    for axis in doc["axes"]:
        axis["num"] = num
    return doc


def submit_and_wait(c: httpx.Client, doc: dict) -> str:
    r = c.post("/v1/sweeps", json=doc)
    assert r.status_code in (200, 201, 202), r.text
    job = r.json()["id"]
    while (s := c.get(f"/v1/sweeps/{job}").json())["status"] in ("queued", "running"):
        time.sleep(0.2)
    assert s["status"] == "succeeded", s
    return job


def stream(c: httpx.Client, job: str, fmt: str, path: Path) -> tuple[int, float]:
    """(bytes, seconds) of streaming the result of ``job`` as ``fmt`` into ``path``."""
    t = time.perf_counter()
    n = 0
    with c.stream("GET", f"/v1/sweeps/{job}/result?format={fmt}") as resp, open(path, "wb") as f:
        assert resp.status_code == 200
        for part in resp.iter_bytes():
            n += len(part)
            f.write(part)
    return n, time.perf_counter() - t


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--num", type=int, default=300)
    num = parser.parse_args().num
    warm_up()  # numba's caches filled before the server loads them
    rows = []
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        env = {"GEARCHAOS_MAX_SWEEP_POINTS": str(num * num),
               "GEARCHAOS_MAX_SWEEP_STEPS": str(10**12),
               "GEARCHAOS_SWEEP_CHUNK_POINTS": "1024"}  # fmt: skip
        with served(tmp / "data", env) as c:
            for label, outputs in (("classification, period", ["classification", "period"]),
                                   ("every output", None)):  # fmt: skip
                job = submit_and_wait(c, map_doc(num, outputs))
                for fmt in ("csv", "json"):
                    n, s = min((stream(c, job, fmt, tmp / f"result.{fmt}") for _ in range(2)),
                               key=lambda r: r[1])  # fmt: skip
                    rows.append((f"service {fmt.upper()}, {label}", n, s))
        result = SweepResult.model_validate_json((tmp / "result.json").read_text())
        t = time.perf_counter()
        text = "".join(to_csv(result))
        rows.append(("CLI CSV writer (`to_csv`), every output", len(text.encode()),
                     time.perf_counter() - t))  # fmt: skip
    load = os.getloadavg()[0]
    table = ["| what | MB | s | MB/s |", "| --- | ---: | ---: | ---: |"]
    table += [f"| {w} | {n / MB:.1f} | {s:.2f} | **{n / MB / s:.1f}** |" for w, n, s in rows]
    section = (
        "## Streaming a big map's CSV and JSON\n\n"
        "Reproduce: `.venv/bin/python benchmarks/bench_stream.py` (rewrites this section).\n\n"
        f"{num} x {num} map of examples/chaos-map.json at 10 + 10 periods x 16 steps through a "
        "real `gearengine serve`, streamed with httpx from request to last byte; the CLI row "
        "writes the CSV in process as `gearengine sweep` does. Target (issue 20): >= 10 MB/s. "
        "The service hands a streamed CSV to the socket in pieces of 64 kB "
        "(`sweeps.export.text_blocks`); row by row it ran at 0.5 MB/s.\n\n"
        + "\n".join(table)
        + f"\n\nLoad average (1 min) at the end of the run: {load:.1f} on 2 cores.\n"
    )
    print(section)
    write_section("stream", section)


if __name__ == "__main__":
    main()
