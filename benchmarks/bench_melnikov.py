"""Speed of the Melnikov verdict against the previous implementation (git commit 2216844).

Run:  .venv/bin/python benchmarks/bench_melnikov.py
Extracts the engine of commit 2216844 with ``git archive`` into a temporary directory and times
it and the working tree, each in its own subprocess (PYTHONPATH set to one or the other), in one
run. Prints a markdown table and writes it into its section of benchmarks/README.md.
Cases: the paper's section 4.1 design (one excitation), a design with stiffness, transmission
error and torque (commensurate 1 : 0.5 : 0.25), both with all thresholds and the default
Omega_e scan; and the verdicts and margins of 10,000 one-excitation designs (the old engine has
no batch: its per-design verdict and four parameter thresholds, timed on 500 designs).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from common import extracted  # benchmarks/common.py (the script's own folder)
from report import write_section

ROOT = Path(__file__).resolve().parents[1]
BASELINE = "2216844"
PREVIOUS = "8ba34c9"
"""Before the per-point verdicts ran compiled: the baseline of rows the old engine cannot run."""
DESIGN = ROOT / "examples" / "design-direct.json"

WORKER = r"""
import json, random, sys, time
from gearengine.homoclinic.thresholds import chaos_possible, parameter_threshold
from gearengine.homoclinic.verdict import melnikov
from gearengine.systems.spur_pair.laws import melnikov_cubic
from gearengine.model.params import GearParams

ONE = GearParams.model_validate({"damping": 0.07, "mean_force": 0.01,
    "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]}})
THREE = GearParams.model_validate({"damping": 0.05, "mean_force": 0.02,
    "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.1, "phase": 0.3}]},
    "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.15, "phase": 0.7}]},
    "torque": {"frequency": 0.25, "harmonics": [{"amplitude": 0.08, "phase": 1.1}]}})


def best_ms(fn, n, repeats=7):
    fn()
    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        for _ in range(n):
            fn()
        best = min(best, (time.perf_counter() - t) / n)
    return 1e3 * best


rng = random.Random(3)
names = ["transmission_error", "stiffness", "torque"]
designs = [GearParams.model_validate({"damping": rng.uniform(0.01, 0.2),
    "backlash": {"model": "cubic", "a": rng.uniform(0.1, 1.0), "c": rng.uniform(0.1, 1.0)},
    rng.choice(names): {"frequency": rng.uniform(0.1, 2.0),
                        "harmonics": [{"amplitude": rng.uniform(-0.5, 0.5)}]}})
    for _ in range(10_000)]
out = {"one": best_ms(lambda: melnikov(ONE), 50), "three": best_ms(lambda: melnikov(THREE), 10)}
try:
    from gearengine.homoclinic import melnikov_batch
except ImportError:  # the baseline: one design at a time, verdict and four thresholds
    def per_design(p):
        a, c, _ = melnikov_cubic(p.backlash)
        verdict = chaos_possible(p)
        return verdict, [parameter_threshold(p, q, a, c) for q in ("F_e1", "mu", "k_p1", "F_p1")]
    sample = designs[:500]
    out["batch"] = best_ms(lambda: [per_design(p) for p in sample], 1, 3) * len(designs) / 500
    out["batch_three"] = None
else:
    out["batch"] = best_ms(lambda: melnikov_batch(designs), 1, 5)
    threes = [THREE.model_copy(update={"damping": 0.01 + 0.1 * k / 1000}) for k in range(1000)]
    out["batch_three"] = best_ms(lambda: melnikov_batch(threes), 1, 3) / 1000
# per-point verdicts: one chaos_possible per sweep point, strength_at along paths
out["chaos_one"] = best_ms(lambda: chaos_possible(ONE), 200)
out["chaos_three"] = best_ms(lambda: chaos_possible(THREE), 200)
try:
    from gearengine.analysis import MelnikovRequest
    from gearengine.engineering import engineering
except ImportError:  # before the design conversion: no engineering block
    out["engineering"] = None
else:
    with open(sys.argv[1]) as f:
        req = MelnikovRequest.model_validate(json.load(f))
    mel = melnikov(req.conversion.params)
    out["engineering"] = best_ms(
        lambda: engineering(req.conversion, req.speed_rpm_range(), mel), 3, 3)
print(json.dumps(out))
"""


def measure(pythonpath: Path) -> dict:
    """Run the worker with ``pythonpath`` first on the path; its timings in ms."""
    env = {**os.environ, "PYTHONPATH": str(pythonpath)}
    run = subprocess.run(
        [sys.executable, "-c", WORKER, str(DESIGN)],
        env=env,
        cwd=pythonpath,
        capture_output=True,
        text=True,
    )
    if run.returncode:
        raise RuntimeError(run.stderr)
    return json.loads(run.stdout.strip().splitlines()[-1])


def measure_commit(commit: str) -> dict:
    """The worker's timings on the engine of ``commit`` (``git archive`` into a temporary dir)."""
    with extracted(commit) as tmp:
        return measure(tmp)


def main() -> None:
    old = measure_commit(BASELINE)
    previous = measure_commit(PREVIOUS)
    new = measure(ROOT)
    rows = [
        ("verdict + thresholds, one excitation (paper 4.1), ms per verdict", "one"),
        ("verdict + thresholds, three excitations, ms per verdict", "three"),
        ("10,000 one-excitation designs: verdict + 4 margins, ms per call", "batch"),
        ("verdict alone (`chaos_possible`, once per sweep point), one excitation, ms", "chaos_one"),
        ("verdict alone (`chaos_possible`), three excitations, ms per call", "chaos_three"),
        (
            "`engineering()` of examples/design-direct.json (speed windows: about 250 "
            "`strength_at`, three excitations, piecewise law), ms per call",
            "engineering",
        ),
    ]
    lines = [
        "## Melnikov verdict",
        "",
        "Reproduce: `.venv/bin/python benchmarks/bench_melnikov.py` (rewrites this section).",
        "",
        f"In-process wall time, best of several repeats, of `melnikov(params)` (all thresholds, "
        f"default 60-point Omega_e scan) and of `melnikov_batch`, against the engine of commit "
        f"{BASELINE} extracted with `git archive` and run in its own subprocess in the same run. "
        "The baseline has no batch: its row is its per-design verdict and four parameter "
        "thresholds, timed on 500 designs and scaled to 10,000.",
        "",
        f"The per-point rows (`chaos_possible`, `strength_at` behind the speed windows of "
        f"`engineering()`) run `kernels.scan_strength` at the design's own speed; the "
        f"`engineering()` row is compared with commit {PREVIOUS} (the baseline has no design "
        "conversion), the last commit before that change, extracted the same way.",
        "",
        f"| what | baseline | baseline, ms | {PREVIOUS}, ms | now, ms | speed-up |",
        "| --- | --- | ---: | ---: | ---: | ---: |",
    ]
    for label, key in rows:
        base, ref = (old, BASELINE) if old[key] is not None else (previous, PREVIOUS)
        lines.append(
            f"| {label} | {ref} | {base[key]:.3f} | {previous[key]:.3f} | {new[key]:.3f} "
            f"| {base[key] / new[key]:.1f}x |"
        )
    lines += [
        "",
        f"Designs with several excitations take the per-design path of `melnikov_batch`: "
        f"{new['batch_three']:.3f} ms per design (three excitations).",
    ]
    markdown = "\n".join(lines)
    print(markdown)
    write_section("melnikov", markdown)


if __name__ == "__main__":
    main()
