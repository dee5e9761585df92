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
[-1.5, 1.5], v in [-0.5, 0.5], seed 0). Each timed run is a new design (``varied``); min and
median of 5 runs (3 with 64 starts); prints the load average; writes its section of
benchmarks/README.md.
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

from common import min_median, timings  # benchmarks/common.py
from report import write_section  # benchmarks/report.py (the script's own folder)

from gearengine.gate.envelope import ENVELOPE_SETTINGS
from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.studies.sweep import SweepRequest, balanced_chunk_points, run_local, validated

ROOT = Path(__file__).resolve().parents[1]
GEAR_REF = Path("/work/shared/reference/gear_ref.c")
REPEATS = 5
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


def varied(design: dict, k: int) -> dict:
    """``design`` with its damping ratio raised by 0.2 % x k: each timed run a new design, so
    the Melnikov and conversion caches of an earlier run do not serve it."""
    d = copy.deepcopy(design)
    d["mesh"]["damping_ratio"] = d["mesh"]["damping_ratio"] * (1.0 + 0.002 * k)
    return d


def in_process_seconds(design: dict, starts: int, repeats: int) -> tuple[float, float]:
    """(min, median) wall time of the envelope sweep of ``repeats`` varied copies of ``design``
    in this process (every core), with ``starts`` random initial states per point when more
    than one."""
    cores = os.cpu_count() or 1

    def request(k: int) -> SweepRequest:
        doc = sweep_doc(varied(design, k))
        if starts > 1:
            box = [[-1.5, 1.5], [-0.5, 0.5]]
            rand = {"count": starts, "box": box, "seed": 0}
            doc["settings"] = {**doc["settings"], "random_initial_states": rand}
        return validated(doc)

    chunk = balanced_chunk_points(request(0).n_points(), cores, smallest=1)
    run_local(request(-1), chunk_points=chunk, workers=cores)  # kernels compiled or loaded
    requests = [request(k) for k in range(1, repeats + 1)]
    calls = [lambda r=r: run_local(r, chunk_points=chunk, workers=cores) for r in requests]
    return min_median(timings(calls))


def command_seconds(design: dict, tmp: Path, *extra: str) -> tuple[float, float]:
    """(min, median) wall time of the whole ``gearengine check`` command (a new process) on the
    default envelope of ``REPEATS`` varied copies of ``design``, with the options ``extra``."""
    speed, torque = f"{SPEEDS[0]:g}:{SPEEDS[1]:g}", f"{TORQUES[0]:g}:{TORQUES[1]:g}"
    calls = []
    for k in range(1, REPEATS + 1):
        path = tmp / f"design-{k}.json"
        path.write_text(json.dumps({"design": varied(design, k)}))
        args = [sys.executable, "-m", "gearengine.cli", "check", str(path), "--speed", speed,
                "--torque", torque, *extra]  # fmt: skip
        calls.append(lambda args=args: subprocess.run(args, capture_output=True, check=False))
    return min_median(timings(calls))


def gear_ref_seconds(tmp: Path) -> tuple[float, float]:
    """(min, median) wall time of one ``gear_ref --simd --batch We`` per torque level, summed
    (plain C, no cache: the same points each time)."""
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

    return min_median(timings([run] * REPEATS))


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
        readme_64 = in_process_seconds(readme_design(), 64, 3)
    n = SPEEDS[2] * TORQUES[2]
    load = os.getloadavg()[0]

    def mm(t: tuple[float, float]) -> str:
        return f"{t[0]:.2f} / {t[1]:.2f} s"

    def ratio(t: tuple[float, float]) -> str:
        return f"{t[1] / ref[1]:.1f}x"

    rows = [
        f"| sweep of the {n} points in process, {cores} threads | {mm(sweep)} | {mm(ref)} | "
        f"{ratio(sweep)} |",
        f"| whole `gearengine check` command (new process) | {mm(command)} | {mm(ref)} | "
        f"{ratio(command)} |",
        f"| README design (examples/ci/design.json: piecewise law, 3 excitations), sweep in "
        f"process | {mm(readme_sweep)} | – | – |",
        f"| whole command, README design, one start per point (`--starts 1`) | {mm(readme_1)} "
        "| – | – |",
        f"| whole command, README design, the gate's default 16 basin starts per point | "
        f"{mm(readme)} | – | – |",
        f"| README design, 64 random starts per point, sweep in process (3 runs) | "
        f"{mm(readme_64)} | – | – |",
    ]
    write_section(
        "envelope",
        "## Envelope check (`gearengine check --speed 500:6000 --torque 20:200`)\n\n"
        f"Default grid {SPEEDS[2]} speeds x {TORQUES[2]} torques, 60 + 60 periods of 128 RK4 "
        "steps; the README design with its transmission error only and the cubic law, so that "
        "gear_ref --simd --batch (one call per torque level over the speeds) runs the same "
        "points. Times are min / median of 5 runs (3 with 64 starts), each run a new design "
        "(the damping ratio raised by 0.2 % per run, so no cache of an earlier run serves it); "
        "ratios of medians. `benchmarks/bench_envelope.py`. Targets (issue 20) for the README "
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
