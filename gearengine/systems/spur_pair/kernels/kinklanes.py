"""The lock-step kernel of the piecewise law, ``run_kink_batch``: many runs (lanes) of Eq. (9)
with the law of Eq. (8), advanced together and split at the kinks |x| = 1 lane by lane, with the
numbers of the scalar kink kernel (``kink.run_kink`` with its forcing table)."""

from __future__ import annotations

import numpy as np
from numba import njit

from gearengine.systems.spur_pair.kernels.kink import kink_split, rk4_region_kf
from gearengine.systems.spur_pair.kernels.scheduler import LANES, LaneLaw, lane_kernel
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, region

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


@njit(**JIT_OPTIONS)
def _kink_lanes(L: int) -> tuple:  # pragma: no cover - compiled
    """The piecewise law's per-lane arrays: alpha, the region of Eq. (8) and its f_h = s x - o,
    the open interval (LO, HI) of the region in x, and whether the lane's step is near a kink."""
    return (
        np.zeros(L),
        np.zeros(L, dtype=np.int64),
        np.zeros(L),
        np.zeros(L),
        np.full(L, -1.0),
        np.full(L, 1.0),
        np.zeros(L, dtype=np.bool_),
    )


@njit(**JIT_OPTIONS)
def _kink_load(
    lane: int, p: int, law: tuple, x0: np.ndarray, coeffs: tuple
) -> None:  # pragma: no cover
    """Run p's alpha and region (its carried one, or that of x0) into ``lane``; an idle lane
    (p < 0) parks inside the clearance."""
    AL, REG, S, O, LO, HI, _ = law  # noqa: E741 - the offset o of f_h = s x - o
    alpha, regc = coeffs[0], coeffs[1]
    if p < 0:
        REG[lane] = 0
    else:
        AL[lane] = alpha[p]
        REG[lane] = region(x0[p]) if regc[p] == NO_REGION else regc[p]
    S[lane], O[lane] = _law_slope_offset(REG[lane], AL[lane])
    LO[lane], HI[lane] = _region_interval(REG[lane])


@njit(**JIT_OPTIONS, inline="always")
def _kink_steps(
    N, Kl, Fl, PT, owner, lane_state, rates, law, coeffs, tangent
) -> None:  # pragma: no cover
    """N kink-splitting RK4 steps of every lane (the scheduler's ``steps``; kernel doc), with the
    tangent whatever ``tangent`` says: skipping it under ``if tangent`` in the lane loop left
    that loop 2.7x slower (thread CPU of 301 paper points, piecewise, fixed length)."""
    X, V, DX, DV, XMIN, XMAX, FMIN, FMAX = lane_state
    TM, H, H2, H6 = rates
    AL, REG, S, O, LO, HI, NEAR = law  # noqa: E741
    _, _, kc, nk, fm, fc, nf = coeffs
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
                j * h, Kl[j0, lane], Fl[j0, lane], h, x, v, dx, dv, x1, v1, dx1, dv1,
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


@njit(**JIT_OPTIONS)
def _kink_keep(lane: int, p: int, law: tuple, coeffs: tuple) -> None:  # pragma: no cover
    """Run p carries its region of Eq. (8) into a next call."""
    coeffs[1][p] = law[1][lane]


KINK = LaneLaw(
    "kink",
    """Kink-splitting RK4 of Eq. (9) + tangent, piecewise law of Eq. (8), for P runs in lanes.

    Every step of every lane is first taken whole in its current region with the lane's forcing
    table (the arithmetic of ``kink.rk4_region_kf`` written out per lane, so LLVM vectorises the
    lane loop) and bounded by its Hermite reach (``HERMITE_REACH``): a lane whose bound stays in
    its region keeps the step, by selects, not branches. A lane whose bound touches a switching
    point |x| = 1 keeps its state in that loop; a second loop, entered only when some lane is
    near a kink, retakes its step with ``rk4_region_kf`` and hands it to ``kink.kink_split``
    (the crossing test, the Newton iterates and the substeps of the scalar kernel, forcing at the
    time within the period). So each run has the numbers of ``run_kink(..., use_table=True)``
    bit for bit, while the steps far from the kinks cost what the cubic lanes' cost. The forcing
    rows are indexed in place (``Kl[2j, lane]``), not taken as row views: a view's reference
    count is updated around every step (12 atomic calls) once the split loop may use it.
    Streams, lanes, refills, adaptive stopping and outputs are the lane scheduler's
    (``kernels.scheduler``), shared with the cubic law.

    ``coeffs`` = (alpha, regc, kc, nk, fm, fc, nf): alpha, the runs' slope of Eq. (8) inside
    the clearance, shape (P,); regc, the region of Eq. (8) each run starts in, shape (P,),
    overwritten with the one it ends in, as the tangent (at a kink the region follows the
    direction of motion, not x alone), ``NO_REGION`` for the region of x0; kc, fc: the points'
    forcing coefficients (``systems.spur_pair.forcing.packed_forcing``) padded to shapes
    (M, 3, max terms), nk, nf their numbers of terms, shape (M,), fm their mean force, shape
    (M,): the substeps of split steps evaluate the forcing from them.""",
    _kink_lanes,
    _kink_load,
    _kink_steps,
    _kink_keep,
)
"""The piecewise law's pieces of the lane scheduler."""

run_kink_batch = lane_kernel(KINK)
"""The piecewise law's lock-step kernel: ``run_kink_batch(mu, x0, v0, dxc, dvc, Ktab, Ftab,
owner, T, N, n_trans, n_rec, bound, adaptive, streams, lle_rel, lle_abs, tangent, alpha, regc,
kc, nk, fm, fc, nf)`` (``scheduler._lanes``)."""
