"""The lock-step SIMD kernel ``run_batch``: many parameter points (lanes) of the cubic law
advanced together; the cubic law's pieces of the lane scheduler (``kernels.scheduler``)."""

from __future__ import annotations

import numpy as np
from numba import njit

from gearengine.systems.spur_pair.kernels.scheduler import LANES, LaneLaw, lane_kernel
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS


@njit(**JIT_OPTIONS)
def _cubic_lanes(L: int) -> tuple:  # pragma: no cover - compiled
    """The cubic law's per-lane arrays: a, c of each lane's run."""
    return np.zeros(L), np.zeros(L)


@njit(**JIT_OPTIONS)
def _cubic_load(
    lane: int, p: int, law: tuple, x0: np.ndarray, coeffs: tuple
) -> None:  # pragma: no cover
    """Run p's a and c into ``lane`` (an idle lane, p < 0, keeps them)."""
    if p < 0:
        return
    A, C = law
    a, c = coeffs
    A[lane] = a[p]
    C[lane] = c[p]


@njit(**JIT_OPTIONS, inline="always")
def _cubic_steps(
    N, Kl, Fl, PT, owner, lane_state, rates, law, coeffs, tangent
) -> None:  # pragma: no cover
    """N RK4 steps of Eq. (9) + tangent (with ``tangent``), cubic law, of every lane
    (scheduler's ``steps``). The state's stages come first and the tangent's after them, from
    the same stage values: each number is the same expression of the same operands as in
    ``run_rk4``, so the order changes no bit."""
    X, V, DX, DV, XMIN, XMAX, FMIN, FMAX = lane_state
    TM, H, H2, H6 = rates
    A, C = law
    for j in range(N):
        K0 = Kl[2 * j]
        F0 = Fl[2 * j]
        K1 = Kl[2 * j + 1]
        F1 = Fl[2 * j + 1]
        K2 = Kl[2 * j + 2]
        F2 = Fl[2 * j + 2]
        for lane in range(LANES):
            aa = A[lane]
            cc = C[lane]
            twomu = TM[lane]
            h = H[lane]
            h2 = H2[lane]
            x = X[lane]
            v = V[lane]
            q1 = x * x  # RK4 stages of Eq. (9), cubic f_h
            b1 = -twomu * v - K0[lane] * (x * (cc * q1 - aa)) + F0[lane]
            x2_, a2 = x + h2 * v, v + h2 * b1
            q2 = x2_ * x2_
            b2 = -twomu * a2 - K1[lane] * (x2_ * (cc * q2 - aa)) + F1[lane]
            x3_, a3 = x + h2 * a2, v + h2 * b2
            q3 = x3_ * x3_
            b3 = -twomu * a3 - K1[lane] * (x3_ * (cc * q3 - aa)) + F1[lane]
            x4_, a4 = x + h * a3, v + h * b3
            q4 = x4_ * x4_
            b4 = -twomu * a4 - K2[lane] * (x4_ * (cc * q4 - aa)) + F2[lane]
            h6 = H6[lane]
            x += h6 * (v + 2.0 * (a2 + a3) + a4)
            v = v + h6 * (b1 + 2.0 * (b2 + b3) + b4)
            X[lane] = x
            V[lane] = v
            XMIN[lane] = min(XMIN[lane], x)
            XMAX[lane] = max(XMAX[lane], x)
            if tangent:  # its stages at the state's stage values x, x2_, x3_, x4_
                dx = DX[lane]
                dv = DV[lane]
                d1 = -twomu * dv - K0[lane] * (3.0 * cc * q1 - aa) * dx
                dxs, c2 = dx + h2 * dv, dv + h2 * d1
                d2 = -twomu * c2 - K1[lane] * (3.0 * cc * q2 - aa) * dxs
                dxs, c3 = dx + h2 * c2, dv + h2 * d2
                d3 = -twomu * c3 - K1[lane] * (3.0 * cc * q3 - aa) * dxs
                dxs, c4 = dx + h * c3, dv + h * d3
                d4 = -twomu * c4 - K2[lane] * (3.0 * cc * q4 - aa) * dxs
                DX[lane] = dx + h6 * (dv + 2.0 * (c2 + c3) + c4)
                DV[lane] = dv + h6 * (d1 + 2.0 * (d2 + d3) + d4)
                q = x * x  # mesh force K(t) f_h(x) + 2 mu v at the step end
                force = K2[lane] * (x * (cc * q - aa)) + twomu * v
                FMIN[lane] = min(FMIN[lane], force)
                FMAX[lane] = max(FMAX[lane], force)


@njit(**JIT_OPTIONS)
def _cubic_keep(lane: int, p: int, law: tuple, coeffs: tuple) -> None:  # pragma: no cover
    """Nothing: a cubic run carries its tangent vector alone."""


CUBIC = LaneLaw(
    "cubic",
    """RK4 of Eq. (9) + tangent, cubic law, ``coeffs`` = (a, c): the runs' law coefficients, shape
    (P,). Same arithmetic, operation by operation, as ``run_rk4`` with a forcing table, so the
    results are identical to the single kernel's. The stages are written out per lane (no
    helper calls) in the law's ``steps`` so LLVM vectorises the lane loop.""",
    _cubic_lanes,
    _cubic_load,
    _cubic_steps,
    _cubic_keep,
)
"""The cubic law's pieces of the lane scheduler."""

run_batch = lane_kernel(CUBIC)
"""The cubic law's lock-step kernel: ``run_batch(mu, x0, v0, dxc, dvc, Ktab, Ftab, owner, T, N,
n_trans, n_rec, bound, adaptive, streams, lle_rel, lle_abs, tangent, a, c)``
(``scheduler._lanes``)."""
