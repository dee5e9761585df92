"""The default envelope check (``gearengine check --speed 500:6000 --torque 20:200``) against
``gear_ref --simd --batch`` on the same points, wall time.

Run:  .venv/bin/python benchmarks/bench_envelope.py
The design is the README's pair with the transmission error as its only excitation and the
paper's cubic law (``backlash_law: cubic_fit``), so that a change of speed moves one frequency
and gear_ref's one-parameter batch can run the same grid: per torque level one
``gear_ref --simd --batch We`` over the 23 speeds (Omega_e and F~_m from the engine's own
conversion), 60 + 60 periods of 128 RK4 steps, the check's default settings. The engine is
timed twice: the whole command (a fresh process: imports, cached kernels, conversion of every
point, Melnikov verdicts, report) and the sweep alone in this process. A second row times the
command on the README design as it is (piecewise law, three excitations), which gear_ref's
batch cannot run, and rows time that design (``examples/ci/design.json``) in process too: with
its one start and with 64 random starts per point (``random_initial_states``, box x in
[-1.5, 1.5], v in [-0.5, 0.5], seed 0; one run). Best of 3; prints the load average; writes its
section of benchmarks/README.md.
"""

from __future__ import annotations

import copy
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from common import best_of  # benchmarks/common.py
from report import write_section  # benchmarks/report.py (the script's own folder)

from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.sweeps import run_local, validated
from gearengine.sweeps.gate import ENVELOPE_SETTINGS

ROOT = Path(__file__).resolve().parents[1]
GEAR_REF = Path("/work/shared/reference/gear_ref.c")
REPEATS = 3
SPEEDS, TORQUES = (500.0, 6000.0, 23), (20.0, 200.0, 5)


def cubic_te_design() -> dict:
    d = copy.deepcopy(EXAMPLE_DESIGN)
    d["mesh"].pop("stiffness_harmonics")
    d.pop("torque_fluctuation")
    d["backlash_law"] = "cubic_fit"
    return d


def sweep_doc(design: dict) -> dict:
    axes = [
        {"parameter": "speed", "start": f"{SPEEDS[0]} rpm", "stop": f"{SPEEDS[1]} rpm",
         "num": SPEEDS[2]},
        {"parameter": "torque", "start": f"{TORQUES[0]} N*m", "stop": f"{TORQUES[1]} N*m",
         "num": TORQUES[2]},
    ]  # fmt: skip
    return {"design": design, "settings": ENVELOPE_SETTINGS, "axes": axes}


def readme_design() -> dict:
    return json.loads((ROOT / "examples" / "ci" / "design.json").read_text())["design"]


def in_process_seconds(design: dict, starts: int, repeats: int) -> float:
    """Best wall time of the envelope sweep of ``design`` in this process (every core), with
    ``starts`` random initial states per point when more than one."""
    doc = sweep_doc(design)
    if starts > 1:
        box = [[-1.5, 1.5], [-0.5, 0.5]]
        rand = {"count": starts, "box": box, "seed": 0}
        doc["settings"] = {**doc["settings"], "random_initial_states": rand}
    req = validated(doc)
    cores = os.cpu_count() or 1
    chunk = max(1, req.n_points() // (4 * cores))
    run_local(validated(sweep_doc(design)), chunk_points=chunk, workers=cores)  # warm
    return best_of(lambda: run_local(req, chunk_points=chunk, workers=cores), repeats)


def command_seconds(design: dict, tmp: Path, *extra: str) -> float:
    """Best wall time of the whole ``gearengine check`` command (a new process) on the default
    envelope of ``design``, with the options ``extra``."""
    path = tmp / "design.json"
    path.write_text(json.dumps({"design": design}))
    speed, torque = f"{SPEEDS[0]:g}:{SPEEDS[1]:g}", f"{TORQUES[0]:g}:{TORQUES[1]:g}"
    args = [sys.executable, "-m", "gearengine.cli", "check", str(path), "--speed", speed,
            "--torque", torque, *extra]  # fmt: skip
    return best_of(lambda: subprocess.run(args, capture_output=True, check=False), REPEATS)


def gear_ref_seconds(tmp: Path) -> float:
    """Wall time of one ``gear_ref --simd --batch We`` per torque level, summed."""
    exe = tmp / "gear_ref"
    gcc = shutil.which("gcc") or sys.exit("gcc is needed to build gear_ref")
    subprocess.run([gcc, "-O3", "-march=native", "-o", exe, GEAR_REF, "-lm"], check=True)
    req = validated(sweep_doc(cubic_te_design()))
    speeds, torques = req.grids()
    calls = []
    for torque in torques:
        lo, hi = (req.point({"speed": s, "torque": torque}) for s in (speeds[0], speeds[-1]))
        we_lo, we_hi = lo.transmission_error.frequency, hi.transmission_error.frequency
        fe = lo.transmission_error.harmonics[0].amplitude
        s = ENVELOPE_SETTINGS
        calls.append([exe, "--simd", "--batch", "We", f"{we_lo!r}", f"{we_hi!r}", str(SPEEDS[2]),
                      f"{lo.damping!r}", f"{fe!r}", f"{we_lo!r}", f"{lo.mean_force!r}", "0", "1",
                      "0", "1", "cubic", str(s["steps_per_period"]), str(s["transient_periods"]),
                      str(s["record_periods"])])  # fmt: skip

    def run() -> None:
        for call in calls:
            subprocess.run(call, check=True, capture_output=True)

    return best_of(run, REPEATS)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp_dir:
        tmp = Path(tmp_dir)
        ref = gear_ref_seconds(tmp)
        cores = os.cpu_count() or 1
        sweep = in_process_seconds(cubic_te_design(), 1, REPEATS)
        command = command_seconds(cubic_te_design(), tmp)
        readme = command_seconds(readme_design(), tmp)
        readme_1 = command_seconds(readme_design(), tmp, "--starts", "1")
        readme_sweep = in_process_seconds(readme_design(), 1, REPEATS)
        readme_64 = in_process_seconds(readme_design(), 64, 1)
    n = SPEEDS[2] * TORQUES[2]
    load = os.getloadavg()[0]
    rows = [
        f"| sweep of the {n} points in process, {cores} threads | {sweep:.2f} s | "
        f"{ref:.2f} s | {sweep / ref:.1f}x |",
        f"| whole `gearengine check` command (new process) | {command:.2f} s | {ref:.2f} s | "
        f"{command / ref:.1f}x |",
        f"| README design (examples/ci/design.json: piecewise law, 3 excitations), sweep in "
        f"process | {readme_sweep:.2f} s | – | – |",
        f"| whole command, README design, one start per point (`--starts 1`) | {readme_1:.2f} s "
        "| – | – |",
        f"| whole command, README design, the gate's default 16 basin starts per point | "
        f"{readme:.2f} s | – | – |",
        f"| README design, 64 random starts per point, sweep in process (one run) | "
        f"{readme_64:.2f} s | – | – |",
    ]
    write_section(
        "envelope",
        "## Envelope check (`gearengine check --speed 500:6000 --torque 20:200`)\n\n"
        f"Default grid {SPEEDS[2]} speeds x {TORQUES[2]} torques, 60 + 60 periods of 128 RK4 "
        "steps; the README design with its transmission error only and the cubic law, so that "
        "gear_ref --simd --batch (one call per torque level over the speeds) runs the same "
        "points. Best of 3, `benchmarks/bench_envelope.py`. Targets (issue 20) for the README "
        "design: <= 0.4 s in process, <= 1.5 s as a whole command (one start per point, the "
        "gate's default when the issue was written; issue 21 then made it 16 basin starts), "
        "<= 6 s in process with 64 starts per point.\n\n"
        "| what | gearengine | gear_ref --simd --batch | ratio |\n|---|---:|---:|---:|\n"
        + "\n".join(rows)
        + f"\n\nLoad average (1 min) at the end of the run: {load:.1f} on {cores} cores.",
    )
    print("\n".join(rows))


if __name__ == "__main__":
    main()
