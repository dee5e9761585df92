"""POST /v1/melnikov in process through the ASGI app: byte identity against another tree, and
the CPU time of a request.

    PYTHONPATH=$PWD .venv/bin/python benchmarks/melnikov_identity.py --against TREE
    PYTHONPATH=$PWD .venv/bin/python benchmarks/melnikov_identity.py --cpu TREE [--profile]
    PYTHONPATH=$PWD .venv/bin/python benchmarks/melnikov_identity.py --store FILE --from TREE

``--against``: about 500 varied requests (one and three excitations, loads of both signs and
above F_crit, quadrature, perturbation load, not applicable, incommensurate, inactive
excitations, several harmonics, extreme frequencies, designs, refusals, repeats that the cache
answers) sent to the app of this tree and of TREE (a directory holding another tree's
gearengine and service, e.g. a ``git worktree add --detach`` of main), each in its own process;
every status, media type, ETag and body must be the same bytes. ``--cpu``: the CPU time of the
worker thread (``time.thread_time``) per one-excitation request through the whole ASGI app
(middlewares, routing, validation, verdict, JSON), each a new design, batches alternating
between this tree and TREE; ``--profile`` adds cProfile's top functions of this tree.
``--store``: 60 of those requests with the digests of TREE's answers, the data of
``tests/test_verdict_lane.py``.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import random
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DESIGN = json.loads((ROOT / "examples" / "design-direct.json").read_text())

WORKER = r"""
import asyncio, cProfile, io, json, pstats, sys, tempfile, time
from service.core.config import Settings
from service.main import create_app

from service.server import log_to_stderr

app = create_app(Settings(data_dir=tempfile.mkdtemp(), workers=0))
log_to_stderr()  # the served log: a request's record queued for the log thread


async def call(media, body):
    scope = {"type": "http", "asgi": {"version": "3.0"}, "http_version": "1.1",
             "method": "POST", "scheme": "http", "path": "/v1/melnikov",
             "raw_path": b"/v1/melnikov", "query_string": b"", "root_path": "",
             "headers": [(b"host", b"127.0.0.1"), (b"content-type", media.encode()),
                         (b"content-length", str(len(body)).encode())],
             "client": ("127.0.0.1", 50000), "server": ("127.0.0.1", 8000)}
    done = False

    async def receive():
        nonlocal done
        if done:
            return {"type": "http.disconnect"}
        done = True
        return {"type": "http.request", "body": body, "more_body": False}

    out = {"body": b""}

    async def send(message):
        if message["type"] == "http.response.start":
            out["status"] = message["status"]
            out["headers"] = dict(message["headers"])
        else:
            out["body"] += message.get("body", b"")

    await app(scope, receive, send)
    return out


async def main():
    for line in sys.stdin:
        command, requests = json.loads(line)
        bodies = [(m, b.encode()) for m, b in requests]
        if command == "responses":
            got = []
            for media, body in bodies:
                r = await call(media, body)
                h = r["headers"]
                got.append([r["status"], h.get(b"content-type", b"").decode(),
                            h.get(b"etag", b"").decode(), r["body"].decode()])
            print(json.dumps(got), flush=True)
        elif command == "times":
            times = []
            for media, body in bodies:
                cpu = time.thread_time()
                r = await call(media, body)
                times.append(time.thread_time() - cpu)
                assert r["status"] == 200, r
            print(json.dumps(times), flush=True)
        elif command == "parts":  # CPU of validation, verdict and JSON apart, per request
            from gearengine.analysis import MelnikovRequest, answer_melnikov
            from gearengine.jsonio import dumps
            parts = []
            for _, body in bodies:
                t0 = time.thread_time()
                req = MelnikovRequest.model_validate_json(body)
                t1 = time.thread_time()
                result = answer_melnikov(req)
                t2 = time.thread_time()
                dumps(result)
                parts.append([t1 - t0, t2 - t1, time.thread_time() - t2])
            print(json.dumps(parts), flush=True)
        else:  # profile
            prof = cProfile.Profile()
            prof.enable()
            for media, body in bodies:
                await call(media, body)
            prof.disable()
            text = io.StringIO()
            pstats.Stats(prof, stream=text).sort_stats("tottime").print_stats(45)
            print(json.dumps(text.getvalue()), flush=True)


asyncio.run(main())
"""


def one(rng: random.Random, name: str = "transmission_error") -> dict:
    """A one-excitation design: damping, load of either sign (some at or above F_crit of its
    cubic), amplitude of either sign, phase, frequency and cubic drawn afresh."""
    a, c = rng.choice([(0.1667, 0.1667), (rng.uniform(0.05, 2.0), rng.uniform(0.05, 2.0))])
    f_crit = 2 * a / 3 * math.sqrt(a / (3 * c))
    params = {
        "damping": rng.choice([0.0, rng.uniform(0.0, 0.3), rng.uniform(0.01, 0.1)]),
        "mean_force": rng.choice([0.0, rng.uniform(-1.2, 1.2) * f_crit]),
        "backlash": {"model": "cubic", "a": a, "c": c},
        name: {
            "frequency": rng.choice([rng.uniform(0.05, 3.0), rng.uniform(0.3, 0.8)]),
            "harmonics": [
                {
                    "amplitude": rng.uniform(-0.5, 0.5),
                    "phase": rng.choice([0.0, rng.uniform(-4, 4)]),
                }
            ],
        },
    }
    return {"params": params}


def three(rng: random.Random, incommensurate: bool = False) -> dict:
    """Stiffness, transmission error and torque at 2 : 1 : 1/2 of Omega_e (or at ratios
    sqrt 2 and pi / 2, incommensurate)."""
    body = one(rng)
    params = body["params"]
    om = params["transmission_error"]["frequency"]
    ratios = (math.sqrt(2.0), math.pi / 2) if incommensurate else (2.0, 0.5)
    params["stiffness"] = {
        "frequency": ratios[0] * om,
        "harmonics": [{"amplitude": rng.uniform(-0.2, 0.2), "phase": rng.uniform(-3, 3)}],
    }
    params["torque"] = {
        "frequency": ratios[1] * om,
        "harmonics": [{"amplitude": rng.uniform(-0.1, 0.1), "phase": rng.uniform(-3, 3)}],
    }
    return body


ONE_EXCITATION = 430
"""How many of ``varied()`` come first with one excitation given (or none active)."""


def varied(seed: int = 31) -> list[tuple[str, str]]:
    """The (media type, body) of every request of ``--against`` (about 500)."""
    rng = random.Random(seed)
    docs: list[dict | str] = []
    docs += [one(rng) for _ in range(200)]
    docs += [one(rng, "stiffness") for _ in range(50)]
    docs += [one(rng, "torque") for _ in range(50)]
    for _ in range(30):  # the paper's first-order treatment of the load
        body = one(rng)
        body["mean_load"] = "perturbation"
        docs.append(body)
    for _ in range(30):  # an inactive excitation beside the active one
        body = one(rng)
        other = rng.choice(["stiffness", "torque"])
        body["params"][other] = {
            "frequency": rng.uniform(0.1, 2),
            "harmonics": rng.choice(
                [[], [{"amplitude": 0.0}], [{"amplitude": 0.0}, {"amplitude": 0.0, "phase": 1.0}]]
            ),
        }
        docs.append(body)
    for _ in range(12):  # no amplitude at all
        body = one(rng)
        body["params"]["transmission_error"]["harmonics"] = rng.choice([[], [{"amplitude": 0}]])
        docs.append(body)
    for _ in range(25):  # two harmonics, or the first silent and the second active
        body = one(rng)
        first = rng.choice([rng.uniform(-0.3, 0.3), 0.0])
        body["params"]["transmission_error"]["harmonics"] = [
            {"amplitude": first},
            {"amplitude": rng.uniform(-0.1, 0.1), "phase": 0.4},
        ]
        docs.append(body)
    for _ in range(20):  # no saddle loop: a <= 0 or c <= 0
        body = one(rng)
        body["params"]["backlash"] = {"model": "cubic", "a": rng.uniform(-1, 0.0), "c": 0.2}
        docs.append(body)
    for freq in (1e-6, 1e-3, 40.0, 300.0, 1000.0):  # coefficients that underflow, or nearly
        body = one(rng)
        body["params"]["transmission_error"]["frequency"] = freq
        docs.append(body)
        docs.append(one(rng, "stiffness") | {})
        docs[-1]["params"]["stiffness"]["frequency"] = freq
    for amp in (1e-12, 1e3, 1e6):
        body = one(rng)
        body["params"]["transmission_error"]["harmonics"][0]["amplitude"] = amp
        docs.append(body)
    assert len(docs) == ONE_EXCITATION
    docs += [three(rng) for _ in range(35)]
    docs += [three(rng, incommensurate=True) for _ in range(12)]
    for _ in range(8):  # quadrature
        body = one(rng, rng.choice(["transmission_error", "stiffness", "torque"]))
        body["method"] = "quadrature"
        docs.append(body)
    docs.append(three(rng) | {"method": "quadrature"})
    for alpha in (0.0, 0.3):
        body = one(rng)
        body["params"]["backlash"] = {"model": "piecewise", "alpha": alpha}
        docs.append(body)
    for torque in ("40 N*m", "5 N*m"):
        design = json.loads(json.dumps(DESIGN))
        design["design"]["torque"] = torque
        docs.append(design)
    docs.append({"design": DESIGN["design"], "params": one(rng)["params"]})  # both: refused
    docs += [
        {},
        {"params": None},
        {"params": {"damping": -0.1}},
        {"params": {"damping": 0.05, "transmission_error": {"frequency": 0.0}}},
        {"params": {"damping": 0.05, "extra": 1}},
        {"params": {"damping": "0.05"}},
        {"params": {"damping": 0.05}, "method": "euler"},
        {"params": {"damping": 0.05}, "mean_load": "both"},
        "[1, 2",
        "",
        "null",
    ]
    repeats = [docs[k] for k in range(0, 60, 6)]  # the cache answers these the second time
    out = [("application/json", d if isinstance(d, str) else json.dumps(d)) for d in docs]
    out += [("application/json", json.dumps(d)) for d in repeats]
    out += [("text/plain", json.dumps(docs[0])), ("application/json; charset=utf-8", out[1][1])]
    return out


def worker(tree: Path) -> subprocess.Popen:
    """A process serving the app of ``tree`` (its gearengine and service first on the path)."""
    return subprocess.Popen(
        [sys.executable, "-c", WORKER],
        env={**os.environ, "PYTHONPATH": str(tree)},
        cwd=tree,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )


def ask(proc: subprocess.Popen, command: str, requests: list[tuple[str, str]]) -> object:
    proc.stdin.write(json.dumps([command, requests]) + "\n")
    proc.stdin.flush()
    return json.loads(proc.stdout.readline())


def against(tree: Path) -> int:
    """Compare every response of ``varied()``; the number of differences."""
    requests = varied()
    procs = {"this": worker(ROOT), "other": worker(tree)}
    try:
        got = {label: ask(p, "responses", requests) for label, p in procs.items()}
    finally:
        for p in procs.values():
            p.stdin.close()
            p.wait()
    bad = [k for k, (x, y) in enumerate(zip(got["this"], got["other"], strict=True)) if x != y]
    for k in bad[:5]:
        print(f"request {k}: {requests[k][1][:300]}\n this: {got['this'][k]}\n other: "
              f"{got['other'][k]}")  # fmt: skip
    statuses = sorted({r[0] for r in got["this"]})
    print(f"{len(requests)} requests (statuses {statuses}): {len(bad)} differ")
    return len(bad)


def cpu(tree: Path, rounds: int = 20, per_round: int = 100, profile: bool = False) -> None:
    """Min and median CPU ms per new one-excitation request, this tree against ``tree``."""
    procs = {"this": worker(ROOT), "other": worker(tree)}
    times: dict[str, list[float]] = {label: [] for label in procs}
    try:
        for k in range(-1, rounds):
            rng = random.Random(1000 + k)
            docs = [("application/json", json.dumps(bench_one(rng))) for _ in range(per_round)]
            for label in list(procs)[:: 1 if k % 2 else -1]:
                got = ask(procs[label], "times", docs)
                if k >= 0:
                    times[label] += got
        parts = ask(procs["this"], "parts", docs * 10)
        columns = zip(*parts, strict=True)
        for name, column in zip(("validation", "verdict", "JSON"), columns, strict=True):
            print(f"this, {name}: {1e3 * statistics.median(column):.4f} median ms CPU")
        if profile:
            rng = random.Random(5)
            docs = [("application/json", json.dumps(bench_one(rng))) for _ in range(3000)]
            print(ask(procs["this"], "profile", docs))
    finally:
        for p in procs.values():
            p.stdin.close()
            p.wait()
    for label, ts in times.items():
        print(f"{label}: {1e3 * min(ts):.4f} min / {1e3 * statistics.median(ts):.4f} median ms "
              f"CPU, {len(ts)} requests")  # fmt: skip
    print(f"load average (1 min): {os.getloadavg()[0]:.2f}")


def bench_one(rng: random.Random) -> dict:
    """A new design as ``bench_melnikov.varied("one")`` draws it (the served bench's kind)."""
    return {
        "params": {
            "damping": rng.uniform(0.04, 0.09),
            "mean_force": rng.uniform(0.0, 0.04),
            "transmission_error": {
                "frequency": rng.uniform(0.4, 0.6),
                "harmonics": [{"amplitude": rng.uniform(0.05, 0.3)}],
            },
        }
    }


def store(tree: Path, path: Path) -> None:
    """Write a sample of ``varied()`` (every 25th one-excitation request, every second of the
    rest) with the status, media type, ETag and sha256 of the body that the app of ``tree``
    answers (``tests/test_verdict_lane.py``)."""
    requests = varied()
    requests = requests[:ONE_EXCITATION:25] + requests[ONE_EXCITATION::2]
    proc = worker(tree)
    try:
        got = ask(proc, "responses", requests)
    finally:
        proc.stdin.close()
        proc.wait()
    rows = [
        {"media": media, "body": body, "status": status, "content_type": kind, "etag": etag,
         "sha256": hashlib.sha256(answer.encode()).hexdigest()}
        for (media, body), (status, kind, etag, answer) in zip(requests, got, strict=True)
    ]  # fmt: skip
    path.write_text(json.dumps(rows, indent=1) + "\n")
    print(f"{len(rows)} responses of {tree} written to {path}")


def main() -> None:
    if "--store" in sys.argv:
        store(
            Path(sys.argv[sys.argv.index("--from") + 1]),
            Path(sys.argv[sys.argv.index("--store") + 1]),
        )
        return
    if "--against" in sys.argv:
        sys.exit(1 if against(Path(sys.argv[sys.argv.index("--against") + 1])) else 0)
    cpu(Path(sys.argv[sys.argv.index("--cpu") + 1]), profile="--profile" in sys.argv)


if __name__ == "__main__":
    main()
