"""Lock-step RK4 of many gear trains (lanes) at once: the state of every lane in one array,
(u, v, du, dv) x coordinate x lane, advanced step by step together.

Each lane is one train (its point's matrices, forcing table and step h = T0 / N) from one
start; all lanes of a call share the state dimension n, the backlash law and the steps N per
T0. Per lane the arithmetic is that of ``kernel.run_train`` with a tabulated forcing (the same
operations in the same order, across lanes in the innermost loop so that the compiler may
vectorise them), so every lane's numbers are those of its own run. What is kept is what the
verdicts of ``numerics.lanes`` read (the pair's lock-step layout): strobes of delta and delta',
the log of the tangent's growth per T0, the extremes of delta and of the mesh force over the
record, and delta, delta' at the record's last history sample (``Run.final`` of a run).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from gearengine.jitcache import drop_stale
from gearengine.systems.spur_pair.kernels import smooth
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, law_force

drop_stale(
    "lanes",
    [Path(__file__), Path(smooth.__file__)],
    Path(__file__).parent / "__pycache__",
)
"""Before any kernel runs: numba watches only this file; ``law_force`` lives in smooth."""


@njit(**JIT_OPTIONS)
def run_train_lanes(
    law: int,
    a: float,
    c: float,
    alpha: float,
    mu: np.ndarray,
    AK: np.ndarray,
    AC: np.ndarray,
    g: np.ndarray,
    w: np.ndarray,
    f: np.ndarray,
    p: np.ndarray,
    tables: np.ndarray,
    owner: np.ndarray,
    per: np.ndarray,
    u0: np.ndarray,
    v0: np.ndarray,
    N: int,
    n_trans: int,
    n_rec: int,
    last: int,
    bound: float,
):  # pragma: no cover - compiled
    """Classical RK4 of every lane + tangent over n_trans + n_rec intervals T0 of N steps.

    Args:
        law, a, c, alpha: the backlash law shared by the lanes.
        mu (P,), AK, AC (P, n, n), g, w, f, p (P, n): each point's train (``kernel``).
        tables: each point's forcing (K, e, e', T) at the 2N + 1 stage times of a period,
            (P, 2N + 1, 4) (``kernel.forcing_table``, as ``run_train`` tabulates it).
        owner: the point of each lane (L,); per: each point's T0 (P,).
        u0, v0: the lanes' starts, (L, n).
        N, n_trans, n_rec: steps per T0, intervals; last: the record step (1-based) of the
            last history sample, whose delta and delta' are the final state.
        bound: divergence bound on every |u_i|, |v_i| (checked every T0).

    Returns:
        xs, vs, logs (L, n_rec); xmin, xmax, fmin, fmax (L,) over the recorded steps; done
        (intervals), rec (recorded intervals), diverged (L,); xf, vf (L,): ``numerics.lanes``'
        layout of the pair's lock-step kernels.
    """
    L = owner.size
    n = u0.shape[1]
    y = np.empty((4, n, L))
    k = np.empty((4, 4, n, L))
    s = np.empty((4, n, L))
    start = 1.0 / math.sqrt(2.0 * n)
    for lane in range(L):
        for i in range(n):
            y[0, i, lane], y[1, i, lane] = u0[lane, i], v0[lane, i]
            y[2, i, lane], y[3, i, lane] = start, start
    # each lane's train with the lane innermost (contiguous across lanes: vector loads)
    AKl = np.empty((n, n, L))
    ACl = np.empty((n, n, L))
    gl = np.empty((n, L))
    wl = np.empty((n, L))
    fl = np.empty((n, L))
    pl = np.empty((n, L))
    for lane in range(L):
        pt = owner[lane]
        for i in range(n):
            gl[i, lane], wl[i, lane] = g[pt, i], w[pt, i]
            fl[i, lane], pl[i, lane] = f[pt, i], p[pt, i]
            for jj in range(n):
                AKl[i, jj, lane], ACl[i, jj, lane] = AK[pt, i, jj], AC[pt, i, jj]
    Tl = np.empty(L)
    step = np.empty(L)
    h = np.empty(L)
    h2 = np.empty(L)
    h6 = np.empty(L)
    twomu = np.empty(L)
    for lane in range(L):
        h[lane] = per[owner[lane]] / N
        h2[lane] = 0.5 * h[lane]
        h6[lane] = h[lane] / 6.0
        twomu[lane] = 2.0 * mu[owner[lane]]
    xs = np.zeros((L, n_rec))
    vs = np.zeros((L, n_rec))
    logs = np.zeros((L, n_rec))
    xmin = np.full(L, np.inf)
    xmax = np.full(L, -np.inf)
    fmin = np.full(L, np.inf)
    fmax = np.full(L, -np.inf)
    xf = np.full(L, np.nan)
    vf = np.full(L, np.nan)
    done = np.zeros(L, dtype=np.int64)
    alive = np.ones(L, dtype=np.bool_)
    delta = np.empty(L)
    deltad = np.empty(L)
    W = np.empty(L)
    dW = np.empty(L)
    living = L
    for it in range(n_trans + n_rec):
        rec = it >= n_trans
        for j in range(N):
            for stage in range(4):
                q = 0 if stage == 0 else (2 if stage == 3 else 1)
                row = 2 * j + q
                if stage == 0:
                    for r in range(4):
                        for i in range(n):
                            for lane in range(L):
                                s[r, i, lane] = y[r, i, lane]
                else:
                    for lane in range(L):
                        step[lane] = h[lane] if stage == 3 else h2[lane]
                    for r in range(4):
                        for i in range(n):
                            for lane in range(L):
                                s[r, i, lane] = (
                                    y[r, i, lane] + step[lane] * k[stage - 1, r, i, lane]
                                )
                for lane in range(L):  # the mesh: _field's delta, W and its variation
                    pt = owner[lane]
                    dl = -tables[pt, row, 1]
                    dd = -tables[pt, row, 2]
                    wdu = 0.0
                    wdv = 0.0
                    for i in range(n):
                        dl += wl[i, lane] * s[0, i, lane]
                        dd += wl[i, lane] * s[1, i, lane]
                        wdu += wl[i, lane] * s[2, i, lane]
                        wdv += wl[i, lane] * s[3, i, lane]
                    fh, dfh = law_force(law, a, c, alpha, dl)
                    K = tables[pt, row, 0]
                    W[lane] = K * fh + twomu[lane] * dd
                    dW[lane] = K * dfh * wdu + twomu[lane] * wdv
                    Tl[lane] = tables[pt, row, 3]
                for i in range(n):
                    for lane in range(L):
                        k[stage, 0, i, lane] = s[1, i, lane]
                        k[stage, 1, i, lane] = (
                            fl[i, lane] + pl[i, lane] * Tl[lane] - gl[i, lane] * W[lane]
                        )
                        k[stage, 2, i, lane] = s[3, i, lane]
                        k[stage, 3, i, lane] = -gl[i, lane] * dW[lane]
                    for jj in range(n):
                        for lane in range(L):
                            k[stage, 1, i, lane] -= (
                                AKl[i, jj, lane] * s[0, jj, lane]
                                + ACl[i, jj, lane] * s[1, jj, lane]
                            )
                            k[stage, 3, i, lane] -= (
                                AKl[i, jj, lane] * s[2, jj, lane]
                                + ACl[i, jj, lane] * s[3, jj, lane]
                            )
            for r in range(4):
                for i in range(n):
                    for lane in range(L):
                        y[r, i, lane] += h6[lane] * (
                            k[0, r, i, lane]
                            + 2.0 * (k[1, r, i, lane] + k[2, r, i, lane])
                            + k[3, r, i, lane]
                        )
            rstep = (it - n_trans) * N + j + 1
            for lane in range(L):
                if not alive[lane]:
                    continue
                pt = owner[lane]
                dl = -tables[pt, 2 * j + 2, 1]
                dd = -tables[pt, 2 * j + 2, 2]
                for i in range(n):
                    dl += w[pt, i] * y[0, i, lane]
                    dd += w[pt, i] * y[1, i, lane]
                delta[lane] = dl
                deltad[lane] = dd
                xmin[lane] = min(xmin[lane], dl)
                xmax[lane] = max(xmax[lane], dl)
                force = tables[pt, 2 * j + 2, 0] * law_force(law, a, c, alpha, dl)[0]
                force += twomu[lane] * dd
                fmin[lane] = min(fmin[lane], force)
                fmax[lane] = max(fmax[lane], force)
                if rec and rstep == last:
                    xf[lane] = dl
                    vf[lane] = dd
        for lane in range(L):
            if not alive[lane]:
                continue
            nrm = 0.0
            big = 0.0
            for i in range(n):
                nrm += y[2, i, lane] * y[2, i, lane] + y[3, i, lane] * y[3, i, lane]
                big = max(big, abs(y[0, i, lane]), abs(y[1, i, lane]))
            nrm = math.sqrt(nrm)
            for i in range(n):
                y[2, i, lane] /= nrm
                y[3, i, lane] /= nrm
            if not big < bound:
                alive[lane] = False
                living -= 1
                for i in range(n):  # park it at rest: no overflow in the steps to come
                    y[0, i, lane] = 0.0
                    y[1, i, lane] = 0.0
                continue
            if rec:
                r = it - n_trans
                logs[lane, r] = math.log(nrm)
                xs[lane, r] = delta[lane]
                vs[lane, r] = deltad[lane]
            elif it + 1 == n_trans:
                xmin[lane], xmax[lane] = np.inf, -np.inf
                fmin[lane], fmax[lane] = np.inf, -np.inf
            done[lane] = it + 1
        if living == 0:
            break
    rec_n = np.maximum(done - n_trans, 0)
    diverged = done < n_trans + n_rec
    return xs, vs, logs, xmin, xmax, fmin, fmax, done, rec_n, diverged, xf, vf
