"""Chaos maps at default settings: adaptive stopping vs fixed length vs ``gear_ref --simd --batch``.

Run:  .venv/bin/python benchmarks/bench_map.py
The map of examples/chaos-map.json (Omega_e x F_e1, cubic law) at 100 x 100 and 200 x 200
points with default settings (500 + 500 periods x 200 RK4 steps, one start), measured in one run:

* ``gearengine sweep FILE`` end to end (a subprocess: imports, every point's verdict, JSON, CSV
  and the PNG map), once with ``"adaptive": true`` (the default) and once with ``false``;
* ``gear_ref --simd --batch We`` (gcc -O3 -march=native, single-threaded), one call per line of
  the second axis (one F_e1 value, all Omega_e values), wall time of all calls;
* the same command of the previous implementation (commit 2216844, before issue 13: no adaptive
  stopping; its ``gearengine`` package extracted with ``git archive``, same dependencies, its
  numba cache warmed first), default settings, on the same points.

Issue 13 measured 16.7 s for the 100 x 100 map with the previous implementation; the target is
at most a fifth of the previous implementation's time, measured here in the same run. Writes
its section of benchmarks/README.md. Wall times on a shared machine vary; the CPU time of each
sweep process is printed beside them.
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
from common import extracted  # benchmarks/common.py (the script's own folder)
from report import write_section

ROOT = Path(__file__).resolve().parents[1]
GEAR_REF = Path("/work/shared/reference/gear_ref.c")
BASELINE = "2216844"
"""The last commit before issue 13 (the layout commit, numerics unchanged since the round began)."""
SIZES = (100, 200)
FULL_LENGTH = ("chaotic", "quasi_periodic")
"""Classes whose points run every period with adaptive stopping too."""
TAGS = {True: "a", False: "f", None: "p"}
"""File tags of the runs: adaptive, fixed length, previous implementation."""


def map_doc(num: int, adaptive: bool | None) -> dict:
    """The map at ``num`` x ``num`` points, default settings (``adaptive`` None: the previous
    implementation's settings document, which has no such field)."""
    doc = json.loads((ROOT / "examples" / "chaos-map.json").read_text())
    doc["settings"] = {} if adaptive is None else {"adaptive": adaptive}
    for axis in doc["axes"]:
        axis["num"] = num
    return doc


def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def sweep_seconds(
    tmp: Path, num: int, adaptive: bool | None, code: Path = ROOT
) -> tuple[float, float, dict]:
    """Wall and CPU seconds of ``gearengine sweep`` on the map, and its result document;
    ``code``: the directory whose ``gearengine`` package runs (``PYTHONPATH``)."""
    name = f"map{num}{TAGS[adaptive]}"
    path = tmp / f"{name}.json"
    path.write_text(json.dumps(map_doc(num, adaptive)))
    out = tmp / "out"
    env = {**os.environ, "PYTHONPATH": str(code)}
    cpu = children_cpu()
    t = time.perf_counter()
    subprocess.run([sys.executable, "-m", "gearengine.cli", "sweep", str(path), "--out",
                    str(out)], cwd=code, env=env, check=True, capture_output=True)  # fmt: skip
    wall = time.perf_counter() - t
    return wall, children_cpu() - cpu, json.loads((out / f"{name}.json").read_text())


BARE_START = """
from gearengine.model.params import GearParams
from gearengine.numerics.batch import simulate_batch
from gearengine.numerics.settings import SimulationSettings
te = {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]}
p = GearParams.model_validate({"damping": 0.07, "transmission_error": te})
simulate_batch([p, p], SimulationSettings(transient_periods=1, record_periods=4))
"""
"""A process that only loads the engine and its lock-step kernel (from numba's cache)."""


def bare_start_seconds() -> float:
    """Wall seconds of ``BARE_START``: Python, numpy, pydantic, numba and the kernel's cache."""
    t = time.perf_counter()
    subprocess.run([sys.executable, "-c", BARE_START], cwd=ROOT, check=True)
    return time.perf_counter() - t


def floor_seconds(num: int, points: list[dict]) -> tuple[float, float]:
    """Seconds spent inside the lock-step kernel (``kernels.run_batch``, every core) on the work
    no adaptive run can avoid, at fixed length: (1) the chaotic and quasi-periodic points over
    all 1000 periods (issue 13 keeps their LLE unchanged, so they run to the end) and (2) the
    periodic points over the fewest periods the stopping rule allows, ``ADAPT_SETTLE +
    ADAPT_WINDOW`` (systems/spur_pair/kernels/adaptive.py). Diverged points count as free, and so
    does every verdict, document and figure."""
    from gearengine.numerics.batch import simulate_batch
    from gearengine.numerics.settings import SimulationSettings
    from gearengine.studies.sweep.request import validated
    from gearengine.systems.spur_pair import kernels
    from gearengine.systems.spur_pair.kernels.adaptive import ADAPT_SETTLE, ADAPT_WINDOW

    request = validated(map_doc(num, False))
    full = [request.point(p["values"]) for p in points if p["classification"] in FULL_LENGTH]
    least = [request.point(p["values"]) for p in points if p["classification"] == "periodic"]
    fixed = SimulationSettings(adaptive=False)
    shortest = fixed.model_copy(
        update={"transient_periods": ADAPT_SETTLE, "record_periods": ADAPT_WINDOW}
    )
    simulate_batch(full[:4], shortest)  # kernels loaded
    inside = [0.0]
    run_batch = kernels.run_batch

    def timed(*args: object) -> tuple:
        t = time.perf_counter()
        out = run_batch(*args)
        inside[0] += time.perf_counter() - t
        return out

    kernels.run_batch = timed
    try:
        simulate_batch(full, fixed)
        t_full, inside[0] = inside[0], 0.0
        simulate_batch(least, shortest)
    finally:
        kernels.run_batch = run_batch
    return t_full, inside[0]


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
    with tempfile.TemporaryDirectory() as d, extracted(BASELINE) as old:
        tmp = Path(d)
        exe = tmp / "gear_ref"
        gcc = shutil.which("gcc") or sys.exit("gcc is needed to build gear_ref")
        subprocess.run([gcc, "-O3", "-march=native", "-o", exe, GEAR_REF, "-lm"], check=True)
        sweep_seconds(tmp, 4, True)  # numba caches warm
        sweep_seconds(tmp, 4, None, old)
        start = min(sweep_seconds(tmp, 2, True)[0] for _ in range(3))  # a 2 x 2 map: start-up
        bare = min(bare_start_seconds() for _ in range(3))
        floors = []
        for num in SIZES:
            pr, pr_cpu, res_p = sweep_seconds(tmp, num, None, old)
            ad, ad_cpu, res_a = sweep_seconds(tmp, num, True)
            fx, fx_cpu, res_f = sweep_seconds(tmp, num, False)
            ref = gear_ref_seconds(exe, num)
            pa, pf, pp = res_a["points"], res_f["points"], res_p["points"]
            same = sum((a["classification"], a["period"]) == (f["classification"], f["period"])
                       for a, f in zip(pa, pf, strict=True))  # fmt: skip
            as_before = sum((a["classification"], a["period"]) == (q["classification"], q["period"])
                            for a, q in zip(pa, pp, strict=True))  # fmt: skip
            mean_run = sum(a["periods_run"] for a in pa) / len(pa)
            agree = (100.0 * same / len(pa), 100.0 * as_before / len(pa))
            rows.append((num, pr, pr_cpu, ad, ad_cpu, fx, fx_cpu, ref, *agree, mean_run))
            full = sum(a["classification"] in FULL_LENGTH for a in pa)
            floors.append((num, pr, ad, full, len(pa), *floor_seconds(num, pa)))
            print(rows[-1], floors[-1], flush=True)
    cores = os.cpu_count() or 1
    table = (
        f"| map | previous ({BASELINE}), s (CPU s) | adaptive, s (CPU s) | fixed length, s (CPU s) "
        "| gear_ref --simd --batch, 1 thread, s | previous / adaptive | adaptive / fixed | "
        "adaptive / gear_ref | verdicts equal to fixed length | to previous | mean periods run |"
        "\n| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n"
    )
    for num, pr, pr_cpu, ad, ad_cpu, fx, fx_cpu, ref, same, as_before, mean_run in rows:
        table += (
            f"| {num} x {num} | {pr:.1f} ({pr_cpu:.1f}) | {ad:.1f} ({ad_cpu:.1f}) | {fx:.1f} "
            f"({fx_cpu:.1f}) | {ref:.1f} | **{pr / ad:.1f}x** | {ad / fx:.2f}x | {ad / ref:.2f}x | "
            f"{same:.2f} % | {as_before:.2f} % | {mean_run:.0f} of 1000 |\n"
        )
    table += (
        "\nWhat no implementation of issue 13 can avoid: a new process that loads the engine "
        f"and writes the three files ({start:.2f} s: `gearengine sweep` on a 2 x 2 map), the "
        "kernel time of the points that must run all 1000 periods (chaotic and quasi-periodic: "
        "their LLE stays unchanged) and of the periodic points run for the fewest periods the "
        "stopping rule allows (`ADAPT_SETTLE + ADAPT_WINDOW` = 140), both at fixed length: the "
        f"time inside the lock-step kernel `run_batch` ({cores} cores). Their sum is the fastest "
        "any end-to-end run could be with every verdict, document and figure free. The bare "
        f"floor starts from a process that only loads the engine and its kernel ({bare:.2f} s) "
        "instead: what would be left if the documents and the figure of a 2 x 2 map cost "
        "nothing too.\n\n"
        "| map | points run to the end | their kernel, s | periodic points at 140 periods, s "
        "| start-up, s | floor, s | previous / floor | adaptive / floor | bare floor, s | "
        "previous / bare floor |\n"
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n"
    )
    for num, pr, ad, full, n, t_full, t_least in floors:
        floor = start + t_full + t_least
        least = bare + t_full + t_least
        table += (
            f"| {num} x {num} | {full} of {n} | {t_full:.2f} | {t_least:.2f} | {start:.2f} | "
            f"{floor:.2f} | {pr / floor:.1f}x | {ad / floor:.2f}x | {least:.2f} | "
            f"{pr / least:.1f}x |\n"
        )
    summary = "Target (issue 13): each map in at most a fifth of the previous implementation's " + (
        "time: met." if all(r[1] / r[3] >= 5.0 for r in rows) else "time: NOT met."
    )
    print(table + "\n" + summary)
    write_section(
        "maps",
        "## Chaos maps: adaptive stopping vs fixed length vs the previous implementation vs "
        "gear_ref\n\n"
        "Reproduce: `.venv/bin/python benchmarks/bench_map.py` (rewrites this section).\n\n"
        "examples/chaos-map.json (Omega_e 0.3..1.2 x F_e1 0..0.6, cubic law) at default "
        "settings (500 + 500 periods x 200 RK4 steps), all in one run: `gearengine sweep` end "
        f"to end (a new process: imports, verdicts, JSON, CSV, PNG; {cores} cores) of the "
        f"previous implementation (commit {BASELINE}, extracted with `git archive`, its numba "
        "cache warmed first) and of this one with adaptive stopping (default) and with "
        '`"adaptive": false`; and `gear_ref --simd --batch We` single-threaded, one call per '
        "F_e1 line, on the same points. Adaptive stopping: systems/spur_pair/kernels/adaptive.py. "
        "Wall times on a shared machine vary; the CPU time of each command is beside it.\n\n"
        f"{table}\n{summary}\n",
    )


if __name__ == "__main__":
    main()
