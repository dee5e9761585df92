"""A 301-point bifurcation sweep over HTTP against ``gear_ref --simd --batch``, wall time.

Run:  .venv/bin/python benchmarks/bench_sweep.py
Starts a real ``gearengine serve`` (default settings: one worker process per core, chunks of
64 points), submits the paper's F_e1 = 0..0.3 sweep (Omega_e = 0.5, mu = 0.07, F_m = 0.01,
500 + 500 periods x 200 RK4 steps, default settings) with POST /v1/sweeps, polls the job every
10 ms and downloads the JSON result: the wall time is submission to result in hand. gear_ref
(gcc -O3 -march=native) runs the same 301 points with --simd --batch, wall time of the process.
Best of 5 each; writes its section of benchmarks/README.md. Target: HTTP <= 4x gear_ref.
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import httpx
from common import wait_ready  # benchmarks/common.py
from report import write_section  # benchmarks/report.py (the script's own folder)

ROOT = Path(__file__).resolve().parents[1]
GEAR_REF = Path("/work/shared/reference/gear_ref.c")
REPEATS = 5
PARAMS = {
    "damping": 0.07,
    "mean_force": 0.01,
    "backlash": {"model": "cubic", "a": 0.1667, "c": 0.1667},
    "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]},
}
SWEEP = {"params": PARAMS, "axes": [{"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 301}]}
GEAR_REF_ARGS = ["--simd", "--batch", "Fe", "0", "0.3", "301"]
GEAR_REF_ARGS += ["0.07", "0.2", "0.5", "0.01", "0", "1", "0", "1", "cubic", "200", "500", "500"]


def gear_ref_seconds(tmp: Path) -> float:
    """Best wall time of ``gear_ref --simd --batch`` over the 301 points, seconds."""
    exe = tmp / "gear_ref"
    gcc = shutil.which("gcc") or sys.exit("gcc is needed to build gear_ref")
    subprocess.run([gcc, "-O3", "-march=native", "-o", exe, GEAR_REF, "-lm"], check=True)
    times = []
    for _ in range(REPEATS):
        t = time.perf_counter()
        subprocess.run([exe, *GEAR_REF_ARGS], check=True, capture_output=True)
        times.append(time.perf_counter() - t)
    return min(times)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def http_sweep_seconds(tmp: Path) -> tuple[float, int]:
    """Best submission-to-result wall time of the sweep on a fresh server; and its workers."""
    port = free_port()
    url = f"http://127.0.0.1:{port}"
    cmd = [sys.executable, "-m", "gearengine.cli", "serve", "--port", str(port)]
    log = open(tmp / "server.log", "w")  # noqa: SIM115
    proc = subprocess.Popen(
        [*cmd, "--data-dir", str(tmp / "data")], cwd=ROOT, stdout=log, stderr=subprocess.STDOUT
    )
    try:
        with httpx.Client(base_url=url, timeout=60) as c:
            wait_ready(c)
            times = []
            for _ in range(REPEATS):
                t = time.perf_counter()
                job = c.post("/v1/sweeps", json=SWEEP).json()
                while c.get(f"/v1/sweeps/{job['id']}").json()["status"] in ("queued", "running"):
                    time.sleep(0.01)
                result = c.get(f"/v1/sweeps/{job['id']}/result").json()
                times.append(time.perf_counter() - t)
                assert len(result["points"]) == 301
    finally:
        proc.terminate()
        proc.wait(timeout=30)
        log.close()
    return min(times), os.cpu_count() or 1


def main() -> None:
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        ref = gear_ref_seconds(tmp)
        http, workers = http_sweep_seconds(tmp)
    ratio = http / ref
    table = (
        "| what | wall time, s | ratio to gear_ref |\n| --- | ---: | ---: |\n"
        f"| POST /v1/sweeps 301 points, submit to result (`gearengine serve`, {workers} "
        f"workers) | {http:.3f} | {ratio:.2f}x |\n"
        f"| gear_ref --simd --batch 301 points (one process) | {ref:.3f} | 1.00x |\n"
    )
    print(table)
    write_section(
        "sweeps",
        "## Sweeps over HTTP\n\n"
        "Reproduce: `.venv/bin/python benchmarks/bench_sweep.py` (rewrites this section).\n\n"
        "The paper's bifurcation sweep F_e1 = 0..0.3, 301 points, default settings (500 + 500 "
        "periods x 200 RK4 steps), submitted to a real `gearengine serve` with default "
        "settings; wall time from POST to the JSON result in hand (polling every 10 ms), best "
        f"of {REPEATS}. Target: at most 4x gear_ref.\n\n{table}",
    )


if __name__ == "__main__":
    main()
