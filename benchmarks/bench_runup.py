"""The cost of a run-up: the README design (``examples/design-direct.json``, 40 N m) from 500 to
6,000 rpm at 1,000 rpm/s (5.5 s of gear time), 50 rpm bins, the default 8-member ensemble and
the quasi-static continuation sweep up and down on the 110 bin centres.

Run:  .venv/bin/python benchmarks/bench_runup.py
Rows: the whole job in this process (``runup.run_local``, 2 threads, as ``gearengine runup``),
one ensemble member alone, the quasi-static lines alone; the baseline is the stationary
kink-splitting kernel (``run_kink``, forcing at absolute time) on the same design at 6,000 rpm
with the same step, timed in the same process: the ratio of ns per RK4 step says what the
ramp's forcing on the integrated driver angle costs. Best of 3; writes its section of
benchmarks/README.md.
"""

from __future__ import annotations

import math
import os

from common import best_of  # benchmarks/common.py
from report import write_section  # benchmarks/report.py (the script's own folder)

from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.model.units import RPM
from gearengine.signals.classify import DIVERGENCE_BOUND
from gearengine.studies.runup import run_local
from gearengine.studies.runup.compute import compute_chunk
from gearengine.studies.runup.profile import runup_plan, validated_runup
from gearengine.studies.sweep.axes import point_params
from gearengine.systems.spur_pair.forcing import packed_forcing
from gearengine.systems.spur_pair.kernels import run_kink

REPEATS = 3


def main() -> None:
    request = validated_runup({"design": EXAMPLE_DESIGN, "from_speed": "500 rpm",
                         "to_speed": "6000 rpm", "rate": "1000 rpm/s"})  # fmt: skip
    plan = runup_plan(request)
    members = request.ensemble.size
    member_steps = plan.work(1)
    run_local(request, workers=2)  # compile and warm the caches
    whole = best_of(lambda: run_local(request, workers=2), REPEATS)
    member = best_of(lambda: compute_chunk(request, 0), REPEATS)
    quasi = best_of(lambda: [compute_chunk(request, members + k) for k in (0, 1)], REPEATS)
    # baseline: the stationary kernel on the same design at the top speed, the same step
    top = plan.segments[-1]
    params = point_params(request.params, request.design, {"speed": 6000 * RPM})
    kc, fm, fc = packed_forcing(params)
    mesh = 2.0 * math.pi / (params.stiffness.frequency)  # mesh period in tau
    steps = max(1, round(mesh / top.h))
    periods = max(1, member_steps // steps)
    alpha, mu = float(params.backlash.alpha), float(params.damping)

    def stationary() -> None:
        run_kink(alpha, mu, 1.0 + fm, 0.0, kc, fm, fc, mesh, steps, 0, periods, steps,
                 DIVERGENCE_BOUND)  # fmt: skip

    stationary()
    base = best_of(stationary, REPEATS)
    base_ns = base / (periods * steps) * 1e9
    member_ns = member / member_steps * 1e9
    cores = os.cpu_count() or 1
    load = os.getloadavg()[0]
    rows = [
        ("whole run-up job (`runup.run_local`, 2 threads)", whole, None),
        (f"one ensemble member ({member_steps:,} RK4 steps)", member, member_ns),
        ("quasi-static continuation, up + down (220 points)", quasi, None),
        ("stationary `run_kink`, same design at 6,000 rpm, same step", base, base_ns),
    ]
    table = "\n".join(
        f"| {what} | {seconds:.3f} | {'' if ns is None else f'{ns:.1f}'} | "
        f"{'' if ns is None else f'{ns / base_ns:.2f}x'} |"
        for what, seconds, ns in rows
    )
    write_section(
        "runup",
        f"""
## Run-up

Reproduce: `.venv/bin/python benchmarks/bench_runup.py` (rewrites this section).

The README design (`examples/design-direct.json`, 40 N·m) from 500 to 6,000 rpm at 1,000 rpm/s
(5.5 s of gear time, {plan.work(members):,} RK4 steps over {members} ensemble members), 50 rpm
bins, and the quasi-static continuation sweep up and down on the 110 bin centres (60 + 40 shaft
revolutions per point). Ratios: ns per RK4 step against the stationary kink-splitting kernel in
the same process; at 6,000 rpm the stationary run separates every mesh period (every step near
an edge is split), while the ramp is in contact for most of its 5.5 s, so the ramp's forcing on
the integrated angle costs less than the splitting it avoids there.
Machine: {cores} cores shared with other jobs while measured (loaded), best
of {REPEATS}.

| what | wall time, s | ns per RK4 step | ratio to stationary |
| --- | ---: | ---: | ---: |
{table}

Load average (1 min) at the end of the run: {load:.1f} on {cores} cores.
""",
    )


if __name__ == "__main__":
    main()
