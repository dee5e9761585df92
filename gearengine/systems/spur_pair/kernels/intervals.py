"""The end of a sampling interval T0 of the lanes of a stream of the lock-step kernels
(``lockstep.run_batch`` for the cubic law, ``kinklanes.run_kink_batch`` for the piecewise law):
Benettin renormalisation, the record, divergence and the stopping rules of ``kernels.adaptive``.

It runs once per interval, beside N vectorised steps of every lane, so it is a compiled helper
both kernels call rather than code written out in their bodies. The buffers are passed as
tuples:

* ``lane_state``: (X, V, DX, DV, XMIN, XMAX, FMIN, FMAX), shape (LANES,) each: the state, the
  tangent vector and the extremes of x and of the mesh force over the current interval;
* ``counters``: (NN, STREAK, LASTQ), int64 (LANES,): intervals run, the adaptive rule's streak
  and its candidate period; ``TOL2`` (LANES,): the prefilter's squared tolerance;
* ``ring``: (RX, RV, RL, RXN, RXX, RFN, RFX), shape (max(W, 1), LANES): the last W intervals'
  strobes, logs and extremes;
* ``out``: the kernels' outputs (xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged,
  xf, vf), see ``lockstep.run_batch``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gearengine.systems.spur_pair.kernels.adaptive import (
    ADAPT_MAX_PERIOD,
    ADAPT_PROBE,
    ADAPT_RECHECK,
    ADAPT_WINDOW,
    lle_known,
    settled,
    smallest_lag,
    window_tol,
)
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, SQRT1_2


@njit(**JIT_OPTIONS)
def new_outputs(P: int, n_rec: int) -> tuple:  # pragma: no cover - compiled
    """The zeroed ``out`` tuple of P lanes with records of n_rec intervals."""
    return (
        np.zeros((P, n_rec)),
        np.zeros((P, n_rec)),
        np.zeros((P, n_rec)),
        np.full(P, np.inf),
        np.full(P, -np.inf),
        np.full(P, np.inf),
        np.full(P, -np.inf),
        np.zeros(P, dtype=np.int64),
        np.zeros(P, dtype=np.int64),
        np.zeros(P, dtype=np.int64),
        np.zeros(P),
        np.zeros(P),
    )


@njit(**JIT_OPTIONS)
def new_ring(W: int, lanes: int) -> tuple:  # pragma: no cover - compiled
    """The ``ring`` tuple of the adaptive rule's window (one row when W = 0)."""
    WR = max(W, 1)
    return (
        np.zeros((WR, lanes)),
        np.zeros((WR, lanes)),
        np.zeros((WR, lanes)),
        np.zeros((WR, lanes)),
        np.zeros((WR, lanes)),
        np.zeros((WR, lanes)),
        np.zeros((WR, lanes)),
    )


@njit(**JIT_OPTIONS)
def adaptive_window(adaptive: bool, n_rec: int) -> int:  # pragma: no cover - compiled
    """W: ``ADAPT_WINDOW`` when the periodic rule may apply (adaptive, n_rec >= the window)."""
    return ADAPT_WINDOW if (adaptive and n_rec >= ADAPT_WINDOW) else 0


@njit(**JIT_OPTIONS)
def reset_lane(lane: int, lane_state: tuple, x0: float, v0: float) -> None:  # pragma: no cover
    """Start ``lane`` afresh from (x0, v0), tangent (1, 1)/sqrt 2, empty extremes."""
    X, V, DX, DV, XMIN, XMAX, FMIN, FMAX = lane_state
    X[lane], V[lane], DX[lane], DV[lane] = x0, v0, SQRT1_2, SQRT1_2
    XMIN[lane], XMAX[lane] = np.inf, -np.inf
    FMIN[lane], FMAX[lane] = np.inf, -np.inf


@njit(**JIT_OPTIONS)
def end_intervals(
    PT: np.ndarray,
    lane_state: tuple,
    counters: tuple,
    TOL2: np.ndarray,
    ring: tuple,
    out: tuple,
    T: np.ndarray,
    n_trans: int,
    n_rec: int,
    W: int,
    settle0: int,
    bound: float,
    lle_rel: float,
    lle_abs: float,
    NEED: np.ndarray,
) -> int:  # pragma: no cover - compiled
    """End the interval of every lane (run ``PT[lane]`` of period ``T[PT[lane]]``, PT < 0 for
    an idle lane): renormalise its tangent, record the interval, and apply divergence, the end
    of the run and the adaptive rules (W > 0: the periodic rule of ``kernels.adaptive``;
    lle_rel or lle_abs > 0: its LLE rule). Sets ``NEED[lane]`` of each lane whose run is
    finished (its outputs written) and returns how many.

    One call for all the lanes of a stream, not one a lane: a call takes its ~30 arrays out of
    the tuples with a reference-count increment and decrement each (~60 atomic operations,
    ~240 ns), which one call a lane paid every interval (1.2 ns of the 5 per lane-step at 200
    steps per T0, ``benchmarks/README.md``)."""
    X, V, DX, DV, XMIN, XMAX, FMIN, FMAX = lane_state
    NN, STREAK, LASTQ = counters
    RX, RV, RL, RXN, RXX, RFN, RFX = ring
    xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf = out
    total = n_trans + n_rec
    ended = 0
    for lane in range(PT.size):
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
            elif n >= n_trans and (lle_rel > 0.0 or lle_abs > 0.0):
                kept = n - n_trans + 1
                if lle_known(xs[p], vs[p], logs[p], kept, xmin[p], xmax[p], T[p], lle_rel,
                             lle_abs):  # fmt: skip
                    finished = True  # the LLE rule: the record so far is the record
                    rec[p] = kept
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
                        tol = window_tol(RXN, RXX, lane, W)
                        stop = settled(RX, RV, RL, lane, slot, W, q, tol, T[p])
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
            ended += 1
    return ended
