"""Numba kernels: fixed-step RK4 of Eq. (9) with its tangent equation.

    x' = v,    v' = -2 mu v - K(t) f_h(x) + F(t)                       (Eq. 9)
    dx' = dv,  dv' = -2 mu dv - K(t) f_h'(x) dx                        (tangent equation)

The three run kernels share one output layout (see ``run_rk4``); ``monodromy`` is the fourth:

* ``run_rk4``: classical RK4 with N steps per sampling interval T0, forcing either tabulated once
  at the 2N+1 stage times of a period (commensurate forcing) or evaluated at absolute time
  t = n T0 + j h (no drift). Cubic law, or the piecewise law of Eq. (8) stepped straight across
  the kinks (first-order accurate there; kept for comparison with ``run_kink``).
* ``run_kink``: piecewise law of Eq. (8) with every RK4 step split at the switching times
  |x| = 1 (``gear_ref.c --kink``'s splitting, general alpha): a crossing is detected from a
  cubic Hermite interpolant of x over the substep, located by Newton on RK4 substeps from the
  interpolant's root (Illinois regula falsi where Newton leaves the bracket) to ~1e-13 h, and
  integration restarts there with the new region's field. The field is continuous across
  |x| = 1, so the tangent vector needs no saltation jump. Forcing at absolute time.
* ``monodromy``: the flow over n intervals T0 and its 2x2 Jacobian (the monodromy matrix), for
  Newton shooting and Floquet multipliers (``numerics.floquet``); both laws, same RK4 arithmetic.
* ``run_batch``: cubic law only; many parameter points ("lanes") in lock-step, struct of arrays,
  inner loops over ``LANES`` lanes so LLVM vectorises, ``prange`` over chunks of lanes. Same
  arithmetic as ``run_rk4`` with a forcing table.
* ``run_kink_batch`` (``kinklanes``): the piecewise law in lock-step lanes, each step split at
  the kinks lane by lane; the numbers of ``run_kink`` with its forcing table. Both lock-step
  kernels are the one lane scheduler (``scheduler``: streams, refill, and the end of every
  interval, ``intervals.end_intervals``: record, adaptive stopping) with their law's steps.

Benettin et al. (Meccanica 15, 1980): the tangent vector starts at (1, 1)/sqrt(2) and is
renormalised at the end of every interval T0; the log of its norm is recorded over the n_rec
recorded intervals. A run stops early (diverged) when |x| or |v| is not below ``bound`` at an
interval end (this also catches NaN).

Forcing coefficients are packed as kc, fc of shape (3, n_terms): rows amplitude, omega, phase
(see ``gearengine.systems.spur_pair.forcing``); K(t) = 1 + sum kc0 cos(kc1 t + kc2),
F(t) = fm + sum fc0 cos(fc1 t + fc2).

The kernels call each other across these files and freeze constants of ``signals.periodicity``,
``signals.lyapunov`` and ``signals.classify``; ``gearengine.jitcache`` drops their numba cache
when any of those sources changes (numba itself watches only the defining file).
"""

from pathlib import Path

from gearengine.jitcache import drop_stale
from gearengine.systems.spur_pair.kernels.kink import run_kink
from gearengine.systems.spur_pair.kernels.kinklanes import NO_REGION, run_kink_batch
from gearengine.systems.spur_pair.kernels.lockstep import run_batch
from gearengine.systems.spur_pair.kernels.monodromy import monodromy
from gearengine.systems.spur_pair.kernels.scheduler import LANES
from gearengine.systems.spur_pair.kernels.smooth import (
    SQRT1_2,
    forcing_at,
    forcing_table,
    law_force,
    region_force,
    run_rk4,
)

__all__ = [
    "LANES",
    "NO_REGION",
    "SQRT1_2",
    "forcing_at",
    "forcing_table",
    "law_force",
    "monodromy",
    "region_force",
    "run_batch",
    "run_kink",
    "run_kink_batch",
    "run_rk4",
]

_HERE = Path(__file__).parent
drop_stale(  # before any kernel runs: numba loads a cached kernel on its first call
    "adaptive,intervals,kink,kinklanes,lockstep,monodromy,phase,ramp,scheduler,smooth",
    [
        *_HERE.glob("*.py"),
        *(
            _HERE.parents[2] / "signals" / f"{m}.py"
            for m in ("periodicity", "lyapunov", "classify")
        ),
    ],
    _HERE / "__pycache__",
)
