"""The lock-step SIMD kernel ``run_batch``: many parameter points (lanes) of the cubic law
advanced together."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from gearengine.systems.spur_pair.kernels.adaptive import ADAPT_SETTLE
from gearengine.systems.spur_pair.kernels.intervals import (
    adaptive_window,
    end_interval,
    new_outputs,
    new_ring,
    reset_lane,
)
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, SQRT1_2

LANES = 16
"""Lanes advanced together in ``run_batch``."""


@njit(**JIT_OPTIONS, parallel=True)
def run_batch(
    a: np.ndarray,
    c: np.ndarray,
    mu: np.ndarray,
    x0: np.ndarray,
    v0: np.ndarray,
    dxc: np.ndarray,
    dvc: np.ndarray,
    Ktab: np.ndarray,
    Ftab: np.ndarray,
    owner: np.ndarray,
    T: np.ndarray,
    N: int,
    n_trans: int,
    n_rec: int,
    bound: float,
    adaptive: bool = False,
    streams: int = 1,
    lle_rel: float = 0.0,
    lle_abs: float = 0.0,
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
    ``kernels.adaptive`` (its last ``ADAPT_WINDOW`` strobes kept in a ring buffer per lane),
    and a chaotic or quasi-periodic one by its LLE rule when ``lle_rel`` or ``lle_abs`` is
    positive; otherwise every point runs ``n_trans + n_rec`` intervals, as ``run_rk4``. The end
    of an interval is ``kernels.intervals.end_interval``.

    The dimensionless mesh force K(t) f_h(x) + 2 mu x' is evaluated at every step end (a few
    flops) and its extremes over the record returned.

    Args:
        a, c, mu, x0, v0, T: per-point law coefficients, damping, initial state and period T0,
            shape (P,).
        dxc, dvc: the tangent vector each point starts from, shape (P,), overwritten with the
            (renormalised) one it ends with: a record continued by a second call from the first
            one's final state and tangent has the numbers of one call running on
            (``numerics.physical``); (1, 1)/sqrt 2 for a fresh start.
        Ktab, Ftab: forcing tables from ``forcing_table`` of the M parameter points, shape
            (M, 2N+1); owner: the point of each lane's run, shape (P,), values in 0..M-1 (the
            runs of a point share its table).
        N, n_trans, n_rec, bound: as in ``run_rk4`` (shared by all points).
        adaptive: allow early stopping of periodic points (``kernels.adaptive``).
        streams: parallel streams of lanes (at most the number of threads is useful).
        lle_rel, lle_abs: tolerances of the LLE rule (``kernels.adaptive.lle_known``); 0 and 0
            turn it off.

    Returns:
        xs, vs, logs: shape (P, n_rec), the record in its first ``rec`` entries; xmin, xmax,
        fmin, fmax (extremes of x and of the mesh force over the record's steps), xf, vf (final
        state): shape (P,); done (intervals run), rec (intervals recorded), diverged (1 if the
        run left ``bound``): shape (P,).
    """
    P = a.size
    xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf = new_outputs(P, n_rec)
    for stream in prange(streams):  # one call per stream: tuples stay out of the parfor
        _cubic_stream(
            stream, streams, a, c, mu, x0, v0, dxc, dvc, Ktab, Ftab, owner, T, N, n_trans, n_rec,
            bound, adaptive, lle_rel, lle_abs,
            xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf,
        )  # fmt: skip
    return xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf


@njit(**JIT_OPTIONS)
def _cubic_stream(
    stream: int,
    streams: int,
    a,
    c,
    mu,
    x0,
    v0,
    dxc,
    dvc,
    Ktab,
    Ftab,
    owner,
    T,
    N,
    n_trans,
    n_rec,
    bound,
    adaptive,
    lle_rel,
    lle_abs,
    xs,
    vs,
    logs,
    xmin,
    xmax,
    fmin,
    fmax,
    done,
    rec,
    diverged,
    xf,
    vf,
) -> None:  # pragma: no cover - compiled
    """One stream of lanes of the kernel above (its arguments and outputs)."""
    P = a.size
    W = adaptive_window(adaptive, n_rec)
    settle0 = min(n_trans, ADAPT_SETTLE)
    out = (xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf)
    Kl = np.ones((2 * N + 1, LANES))
    Fl = np.zeros((2 * N + 1, LANES))
    PT = np.full(LANES, -1, dtype=np.int64)
    counters = (
        np.zeros(LANES, dtype=np.int64),
        np.zeros(LANES, dtype=np.int64),
        np.zeros(LANES, dtype=np.int64),
    )
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
    lane_state = (X, V, DX, DV, XMIN, XMAX, FMIN, FMAX)
    ring = new_ring(W, LANES)
    taken = 0  # points of this stream loaded so far
    active = 0
    while True:
        for lane in range(LANES):  # load the stream's next point into every free lane
            if not NEED[lane]:
                continue
            NEED[lane] = False
            reset_lane(lane, lane_state, 0.0, 0.0)
            p = stream + taken * streams
            if p >= P:
                PT[lane] = -1  # idle: parked on a harmless state
                continue
            taken += 1
            active += 1
            PT[lane] = p
            for counter in counters:
                counter[lane] = 0
            for s in range(2 * N + 1):
                Kl[s, lane] = Ktab[owner[p], s]
                Fl[s, lane] = Ftab[owner[p], s]
            A[lane] = a[p]
            C[lane] = c[p]
            TM[lane] = 2.0 * mu[p]
            H[lane] = T[p] / N
            H2[lane] = 0.5 * H[lane]
            H6[lane] = H[lane] / 6.0
            X[lane] = x0[p]
            V[lane] = v0[p]
            DX[lane] = dxc[p]
            DV[lane] = dvc[p]
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
            if end_interval(
                lane, PT[lane], lane_state, counters, TOL2, ring, out, T[max(PT[lane], 0)],
                n_trans, n_rec, W, settle0, bound, lle_rel, lle_abs,
            ):  # fmt: skip
                NEED[lane] = True
                active -= 1
                dxc[PT[lane]], dvc[PT[lane]] = DX[lane], DV[lane]
