"""Remedies of the README design over its default envelope, against one envelope check of the
same envelope in the same process, wall time.

Run:  .venv/bin/python benchmarks/bench_remedies.py [OUT.json]
The README design (``examples/ci/design.json``) over ``--speed 500:6000 --torque 20:200`` (23 x 5
points, 60 + 60 periods of 128 RK4 steps) passes ``--fail-on chaotic``; with ``--fail-on
separation`` (the teeth must never leave the drive flank) it fails at light load, so every lever
is searched, at the gate's default of 16 basin starts per point. One run each (a remedies search
is many envelope checks; the ratio says how many one costs). Writes its section of
benchmarks/README.md (and the result to OUT.json if given).
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

from report import write_section  # benchmarks/report.py (the script's own folder)

from gearengine.gate.envelope import check_envelope
from gearengine.gate.remedies import RemediesRequest, remedies

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "examples" / "ci" / "design.json"


def main() -> None:
    body = {"design": json.loads(DESIGN.read_text())["design"], "fail_on": ["separation"],
            "envelope": {"speed": "500:6000", "torque": "20:200"}}  # fmt: skip
    request = RemediesRequest.model_validate(body)
    cores = os.cpu_count() or 1
    check_envelope(request.sweep(), request.rules(), workers=cores)  # warm
    t = time.perf_counter()
    baseline = check_envelope(request.sweep(), request.rules(), workers=cores)
    one = time.perf_counter() - t
    t = time.perf_counter()
    result = remedies(request, workers=cores)
    total = time.perf_counter() - t
    load = os.getloadavg()[0]
    if len(sys.argv) > 1:
        Path(sys.argv[1]).write_text(result.model_dump_json())
    searched = {(r.lever, r.to > r.from_) for r in result.remedies}
    searched |= {(u.lever, u.searched[0]) for u in result.unreachable}
    rows = [
        f"| one envelope check, {baseline.points} points x 16 starts, {cores} threads | "
        f"{one:.1f} s | 1x |",
        f"| remedies: {len(result.remedies)} found, {len(result.unreachable)} unreachable "
        f"bounds | {total:.1f} s | {total / one:.0f}x |",
    ]
    write_section(
        "remedies",
        "## Remedies (`gearengine remedies examples/ci/design.json --speed 500:6000 --torque "
        "20:200 --fail-on separation`)\n\n"
        "The README design over its default envelope (23 x 5 points, 16 basin starts each, 60 + "
        "60 periods of 128 RK4 steps: the gate's defaults), which fails `--fail-on separation` "
        "at light load: every default lever is "
        "searched (bracket samples, bisection with full envelope runs, the Melnikov bound and "
        "its verifying run, then the two-lever combination chunk). One run each, "
        "`benchmarks/bench_remedies.py`; the ratio is the cost in envelope checks. The machine "
        f"was loaded by other work (load average {load:.1f} on 2 cores at the end), so the "
        "seconds are pessimistic; the ratio is the number to read.\n\n"
        "| what | wall time | ratio |\n|---|---:|---:|\n" + "\n".join(rows),
    )
    print("\n".join(rows))
    print(result.answer)


if __name__ == "__main__":
    main()
