"""Speed of the numba kernels against gear_ref.c and scipy, in ns per RK4 step (with tangent).

Run:  .venv/bin/python benchmarks/bench_kernels.py
Prints a markdown table and writes it, with the command, into its section of
benchmarks/README.md.
Cases: the paper's point Fe = 0.25 (cubic, 500 + 500 periods x 200 steps) for one analysis;
a 301-point sweep Fe = 0..0.3 for the batch kernel.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import common  # benchmarks/common.py
import numba
import numpy as np
from report import write_section  # benchmarks/report.py (the script's own folder)
from scipy.integrate import solve_ivp

from gearengine.model.params import GearParams
from gearengine.numerics.runs import integrate
from gearengine.numerics.simulation import (
    SimulationSettings,
    simulate,
    simulate_batch,
    warm_up,
)

ROOT = Path(__file__).resolve().parent
GEAR_REF = Path("/work/shared/reference/gear_ref.c")
REPEATS = 5
SETTINGS = SimulationSettings(adaptive=False)
"""Default settings at fixed length: every point runs every step, so time per step is honest
(adaptive stopping is measured by bench_map.py and adaptive_agreement.py)."""
STEPS = (SETTINGS.transient_periods + SETTINGS.record_periods) * SETTINGS.steps_per_period
SWEEP = np.linspace(0.0, 0.3, 301)


def paper(fe: float) -> GearParams:
    """The paper's cubic case at transmission-error amplitude ``fe``."""
    return GearParams.model_validate(
        {
            "damping": 0.07,
            "mean_force": 0.01,
            "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": fe}]},
        }
    )


def best_of(fn: Callable[[], object], repeats: int = REPEATS) -> float:
    """Smallest wall time of ``repeats`` calls, seconds (``common.best_of``)."""
    return common.best_of(fn, repeats)


def scipy_ns_per_step(periods: int = 20) -> float:
    """DOP853 (rtol 1e-10, atol 1e-12) of Eq. (9) + tangent over ``periods`` forcing periods with
    Benettin renormalisation per period, per equivalent RK4 step (200 per period)."""
    mu, fm, we, fe, a, c = 0.07, 0.01, 0.5, 0.25, 0.1667, 0.1667

    def rhs(t: float, y: np.ndarray) -> list[float]:
        f = fm + we * we * fe * math.cos(we * t)
        x = y[0]
        return [
            y[1],
            -2 * mu * y[1] - x * (c * x * x - a) + f,
            y[3],
            -2 * mu * y[3] - (3 * c * x * x - a) * y[2],
        ]

    T = 2 * math.pi / we
    y = np.array([0.01, 0.01, math.sqrt(0.5), math.sqrt(0.5)])
    t = time.perf_counter()
    for n in range(periods):
        y = solve_ivp(rhs, (n * T, (n + 1) * T), y, method="DOP853", rtol=1e-10, atol=1e-12).y[
            :, -1
        ]
        y[2:] /= math.hypot(y[2], y[3])
    return 1e9 * (time.perf_counter() - t) / (periods * 200)


def gear_ref_ns(tmp: Path) -> tuple[float, float] | None:
    """(scalar ns/step, --simd --batch ns/point-step) of gear_ref.c built with gcc -O3."""
    gcc = shutil.which("gcc")
    if gcc is None or not GEAR_REF.exists():
        print("gcc or gear_ref.c missing: gear_ref comparison skipped", file=sys.stderr)
        return None
    exe = tmp / "gear_ref"
    subprocess.run([gcc, "-O3", "-march=native", "-o", exe, GEAR_REF, "-lm"], check=True)
    args = ["0.07", "0.25", "0.5", "0.01", "0", "1", "0", "1", "cubic", "200", "500", "500"]

    def run(extra: list[str]) -> str:
        return subprocess.run(
            [exe, *extra, *args], check=True, capture_output=True, text=True
        ).stdout

    scalar = min(float(run(["--summary"]).split()[5]) for _ in range(REPEATS)) * 1e9 / STEPS
    simd = min(
        float(run(["--simd", "--batch", "Fe", "0", "0.3", "301"]).split("ns_per_step")[1])
        for _ in range(3)
    )
    return scalar, simd


def main() -> None:
    warm_up()
    numba.set_num_threads(1)
    p = paper(0.25)
    kernel = best_of(lambda: integrate(p, SETTINGS, (0.01, 0.01))) * 1e9 / STEPS
    single = best_of(lambda: simulate(p, SETTINGS)) * 1e9 / STEPS
    points = [paper(fe) for fe in SWEEP]
    batch_1 = best_of(lambda: simulate_batch(points, SETTINGS), 3) * 1e9 / (STEPS * len(points))
    cores = numba.config.NUMBA_NUM_THREADS
    numba.set_num_threads(cores)
    batch_n = best_of(lambda: simulate_batch(points, SETTINGS), 3) * 1e9 / (STEPS * len(points))
    sp = scipy_ns_per_step()
    with tempfile.TemporaryDirectory() as tmp:
        ref = gear_ref_ns(Path(tmp))
    rows = [
        ("numba single-analysis kernel `run_rk4` (1 thread)", kernel, 0),
        ("numba `simulate` (one analysis, 1 thread, incl. diagnostics)", single, 0),
        ("numba `simulate_batch` 301 points, 1 thread", batch_1, 1),
        (f"numba `simulate_batch` 301 points, {cores} threads (per core)", batch_n * cores, 1),
        ("scipy `solve_ivp` DOP853 rtol 1e-10 (per equivalent step)", sp, 0),
    ]
    if ref is not None:
        rows += [("gear_ref scalar (gcc -O3 -march=native)", ref[0], 0)]
        rows += [("gear_ref --simd --batch 301 points", ref[1], 1)]
    lines = ["| what | ns per RK4 step per core | ratio to gear_ref |", "| --- | ---: | ---: |"]
    for name, ns, kind in rows:
        ratio = f"{ns / ref[kind]:.2f}x" if ref is not None else "n/a"
        lines.append(f"| {name} | {ns:.2f} | {ratio} |")
    table = "\n".join(lines)
    print(table)
    write_section(
        "kernels",
        "## Kernels\n\n"
        "Reproduce: `.venv/bin/python benchmarks/bench_kernels.py` (rewrites this section).\n\n"
        "One analysis = paper case Fe = 0.25 (cubic, chaotic), 500 transient + 500 recorded "
        "periods x 200 RK4 steps with the tangent equation; batch = 301 points Fe = 0..0.3. "
        "Ratios: single-analysis rows against gear_ref scalar, batch rows against gear_ref "
        "--simd (per point-step). Multi-thread rows are wall time x threads.\n\n"
        f"{table}\n\nMachine: {numba.config.NUMBA_NUM_THREADS} cores, numba {numba.__version__}.\n",
    )


if __name__ == "__main__":
    main()
