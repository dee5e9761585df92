"""A robustness study over the default envelope: 23 speeds x 5 torques x 256 samples of the
tolerances (ISO 1328 class 7, backlash band 80-120 µm, damping ratio 0.04-0.06) of the issue's
23/67 pair, module 2.5 mm, with the envelope check's light settings (60 + 60 periods of 128 RK4
steps, one start): 29 440 runs, every one a lane of the lock-step kernels.

Run:  .venv/bin/python benchmarks/bench_robustness.py
Baseline in the same run: the envelope sweep of the nominal design over the same 115 points
(one run per point), so the ratio is the cost of one sample against one nominal run. One
repeat (the study is long; the machine is shared: the numbers are an upper bound). Writes its
section of benchmarks/README.md.
"""

from __future__ import annotations

import os
import time

from report import write_section  # benchmarks/report.py (the script's own folder)

from gearengine.cli.envelope import ENVELOPE_SETTINGS
from gearengine.studies.robustness.study import RobustnessRequest, checked, run_local
from gearengine.studies.sweep import run_local as run_sweep
from gearengine.studies.sweep import validated

GEOMETRY = {"module": "2.5 mm", "face_width": "20 mm"}
DESIGN = {
    "driver": {"teeth": 23, **GEOMETRY},
    "driven": {"teeth": 67, **GEOMETRY},
    "speed": "3000 rpm",
    "torque": "20 N*m",
    "mesh": {"stiffness": "iso6336", "damping_ratio": 0.05, "half_backlash": "50 um"},
}
TOLERANCES = {
    "accuracy": {"standard": "ISO 1328-1:2013", "class": 7},
    "backlash": {"min": "80 um", "max": "120 um"},
    "mesh.damping_ratio": {"uniform": [0.04, 0.06]},
}
AXES = [
    {"parameter": "speed", "start": "500 rpm", "stop": "6000 rpm", "num": 23},
    {"parameter": "torque", "start": "5 N*m", "stop": "60 N*m", "num": 5},
]
SAMPLES = 256


def main() -> None:
    cores = os.cpu_count() or 1
    load = os.getloadavg()[0]
    nominal = validated({"design": {**DESIGN, "transmission_error": {"harmonics": [
        {"amplitude": "5.6 um"}]}}, "settings": ENVELOPE_SETTINGS, "axes": AXES})  # fmt: skip
    run_sweep(nominal, chunk_points=8, workers=cores)  # kernels loaded
    t = time.perf_counter()
    run_sweep(nominal, chunk_points=8, workers=cores)
    sweep = time.perf_counter() - t
    study = checked(RobustnessRequest.model_validate({
        "design": {**DESIGN, "tolerances": TOLERANCES}, "settings": ENVELOPE_SETTINGS,
        "samples": SAMPLES, "axes": AXES}))  # fmt: skip
    t = time.perf_counter()
    result = run_local(study, workers=cores)
    robust = time.perf_counter() - t
    runs = 115 * SAMPLES
    worst = max(result.points, key=lambda p: p.probabilities["chaotic"].value or 0.0)
    rows = [
        f"| nominal envelope, 115 runs | {sweep:.2f} s | {1e3 * sweep / 115:.2f} ms | 1 |",
        f"| robustness, 115 points x {SAMPLES} samples = {runs} runs | {robust:.1f} s | "
        f"{1e3 * robust / runs:.2f} ms | {robust / runs / (sweep / 115):.1f}x |",
    ]
    write_section(
        "robustness",
        "## Robustness study (`gearengine robustness --speed 500:6000 --torque 5:60 "
        "--samples 256`)\n\n"
        "23 speeds x 5 torques x 256 scrambled Sobol samples of ISO 1328 class 7, a backlash "
        "band of 80-120 µm and a damping ratio of 0.04-0.06 (the issue's 23/67 pair, module "
        "2.5 mm, piecewise law), 60 + 60 periods of 128 RK4 steps, in process on "
        f"{cores} threads; baseline: the nominal envelope in the same run. One repeat, on a "
        f"shared, loaded machine (1-minute load average {load:.1f} on {cores} cores): an upper "
        "bound. `benchmarks/bench_robustness.py`.\n\n"
        "| what | wall time | per run | per run vs nominal |\n|---|---:|---:|---:|\n"
        + "\n".join(rows)
        + f"\n\nMost chaotic point: {worst.shown} with P(chaotic) = "
        f"{worst.probabilities['chaotic'].value:.3f} "
        f"[{worst.probabilities['chaotic'].interval[0]:.3f}, "
        f"{worst.probabilities['chaotic'].interval[1]:.3f}].",
    )
    print("\n".join(rows))


if __name__ == "__main__":
    main()
