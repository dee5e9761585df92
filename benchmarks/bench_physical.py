"""Transient and record in physical time (``numerics.physical``, issue 31) against the fixed
lengths, wall time and agreement.

Run:  .venv/bin/python benchmarks/bench_physical.py [--quick]

1. One analysis (``analyze``, in process after ``warm_up``) of the README CI design
   (examples/ci/design.json: torque ripple at shaft order 1, so T0 is one driver revolution =
   18 mesh periods) at 4,000 rpm, against its no-ripple twin (the same design without
   ``torque_fluctuation``: T0 one mesh period) and against the fixed-length run (``adaptive``
   false: 500 + 500 T0). Each timed run is a new design (speed 4,000 + 7 k rpm and damping ratio
   raised by 0.2 % x k, k = 0..REPEATS-1), the three kinds interleaved so the machine's load
   hits them alike; min and median, ratios of medians. Agreement of class, period, contact
   regime and DTE against the fixed-length run on each of them.
2. The default 23 x 5 envelope of the gate with 16 basin starts per point (``gearengine check
   --starts 16``; settings 60 + 60 T0 of 128 steps) of examples/ci/design.json (500-6,000 rpm x
   20-200 N m) and examples/envelope-map.json (500-6,000 rpm x 2-40 N m): the headline class
   and period of every point with the physical-time lengths, with the lengths of before (the
   kernels' early stopping in T0, ``physical_time`` false) and with fixed lengths (``adaptive``
   false), and each sweep's wall time (once each: in process, 2 threads).

Writes its section of benchmarks/README.md.
"""

from __future__ import annotations

import copy
import json
import os
import sys
import time
from pathlib import Path

from common import min_median  # benchmarks/common.py
from report import write_section  # benchmarks/report.py

from gearengine import AnalysisRequest, analyze, warm_up
from gearengine.gate.envelope import envelope_axis, envelope_sweep, gate_settings
from gearengine.studies.sweep import run_local, validated

ROOT = Path(__file__).resolve().parents[1]
REPEATS = 5
KINDS = {
    "physical time": {},
    "no-ripple twin, physical time": {},
    "fixed length (adaptive false)": {"adaptive": False},
}


Z23 = {
    "driver": {"teeth": 23, "module": "2.5 mm", "face_width": "20 mm"},
    "driven": {"teeth": 67, "module": "2.5 mm", "face_width": "20 mm"},
    "speed": "4000 rpm", "torque": "5 N*m",
    "mesh": {"stiffness": "iso6336", "damping_ratio": 0.05, "half_backlash": "47 um"},
    "transmission_error": {"harmonics": [{"amplitude": "11.3 um"}]},
    "torque_fluctuation": {"order": 1, "harmonics": [{"amplitude": "0.15 N*m"}]},
    "backlash_law": "piecewise",
}  # fmt: skip
"""The issue's z = 23/67 design (module 2.5 mm, face 20 mm, ISO 6336 stiffness, half backlash
47 um, TE 11.3 um, ripple 0.15 N m at order 1) at 4,000 rpm and 5 N m (tooth separation):
T0 is one driver revolution, 23 mesh periods."""
DESIGNS = {
    "README CI design (z = 18, 40 N m)": lambda: json.loads(
        (ROOT / "examples" / "ci" / "design.json").read_text())["design"],
    "z = 23/67, ISO 6336, ripple at order 1": lambda: Z23,
}  # fmt: skip


def design_doc(name: str, k: int, ripple: bool) -> dict:
    """Design ``name`` at 4,000 + 7 k rpm, damping ratio x (1 + 0.002 k), with or without its
    torque ripple."""
    d = copy.deepcopy(DESIGNS[name]())
    d["speed"] = f"{4000 + 7 * k} rpm"
    d["mesh"]["damping_ratio"] *= 1.0 + 0.002 * k
    if not ripple:
        d.pop("torque_fluctuation")
    return d


def one_analysis(name: str, repeats: int) -> tuple[list[str], list[str]]:
    """Section 1 for design ``name``: rows of the table of times and the agreement lines."""
    times: dict[str, list[float]] = {k: [] for k in KINDS}
    results: dict[str, list] = {k: [] for k in KINDS}
    for k in range(repeats):
        for kind, settings in KINDS.items():
            req = AnalysisRequest.model_validate(
                {"design": design_doc(name, k, "twin" not in kind), "settings": settings}
            )
            t = time.perf_counter()
            res = analyze(req)
            times[kind].append(time.perf_counter() - t)
            results[kind].append(res)
    med = {k: min_median(v) for k, v in times.items()}
    base = med["physical time"][1]
    rows = [f"| {name} | {kind} | {lo:.3f} / {md:.3f} s | {md / base:.2f}x |"
            for kind, (lo, md) in med.items()]  # fmt: skip
    lines = []
    for a, f, tw in zip(results["physical time"], results["fixed length (adaptive false)"],
                        results["no-ripple twin, physical time"], strict=True):  # fmt: skip
        na, nf = a.numerics, f.numerics
        ra, rf = a.engineering.response, f.engineering.response
        dte = ra.dte_peak_to_peak_um / rf.dte_peak_to_peak_um - 1.0
        lines.append(
            f"{name}, {a.engineering.speed_rpm:.0f} rpm: {na.classification} {na.period}T "
            f"{ra.contact.regime} DTE {ra.dte_peak_to_peak_um:.4f} µm vs fixed "
            f"{nf.classification} {nf.period}T {rf.contact.regime} "
            f"{rf.dte_peak_to_peak_um:.4f} µm ({100 * dte:+.3f} %); transient "
            f"{na.transient.periods} T0 = {na.transient.mesh_periods:.0f} mesh periods = "
            f"{1e3 * na.transient.seconds:.1f} ms ({na.transient.reason}), record "
            f"{na.record.periods} T0 = {na.record.mesh_periods:.0f} mesh periods "
            f"({na.record.reason}); twin {tw.numerics.transient.mesh_periods:.0f} + "
            f"{tw.numerics.record.mesh_periods:.0f} mesh periods"
        )
    return rows, lines


ENVELOPES = {
    "examples/ci/design.json": ("500:6000", "20:200"),
    "examples/envelope-map.json": ("500:6000", "2:40"),
}
MODES = {
    "physical time (default)": {},
    "before: T0 counts, kernels' early stop": {"physical_time": False},
    "fixed length (adaptive false)": {"adaptive": False},
}


def envelope(path: str, speed: str, torque: str) -> tuple[list[str], list[str]]:
    """Section 2 for one design file: a row per mode and the disagreements."""
    doc = json.loads((ROOT / path).read_text())
    axes = [envelope_axis("speed", speed, "rpm", 23), envelope_axis("torque", torque, "N*m", 5)]
    out: dict[str, tuple[float, list]] = {}
    for mode, extra in MODES.items():
        settings = gate_settings({**(doc.get("settings") or {}), **extra}, 16)
        req = validated(envelope_sweep(doc["design"], settings, axes, "bench"))
        t = time.perf_counter()
        res = run_local(req, workers=os.cpu_count() or 1)
        out[mode] = (time.perf_counter() - t, res.points)
    fixed = out["fixed length (adaptive false)"][1]
    rows, notes = [], []
    for mode, (sec, points) in out.items():
        same = [(p.classification, p.period) == (f.classification, f.period)
                for p, f in zip(points, fixed, strict=True)]  # fmt: skip
        runs = sum(p.periods_run or 0 for p in points) / len(points)
        rows.append(f"| {path} | {mode} | {sec:.2f} s | {sum(same)} / {len(same)} "
                    f"({100 * sum(same) / len(same):.1f} %) | {runs:.0f} |")  # fmt: skip
        for p, f, ok in zip(points, fixed, same, strict=True):
            if not ok and mode == "physical time (default)":
                where = ", ".join(f"{k} {v:g}" for k, v in p.values.items())
                notes.append(
                    f"{path} at {where}: {p.classification} {p.period} (LLE {p.lle}, "
                    f"stderr {p.lle_stderr}, {p.periods_run} T0) vs fixed {f.classification} "
                    f"{f.period} (LLE {f.lle}, stderr {f.lle_stderr})"
                )
    return rows, notes


def main() -> None:
    quick = "--quick" in sys.argv
    warm_up()
    load0 = os.getloadavg()[0]
    table = ["| design | run | min / median | median / physical time's |",
             "|---|---|---:|---:|"]  # fmt: skip
    agreement: list[str] = []
    for name in DESIGNS:
        rows, lines = one_analysis(name, 2 if quick else REPEATS)
        table += rows
        agreement += lines
    env_rows = ["| design | lengths | sweep | class and period as fixed | mean T0 run per "
                "point (worst start) |", "|---|---|---:|---:|---:|"]  # fmt: skip
    env_notes: list[str] = []
    for path, (speed, torque) in ENVELOPES.items():
        rows, notes = envelope(path, speed, torque)
        env_rows += rows
        env_notes += notes
    load1 = os.getloadavg()[0]
    text = "\n".join([
        "## Transient and record in physical time (issue 31)",
        "",
        "Reproduce: `.venv/bin/python benchmarks/bench_physical.py` (rewrites this section). "
        f"Load average (1 min) {load0:.1f} before, {load1:.1f} after, on 2 cores shared with "
        "other work: the ratios of runs interleaved in one process are the result, not the "
        "seconds. Rules: `gearengine/numerics/physical.py`.",
        "",
        "One analysis (`analyze`, in process after `warm_up`) at 4,000 rpm of the README CI "
        "design (T0 = one driver revolution = 18 mesh periods) and of the issue's z = 23/67 "
        "design (ISO 6336 stiffness, TE 11.3 um, ripple 0.15 N m at order 1, 5 N m: 23 mesh "
        f"periods), {len(agreement) // len(DESIGNS)} varied designs each (speed + 7 k rpm, "
        "damping ratio x (1 + 0.002 k)), the three kinds interleaved; the twin is the design "
        "without its ripple (T0 = one mesh period):",
        "",
        *table,
        "",
        "Agreement with the fixed-length run (class, period, contact regime, DTE):",
        "",
        *[f"- {line}" for line in agreement],
        "",
        "The gate's default envelope, 23 x 5 points, 16 basin starts per point (4 x 4 grid), "
        "settings 60 + 60 T0 of 128 steps (the upper bounds with physical time), headline "
        "class and period of each point against the fixed-length run's; one sweep each, in "
        "process on every core:",
        "",
        *env_rows,
        "",
        "Disagreements (physical time vs fixed length):" if env_notes else
        "No disagreement between physical time and fixed length.",
        "",
        *[f"- {n}" for n in env_notes],
    ])  # fmt: skip
    print(text)
    if not quick:
        write_section("physical", text)


if __name__ == "__main__":
    main()
