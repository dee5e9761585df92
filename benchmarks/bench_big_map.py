"""A 1000 x 1000 chaos map at light settings through the real service: time and peak memory.

Run:  .venv/bin/python benchmarks/bench_big_map.py [--num 1000]
Starts ``gearengine serve`` (GEARCHAOS_MAX_SWEEP_POINTS and GEARCHAOS_MAX_SWEEP_STEPS raised to
admit the map, chunks of GEARCHAOS_SWEEP_CHUNK_POINTS = 1024 points), submits the map of
examples/chaos-map.json with num x num points at 10 + 10 periods x 16 RK4 steps and
``"outputs": ["classification", "period"]``, waits for it, then streams the CSV and the JSON
result to files. psutil samples the resident memory of the server process and of its worker
processes every 0.1 s; the peaks are reported with the sizes of the store and of the results.
Writes its section of benchmarks/README.md (for num = 1000).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import httpx
import psutil
from common import wait_ready  # benchmarks/common.py
from report import write_section  # benchmarks/report.py (the script's own folder)

ROOT = Path(__file__).resolve().parents[1]
MB = 1024 * 1024


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Peak(threading.Thread):
    """Peak RSS of a process (``main``) and of the sum of its children, sampled."""

    def __init__(self, pid: int) -> None:
        super().__init__(daemon=True)
        self.proc = psutil.Process(pid)
        self.main = 0
        self.children = 0
        self.stop = threading.Event()

    def run(self) -> None:
        while not self.stop.is_set():
            try:
                self.main = max(self.main, self.proc.memory_info().rss)
                kids = 0
                for c in self.proc.children(recursive=True):
                    with contextlib.suppress(psutil.Error):
                        kids += c.memory_info().rss
                self.children = max(self.children, kids)
            except psutil.Error:
                pass
            time.sleep(0.1)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--num", type=int, default=1000)
    args = parser.parse_args()
    num = args.num
    doc = json.loads((ROOT / "examples" / "chaos-map.json").read_text())
    doc["settings"] = {"transient_periods": 10, "record_periods": 10, "steps_per_period": 16}
    doc["outputs"] = ["classification", "period"]
    for axis in doc["axes"]:
        axis["num"] = num
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        port = free_port()
        env = {**os.environ, "GEARCHAOS_MAX_SWEEP_POINTS": str(num * num),
               "GEARCHAOS_MAX_SWEEP_STEPS": str(10**12),
               "GEARCHAOS_SWEEP_CHUNK_POINTS": "1024"}  # fmt: skip
        log = open(tmp / "server.log", "w")  # noqa: SIM115
        cmd = [sys.executable, "-m", "gearengine.cli", "serve", "--port", str(port),
               "--data-dir", str(tmp / "data")]  # fmt: skip
        proc = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=log, stderr=subprocess.STDOUT)
        peak = Peak(proc.pid)
        peak.start()
        try:
            with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=600) as c:
                wait_ready(c)
                t0 = time.perf_counter()
                r = c.post("/v1/sweeps", json=doc)
                assert r.status_code in (200, 201, 202), r.text
                job = r.json()
                while (s := c.get(f"/v1/sweeps/{job['id']}").json())["status"] in (
                    "queued", "running"
                ):  # fmt: skip
                    time.sleep(0.5)
                assert s["status"] == "succeeded", s
                t_run = time.perf_counter() - t0
                sizes = {}
                for fmt in ("csv", "json"):
                    t = time.perf_counter()
                    n = 0
                    with c.stream("GET", f"/v1/sweeps/{job['id']}/result?format={fmt}") as resp:
                        assert resp.status_code == 200
                        with open(tmp / f"result.{fmt}", "wb") as f:
                            for part in resp.iter_bytes():
                                n += len(part)
                                f.write(part)
                    sizes[fmt] = (n, time.perf_counter() - t)
                with open(tmp / "result.csv") as f:
                    lines = sum(1 for _ in f)
                assert lines == num * num + 1
        finally:
            peak.stop.set()
            proc.terminate()
            proc.wait(timeout=60)
            log.close()
        store = sum(f.stat().st_size for f in (tmp / "data").glob("jobs.sqlite3*"))
    text = (
        f"{num} x {num} map ({num * num} points) of examples/chaos-map.json, 10 + 10 periods x "
        '16 RK4 steps, `"outputs": ["classification", "period"]`, through `gearengine serve` '
        f"(chunks of 1024 points): submit to succeeded {t_run:.0f} s; CSV streamed "
        f"{sizes['csv'][0] / MB:.1f} MB in {sizes['csv'][1]:.1f} s, JSON "
        f"{sizes['json'][0] / MB:.1f} MB in {sizes['json'][1]:.1f} s; job store "
        f"{store / MB:.1f} MB (zlib). Peak RSS: server process **{peak.main / MB:.0f} MB**, its "
        f"worker processes together {peak.children / MB:.0f} MB.\n"
    )
    print(text)
    if num == 1000:
        write_section(
            "big-map",
            "## A 1000 x 1000 map through the service: memory\n\n"
            "Reproduce: `.venv/bin/python benchmarks/bench_big_map.py` (rewrites this "
            "section).\n\n" + text,
        )


if __name__ == "__main__":
    main()
