"""The lock-step SIMD kernel ``run_batch``: many parameter points (lanes) of the cubic law
advanced together."""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from gearengine.numerics.kernels.smooth import JIT_OPTIONS, SQRT1_2

LANES = 16
"""Lanes advanced together in ``run_batch``."""


@njit(**JIT_OPTIONS, parallel=True)
def run_batch(
    a: np.ndarray,
    c: np.ndarray,
    mu: np.ndarray,
    x0: np.ndarray,
    v0: np.ndarray,
    Ktab: np.ndarray,
    Ftab: np.ndarray,
    T: np.ndarray,
    N: int,
    n_trans: int,
    n_rec: int,
    bound: float,
):  # pragma: no cover - compiled
    """RK4 of Eq. (9) + tangent, cubic law, for P points advanced together.

    Same arithmetic, operation by operation, as ``run_rk4`` with a forcing table, so results are
    identical to the single kernel. The stages are written out per lane (no helper calls) so
    LLVM vectorises the lane loop; that is why the body is long. Chunks of ``LANES`` points run
    in parallel (prange); inside a chunk the loop over lanes is vectorised (SIMD over points).
    The last chunk is padded with copies of the last point.

    Args:
        a, c, mu, x0, v0, T: per-point law coefficients, damping, initial state and period T0,
            shape (P,).
        Ktab, Ftab: per-point forcing tables from ``forcing_table``, shape (P, 2N+1).
        N, n_trans, n_rec, bound: as in ``run_rk4`` (shared by all points).

    Returns:
        xs, vs, logs: shape (P, n_rec); xmin, xmax, xf, vf: shape (P,); done: shape (P,).
    """
    P = a.size
    xs = np.zeros((P, n_rec))
    vs = np.zeros((P, n_rec))
    logs = np.zeros((P, n_rec))
    xmin = np.full(P, np.inf)
    xmax = np.full(P, -np.inf)
    xf = np.zeros(P)
    vf = np.zeros(P)
    done = np.zeros(P, dtype=np.int64)
    for chunk in prange((P + LANES - 1) // LANES):
        p0 = chunk * LANES
        lane_p = np.minimum(np.arange(p0, p0 + LANES), P - 1)
        Kl = np.empty((2 * N + 1, LANES))
        Fl = np.empty((2 * N + 1, LANES))
        for s in range(2 * N + 1):
            for lane in range(LANES):
                Kl[s, lane] = Ktab[lane_p[lane], s]
                Fl[s, lane] = Ftab[lane_p[lane], s]
        A = a[lane_p]
        C = c[lane_p]
        TM = 2.0 * mu[lane_p]
        H = T[lane_p] / N
        H2 = 0.5 * H
        H6 = H / 6.0
        X = x0[lane_p]
        V = v0[lane_p]
        DX = np.full(LANES, SQRT1_2)
        DV = np.full(LANES, SQRT1_2)
        XMIN = np.full(LANES, np.inf)
        XMAX = np.full(LANES, -np.inf)
        live = lane_p == np.arange(p0, p0 + LANES)
        for n in range(n_trans + n_rec):
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
                    dx = DX[lane]
                    dv = DV[lane]
                    x2 = x * x  # RK4 stages of Eq. (9) + tangent, cubic f_h
                    b1 = -twomu * v - K0[lane] * (x * (cc * x2 - aa)) + F0[lane]
                    d1 = -twomu * dv - K0[lane] * (3.0 * cc * x2 - aa) * dx
                    xs_, a2, dxs, c2 = x + h2 * v, v + h2 * b1, dx + h2 * dv, dv + h2 * d1
                    x2 = xs_ * xs_
                    b2 = -twomu * a2 - K1[lane] * (xs_ * (cc * x2 - aa)) + F1[lane]
                    d2 = -twomu * c2 - K1[lane] * (3.0 * cc * x2 - aa) * dxs
                    xs_, a3, dxs, c3 = x + h2 * a2, v + h2 * b2, dx + h2 * c2, dv + h2 * d2
                    x2 = xs_ * xs_
                    b3 = -twomu * a3 - K1[lane] * (xs_ * (cc * x2 - aa)) + F1[lane]
                    d3 = -twomu * c3 - K1[lane] * (3.0 * cc * x2 - aa) * dxs
                    xs_, a4, dxs, c4 = x + h * a3, v + h * b3, dx + h * c3, dv + h * d3
                    x2 = xs_ * xs_
                    b4 = -twomu * a4 - K2[lane] * (xs_ * (cc * x2 - aa)) + F2[lane]
                    d4 = -twomu * c4 - K2[lane] * (3.0 * cc * x2 - aa) * dxs
                    h6 = H6[lane]
                    x += h6 * (v + 2.0 * (a2 + a3) + a4)
                    X[lane] = x
                    V[lane] = v + h6 * (b1 + 2.0 * (b2 + b3) + b4)
                    DX[lane] = dx + h6 * (dv + 2.0 * (c2 + c3) + c4)
                    DV[lane] = dv + h6 * (d1 + 2.0 * (d2 + d3) + d4)
                    XMIN[lane] = min(XMIN[lane], x)
                    XMAX[lane] = max(XMAX[lane], x)
            for lane in range(LANES):
                nrm = math.sqrt(DX[lane] * DX[lane] + DV[lane] * DV[lane])
                DX[lane] /= nrm
                DV[lane] /= nrm
                if not live[lane]:
                    continue
                p = lane_p[lane]
                if not (abs(X[lane]) < bound and abs(V[lane]) < bound):
                    live[lane] = False  # diverged: park the lane on a harmless state
                    X[lane], V[lane], DX[lane], DV[lane] = 0.0, 0.0, SQRT1_2, SQRT1_2
                    continue
                if n >= n_trans:
                    logs[p, n - n_trans] = math.log(nrm)
                    xs[p, n - n_trans] = X[lane]
                    vs[p, n - n_trans] = V[lane]
                done[p] = n + 1
                xf[p] = X[lane]
                vf[p] = V[lane]
                xmin[p] = XMIN[lane]
                xmax[p] = XMAX[lane]
            if n + 1 == n_trans:
                XMIN[:] = np.inf
                XMAX[:] = -np.inf
    return xs, vs, logs, xmin, xmax, done, xf, vf
