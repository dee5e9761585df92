"""Chaos maps at default settings: adaptive stopping vs fixed length vs ``gear_ref --simd --batch``.

Run:  .venv/bin/python benchmarks/bench_map.py
The map of examples/chaos-map.json (Omega_e x F_e1, cubic law) at 100 x 100 and 200 x 200
points with default settings (500 + 500 periods x 200 RK4 steps, one start), measured in one run:

* ``gearengine sweep FILE`` end to end (a subprocess: imports, every point's verdict, JSON, CSV
  and the PNG map), once with ``"adaptive": true`` (the default) and once with ``false``;
* ``gear_ref --simd --batch We`` (gcc -O3 -march=native, single-threaded), one call per line of
  the second axis (one F_e1 value, all Omega_e values), wall time of all calls.

The previous implementation (before adaptive stopping) took 16.7 s wall for the 100 x 100 map
through ``gearengine sweep`` on both cores (issue 13); the target is at most a fifth of that.
Writes its section of benchmarks/README.md. Wall times on a shared machine vary; the CPU time
of the sweep process is printed beside them.
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from report import write_section  # benchmarks/report.py (the script's own folder)

ROOT = Path(__file__).resolve().parents[1]
GEAR_REF = Path("/work/shared/reference/gear_ref.c")
PREVIOUS_100 = 16.7
"""Wall time [s] of the 100 x 100 map through ``gearengine sweep`` before (issue 13)."""
SIZES = (100, 200)


def map_doc(num: int, adaptive: bool) -> dict:
    doc = json.loads((ROOT / "examples" / "chaos-map.json").read_text())
    doc["settings"] = {"adaptive": adaptive}
    for axis in doc["axes"]:
        axis["num"] = num
    return doc


def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def sweep_seconds(tmp: Path, num: int, adaptive: bool) -> tuple[float, float, dict]:
    """Wall and CPU seconds of ``gearengine sweep`` on the map, and its result document."""
    name = f"map{num}{'a' if adaptive else 'f'}"
    path = tmp / f"{name}.json"
    path.write_text(json.dumps(map_doc(num, adaptive)))
    out = tmp / "out"
    cpu = children_cpu()
    t = time.perf_counter()
    subprocess.run([sys.executable, "-m", "gearengine.cli", "sweep", str(path), "--out",
                    str(out)], cwd=ROOT, check=True, capture_output=True)  # fmt: skip
    wall = time.perf_counter() - t
    return wall, children_cpu() - cpu, json.loads((out / f"{name}.json").read_text())


def gear_ref_seconds(exe: Path, num: int) -> float:
    """Wall seconds of one ``gear_ref --simd --batch We`` call per F_e1 line of the map."""
    doc = map_doc(num, False)
    om, fe = doc["axes"]
    p = doc["params"]
    t = time.perf_counter()
    for f in np.linspace(fe["start"], fe["stop"], fe["num"]):
        args = ["--simd", "--batch", "We", str(om["start"]), str(om["stop"]), str(om["num"]),
                str(p["damping"]), repr(float(f)), "1", str(p["mean_force"]), "0", "1", "0",
                "1", "cubic", "200", "500", "500"]  # fmt: skip
        subprocess.run([exe, *args], check=True, capture_output=True)
    return time.perf_counter() - t


def main() -> None:
    rows = []
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        exe = tmp / "gear_ref"
        gcc = shutil.which("gcc") or sys.exit("gcc is needed to build gear_ref")
        subprocess.run([gcc, "-O3", "-march=native", "-o", exe, GEAR_REF, "-lm"], check=True)
        sweep_seconds(tmp, 4, True)  # numba caches warm
        for num in SIZES:
            ad, ad_cpu, res_a = sweep_seconds(tmp, num, True)
            fx, fx_cpu, res_f = sweep_seconds(tmp, num, False)
            ref = gear_ref_seconds(exe, num)
            pa, pf = res_a["points"], res_f["points"]
            same = sum((a["classification"], a["period"]) == (f["classification"], f["period"])
                       for a, f in zip(pa, pf, strict=True))  # fmt: skip
            mean_run = sum(a["periods_run"] for a in pa) / len(pa)
            rows.append((num, ad, ad_cpu, fx, fx_cpu, ref, 100.0 * same / len(pa), mean_run))
            print(rows[-1], flush=True)
    cores = os.cpu_count() or 1
    table = (
        "| map | adaptive, s (CPU s) | fixed length, s (CPU s) | gear_ref --simd --batch, 1 "
        "thread, s | adaptive / fixed | adaptive / gear_ref | verdicts equal | mean periods "
        "run |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n"
    )
    for num, ad, ad_cpu, fx, fx_cpu, ref, same, mean_run in rows:
        table += (
            f"| {num} x {num} | {ad:.1f} ({ad_cpu:.1f}) | {fx:.1f} ({fx_cpu:.1f}) | {ref:.1f} | "
            f"{ad / fx:.2f}x | {ad / ref:.2f}x | {same:.2f} % | {mean_run:.0f} of 1000 |\n"
        )
    first = rows[0][1]
    summary = (
        f"The 100 x 100 map now takes {first:.1f} s wall against {PREVIOUS_100} s before "
        f"(issue 13): {PREVIOUS_100 / first:.1f}x faster, target >= 5x."
    )
    print(table + "\n" + summary)
    write_section(
        "maps",
        "## Chaos maps: adaptive stopping vs fixed length vs gear_ref\n\n"
        "Reproduce: `.venv/bin/python benchmarks/bench_map.py` (rewrites this section).\n\n"
        "examples/chaos-map.json (Omega_e 0.3..1.2 x F_e1 0..0.6, cubic law) at default "
        "settings (500 + 500 periods x 200 RK4 steps): `gearengine sweep` end to end (imports, "
        f"verdicts, JSON, CSV, PNG; {cores} cores) with adaptive stopping (default) and with "
        '`"adaptive": false`, and `gear_ref --simd --batch We` single-threaded, one call per '
        "F_e1 line, on the same points. Adaptive stopping: numerics/kernels/adaptive.py.\n\n"
        f"{table}\n{summary}\n",
    )


if __name__ == "__main__":
    main()
