"""A gear train's envelope check against the single-DOF pair's, in one process.

Run:  .venv/bin/python benchmarks/bench_train_envelope.py
Prints a markdown table and writes it, with the command and the load average, into its section
of benchmarks/README.md.
Case: ``examples/design-train.json`` (issue 32's train around the design-direct pair) checked
over 1,000-6,000 rpm (6 speeds) x 20-40 N m (2 torques) under the gate's settings
(``ENVELOPE_SETTINGS``: 60 + 60 periods, 128 steps per period) with the settings' own start
(``gearengine check --starts 1``), ``check_envelope`` on 2 threads; pair = the same check of the
design without its train. Each run shifts the speeds by 1 rpm (a new design, no cache of an
earlier input flatters it); runs interleave train and pair so both see the same load. The
pair's points run as lanes of the lock-step kernels, a train's as lanes of the train's
lock-step kernel (``systems.gear_train.lanes``, its steps raised to resolve the fastest mode:
2,304 per T0 here against the pair's 128 per mesh period), which the ratio shows.
"""

from __future__ import annotations

import json
import os
import sys

import common  # benchmarks/common.py
from report import write_section  # benchmarks/report.py (the script's own folder)

from gearengine.gate.envelope import ENVELOPE_SETTINGS, check_envelope
from gearengine.gate.rules import Rules
from gearengine.studies.sweep import validated

RUNS = 3
WORKERS = 2
TRAIN = json.loads((common.ROOT / "examples" / "design-train.json").read_text())["design"]
PAIR = {k: v for k, v in TRAIN.items() if k != "train"}


def request(design: dict, shift: int):
    axes = [
        {"parameter": "speed", "start": f"{1000 + shift} rpm", "stop": f"{6000 + shift} rpm",
         "num": 6},
        {"parameter": "torque", "start": "20 N*m", "stop": "40 N*m", "num": 2},
    ]  # fmt: skip
    return validated({"design": design, "settings": ENVELOPE_SETTINGS, "axes": axes})


def main() -> None:
    rules = Rules(max_dte_um=30.0)
    check_envelope(request(TRAIN, -1), rules, workers=WORKERS)  # compile / load every kernel
    check_envelope(request(PAIR, -1), rules, workers=WORKERS)
    train, pair, failing = [], [], []
    for k in range(RUNS):
        train += common.timings([lambda k=k: check_envelope(request(TRAIN, k), rules,
                                                            workers=WORKERS)])  # fmt: skip
        pair += common.timings([lambda k=k: check_envelope(request(PAIR, k), rules,
                                                           workers=WORKERS)])  # fmt: skip
    failing = [check_envelope(request(d, 0), rules, workers=WORKERS).failing_points
               for d in (TRAIN, PAIR)]  # fmt: skip
    load = os.getloadavg()[0]
    ratios = [t / p for t, p in zip(train, pair, strict=True)]
    rows = [
        ("train envelope check [s]", *common.min_median(train)),
        ("pair envelope check [s]", *common.min_median(pair)),
        ("train / pair", *common.min_median(ratios)),
    ]
    table = "\n".join(
        ["| quantity | min | median |", "|---|---|---|"]
        + [f"| {name} | {lo:.3g} | {med:.3g} |" for name, lo, med in rows]
    )
    text = (
        "## Gear train envelope check against the pair's\n\n"
        f"`{sys.executable.rsplit('/', 1)[-1]} benchmarks/bench_train_envelope.py`: "
        f"{RUNS} runs, 12 operating points (1,000-6,000 rpm x 20-40 N m), 60 + 60 periods, "
        f"128 steps per period, one start per point, {WORKERS} threads; --max-dte 30 µm "
        f"fails {failing[0]} train points and {failing[1]} pair points.\n\n"
        f"{table}\n\nLoad average (1 min) at the end of the run: {load:.1f} on "
        f"{os.cpu_count()} cores (the machine is shared).\n"
    )
    print(text)
    write_section("train-envelope", text)


if __name__ == "__main__":
    main()
