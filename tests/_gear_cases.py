"""Shared cases and an independent scipy implementation of Eq. (9) + tangent for the tests."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from gearengine.model.params import GearParams
from gearengine.signals.periodicity import attractor_size, detect_period
from gearengine.systems.spur_pair.forcing import packed_forcing, step_plan
from gearengine.systems.spur_pair.laws import law

GEAR_REF_SOURCE = Path("/work/shared/reference/gear_ref.c")


def paper(
    fe: float, mu: float = 0.07, we: float = 0.5, model: str = "cubic", **extra
) -> GearParams:
    """The paper's case: Fm = 0.01, first transmission-error harmonic only."""
    return GearParams.model_validate(
        {
            "damping": mu,
            "mean_force": 0.01,
            "backlash": {"model": model, **extra},
            "transmission_error": {"frequency": we, "harmonics": [{"amplitude": fe}]},
        }
    )


def scipy_run(
    params: GearParams, n_trans: int, n_rec: int, x0: tuple[float, float] = (0.01, 0.01)
) -> tuple[int | None, float, np.ndarray]:
    """DOP853 (rtol 1e-10, atol 1e-12) of Eq. (9) + tangent with Benettin renormalisation.

    Returns (period, LLE per unit time, final state).
    """
    kc, fm, fc = packed_forcing(params)
    lw = law(params)
    twomu = 2.0 * params.damping

    def force(x: float) -> tuple[float, float]:
        if lw.code == 0:
            return -lw.a * x + lw.c * x**3, -lw.a + 3.0 * lw.c * x * x
        if x > 1.0:
            return x - (1.0 - lw.alpha), 1.0
        if x < -1.0:
            return x + (1.0 - lw.alpha), 1.0
        return lw.alpha * x, lw.alpha

    def rhs(t: float, y: np.ndarray) -> list[float]:
        K = 1.0 + np.sum(kc[0] * np.cos(kc[1] * t + kc[2]))
        F = fm + np.sum(fc[0] * np.cos(fc[1] * t + fc[2]))
        fh, dfh = force(y[0])
        return [y[1], -twomu * y[1] - K * fh + F, y[3], -twomu * y[3] - K * dfh * y[2]]

    T = step_plan(params, 200).period
    y = np.array([x0[0], x0[1], math.sqrt(0.5), math.sqrt(0.5)])
    opts = {"method": "DOP853", "rtol": 1e-10, "atol": 1e-12}
    sol = solve_ivp(rhs, (0.0, n_trans * T), y, **opts)
    y = sol.y[:, -1]
    y[2:] /= np.hypot(y[2], y[3])
    xs, vs, logs, dense = [], [], [], []
    for n in range(n_trans, n_trans + n_rec):
        t = np.linspace(n * T, (n + 1) * T, 41)
        sol = solve_ivp(rhs, (t[0], t[-1]), y, t_eval=t, **opts)
        y = sol.y[:, -1].copy()
        dense.append(sol.y[0])
        nrm = math.hypot(y[2], y[3])
        y[2:] /= nrm
        logs.append(math.log(nrm))
        xs.append(y[0])
        vs.append(y[1])
    allx = np.concatenate(dense)
    size = attractor_size(float(allx.min()), float(allx.max()))
    period = detect_period(np.array(xs), np.array(vs), size)
    return period, sum(logs) / (n_rec * T), y[:2]


def gear_ref_binary(tmp_dir: Path) -> Path | None:
    """gear_ref.c built without FMA contraction (same rounding as the numba kernels), or None."""
    gcc = shutil.which("gcc")
    if gcc is None or not GEAR_REF_SOURCE.exists():
        return None
    exe = tmp_dir / "gear_ref_nofma"
    if not exe.exists():
        subprocess.run(
            [gcc, "-O2", "-ffp-contract=off", "-o", str(exe), str(GEAR_REF_SOURCE), "-lm"],
            check=True,
        )
    return exe


def gear_ref_summary(exe: Path, args: list[str]) -> tuple[int, float, float, float]:
    """Run ``gear_ref --summary``: (period, lle, x_last, v_last)."""
    out = subprocess.run(
        [str(exe), "--summary", *args], check=True, capture_output=True, text=True
    ).stdout.split()
    return int(out[0]), float(out[1]), float(out[2]), float(out[3])
