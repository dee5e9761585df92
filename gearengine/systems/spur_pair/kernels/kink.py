"""Kink-splitting RK4 for the piecewise law of Eq. (8) (gear_ref.c --kink's splitting, general
alpha): every step is split at the switching times |x| = 1. The crossing time is found by
Newton from the root of the step's Hermite interpolant, each iterate an RK4 substep whose
velocity is the slope (two substeps to 1e-13 of a step; gear_ref.c's bracketing Illinois
regula falsi took ~6.5 and stays as the fallback for a grazing excursion), so a chaotic run
parts from gear_ref.c's after a few hundred periods, as any two runs 1e-13 apart do."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gearengine.systems.spur_pair.kernels.phase import excitation_at
from gearengine.systems.spur_pair.kernels.smooth import (
    JIT_OPTIONS,
    SQRT1_2,
    forcing_table,
    region,
    region_force,
    stiffness_at,
)


@njit(**JIT_OPTIONS)
def _rhs_region(
    reg: int,
    alpha: float,
    twomu: float,
    K: float,
    F: float,
    x: float,
    v: float,
    dx: float,
    dv: float,
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """Eq. (9) + tangent with the linear law of region ``reg`` extended beyond its boundary."""
    fh, dfh = region_force(reg, alpha, x)
    return v, -twomu * v - K * fh + F, dv, -twomu * dv - K * dfh * dx


@njit(**JIT_OPTIONS)
def rk4_region_kf(
    reg: int,
    alpha: float,
    twomu: float,
    K0: float,
    F0: float,
    K1: float,
    F1: float,
    K2: float,
    F2: float,
    dt: float,
    x: float,
    v: float,
    dx: float,
    dv: float,
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """One RK4 step of length dt in region ``reg`` with the forcing (K, F) at its start (0),
    middle (1) and end (2) given: the arithmetic ``kernels.kinklanes`` repeats lane by lane."""
    a1, b1, c1, d1 = _rhs_region(reg, alpha, twomu, K0, F0, x, v, dx, dv)
    h2 = 0.5 * dt
    a2, b2, c2, d2 = _rhs_region(
        reg, alpha, twomu, K1, F1, x + h2 * a1, v + h2 * b1, dx + h2 * c1, dv + h2 * d1
    )
    a3, b3, c3, d3 = _rhs_region(
        reg, alpha, twomu, K1, F1, x + h2 * a2, v + h2 * b2, dx + h2 * c2, dv + h2 * d2
    )
    a4, b4, c4, d4 = _rhs_region(
        reg, alpha, twomu, K2, F2, x + dt * a3, v + dt * b3, dx + dt * c3, dv + dt * d3
    )
    h6 = dt / 6.0
    return (
        x + h6 * (a1 + 2.0 * (a2 + a3) + a4),
        v + h6 * (b1 + 2.0 * (b2 + b3) + b4),
        dx + h6 * (c1 + 2.0 * (c2 + c3) + c4),
        dv + h6 * (d1 + 2.0 * (d2 + d3) + d4),
    )


@njit(**JIT_OPTIONS)
def _rk4_region(
    reg: int,
    alpha: float,
    twomu: float,
    kc: np.ndarray,
    fm: float | np.ndarray,
    fc: np.ndarray,
    K0: float,
    F0: float,
    t: float,
    dt: float,
    x: float,
    v: float,
    dx: float,
    dv: float,
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """One RK4 step of length dt from time t in region ``reg``, the forcing (K0, F0) at t given
    and the rest evaluated: stationary (float ``fm``) or on a speed ramp (``fm`` a ramp record,
    ``kernels.phase``). The bracketing and regula falsi of ``kink_split`` step from one substep
    start many times and evaluate its forcing once."""
    K1, F1 = excitation_at(t + 0.5 * dt, kc, fm, fc)
    K2, F2 = excitation_at(t + dt, kc, fm, fc)
    return rk4_region_kf(reg, alpha, twomu, K0, F0, K1, F1, K2, F2, dt, x, v, dx, dv)


NEWTON_SUBSTEPS = 4
"""Newton iterations on the crossing time of a split step before the regula falsi takes over."""


@njit(**JIT_OPTIONS)
def _hermite_crossing(
    x: float, vr: float, x1: float, v1r: float, b: float, lo: float, hi: float
) -> float:  # pragma: no cover - compiled
    """The theta in [lo, hi] where the cubic Hermite interpolant of x over a substep (ends x,
    x1; slopes vr, v1r per unit theta) crosses b, bracketed by its samples at lo and hi:
    safeguarded Newton on the polynomial (no forcing evaluated)."""
    h_lo = _hermite(x, vr, x1, v1r, lo) - b
    h_hi = _hermite(x, vr, x1, v1r, hi) - b
    th = lo + (hi - lo) * h_lo / (h_lo - h_hi) if h_lo != h_hi else 0.5 * (lo + hi)
    for _ in range(8):
        f = _hermite(x, vr, x1, v1r, th) - b
        if (f > 0.0) == (h_lo > 0.0):
            lo, h_lo = th, f
        else:
            hi = th
        s2 = th * th
        d = (6 * s2 - 6 * th) * x + (3 * s2 - 4 * th + 1) * vr + (6 * th - 6 * s2) * x1
        d += (3 * s2 - 2 * th) * v1r
        nxt = th - f / d if d != 0.0 else 0.5 * (lo + hi)
        th = nxt if lo < nxt < hi else 0.5 * (lo + hi)
    return th


@njit(**JIT_OPTIONS)
def _hermite(x: float, vr: float, x1: float, v1r: float, s: float) -> float:  # pragma: no cover
    """The cubic Hermite interpolant at s in [0, 1] (ends x, x1; slopes vr, v1r per unit s)."""
    s2 = s * s
    s3 = s2 * s
    return (
        (2 * s3 - 3 * s2 + 1) * x
        + (s3 - 2 * s2 + s) * vr
        + (3 * s2 - 2 * s3) * x1
        + (s3 - s2) * v1r
    )


@njit(**JIT_OPTIONS)
def kink_step(
    reg: int,
    alpha: float,
    twomu: float,
    kc: np.ndarray,
    fm: float | np.ndarray,
    fc: np.ndarray,
    t: float,
    h: float,
    x: float,
    v: float,
    dx: float,
    dv: float,
) -> tuple[float, float, float, float, int]:  # pragma: no cover - compiled
    """Advance (x, v, dx, dv) from t by h, splitting at every switching time |x| = 1.

    Returns the new (x, v, dx, dv) and region; public because ``kernels.monodromy`` steps the
    two columns of the monodromy matrix with it."""
    K0, F0 = excitation_at(t, kc, fm, fc)
    x1, v1, dx1, dv1 = _rk4_region(reg, alpha, twomu, kc, fm, fc, K0, F0, t, h, x, v, dx, dv)
    return kink_split(reg, alpha, twomu, kc, fm, fc, t, K0, F0, h, x, v, dx, dv, x1, v1, dx1, dv1)


@njit(**JIT_OPTIONS)
def kink_split(
    reg: int,
    alpha: float,
    twomu: float,
    kc: np.ndarray,
    fm: float | np.ndarray,
    fc: np.ndarray,
    t: float,
    K0: float,
    F0: float,
    h: float,
    x: float,
    v: float,
    dx: float,
    dv: float,
    x1: float,
    v1: float,
    dx1: float,
    dv1: float,
) -> tuple[float, float, float, float, int]:  # pragma: no cover - compiled
    """``kink_step`` given its first attempt (x1, v1, dx1, dv1), the whole step h from t in
    region ``reg`` (from ``_rk4_region``, or ``rk4_region_kf`` with a forcing table), and the
    forcing (K0, F0) at t (``excitation_at``'s, or the table's, the same bits): the step is
    accepted if no sample of its Hermite interpolant leaves the region, else split at the
    crossing, the substeps evaluating the forcing at their times (a step near a kink that
    crosses none, the most of them, evaluates none)."""
    rem = h
    tc = t
    for it in range(16):
        if not rem > 0.0:
            return x, v, dx, dv, reg
        if it > 0:
            K0, F0 = excitation_at(tc, kc, fm, fc)  # the forcing at the substep's start
            x1, v1, dx1, dv1 = _rk4_region(
                reg, alpha, twomu, kc, fm, fc, K0, F0, tc, rem, x, v, dx, dv
            )
        # cubic Hermite interpolant of x over the substep, sampled at 8 points
        kfound = 0
        b = 0.0
        for k in range(1, 9):
            s = k / 8.0
            s2 = s * s
            s3 = s2 * s
            xh = (
                (2 * s3 - 3 * s2 + 1) * x
                + (s3 - 2 * s2 + s) * rem * v
                + (-2 * s3 + 3 * s2) * x1
                + (s3 - s2) * rem * v1
            )
            if region(xh) != reg:
                kfound = k
                b = float(reg) if reg != 0 else (1.0 if xh > 1.0 else -1.0)
                break
        if kfound == 0:
            return x1, v1, dx1, dv1, reg
        lo = (kfound - 1) / 8.0
        hi = kfound / 8.0
        # Newton on theta from the Hermite interpolant's crossing, the slope the velocity of
        # the RK4 substep to theta: one substep lands within ~1e-9 of the root, a second
        # confirms it (the bracketing regula falsi below took ~6.5)
        th = _hermite_crossing(x, rem * v, x1, rem * v1, b, lo, hi)
        crossed = False
        xth, vth, dxth, dvth = x, v, dx, dv
        for _n in range(NEWTON_SUBSTEPS):
            if not (th > 0.0 and th <= hi):
                break
            xth, vth, dxth, dvth = _rk4_region(
                reg, alpha, twomu, kc, fm, fc, K0, F0, tc, th * rem, x, v, dx, dv
            )
            slope = vth * rem
            if slope == 0.0:
                break
            step = (xth - b) / slope
            if abs(step) * rem < 1e-13 * h:
                crossed = True
                break
            th -= step
        if crossed:
            dt = th * rem
            v, dx, dv = vth, dxth, dvth
        else:  # a grazing excursion, or Newton left the bracket: bracket and regula falsi
            # g(theta) = side (x(theta) - b) > 0 inside the current region
            side = float(reg) if reg != 0 else -b
            xlo = x
            if lo > 0.0:
                xlo = _rk4_region(
                    reg, alpha, twomu, kc, fm, fc, K0, F0, tc, lo * rem, x, v, dx, dv
                )[0]
            # the state at hi is kept: the step to the crossing is the last bracket's hi
            xhi, vhi, dxhi, dvhi = _rk4_region(
                reg, alpha, twomu, kc, fm, fc, K0, F0, tc, hi * rem, x, v, dx, dv
            )
            kept = True
            glo = side * (xlo - b)
            ghi = side * (xhi - b)
            if not (glo > 0.0) or not (ghi < 0.0):
                if side * (x1 - b) < 0.0 and side * (x - b) > 0.0:
                    lo, hi, glo, ghi = 0.0, 1.0, side * (x - b), side * (x1 - b)
                    kept = False  # x1 came from the whole step's forcing: not hi's state
                else:  # grazing excursion not confirmed by RK4: accept the substep
                    return x1, v1, dx1, dv1, reg
            # Illinois regula falsi on theta in (lo, hi)
            last = 0
            for _it in range(60):
                th = (lo * ghi - hi * glo) / (ghi - glo)
                if not (th > lo and th < hi):
                    th = 0.5 * (lo + hi)
                xth, vth, dxth, dvth = _rk4_region(
                    reg, alpha, twomu, kc, fm, fc, K0, F0, tc, th * rem, x, v, dx, dv
                )
                gm = side * (xth - b)
                if gm > 0.0:
                    lo, glo = th, gm
                    if last == -1:
                        ghi *= 0.5
                    last = -1
                else:
                    hi, ghi = th, gm
                    vhi, dxhi, dvhi, kept = vth, dxth, dvth, True
                    if last == 1:
                        glo *= 0.5
                    last = 1
                if (hi - lo) * rem < 1e-13 * h or gm == 0.0:
                    break
            dt = hi * rem  # just across the boundary
            if kept:  # the step of length hi rem was taken above: the same numbers
                v, dx, dv = vhi, dxhi, dvhi
            else:
                v, dx, dv = _rk4_region(
                    reg, alpha, twomu, kc, fm, fc, K0, F0, tc, dt, x, v, dx, dv
                )[1:]
        x = b  # exactly on the switching point
        tc += dt
        rem -= dt
        # new region from the direction of motion
        reg = (1 if v > 0.0 else 0) if b > 0.0 else (-1 if v < 0.0 else 0)
    if rem > 0.0:  # more than 16 crossings in one step: finish without splitting
        K0, F0 = excitation_at(tc, kc, fm, fc)
        x, v, dx, dv = _rk4_region(reg, alpha, twomu, kc, fm, fc, K0, F0, tc, rem, x, v, dx, dv)
        reg = region(x)
    return x, v, dx, dv, reg


@njit(**JIT_OPTIONS)
def run_kink(
    alpha: float,
    mu: float,
    x0: float,
    v0: float,
    kc: np.ndarray,
    fm: float,
    fc: np.ndarray,
    T: float,
    N: int,
    n_trans: int,
    n_rec: int,
    stride: int,
    bound: float,
    use_table: bool = False,
):  # pragma: no cover - compiled
    """Kink-splitting RK4 of Eq. (9) with the piecewise law of Eq. (8); outputs as ``run_rk4``.

    With ``use_table`` (T-periodic forcing) the whole steps take K and F from the table of one
    period (``forcing_table``), as ``run_rk4`` does, and the substeps of a split step evaluate
    them at the time within the period (t - n T); otherwise everything is evaluated at absolute
    time. The mesh force needs K at the step end: the table's, or one ``stiffness_at`` per
    recorded step (the stiffness harmonics only). ``kernels.kinklanes`` runs the same steps in
    lock-step lanes, bit for bit."""
    h = T / N
    twomu = 2.0 * mu
    if use_table:
        Kt, Ft = forcing_table(T, N, kc, fm, fc)
    else:
        Kt = np.empty(0)
        Ft = np.empty(0)
    xs = np.zeros(n_rec)
    vs = np.zeros(n_rec)
    logs = np.zeros(n_rec)
    hx = np.zeros(n_rec * N // stride)
    hv = np.zeros(n_rec * N // stride)
    x, v, dx, dv = x0, v0, SQRT1_2, SQRT1_2
    reg = region(x)
    xmin, xmax = np.inf, -np.inf
    fmin, fmax = np.inf, -np.inf
    done = 0
    count = 0
    ih = 0
    # The per-period bookkeeping below repeats run_rk4's on purpose: factoring it into
    # inline="always" helpers returning tuples made run_rk4 45 % slower (26 vs 18 ns per step).
    for n in range(n_trans + n_rec):
        rec = n >= n_trans
        for j in range(N):
            if use_table:
                K0, F0, K1, F1 = Kt[2 * j], Ft[2 * j], Kt[2 * j + 1], Ft[2 * j + 1]
                K2, F2 = Kt[2 * j + 2], Ft[2 * j + 2]
                x1, v1, dx1, dv1 = rk4_region_kf(
                    reg, alpha, twomu, K0, F0, K1, F1, K2, F2, h, x, v, dx, dv
                )
                x, v, dx, dv, reg = kink_split(
                    reg, alpha, twomu, kc, fm, fc, j * h, K0, F0, h, x, v, dx, dv, x1, v1,
                    dx1, dv1,
                )  # fmt: skip
            else:
                x, v, dx, dv, reg = kink_step(
                    reg, alpha, twomu, kc, fm, fc, n * T + j * h, h, x, v, dx, dv
                )
                K2 = stiffness_at(n * T + (j + 1) * h, kc) if rec else 1.0
            xmin = min(xmin, x)
            xmax = max(xmax, x)
            if rec:  # mesh force K(t) f_h(x) + 2 mu x' at the step end
                force = K2 * region_force(reg, alpha, x)[0]
                force += twomu * v
                fmin = min(fmin, force)
                fmax = max(fmax, force)
            count += 1
            if count == stride:
                count = 0
                hx[ih] = x
                hv[ih] = v
                ih = ih + 1 if rec else 0
        nrm = math.sqrt(dx * dx + dv * dv)
        dx /= nrm
        dv /= nrm
        if not (abs(x) < bound and abs(v) < bound):
            break
        if rec:
            k = n - n_trans
            logs[k] = math.log(nrm)
            xs[k] = x
            vs[k] = v
        elif n + 1 == n_trans:
            xmin, xmax, count, ih = np.inf, -np.inf, 0, 0
        done = n + 1
    return xs, vs, logs, hx, hv, xmin, xmax, done, x, v, fmin, fmax
