"""The lock-step SIMD kernel ``run_batch``: many parameter points (lanes) of the cubic law
advanced together."""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from gearengine.numerics.kernels.adaptive import (
    ADAPT_MAX_PERIOD,
    ADAPT_PROBE,
    ADAPT_RECHECK,
    ADAPT_SETTLE,
    ADAPT_WINDOW,
    settled,
    smallest_lag,
    window_tol,
)
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
    adaptive: bool = False,
    streams: int = 1,
):  # pragma: no cover - compiled
    """RK4 of Eq. (9) + tangent, cubic law, for P points advanced together.

    Same arithmetic, operation by operation, as ``run_rk4`` with a forcing table, so results are
    identical to the single kernel. The stages are written out per lane (no helper calls) so
    LLVM vectorises the lane loop; that is why the body is long, and why the per-interval
    bookkeeping (records, adaptive stopping, lane refill) sits in the same body: it runs once
    per N steps and per lane, so its cost is small beside the N vectorised steps.

    The points are dealt to ``streams`` streams (point p to stream p mod streams, so clustered
    chaotic regions of a map are shared out) run in parallel (prange); a stream keeps ``LANES``
    lanes busy, each lane advancing one point, and loads the stream's next point into a lane as
    soon as its point is finished (lanes run at different interval counts; the forcing table
    of a lane is its point's). With ``adaptive`` a point may finish early by the rule of
    ``kernels.adaptive`` (its last ``ADAPT_WINDOW`` strobes kept in a ring buffer per lane);
    otherwise every point runs ``n_trans + n_rec`` intervals, as ``run_rk4``.

    The dimensionless mesh force K(t) f_h(x) + 2 mu x' is evaluated at every step end (a few
    flops) and its extremes over the record returned.

    Args:
        a, c, mu, x0, v0, T: per-point law coefficients, damping, initial state and period T0,
            shape (P,).
        Ktab, Ftab: per-point forcing tables from ``forcing_table``, shape (P, 2N+1).
        N, n_trans, n_rec, bound: as in ``run_rk4`` (shared by all points).
        adaptive: allow early stopping (``kernels.adaptive``).
        streams: parallel streams of lanes (at most the number of threads is useful).

    Returns:
        xs, vs, logs: shape (P, n_rec), the record in its first ``rec`` entries; xmin, xmax,
        fmin, fmax (extremes of x and of the mesh force over the record's steps), xf, vf (final
        state): shape (P,); done (intervals run), rec (intervals recorded), diverged (1 if the
        run left ``bound``): shape (P,).
    """
    P = a.size
    total = n_trans + n_rec
    W = ADAPT_WINDOW if (adaptive and n_rec >= ADAPT_WINDOW) else 0
    settle0 = min(n_trans, ADAPT_SETTLE)
    WR = max(W, 1)
    xs = np.zeros((P, n_rec))
    vs = np.zeros((P, n_rec))
    logs = np.zeros((P, n_rec))
    xmin = np.full(P, np.inf)
    xmax = np.full(P, -np.inf)
    fmin = np.full(P, np.inf)
    fmax = np.full(P, -np.inf)
    xf = np.zeros(P)
    vf = np.zeros(P)
    done = np.zeros(P, dtype=np.int64)
    rec = np.zeros(P, dtype=np.int64)
    diverged = np.zeros(P, dtype=np.int64)
    for stream in prange(streams):
        Kl = np.ones((2 * N + 1, LANES))
        Fl = np.zeros((2 * N + 1, LANES))
        PT = np.full(LANES, -1, dtype=np.int64)
        NN = np.zeros(LANES, dtype=np.int64)
        STREAK = np.zeros(LANES, dtype=np.int64)
        LASTQ = np.zeros(LANES, dtype=np.int64)
        TOL2 = np.zeros(LANES)
        NEED = np.ones(LANES, dtype=np.bool_)
        A = np.zeros(LANES)
        C = np.zeros(LANES)
        TM = np.zeros(LANES)
        H = np.zeros(LANES)
        H2 = np.zeros(LANES)
        H6 = np.zeros(LANES)
        X = np.zeros(LANES)
        V = np.zeros(LANES)
        DX = np.full(LANES, SQRT1_2)
        DV = np.full(LANES, SQRT1_2)
        XMIN = np.full(LANES, np.inf)
        XMAX = np.full(LANES, -np.inf)
        FMIN = np.full(LANES, np.inf)
        FMAX = np.full(LANES, -np.inf)
        RX = np.zeros((WR, LANES))
        RV = np.zeros((WR, LANES))
        RL = np.zeros((WR, LANES))
        RXN = np.zeros((WR, LANES))
        RXX = np.zeros((WR, LANES))
        RFN = np.zeros((WR, LANES))
        RFX = np.zeros((WR, LANES))
        taken = 0  # points of this stream loaded so far
        active = 0
        while True:
            for lane in range(LANES):  # load the stream's next point into every free lane
                if not NEED[lane]:
                    continue
                NEED[lane] = False
                X[lane], V[lane], DX[lane], DV[lane] = 0.0, 0.0, SQRT1_2, SQRT1_2
                XMIN[lane], XMAX[lane] = np.inf, -np.inf
                FMIN[lane], FMAX[lane] = np.inf, -np.inf
                p = stream + taken * streams
                if p >= P:
                    PT[lane] = -1  # idle: parked on a harmless state
                    continue
                taken += 1
                active += 1
                PT[lane] = p
                NN[lane] = 0
                STREAK[lane] = 0
                LASTQ[lane] = 0
                for s in range(2 * N + 1):
                    Kl[s, lane] = Ktab[p, s]
                    Fl[s, lane] = Ftab[p, s]
                A[lane] = a[p]
                C[lane] = c[p]
                TM[lane] = 2.0 * mu[p]
                H[lane] = T[p] / N
                H2[lane] = 0.5 * H[lane]
                H6[lane] = H[lane] / 6.0
                X[lane] = x0[p]
                V[lane] = v0[p]
            if active == 0:
                break
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
                    v = v + h6 * (b1 + 2.0 * (b2 + b3) + b4)
                    X[lane] = x
                    V[lane] = v
                    DX[lane] = dx + h6 * (dv + 2.0 * (c2 + c3) + c4)
                    DV[lane] = dv + h6 * (d1 + 2.0 * (d2 + d3) + d4)
                    XMIN[lane] = min(XMIN[lane], x)
                    XMAX[lane] = max(XMAX[lane], x)
                    x2 = x * x  # mesh force K(t) f_h(x) + 2 mu v at the step end
                    force = K2[lane] * (x * (cc * x2 - aa)) + twomu * v
                    FMIN[lane] = min(FMIN[lane], force)
                    FMAX[lane] = max(FMAX[lane], force)
            for lane in range(LANES):  # end of an interval T0 for every lane
                nrm = math.sqrt(DX[lane] * DX[lane] + DV[lane] * DV[lane])
                DX[lane] /= nrm
                DV[lane] /= nrm
                p = PT[lane]
                if p < 0:
                    continue
                n = NN[lane]
                finished = False
                if not (abs(X[lane]) < bound and abs(V[lane]) < bound):
                    done[p] = n  # diverged
                    rec[p] = max(0, n - n_trans)
                    diverged[p] = 1
                    finished = True
                else:
                    lg = math.log(nrm)
                    if n >= n_trans:
                        k = n - n_trans
                        logs[p, k] = lg
                        xs[p, k] = X[lane]
                        vs[p, k] = V[lane]
                        xmin[p] = min(xmin[p], XMIN[lane])
                        xmax[p] = max(xmax[p], XMAX[lane])
                        fmin[p] = min(fmin[p], FMIN[lane])
                        fmax[p] = max(fmax[p], FMAX[lane])
                    m = n + 1
                    NN[lane] = m
                    if m == total:
                        finished = True
                        rec[p] = n_rec
                    elif W > 0:
                        slot = n % W
                        RX[slot, lane] = X[lane]
                        RV[slot, lane] = V[lane]
                        RL[slot, lane] = lg
                        RXN[slot, lane] = XMIN[lane]
                        RXX[slot, lane] = XMAX[lane]
                        RFN[slot, lane] = FMIN[lane]
                        RFX[slot, lane] = FMAX[lane]
                        if settle0 + ADAPT_MAX_PERIOD < m <= n_trans and (
                            LASTQ[lane] > 0 or m % ADAPT_PROBE == 0
                        ):  # the cheap streak (probed every ADAPT_PROBE until a lag matches)
                            if LASTQ[lane] == 0 or m % ADAPT_PROBE == 0:
                                TOL2[lane] = window_tol(RXN, RXX, lane, min(m, W)) ** 2
                            q = smallest_lag(RX, RV, lane, slot, W, TOL2[lane])
                            STREAK[lane] = STREAK[lane] + 1 if (q > 0 and q == LASTQ[lane]) else 1
                            LASTQ[lane] = q
                            if q > 0 and settle0 + W <= m and STREAK[lane] >= W - q:
                                stop = settled(
                                    RX,
                                    RV,
                                    RL,
                                    lane,
                                    slot,
                                    W,
                                    q,
                                    window_tol(RXN, RXX, lane, W),
                                    T[p],
                                )
                                if not stop:  # the rule again after ADAPT_RECHECK more matches
                                    STREAK[lane] = W - q - ADAPT_RECHECK
                            else:
                                stop = False
                            if stop:
                                finished = True  # early stop: the window is the record
                                rec[p] = W
                                xmin[p], xmax[p] = np.inf, -np.inf
                                fmin[p], fmax[p] = np.inf, -np.inf
                                for i in range(W):
                                    o = (slot + 1 + i) % W
                                    xs[p, i] = RX[o, lane]
                                    vs[p, i] = RV[o, lane]
                                    logs[p, i] = RL[o, lane]
                                    xmin[p] = min(xmin[p], RXN[o, lane])
                                    xmax[p] = max(xmax[p], RXX[o, lane])
                                    fmin[p] = min(fmin[p], RFN[o, lane])
                                    fmax[p] = max(fmax[p], RFX[o, lane])
                    if finished:
                        done[p] = m
                        xf[p] = X[lane]
                        vf[p] = V[lane]
                XMIN[lane], XMAX[lane] = np.inf, -np.inf
                FMIN[lane], FMAX[lane] = np.inf, -np.inf
                if finished:
                    NEED[lane] = True
                    active -= 1
    return xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf
