"""Cost of a gear train's analysis against the single-DOF pair's, in one process.

Run:  .venv/bin/python benchmarks/bench_train.py
Prints a markdown table and writes it, with the command, into its section of
benchmarks/README.md.
Case: ``examples/design-train.json`` (the design-direct pair inside issue 32's train: motor,
two shafts, load, bearings; 6 coordinates, 5 relative), 200 + 200 periods T0 at 200 steps per
mesh period (T0 = 18 mesh periods: 3,600 RK4 steps per T0; the train needs no more). Each run is
a new design (speed +1 rpm per run: 1500, 1501, ...), so no cache of an earlier input flatters
it. Train = ``gearengine.analyze`` of the design with its train (n-dimensional RK4 with the
10-dimensional tangent, the Melnikov reduction, the modes); pair = ``gearengine.analyze`` of
the same design without the train (the piecewise kink-splitting kernel of Eq. 9). The ratio is
train / pair per run; min and median over the runs.
"""

from __future__ import annotations

import json
import sys

import common  # benchmarks/common.py
from report import write_section  # benchmarks/report.py (the script's own folder)

import gearengine
from gearengine.model.design import Design
from gearengine.numerics.settings import SimulationSettings

RUNS = 7
SETTINGS = SimulationSettings(transient_periods=200, record_periods=200)
TRAIN = json.loads((common.ROOT / "examples" / "design-train.json").read_text())["design"]
PAIR = {k: v for k, v in TRAIN.items() if k != "train"}


def main() -> None:
    designs = [
        (Design.model_validate({**TRAIN, "speed": f"{1500 + k} rpm"}),
         Design.model_validate({**PAIR, "speed": f"{1500 + k} rpm"}))
        for k in range(RUNS + 1)
    ]  # fmt: skip
    gearengine.analyze(designs[0][0], SETTINGS)  # compile / load every kernel once
    gearengine.analyze(designs[0][1], SETTINGS)
    train, pair = [], []
    for with_train, alone in designs[1:]:  # interleaved: both see the same machine load
        train += common.timings([lambda d=with_train: gearengine.analyze(d, SETTINGS)])
        pair += common.timings([lambda d=alone: gearengine.analyze(d, SETTINGS)])
    ratios = [t / p for t, p in zip(train, pair, strict=True)]
    rows = [
        ("train analysis [s]", *common.min_median(train)),
        ("pair analysis [s]", *common.min_median(pair)),
        ("train / pair", *common.min_median(ratios)),
    ]
    table = "\n".join(
        ["| quantity | min | median |", "|---|---|---|"]
        + [f"| {name} | {lo:.3g} | {med:.3g} |" for name, lo, med in rows]
    )
    text = (
        "## Gear train analysis against the pair's\n\n"
        f"`{sys.executable.rsplit('/', 1)[-1]} benchmarks/bench_train.py`: "
        f"{RUNS} runs, each a new speed, 200 + 200 periods T0 (3,600 RK4 steps per T0).\n\n"
        f"{table}\n"
    )
    print(text)
    write_section("train", text)


if __name__ == "__main__":
    main()
