"""The figure and the table of docs/melnikov-under-load.md: the potential of the unperturbed
system x'' = a x - c x^3 + F_m and its homoclinic loops at three loads, and the F~_e1
thresholds of both loops against F_m for the paper's case (section 4.1).

Run:  PYTHONPATH=. .venv/bin/python docs/melnikov_under_load.py
(writes docs/melnikov-under-load.png and prints the table in Markdown).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from gearengine.homoclinic.coefficients import critical_mean_force, homoclinic_orbit
from gearengine.homoclinic.loops import saddle
from gearengine.homoclinic.verdict import melnikov
from gearengine.model.params import GearParams

A = C = 0.1667
F_CRIT = critical_mean_force(A, C)
LOADS = [(0.0, "F_m = 0 (the paper's loops)"), (0.6 * F_CRIT, "F_m = 0.6 F_crit"),
         (1.3 * F_CRIT, "F_m = 1.3 F_crit: no saddle")]  # fmt: skip
COLORS = ["#1f77b4", "#d62728", "#7f7f7f"]
TABLE_LOADS = [0.0, 0.005, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.064]


def potential(x: np.ndarray, fm: float) -> np.ndarray:
    """V(x) = -a x^2 / 2 + c x^4 / 4 - F_m x, so that x'' = -V'(x)."""
    return -A * x**2 / 2 + C * x**4 / 4 - fm * x


def paper(fm: float) -> GearParams:
    return GearParams.model_validate({
        "damping": 0.07, "mean_force": fm, "backlash": {"model": "cubic", "a": A, "c": C},
        "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]},
    })  # fmt: skip


def thresholds(fm: float) -> tuple[float, float, float]:
    """(plus loop, minus loop, first order) F~_e1 thresholds at Omega_e = 0.5, mu~ = 0.07."""
    t = melnikov(paper(fm)).thresholds["F_e1"]
    first = melnikov(paper(fm), mean_load="perturbation").thresholds["F_e1"]
    plus, minus = (max(t.branches[b].critical_values) for b in ("plus", "minus"))
    return plus, minus, max(first.critical_values)


def figure() -> Figure:
    fig = Figure(figsize=(13.0, 4.2), layout="constrained")
    pot, phase, thr = fig.subplots(1, 3)
    x = np.linspace(-2.2, 2.2, 801)
    for (fm, label), color in zip(LOADS, COLORS, strict=True):
        pot.plot(x, potential(x, fm), color=color, label=label)
        if abs(fm) < F_CRIT:
            xs = saddle(A, C, fm)
            pot.plot([xs], [potential(np.array(xs), fm)], "o", color=color, ms=5)
            t = np.linspace(-60, 60, 4001)
            for br, ls in (("plus", "-"), ("minus", "--")):
                xh, yh = homoclinic_orbit(t, A, C, br, fm)
                phase.plot(xh, yh, color=color, ls=ls, lw=1.4,
                           label=f"{label}, {br} loop" if fm else None)  # fmt: skip
            phase.plot([xs], [0.0], "o", color=color, ms=5)
        else:
            well = np.sqrt(A / C) * 1.18  # the one equilibrium, a centre (root of the force)
            well = well - (C * well**3 - A * well - fm) / (3 * C * well**2 - A)
            pot.plot([well], [potential(np.array(well), fm)], "s", color=color, ms=5)
            phase.plot([well], [0.0], "s", color=color, ms=5, label=f"{label}: one centre")
    phase.plot([], [], color=COLORS[0], label=LOADS[0][1] + ", both loops")
    pot.set_ylim(-0.16, 0.12)
    pot.set_xlabel("x (half backlashes)")
    pot.set_ylabel("V(x) = -a x²/2 + c x⁴/4 - F_m x")
    pot.set_title("Potential of x'' = a x - c x³ + F_m (a = c = 0.1667)", fontsize=10)
    pot.legend(fontsize=8)
    phase.set_xlabel("x")
    phase.set_ylabel("x'")
    phase.set_title("Homoclinic loops (dots: saddle; square: the only well)", fontsize=10)
    phase.set_ylim(-0.72, 0.48)
    phase.legend(fontsize=7, loc="lower center")
    loads = np.linspace(0.0, 0.999 * F_CRIT, 60)
    rows = np.array([thresholds(fm) for fm in loads])
    thr.plot(loads, rows[:, 0], color="#1f77b4", label="plus loop (x > x_s)")
    thr.plot(loads, rows[:, 1], color="#d62728", ls="--", label="minus loop (x < x_s)")
    thr.plot(loads, rows[:, 2], color="k", ls=":", label="mean load as a perturbation (paper)")
    thr.axvline(F_CRIT, color="0.5", lw=0.8)
    thr.text(F_CRIT, 0.55, "F_crit ", color="0.4", fontsize=8, ha="right")
    thr.plot([0.01], [0.19588], "k.", ms=6)
    thr.set_xlabel("F~_m")
    thr.set_ylabel("critical F~_e1")
    thr.set_ylim(0.0, 0.6)  # the minus loop's threshold runs off to 2.8 at 0.997 F_crit
    thr.set_title("F~_e1 thresholds, Omega_e = 0.5, mu~ = 0.07", fontsize=10)
    thr.legend(fontsize=8)
    return fig


def table() -> str:
    lines = ["| F~_m | F~_m / F_crit | x_s | plus loop | minus loop | as a perturbation |",
             "|---:|---:|---:|---:|---:|---:|"]  # fmt: skip
    for fm in TABLE_LOADS:
        plus, minus, first = thresholds(fm)
        lines.append(f"| {fm:g} | {fm / F_CRIT:.3f} | {saddle(A, C, fm):.5f} | {plus:.5f} | "
                     f"{minus:.5f} | {first:.5f} |")  # fmt: skip
    return "\n".join(lines)


if __name__ == "__main__":
    out = Path(__file__).with_name("melnikov-under-load.png")
    figure().savefig(out, dpi=110)
    print(f"wrote {out}; F_crit = {F_CRIT:.6f}")
    print(table())
