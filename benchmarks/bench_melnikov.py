"""Speed of the Melnikov verdict against the previous implementation (git commit 2216844).

Run:  .venv/bin/python benchmarks/bench_melnikov.py
Extracts the engine of commit 2216844 with ``git archive`` into a temporary directory and times
it and the working tree, each in its own subprocess (PYTHONPATH set to one or the other), in one
run. Prints a markdown table and writes it into its section of benchmarks/README.md.
Cases: the paper's section 4.1 design (one excitation), a design with stiffness, transmission
error and torque (commensurate 1 : 0.5 : 0.25), both with all thresholds and the default
Omega_e scan; and the verdicts and margins of 10,000 one-excitation designs (the old engine has
no batch: its per-design verdict and four parameter thresholds, timed on 500 designs).

Served (issue 31): POST /v1/melnikov through a real ``gearengine serve`` of the working tree and
one of commit 9b6ddae (before issue 31, ``git archive`` of gearengine and service), both warm,
requests alternating between them (a shared machine loads both alike); every request a new
design (no cache serves it), one excitation or three; and the same verdicts in process
(``answer_melnikov`` and its JSON) in a worker of each tree, batches alternating, in wall time
and in the worker thread's CPU time (which a loaded machine inflates far less).

    .venv/bin/python benchmarks/bench_melnikov.py --served [--before REF]

runs only that part, against REF (a commit, or a directory holding an earlier tree's
gearengine and service, whose compiled kernels are then reused), into its own section.
"""

from __future__ import annotations

import json
import os
import random
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from common import extracted, min_median, served  # benchmarks/common.py (the script's folder)
from report import write_section

ROOT = Path(__file__).resolve().parents[1]
BASELINE = "2216844"
PREVIOUS = "8ba34c9"
"""Before the per-point verdicts ran compiled: the baseline of rows the old engine cannot run."""
DESIGN = ROOT / "examples" / "design-direct.json"
BEFORE = "9b6ddae"
"""Before issue 31: the loops' largest speed and force sampled on all 4001 grid times, the API
key check and every verdict in a worker thread."""
ROUNDS, PER_ROUND = 12, 40
"""Served and in-process timings: rounds (the trees alternate, first one then the other) of
that many new designs each, per excitation count."""

WORKER = r"""
import json, random, sys, time
from gearengine.homoclinic.thresholds import chaos_possible, parameter_threshold
from gearengine.homoclinic.verdict import melnikov
try:
    from gearengine.systems.spur_pair.laws import melnikov_cubic
except ImportError:  # the baseline 2216844 and 8ba34c9: the law was in model.backlash
    from gearengine.model.backlash import melnikov_cubic
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
    from gearengine.engineering.block import engineering
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


def varied(kind: str, rng: random.Random) -> dict:
    """A new /v1/melnikov request: one excitation (transmission error) or three (stiffness,
    transmission error and torque at 1 : 0.5 : 0.25), amplitude, damping, load and speed drawn
    afresh (loads below F_crit = 0.0642 of the paper's cubic: the loaded loops)."""
    om = rng.uniform(0.4, 0.6)
    params = {
        "damping": rng.uniform(0.04, 0.09),
        "mean_force": rng.uniform(0.0, 0.04),
        "transmission_error": {
            "frequency": om,
            "harmonics": [{"amplitude": rng.uniform(0.05, 0.3)}],
        },
    }
    if kind == "three":
        params["stiffness"] = {"frequency": 2 * om, "harmonics": [{"amplitude": 0.1, "phase": 0.3}]}
        params["torque"] = {"frequency": om / 2, "harmonics": [{"amplitude": 0.08, "phase": 1.1}]}
    return {"params": params}


class Plain:
    """A blocking keep-alive HTTP/1.1 connection on a bare socket: the client adds microseconds,
    not the fraction of a millisecond of httpx, to a served verdict."""

    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port))
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.file = self.sock.makefile("rb")

    def request(self, method: str, path: str, body: bytes = b"") -> tuple[int, bytes]:
        """(status, body) of one request; the response must carry Content-Length."""
        head = f"{method} {path} HTTP/1.1\r\nHost: 127.0.0.1\r\n"
        if body:
            head += f"Content-Type: application/json\r\nContent-Length: {len(body)}\r\n"
        self.sock.sendall(head.encode() + b"\r\n" + body)
        status = int(self.file.readline().split()[1])
        length = 0
        while (line := self.file.readline()) not in (b"\r\n", b""):
            key, _, value = line.partition(b":")
            if key.strip().lower() == b"content-length":
                length = int(value)
        return status, self.file.read(length)

    def close(self) -> None:
        self.file.close()
        self.sock.close()


def served_timings(ports: dict[str, int]) -> dict[tuple[str, str], list[float]]:
    """Wall time per request [s], by (tree, what): POST /v1/melnikov of new designs ("one",
    "three") and GET /v1/health ("health", the floor of any request), the trees alternating."""
    clients = {label: Plain(port) for label, port in ports.items()}
    times: dict[tuple[str, str], list[float]] = {}
    try:
        for warm in range(20):  # both servers' HTTP processes warm
            for client in clients.values():
                client.request(
                    "POST", "/v1/melnikov", json.dumps(varied("one", random.Random(warm))).encode()
                )
        for k in range(ROUNDS):
            order = list(clients) if k % 2 == 0 else list(clients)[::-1]
            for what in ("one", "three", "health"):
                for label in order:
                    rng = random.Random(1000 * k + len(what))  # the same designs for both trees
                    for _ in range(PER_ROUND):
                        body = b"" if what == "health" else json.dumps(varied(what, rng)).encode()
                        method, path = (
                            ("GET", "/v1/health") if what == "health" else ("POST", "/v1/melnikov")
                        )
                        t = time.perf_counter()
                        status, _ = clients[label].request(method, path, body)
                        times.setdefault((label, what), []).append(time.perf_counter() - t)
                        if status != 200:
                            raise RuntimeError(f"{label} {what}: HTTP {status}")
    finally:
        for client in clients.values():
            client.close()
    return times


VERDICTS = r"""
import json, sys, time
from gearengine.analysis import MelnikovRequest, answer_melnikov
from gearengine.jsonio import dumps
for line in sys.stdin:
    reqs = [MelnikovRequest.model_validate(d) for d in json.loads(line)]
    times = []
    for r in reqs:
        t, cpu = time.perf_counter(), time.thread_time()
        dumps(answer_melnikov(r))
        times.append((time.perf_counter() - t, time.thread_time() - cpu))
    print(json.dumps(times), flush=True)
"""


def in_process_timings(trees: dict[str, Path]) -> dict[tuple[str, str], list[float]]:
    """Wall time [s] of ``answer_melnikov`` and its JSON per new design, by (tree, "one" or
    "three"), and its CPU time by (tree, "one cpu" or "three cpu"), in one worker process per
    tree, batches alternating between them."""
    workers = {
        label: subprocess.Popen(
            [sys.executable, "-c", VERDICTS],
            env={**os.environ, "PYTHONPATH": str(tree)},
            cwd=tree,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        for label, tree in trees.items()
    }

    def batch(label: str, docs: list[dict]) -> list[float]:
        worker = workers[label]
        worker.stdin.write(json.dumps(docs) + "\n")
        worker.stdin.flush()
        return json.loads(worker.stdout.readline())

    times: dict[tuple[str, str], list[float]] = {}
    try:
        for k in range(-1, ROUNDS):  # round -1 warms the kernels and caches of fixed things
            order = list(workers) if k % 2 == 0 else list(workers)[::-1]
            for what in ("one", "three"):
                rng = random.Random(7000 + k)
                docs = [varied(what, rng) for _ in range(PER_ROUND)]
                for label in order:
                    got = batch(label, docs)
                    if k >= 0:
                        times.setdefault((label, what), []).extend(w for w, _ in got)
                        times.setdefault((label, f"{what} cpu"), []).extend(c for _, c in got)
    finally:
        for worker in workers.values():
            worker.stdin.close()
            worker.wait()
    return times


@contextmanager
def earlier_tree(ref: str) -> Iterator[Path]:
    """The gearengine and service of ``ref``: a directory holding them, as it is, or a commit,
    extracted (``git archive``) into a temporary directory."""
    if Path(ref).is_dir():
        yield Path(ref)
        return
    with extracted(ref, ("gearengine", "service")) as old:
        yield old


def served_section(before: str = BEFORE) -> list[str]:
    """The served and in-process rows of issue 31, ``before`` (a commit or an earlier tree,
    ``earlier_tree``) and now, as markdown."""
    with earlier_tree(before) as old, tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for label in ("before", "now"):
            (tmp / label).mkdir()
        with served(tmp / "before" / "data", {}, old) as a, served(tmp / "now" / "data", {}) as b:
            ports = {"before": a.base_url.port, "now": b.base_url.port}
            http = served_timings(ports)
        local = in_process_timings({"before": old, "now": ROOT})
    load = os.getloadavg()[0]
    rows = [
        ("served: POST /v1/melnikov, one excitation", http, "one"),
        ("served: POST /v1/melnikov, three excitations", http, "three"),
        ("served: GET /v1/health (the floor of any request)", http, "health"),
        ("in process: `answer_melnikov` + JSON, one excitation", local, "one"),
        ("in process: `answer_melnikov` + JSON, three excitations", local, "three"),
        ("in process, CPU time of the worker thread: one excitation", local, "one cpu"),
        ("in process, CPU time of the worker thread: three excitations", local, "three cpu"),
    ]
    label_before = Path(before).name if Path(before).is_dir() else before  # a dir: its name
    lines = [
        f"### Served (issue 31): before ({label_before}) and now",
        "",
        f"Reproduce: `.venv/bin/python benchmarks/bench_melnikov.py --served --before "
        f"{label_before}` (rewrites this section; REF a commit, or a directory holding that "
        "commit's gearengine and service, extracted with `git archive`, whose compiled kernels "
        "are reused).",
        "",
        f"A real `gearengine serve` of each tree (its defaults: one HTTP process per core), warm; "
        f"{ROUNDS} rounds of {PER_ROUND} requests per row, alternating between the trees, from "
        "one blocking keep-alive client on a bare socket (wall time from the request written to "
        "the response read); every verdict a new design (amplitude, damping, load below F_crit "
        "and speed drawn afresh), so no response cache serves it. In process: the same kind "
        "of designs in one worker per tree, batches alternating. Targets (issue 31): served at "
        "or under 0.6 ms (one excitation) and 6 ms (three).",
        "",
        "| what | before, min / median ms | now, min / median ms | before / now (median) |",
        "| --- | ---: | ---: | ---: |",
    ]
    for label, times, what in rows:
        (b_min, b_med), (n_min, n_med) = (
            min_median(times[(tree, what)]) for tree in ("before", "now")
        )
        lines.append(
            f"| {label} | {1e3 * b_min:.3f} / {1e3 * b_med:.3f} | {1e3 * n_min:.3f} / "
            f"{1e3 * n_med:.3f} | {b_med / n_med:.2f}x |"
        )
    lines += [
        "",
        f"Load average (1 min) at the end of the run: {load:.1f} on 2 cores. On a loaded machine "
        "the minima and the CPU-time rows compare the trees; the wall-time medians carry the "
        "load of other processes as much as the work.",
    ]
    return lines


def main() -> None:
    if "--served" in sys.argv:
        before = sys.argv[sys.argv.index("--before") + 1] if "--before" in sys.argv else BEFORE
        lines = served_section(before)
        print("\n".join(lines))
        write_section("melnikov-served", "\n".join(lines))
        return
    issue31 = served_section()
    print("\n".join(issue31), flush=True)
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
    write_section("melnikov-served", "\n".join(issue31))


if __name__ == "__main__":
    main()
