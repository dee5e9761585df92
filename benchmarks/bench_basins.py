"""The cost of basins: an analysis with 64 and 256 basin starts against one start, and the
default envelope gate (16 basin starts per point) against ``--starts 1``.

Run:  .venv/bin/python benchmarks/bench_basins.py
Analyses: the envelope example's pair at 5,750 rpm and 2 N*m (examples/basins-5750rpm.json,
piecewise law, three excitations: 60 + 60 periods of 2,304 RK4 steps) and the paper's cubic
case Fe = 0.25 (200 + 200 periods of 200 steps, the lock-step kernel), in this process after a
warm-up, best of 2. Gate: ``gearengine check examples/envelope-map.json --speed 500:6000
--torque 2:40`` (23 x 5 points) as a new process, once each (it is long). Writes its section of
benchmarks/README.md; the machine is shared, so say how loaded it was.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

from common import best_of  # benchmarks/common.py
from report import write_section  # benchmarks/report.py

from gearengine.analysis import AnalysisRequest, analyze

ROOT = Path(__file__).resolve().parents[1]
PAPER = {"damping": 0.07, "mean_force": 0.01,
         "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.25}]}}  # fmt: skip


NOTE = (
    "A basin start is a lane of the lock-step kernels with no diagnostics (spectrum, time histo"
    "ry, Floquet), so it costs a fraction of a one-start analysis; the gate's default of 16 sta"
    "rts per point (the least the issue allows) is what its cost makes affordable in a CI job."
)


def analysis_seconds(doc: dict, starts: int | None) -> float:
    settings = dict(doc["settings"])
    settings.pop("basins", None)
    if starts is not None:
        settings["basins"] = {"starts": starts}
    request = AnalysisRequest.model_validate({**doc, "settings": settings})
    return best_of(lambda: analyze(request), 2)


def gate_seconds(*extra: str) -> float:
    args = [sys.executable, "-m", "gearengine.cli", "check", str(ROOT / "examples" /
            "envelope-map.json"), "--speed", "500:6000", "--torque", "2:40", *extra]  # fmt: skip
    t = time.perf_counter()
    subprocess.run(args, capture_output=True, check=False, cwd=ROOT)
    return time.perf_counter() - t


def main() -> None:
    load = os.getloadavg()[0]
    design = json.loads((ROOT / "examples" / "basins-5750rpm.json").read_text())
    paper = {"params": PAPER, "settings": {"transient_periods": 200, "record_periods": 200}}
    rows = []
    for name, doc in (("pair at 5,750 rpm (piecewise, 3 excitations)", design),
                      ("paper case Fe = 0.25 (cubic, lock-step)", paper)):  # fmt: skip
        analysis_seconds(doc, 16)  # warm the kernels
        one = analysis_seconds(doc, None)
        for n in (64, 256):
            t = analysis_seconds(doc, n)
            rows.append(f"| analysis, {name}, {n} basin starts | {t:.2f} s | {one:.2f} s | "
                        f"{t / one:.1f}x |")  # fmt: skip
    single = gate_seconds("--starts", "1")
    default = gate_seconds()
    rows.append(f"| default gate (16 basin starts per point), 115 points | {default:.1f} s | "
                f"{single:.1f} s | {default / single:.1f}x |")  # fmt: skip
    after = os.getloadavg()[0]
    write_section(
        "basins",
        "## Basins (`settings.basins`, the gate's default `--starts 16`)\n\n"
        "Reproduce: `.venv/bin/python benchmarks/bench_basins.py` (rewrites this section). "
        "Baseline: the same request with one start (no basins), and the gate with `--starts "
        "1`. Analyses in process after a warm-up, best of 2; the gate as a new process, once. "
        f"The machine was shared with other work (load average {load:.1f} before, "
        f"{after:.1f} after, on 2 cores): the ratios, not the seconds, are the result. "
        f"{NOTE}\n\n"
        "| what | with basins | one start | ratio |\n|---|---:|---:|---:|\n" + "\n".join(rows),
    )
    print("\n".join(rows))


if __name__ == "__main__":
    main()
