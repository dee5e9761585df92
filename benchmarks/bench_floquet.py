"""Cost of the Floquet refinement against one default analysis, and of locating the
bifurcation points of a continuation sweep line against computing the line, in one process.

Run:  .venv/bin/python benchmarks/bench_floquet.py   (also part of ``make bench``)
Prints a markdown table and writes it, with the command, into its section of
benchmarks/README.md.
Case: the paper's 1T design F_e1 = 0.2 (cubic, Omega_e = 0.5, mu = 0.07, F_m = 0.01).
One analysis = ``simulate`` with default settings (500 + 500 periods x 200 RK4 steps with the
tangent equation, diagnostics), which now includes the refinement; the refinement alone =
``numerics.floquet.floquet`` from its last Poincare point (Newton shooting over one period with
the 2x2 variational matrix, multipliers, Liouville check), and, as a harder case, from that
point offset by 1e-3 in x (a few Newton steps). The added fraction is refinement / (analysis -
refinement). Target: the refinement adds at most 25 % to one analysis.
Sweep: a continuation line F_e1 = 0.2 .. 0.235, 36 points (each ``simulate`` from the last final
state, as a sweep chunk does), against ``locate_bifurcations`` on the same line reusing its
responses (what a continuation chunk adds).
"""

from __future__ import annotations

from collections.abc import Callable

import common  # benchmarks/common.py
import numba
import numpy as np
from report import write_section  # benchmarks/report.py (the script's own folder)

from gearengine.model.aliases import with_alias
from gearengine.model.params import GearParams
from gearengine.numerics.bifurcations import PointResponse, locate_bifurcations
from gearengine.numerics.floquet import floquet
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import simulate, warm_up

REPEATS = 20
TARGET = 0.25
SETTINGS = SimulationSettings()
PARAMS = {
    "damping": 0.07,
    "mean_force": 0.01,
    "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]},
}
DESIGN = GearParams.model_validate(PARAMS)
LINE = {"parameter": "F_e1", "start": 0.2, "stop": 0.235, "num": 36}


def best_of(fn: Callable[[], object], repeats: int = REPEATS) -> float:
    """Smallest wall time of ``repeats`` calls, seconds (``common.best_of``)."""
    return common.best_of(fn, repeats)


def line_responses(grid: np.ndarray) -> list[PointResponse]:
    """The line computed as a continuation sweep does: each point from the last final state."""
    out, start = [], SETTINGS.initial_state
    for value in grid:
        run = SETTINGS.model_copy(update={"initial_state": list(start)})
        r = simulate(with_alias(DESIGN, "F_e1", float(value)), run)
        final = r.worst_case.final_state
        out.append(PointResponse(r.classification, r.period, r.poincare[-1], tuple(final)))
        start = final
    return out


def main() -> None:
    warm_up()
    numba.set_num_threads(1)
    result = simulate(DESIGN, SETTINGS)
    state, period = result.poincare[-1], result.period
    offset = [state[0] + 1e-3, state[1]]
    fl = floquet(DESIGN, SETTINGS, state, period)  # compiles or loads the kernel
    fl_off = floquet(DESIGN, SETTINGS, offset, period)
    analysis = best_of(lambda: simulate(DESIGN, SETTINGS))
    refinement = best_of(lambda: floquet(DESIGN, SETTINGS, state, period))
    harder = best_of(lambda: floquet(DESIGN, SETTINGS, offset, period))
    added, added_harder = refinement / (analysis - refinement), harder / (analysis - refinement)
    grid = np.linspace(LINE["start"], LINE["stop"], LINE["num"])
    responses = line_responses(grid)
    line = best_of(lambda: line_responses(grid), 3)
    events = locate_bifurcations(DESIGN, "F_e1", grid, SETTINGS, responses=responses)
    locating = best_of(
        lambda: locate_bifurcations(DESIGN, "F_e1", grid, SETTINGS, responses=responses), 3
    )
    verdict = "met" if max(added, added_harder) <= TARGET else "missed"
    table = "\n".join(
        [
            "| what | wall time, ms | ratio |",
            "| --- | ---: | ---: |",
            f"| one analysis: `simulate`, default settings (refinement included) | "
            f"{1e3 * analysis:.3f} | 1.000 |",
            f"| Floquet refinement from its last Poincare point ({fl.newton_steps} Newton "
            f"steps, period {period}) | {1e3 * refinement:.3f} | {added:.3f} added |",
            f"| Floquet refinement from that point + 1e-3 in x ({fl_off.newton_steps} Newton "
            f"steps) | {1e3 * harder:.3f} | {added_harder:.3f} added |",
            f"| continuation line F_e1 = 0.2 .. 0.235, {LINE['num']} points (`simulate` each) | "
            f"{1e3 * line:.1f} | 1.000 |",
            f"| locating its {len(events)} bifurcation points (`locate_bifurcations`, "
            f"responses reused) | {1e3 * locating:.1f} | {locating / line:.3f} added |",
        ]
    )
    print(table)
    print(f"target <= {TARGET:.2f} added to one analysis: {verdict}")
    write_section(
        "floquet",
        "## Floquet refinement and located bifurcations\n\n"
        "Reproduce: `.venv/bin/python benchmarks/bench_floquet.py` (rewrites this section; part "
        "of `make bench`).\n\n"
        "Paper design F_e1 = 0.2 (1T). One analysis = `simulate` with default settings (500 + "
        "500 periods x 200 RK4 steps with the tangent equation, diagnostics, and the Floquet "
        "refinement); refinement = `gearengine.numerics.floquet.floquet` from its last Poincare "
        "point (Newton shooting with the 2x2 variational matrix, multipliers, Liouville check), "
        "also from a state offset by 1e-3; added = refinement / (analysis - refinement). Best of "
        f"{REPEATS}, 1 thread. Target: the refinement adds at most {TARGET:.0%} to one "
        f"analysis ({verdict}). The sweep rows (best of 3) show what locating the bifurcation "
        "points adds to a one-axis continuation line.\n\n"
        f"{table}\n",
    )


if __name__ == "__main__":
    main()
