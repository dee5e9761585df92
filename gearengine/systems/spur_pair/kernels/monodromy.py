"""Monodromy kernel: the flow of Eq. (9) over n sampling intervals and its 2x2 Jacobian.

    x' = v,   v' = -2 mu v - K(t) f_h(x) + F(t)                              (Eq. 9)
    Phi' = J(t) Phi,   J = [[0, 1], [-K(t) f_h'(x), -2 mu]],   Phi(0) = I     (variational eq.)

Used by ``numerics.floquet`` (Newton shooting, Floquet multipliers) and
``numerics.bifurcations``. One numba function carries both laws, as ``run_rk4`` does: the body
is one compiled loop, so it is longer than the ~80-line guide (the six-equation RK4 stage
arithmetic written out is most of it).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gearengine.systems.spur_pair.kernels.kink import kink_step
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, forcing_at, law_force, region


@njit(**JIT_OPTIONS)
def _rhs2(
    law: int,
    a: float,
    c: float,
    alpha: float,
    twomu: float,
    K: float,
    F: float,
    x: float,
    v: float,
    p1: float,
    q1: float,
    p2: float,
    q2: float,
) -> tuple[float, float, float, float, float, float]:  # pragma: no cover - compiled
    """Eq. (9) and its variational equation for two tangent vectors (p1, q1), (p2, q2)."""
    fh, dfh = law_force(law, a, c, alpha, x)
    kd = K * dfh
    return v, -twomu * v - K * fh + F, q1, -twomu * q1 - kd * p1, q2, -twomu * q2 - kd * p2


@njit(**JIT_OPTIONS)
def monodromy(
    law: int,
    a: float,
    c: float,
    alpha: float,
    mu: float,
    x0: float,
    v0: float,
    kc: np.ndarray,
    fm: float,
    fc: np.ndarray,
    T: float,
    N: int,
    n_periods: int,
) -> tuple[float, float, np.ndarray]:  # pragma: no cover - compiled
    """Flow phi_{n T0}(x0, v0) from t = 0 and its Jacobian (monodromy matrix) Phi, by RK4.

    Same fixed-step classical RK4 as ``run_rk4`` (N steps per T0, forcing evaluated at the
    absolute times n T0 + j h, j h + h/2, j h + h; same operation order, so the state path
    equals ``run_rk4`` with ``use_table=False`` bit for bit), applied to the state plus the 2x2
    variational matrix, i.e. two tangent vectors started at (1, 0) and (0, 1).

    Piecewise law (law 1): every step goes through ``kink_step``, which splits the step at the
    switching times |x| = 1 (RK4 on each side, crossing located by Newton from the Hermite
    root). It advances one tangent vector, so it is called once per column of Phi from the
    same state and region; the state path is identical in both calls. No saltation matrix is
    needed at the switching times: the backlash law of Eq. (8) is continuous (only its slope
    jumps, from alpha to 1), so the vector field of Eq. (9) is continuous across |x| = 1 and
    the flow's Jacobian is continuous across the switching surface. The saltation matrix
    S = I + (f+ - f-) n^T / (n^T f-) is the identity when f+ = f- at the switching point; a
    jump correction is needed only when the vector field itself jumps (impacts, friction);
    di Bernardo et al., Piecewise-smooth Dynamical Systems, Springer 2008, ch. 2.

    Args:
        law, a, c, alpha: backlash law (0 cubic -a x + c x^3, 1 piecewise Eq. 8, slope alpha).
        mu: damping ratio mu~; x0, v0: state at t = 0 (a strobe time), units of b and b/tau.
        kc, fm, fc: packed forcing (``systems.spur_pair.forcing.packed_forcing``).
        T: sampling interval T0 (units of tau); N: RK4 steps per T0; n_periods: intervals n.

    Returns:
        (x, v) at t = n T0 and Phi (2, 2), Phi[i, j] = d(x, v)_i(n T0) / d(x0, v0)_j.
    """
    h = T / N
    h2 = 0.5 * h
    h6 = h / 6.0
    twomu = 2.0 * mu
    x, v = x0, v0
    p1, q1, p2, q2 = 1.0, 0.0, 0.0, 1.0
    reg = region(x)
    for n in range(n_periods):
        tn = n * T
        for j in range(N):
            t0 = tn + j * h
            if law == 1:
                xn, vn, p1, q1, rn = kink_step(reg, alpha, twomu, kc, fm, fc, t0, h, x, v, p1, q1)
                p2, q2 = kink_step(reg, alpha, twomu, kc, fm, fc, t0, h, x, v, p2, q2)[2:4]
                x, v, reg = xn, vn, rn
                continue
            K0, F0 = forcing_at(t0, kc, fm, fc)
            K1, F1 = forcing_at(t0 + h2, kc, fm, fc)
            K2, F2 = forcing_at(t0 + h, kc, fm, fc)
            a1, b1, c1, d1, e1, g1 = _rhs2(law, a, c, alpha, twomu, K0, F0, x, v, p1, q1, p2, q2)
            a2, b2, c2, d2, e2, g2 = _rhs2(
                law, a, c, alpha, twomu, K1, F1, x + h2 * a1, v + h2 * b1,
                p1 + h2 * c1, q1 + h2 * d1, p2 + h2 * e1, q2 + h2 * g1,
            )  # fmt: skip
            a3, b3, c3, d3, e3, g3 = _rhs2(
                law, a, c, alpha, twomu, K1, F1, x + h2 * a2, v + h2 * b2,
                p1 + h2 * c2, q1 + h2 * d2, p2 + h2 * e2, q2 + h2 * g2,
            )  # fmt: skip
            a4, b4, c4, d4, e4, g4 = _rhs2(
                law, a, c, alpha, twomu, K2, F2, x + h * a3, v + h * b3,
                p1 + h * c3, q1 + h * d3, p2 + h * e3, q2 + h * g3,
            )  # fmt: skip
            x += h6 * (a1 + 2.0 * (a2 + a3) + a4)
            v += h6 * (b1 + 2.0 * (b2 + b3) + b4)
            p1 += h6 * (c1 + 2.0 * (c2 + c3) + c4)
            q1 += h6 * (d1 + 2.0 * (d2 + d3) + d4)
            p2 += h6 * (e1 + 2.0 * (e2 + e3) + e4)
            q2 += h6 * (g1 + 2.0 * (g2 + g3) + g4)
        if not (math.isfinite(x) and math.isfinite(v)):
            break
    phi = np.empty((2, 2))
    phi[0, 0], phi[1, 0], phi[0, 1], phi[1, 1] = p1, q1, p2, q2
    return x, v, phi
