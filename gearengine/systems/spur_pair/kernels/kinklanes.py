"""The lock-step kernel of the piecewise law, ``run_kink_batch``: many runs (lanes) of Eq. (9)
with the law of Eq. (8), advanced together and split at the kinks |x| = 1 lane by lane, with the
numbers of the scalar kink kernel (``kink.run_kink`` with its forcing table)."""

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
from gearengine.systems.spur_pair.kernels.kink import kink_split, rk4_region_kf
from gearengine.systems.spur_pair.kernels.lockstep import LANES
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, SQRT1_2, region

HERMITE_REACH = 0.15
"""Bound (> 4/27, the largest |Hermite basis h10|, |h11| on [0, 1]) of how far the cubic
Hermite interpolant of x over a step of length h leaves [min(x0, x1), max(x0, x1)], in units
of h (|v0| + |v1|): a step whose bound stays strictly inside its region has no sample of
``kink.kink_split`` outside it, so it is accepted without that test."""
ROUNDING_MARGIN = 1e-9
"""Absolute margin (units of b) added to that bound for the rounding of the samples."""
NO_REGION = 2
"""``regc`` of a run that starts in the region of its x0 (not -1, 0 or 1)."""


@njit(**JIT_OPTIONS)
def _law_slope_offset(reg: int, alpha: float) -> tuple[float, float]:  # pragma: no cover
    """(s, o) with f_h(x) = s x - o and f_h'(x) = s in region ``reg`` of Eq. (8): the same bits
    as ``smooth.region_force`` (x * 1.0 is x, x - (-o) is x + o)."""
    if reg > 0:
        return 1.0, 1.0 - alpha
    if reg < 0:
        return 1.0, -(1.0 - alpha)
    return alpha, 0.0


@njit(**JIT_OPTIONS)
def _region_interval(reg: int) -> tuple[float, float]:  # pragma: no cover - compiled
    """The open interval (lo, hi) of x that is region ``reg`` of Eq. (8)."""
    if reg > 0:
        return 1.0, np.inf
    if reg < 0:
        return -np.inf, -1.0
    return -1.0, 1.0


@njit(**JIT_OPTIONS, parallel=True)
def run_kink_batch(
    alpha: np.ndarray,
    mu: np.ndarray,
    x0: np.ndarray,
    v0: np.ndarray,
    dxc: np.ndarray,
    dvc: np.ndarray,
    regc: np.ndarray,
    Ktab: np.ndarray,
    Ftab: np.ndarray,
    owner: np.ndarray,
    kc: np.ndarray,
    nk: np.ndarray,
    fm: np.ndarray,
    fc: np.ndarray,
    nf: np.ndarray,
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
    """Kink-splitting RK4 of Eq. (9) + tangent, piecewise law of Eq. (8), for P runs in lanes.

    Every step of every lane is first taken whole in its current region with the lane's forcing
    table (the arithmetic of ``kink.rk4_region_kf`` written out per lane, so LLVM vectorises the
    lane loop) and bounded by its Hermite reach (``HERMITE_REACH``): a lane whose bound stays in
    its region keeps the step, by selects, not branches. A lane whose bound touches a switching
    point |x| = 1 keeps its state in that loop; a second loop, entered only when some lane is
    near a kink, retakes its step with ``rk4_region_kf`` and hands it to ``kink.kink_split``
    (the crossing test, the regula falsi and the substeps of the scalar kernel, forcing at the
    time within the period). So each run has the numbers of ``run_kink(..., use_table=True)``
    bit for bit, while the steps far from the kinks cost what the cubic lanes' cost. The forcing
    rows are indexed in place (``Kl[2j, lane]``), not taken as row views: a view's reference
    count is updated around every step (12 atomic calls) once the split loop may use it.
    Streams, lanes, refills, adaptive stopping and outputs are those of ``lockstep.run_batch``.

    Args:
        alpha, mu, x0, v0, T: per-run slope of Eq. (8) inside the clearance, damping, initial
            state and period T0, shape (P,).
        dxc, dvc, regc: the tangent vector and region of Eq. (8) each run starts in, shape (P,),
            overwritten with those it ends in, as ``run_batch``'s tangent (the region is
            carried too: at a kink it follows the direction of motion, not x alone);
            ``NO_REGION`` for the region of x0.
        Ktab, Ftab: forcing tables from ``forcing_table`` of the M parameter points, shape
            (M, 2N+1); owner: the point of each run, shape (P,), values in 0..M-1.
        kc, fc: forcing coefficients of the points (``systems.spur_pair.forcing.packed_forcing``)
            padded to shapes (M, 3, max terms); nk, nf: their numbers of terms, shape (M,);
            fm: mean force, shape (M,). The substeps of split steps evaluate the forcing from
            them.
        N, n_trans, n_rec, bound, adaptive, streams, lle_rel, lle_abs: as in ``run_batch``.

    Returns:
        The outputs of ``run_batch``.
    """
    P = alpha.size
    xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf = new_outputs(P, n_rec)
    for stream in prange(streams):  # one call per stream: tuples stay out of the parfor
        _kink_stream(
            stream, streams, alpha, mu, x0, v0, dxc, dvc, regc, Ktab, Ftab, owner, kc, nk, fm,
            fc, nf, T, N, n_trans, n_rec, bound, adaptive, lle_rel, lle_abs,
            xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf,
        )  # fmt: skip
    return xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf


@njit(**JIT_OPTIONS)
def _kink_stream(
    stream: int,
    streams: int,
    alpha,
    mu,
    x0,
    v0,
    dxc,
    dvc,
    regc,
    Ktab,
    Ftab,
    owner,
    kc,
    nk,
    fm,
    fc,
    nf,
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
    P = alpha.size
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
    AL = np.zeros(LANES)
    REG = np.zeros(LANES, dtype=np.int64)
    S = np.zeros(LANES)
    O = np.zeros(LANES)  # noqa: E741 - the offset o of f_h = s x - o
    TM = np.zeros(LANES)
    H = np.zeros(LANES)
    H2 = np.zeros(LANES)
    H6 = np.zeros(LANES)
    X = np.zeros(LANES)
    V = np.zeros(LANES)
    DX = np.full(LANES, SQRT1_2)
    DV = np.full(LANES, SQRT1_2)
    LO = np.full(LANES, -1.0)  # the open interval (LO, HI) of the lane's region in x
    HI = np.full(LANES, 1.0)
    NEAR = np.zeros(LANES, dtype=np.bool_)
    XMIN = np.full(LANES, np.inf)
    XMAX = np.full(LANES, -np.inf)
    FMIN = np.full(LANES, np.inf)
    FMAX = np.full(LANES, -np.inf)
    lane_state = (X, V, DX, DV, XMIN, XMAX, FMIN, FMAX)
    ring = new_ring(W, LANES)
    taken = 0  # runs of this stream loaded so far
    active = 0
    while True:
        for lane in range(LANES):  # load the stream's next run into every free lane
            if not NEED[lane]:
                continue
            NEED[lane] = False
            reset_lane(lane, lane_state, 0.0, 0.0)
            p = stream + taken * streams
            if p >= P:
                PT[lane] = -1  # idle: parked on a harmless state
                REG[lane] = 0
                S[lane], O[lane] = _law_slope_offset(0, AL[lane])
                LO[lane], HI[lane] = _region_interval(0)
                continue
            taken += 1
            active += 1
            PT[lane] = p
            for counter in counters:
                counter[lane] = 0
            for s in range(2 * N + 1):
                Kl[s, lane] = Ktab[owner[p], s]
                Fl[s, lane] = Ftab[owner[p], s]
            AL[lane] = alpha[p]
            TM[lane] = 2.0 * mu[p]
            H[lane] = T[p] / N
            H2[lane] = 0.5 * H[lane]
            H6[lane] = H[lane] / 6.0
            X[lane] = x0[p]
            V[lane] = v0[p]
            DX[lane] = dxc[p]
            DV[lane] = dvc[p]
            REG[lane] = region(x0[p]) if regc[p] == NO_REGION else regc[p]
            S[lane], O[lane] = _law_slope_offset(REG[lane], alpha[p])
            LO[lane], HI[lane] = _region_interval(REG[lane])
        if active == 0:
            break
        for j in range(N):  # K and F at the step's start, middle and end: Kl[2j + 0, 1, 2]
            j0, j1, j2 = 2 * j, 2 * j + 1, 2 * j + 2
            near = 0
            for lane in range(LANES):  # the whole step in the lane's region, kept if inside it
                s = S[lane]
                o = O[lane]
                twomu = TM[lane]
                h = H[lane]
                h2 = H2[lane]
                x = X[lane]
                v = V[lane]
                dx = DX[lane]
                dv = DV[lane]
                b1 = -twomu * v - Kl[j0, lane] * (x * s - o) + Fl[j0, lane]
                d1 = -twomu * dv - Kl[j0, lane] * s * dx
                xs_, a2, dxs, c2 = x + h2 * v, v + h2 * b1, dx + h2 * dv, dv + h2 * d1
                b2 = -twomu * a2 - Kl[j1, lane] * (xs_ * s - o) + Fl[j1, lane]
                d2 = -twomu * c2 - Kl[j1, lane] * s * dxs
                xs_, a3, dxs, c3 = x + h2 * a2, v + h2 * b2, dx + h2 * c2, dv + h2 * d2
                b3 = -twomu * a3 - Kl[j1, lane] * (xs_ * s - o) + Fl[j1, lane]
                d3 = -twomu * c3 - Kl[j1, lane] * s * dxs
                xs_, a4, dxs, c4 = x + h * a3, v + h * b3, dx + h * c3, dv + h * d3
                b4 = -twomu * a4 - Kl[j2, lane] * (xs_ * s - o) + Fl[j2, lane]
                d4 = -twomu * c4 - Kl[j2, lane] * s * dxs
                h6 = H6[lane]
                xn = x + h6 * (v + 2.0 * (a2 + a3) + a4)
                vn = v + h6 * (b1 + 2.0 * (b2 + b3) + b4)
                dxn = dx + h6 * (dv + 2.0 * (c2 + c3) + c4)
                dvn = dv + h6 * (d1 + 2.0 * (d2 + d3) + d4)
                reach = HERMITE_REACH * h * (abs(v) + abs(vn)) + ROUNDING_MARGIN
                inside = (min(x, xn) - reach > LO[lane]) & (max(x, xn) + reach < HI[lane])
                NEAR[lane] = not inside
                near += not inside
                # a lane near a kink keeps its state for the split below (selects, no branch)
                X[lane] = xn if inside else x
                V[lane] = vn if inside else v
                DX[lane] = dxn if inside else dx
                DV[lane] = dvn if inside else dv
                force = Kl[j2, lane] * (xn * s - o) + twomu * vn  # mesh force at the step end
                XMIN[lane] = min(XMIN[lane], xn if inside else np.inf)
                XMAX[lane] = max(XMAX[lane], xn if inside else -np.inf)
                FMIN[lane] = min(FMIN[lane], force if inside else np.inf)
                FMAX[lane] = max(FMAX[lane], force if inside else -np.inf)
            if near == 0:
                continue
            for lane in range(LANES):  # steps near a kink: the scalar kernel's split
                p = PT[lane]
                if not NEAR[lane] or p < 0:
                    continue
                q = owner[p]
                al = AL[lane]
                twomu = TM[lane]
                h = H[lane]
                x, v, dx, dv = X[lane], V[lane], DX[lane], DV[lane]
                x1, v1, dx1, dv1 = rk4_region_kf(
                    REG[lane], al, twomu, Kl[j0, lane], Fl[j0, lane], Kl[j1, lane],
                    Fl[j1, lane], Kl[j2, lane], Fl[j2, lane], h, x, v, dx, dv,
                )  # fmt: skip
                x, v, DX[lane], DV[lane], reg = kink_split(
                    REG[lane], al, twomu, kc[q, :, : nk[q]], fm[q], fc[q, :, : nf[q]],
                    j * h, h, x, v, dx, dv, x1, v1, dx1, dv1,
                )  # fmt: skip
                X[lane] = x
                V[lane] = v
                REG[lane] = reg
                S[lane], O[lane] = _law_slope_offset(reg, al)
                LO[lane], HI[lane] = _region_interval(reg)
                XMIN[lane] = min(XMIN[lane], x)
                XMAX[lane] = max(XMAX[lane], x)
                force = Kl[j2, lane] * (x * S[lane] - O[lane]) + twomu * v
                FMIN[lane] = min(FMIN[lane], force)
                FMAX[lane] = max(FMAX[lane], force)
        for lane in range(LANES):  # end of an interval T0 for every lane
            if end_interval(
                lane, PT[lane], lane_state, counters, TOL2, ring, out, T[max(PT[lane], 0)],
                n_trans, n_rec, W, settle0, bound, lle_rel, lle_abs,
            ):  # fmt: skip
                NEED[lane] = True
                active -= 1
                p = PT[lane]
                dxc[p], dvc[p], regc[p] = DX[lane], DV[lane], REG[lane]
