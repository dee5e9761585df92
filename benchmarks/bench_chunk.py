"""CPU time of one sweep chunk of the chaos map: the Python around the kernel (issue 31).

Run:  .venv/bin/python benchmarks/bench_chunk.py [--before REF] [--rounds 5] [--profile]

examples/chaos-map.json at 60 x 60 points with default settings (physical time, 200 RK4 steps
per T0) computed as one chunk of 3,600 points (``studies.sweep.compute`` and its JSON, what a
worker computes and hands on), in a fresh process per tree, warmed on a 4 x 4 map first, timed
with ``time.process_time`` (the CPU of all its threads: the kernel's two streams and the
Python). Rounds alternate between REF (a commit, extracted with ``git archive``; default the
merge base with main) and the working tree, so a shared machine loads both alike; min and
median of each and the ratio of the medians, with the load average. The chunk's text of both
trees is compared byte for byte. ``--profile`` prints a cProfile of the working tree's chunk
instead. Writes its section of benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

from common import extracted  # benchmarks/common.py (the script's own folder)
from report import write_section

ROOT = Path(__file__).resolve().parents[1]
SIDE = 60
"""Points per axis of the timed chunk (one chunk of SIDE x SIDE points)."""

WORKER = r"""
import cProfile, hashlib, json, pstats, sys, time
from gearengine.studies.sweep.compute import compute_chunk_json
doc = json.loads(sys.argv[1])
small = {**doc, "axes": [{**a, "num": 4} for a in doc["axes"]]}
compute_chunk_json(json.dumps(small), 0, 16)  # compiled kernels loaded, caches warm
text = json.dumps(doc)
n = 1
for a in doc["axes"]:
    n *= a["num"]
if sys.argv[2] == "profile":
    prof = cProfile.Profile(time.process_time)
    prof.enable()
    compute_chunk_json(text, 0, n)
    prof.disable()
    pstats.Stats(prof).sort_stats("cumulative").print_stats(40)
else:
    t = time.process_time()
    out = compute_chunk_json(text, 0, n)
    cpu = time.process_time() - t
    print(json.dumps({"cpu": cpu, "sha256": hashlib.sha256(out.encode()).hexdigest()}))
"""


def map_doc() -> dict:
    """The chaos map at SIDE x SIDE points, default settings."""
    doc = json.loads((ROOT / "examples" / "chaos-map.json").read_text())
    doc["settings"] = {}
    for axis in doc["axes"]:
        axis["num"] = SIDE
    return doc


def run(tree: Path, mode: str) -> str:
    """The worker's output in a fresh process whose ``gearengine`` is ``tree``'s."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    return subprocess.run([sys.executable, "-c", WORKER, json.dumps(map_doc()), mode], cwd=tree,
                          env=env, check=True, capture_output=True, text=True).stdout  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default=None, help="commit to compare (default: merge base)")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args()
    if args.profile:
        print(run(ROOT, "profile"))
        return
    before = args.before or subprocess.run(["git", "merge-base", "HEAD", "main"], cwd=ROOT,
                                           check=True, capture_output=True,
                                           text=True).stdout.strip()  # fmt: skip
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, check=True,
                          capture_output=True, text=True).stdout.strip()  # fmt: skip
    cpu: dict[str, list[float]] = {"before": [], "now": []}
    digests: set[str] = set()
    loads = [os.getloadavg()[0]]
    with extracted(before, ("gearengine",)) as tree:
        for _ in range(args.rounds):
            for name, path in (("before", tree), ("now", ROOT)):
                got = json.loads(run(path, "time"))
                cpu[name].append(got["cpu"])
                digests.add(got["sha256"])
            loads.append(os.getloadavg()[0])
    same = "byte-identical" if len(digests) == 1 else "DIFFERENT"
    rows = []
    for name in ("before", "now"):
        times = cpu[name]
        rows.append(f"| {name} ({before[:7] if name == 'before' else head}) | "
                    f"{min(times):.3f} / {statistics.median(times):.3f} s | "
                    f"{', '.join(f'{t:.2f}' for t in times)} |")  # fmt: skip
    ratio = statistics.median(cpu["now"]) / statistics.median(cpu["before"])
    markdown = f"""## One sweep chunk of the chaos map: CPU (issue 31)

Reproduce: `.venv/bin/python benchmarks/bench_chunk.py [--before REF]` (rewrites this section;
`--profile` prints a cProfile of the chunk). examples/chaos-map.json at {SIDE} x {SIDE} points,
default settings, as one chunk of {SIDE * SIDE} points (`compute_chunk_json`: verdicts, Melnikov,
the chunk's JSON), each run in a fresh warmed process, CPU time of all its threads
(`time.process_time`), {args.rounds} rounds alternating between the trees. The chunks' texts are
{same}.

| tree | CPU min / median | per round |
| --- | ---: | --- |
{chr(10).join(rows)}

Now / before (medians): **{ratio:.2f}x**. Load average (1 min) during the run:
{min(loads):.1f}-{max(loads):.1f} on 2 cores.
"""
    print(markdown)
    write_section("chunk", markdown)


if __name__ == "__main__":
    main()
