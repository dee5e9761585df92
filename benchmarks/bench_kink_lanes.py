"""Piecewise lanes (``kernels.run_kink_batch``) against cubic lanes on the same points and
against ``gear_ref --kink`` (scalar, one thread), per point-step.

Run:  .venv/bin/python benchmarks/bench_kink_lanes.py
Points: the paper's case (mu 0.07, Omega_e 0.5, F~_m 0.01) with F~_e1 = 0..0.3 (301 points,
from no impact through single-sided periodic responses to chaos), once with the piecewise law
of Eq. (8) (alpha 0) and once with the cubic law; 200 + 200 periods x 200 RK4 steps with the
tangent equation, fixed length (``"adaptive": false``), one start, through
``numerics.batch.run_lanes`` on one numba thread. gear_ref.c (gcc -O3 -march=native, built in a
temporary directory) runs the same points with ``--kink --batch Fe 0 0.3 301`` (its scalar
kink-splitting path, one thread). Times are CPU seconds of this process's run (1 thread) and of
the gear_ref child process, so a shared machine changes them little; the median of 7 runs (4 calls
each), the piecewise and cubic runs interleaved. Writes its section of benchmarks/README.md.
"""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np
from report import write_section  # benchmarks/report.py (the script's own folder)

from gearengine.model.params import GearParams
from gearengine.numerics.batch import run_lanes
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import warm_up

GEAR_REF = Path("/work/shared/reference/gear_ref.c")
N_TRANS, N_REC, STEPS = 200, 200, 200
FE = np.linspace(0.0, 0.3, 301)
REPEATS = 7
SHIFT = 1e-4
"""F~_e1 step between the calls' grids (call j of all: 0..0.3 + j SHIFT)."""
CALLS = 4
"""Calls per timed run (about a second of CPU, each on its own points), so the VM's jitter
averages out."""


def paper(fe: float, model: str) -> GearParams:
    return GearParams.model_validate(
        {"damping": 0.07, "mean_force": 0.01, "backlash": {"model": model},
         "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": float(fe)}]}}
    )  # fmt: skip


def points(fe: np.ndarray, model: str) -> list[GearParams]:
    return [paper(float(f), model) for f in fe]


def cpu_ns_per_point_step(batches: list[list[GearParams]]) -> tuple[float, list]:
    """CPU time of one ``run_lanes`` call per batch of points (one start each), ns per
    point-step, and the last batch's outputs."""
    settings = SimulationSettings(
        transient_periods=N_TRANS, record_periods=N_REC, steps_per_period=STEPS, adaptive=False
    )
    out: list = []
    t = time.process_time()
    for batch in batches:
        out = run_lanes(batch, [(i, (0.01, 0.01)) for i in range(len(batch))], settings)
    steps = sum(len(b) for b in batches) * (N_TRANS + N_REC) * STEPS
    return (time.process_time() - t) * 1e9 / steps, out


def gear_ref_kink_ns(tmp: Path) -> float:
    """CPU ns per point-step of ``gear_ref --kink --batch Fe 0 0.3 301`` (median of 7)."""
    gcc = shutil.which("gcc") or sys.exit("gcc is needed to build gear_ref")
    exe = tmp / "gear_ref"
    subprocess.run([gcc, "-O3", "-march=native", "-o", exe, GEAR_REF, "-lm"], check=True)
    args = [exe, "--kink", "--batch", "Fe", "0", "0.3", str(FE.size), "0.07", "0.25", "0.5",
            "0.01", "0", "1", "0", "1", "pw", str(STEPS), str(N_TRANS), str(N_REC)]  # fmt: skip
    times = []
    for _ in range(REPEATS):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run(args, check=True, capture_output=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        times.append((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime))
    return float(np.median(times)) * 1e9 / (FE.size * (N_TRANS + N_REC) * STEPS)


def main() -> None:
    warm_up()
    numba.set_num_threads(1)
    cpu_ns_per_point_step([points(FE[:16], "piecewise")])  # compiled or loaded
    cpu_ns_per_point_step([points(FE[:16], "cubic")])
    pw, cu, ratios = [], [], []
    for k in range(1, REPEATS + 1):  # interleaved, so a slower minute slows both alike
        # every call new points: no forcing table or cache of an earlier call serves it
        grids = [FE + SHIFT * (CALLS * k + c) for c in range(CALLS)]
        ns, pw_out = cpu_ns_per_point_step([points(fe, "piecewise") for fe in grids])
        pw.append(ns)
        cu.append(cpu_ns_per_point_step([points(fe, "cubic") for fe in grids])[0])
        ratios.append(pw[-1] / cu[-1])
    pw_ns, cubic_ns = float(np.median(pw)), float(np.median(cu))
    with tempfile.TemporaryDirectory() as tmp:
        ref_ns = gear_ref_kink_ns(Path(tmp))
    regimes = {r: sum(o.impact_regime == r for o in pw_out) for r in
               ("no_impact", "single_sided", "double_sided")}  # fmt: skip
    classes = {c: sum(o.classification == c for o in pw_out) for c in
               ("periodic", "quasi_periodic", "chaotic")}  # fmt: skip
    load = os.getloadavg()[0]
    lines = [
        "| what | CPU ns per point-step | ratio |",
        "| --- | ---: | ---: |",
        f"| piecewise lanes `run_kink_batch` (1 thread), min / median | {min(pw):.2f} / "
        f"{pw_ns:.2f} | 1.00x |",
        f"| cubic lanes `run_batch`, same points (1 thread), min / median | {min(cu):.2f} / "
        f"{cubic_ns:.2f} | "
        f"piecewise / cubic **{pw_ns / cubic_ns:.2f}x** (per run: "
        f"{', '.join(f'{r:.2f}' for r in ratios)}) |",
        f"| gear_ref --kink --batch (scalar, 1 thread) | {ref_ns:.2f} | "
        f"gear_ref / piecewise lanes **{ref_ns / pw_ns:.1f}x** |",
    ]
    text = (
        "## Piecewise lanes\n\n"
        "Reproduce: `.venv/bin/python benchmarks/bench_kink_lanes.py` (rewrites this section).\n\n"
        f"The paper's case with F~_e1 = 0..0.3 ({FE.size} points; piecewise responses "
        f"{regimes}, {classes}), {N_TRANS} + {N_REC} periods x {STEPS} RK4 steps with the "
        "tangent, fixed length, one start, `run_lanes` on one thread; the cubic row runs the "
        "same points with the cubic law; gear_ref.c with `--kink --batch` on the same points "
        "(its scalar kink-splitting path). Every call has new points (the F~_e1 grid shifted "
        f"by {SHIFT:g} per call). CPU time of the run (median of 7 runs of 4 calls, "
        "piecewise and "
        "cubic runs interleaved), so a shared "
        "machine changes the ratios little. Targets (issue 20): piecewise lanes <= 2x the "
        "cubic lanes' cost per point-step, >= 4x gear_ref --kink's throughput per core.\n\n"
        + "\n".join(lines)
        + f"\n\nLoad average (1 min) at the end of the run: {load:.1f} on 2 cores.\n"
    )
    print(text)
    write_section("kink-lanes", text)


if __name__ == "__main__":
    main()
