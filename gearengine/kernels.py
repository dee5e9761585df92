"""Numba kernels: fixed-step RK4 of Eq. (9) with its tangent equation.

    x' = v,    v' = -2 mu v - K(t) f_h(x) + F(t)                       (Eq. 9)
    dx' = dv,  dv' = -2 mu dv - K(t) f_h'(x) dx                        (tangent equation)

Three kernels share one output layout (see ``run_rk4``):

* ``run_rk4``: classical RK4 with N steps per sampling interval T0, forcing either tabulated once
  at the 2N+1 stage times of a period (commensurate forcing) or evaluated at absolute time
  t = n T0 + j h (no drift). Cubic law, or the piecewise law of Eq. (8) stepped straight across
  the kinks (first-order accurate there; kept for comparison with ``run_kink``).
* ``run_kink``: piecewise law of Eq. (8) with every RK4 step split at the switching times
  |x| = 1 (port of ``gear_ref.c --kink``, general alpha): a crossing is detected from a cubic
  Hermite interpolant of x over the substep, located by Illinois regula falsi on RK4 substeps to
  ~1e-13 h, and integration restarts there with the new region's field. The field is continuous
  across |x| = 1, so the tangent vector needs no saltation jump. Forcing at absolute time.
* ``run_batch``: cubic law only; many parameter points ("lanes") in lock-step, struct of arrays,
  inner loops over ``LANES`` lanes so LLVM vectorises, ``prange`` over chunks of lanes. Same
  arithmetic as ``run_rk4`` with a forcing table.

Benettin: the tangent vector starts at (1, 1)/sqrt(2) and is renormalised at the end of every
interval T0; the log of its norm is recorded over the n_rec recorded intervals. A run stops early
(diverged) when |x| or |v| is not below ``bound`` at an interval end (this also catches NaN).

Forcing coefficients are packed as kc, fc of shape (3, n_terms): rows amplitude, omega, phase
(see ``gearengine.forcing``); K(t) = 1 + sum kc0 cos(kc1 t + kc2), F(t) = fm + sum fc0 cos(...).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

SQRT1_2 = 0.7071067811865476
"""Initial tangent components (1/sqrt 2, 1/sqrt 2), as in gear_ref.c."""
LANES = 16
"""Lanes advanced together in ``run_batch``."""

_JIT = {"cache": True, "nogil": True, "error_model": "numpy", "boundscheck": False}


@njit(**_JIT)
def forcing_at(
    t: float, kc: np.ndarray, fm: float, fc: np.ndarray
) -> tuple[float, float]:  # pragma: no cover - compiled
    """K(t) and F(t) of Eq. (9) at absolute time t."""
    K = 1.0
    for i in range(kc.shape[1]):
        K += kc[0, i] * math.cos(kc[1, i] * t + kc[2, i])
    F = fm
    for i in range(fc.shape[1]):
        F += fc[0, i] * math.cos(fc[1, i] * t + fc[2, i])
    return K, F


@njit(**_JIT)
def forcing_table(
    T: float, N: int, kc: np.ndarray, fm: float, fc: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """K and F at the 2N+1 RK4 stage times s h/2, s = 0..2N, of one period T (shapes (2N+1,))."""
    h2 = 0.5 * (T / N)
    Kt = np.empty(2 * N + 1)
    Ft = np.empty(2 * N + 1)
    for s in range(2 * N + 1):
        Kt[s], Ft[s] = forcing_at(s * h2, kc, fm, fc)
    return Kt, Ft


@njit(**_JIT)
def law_force(
    law: int, a: float, c: float, alpha: float, x: float
) -> tuple[float, float]:  # pragma: no cover - compiled
    """f_h(x) and f_h'(x): cubic -a x + c x^3 (law 0) or Eq. (8) (law 1)."""
    if law == 0:
        x2 = x * x
        return x * (c * x2 - a), 3.0 * c * x2 - a
    if x > 1.0:
        return x - (1.0 - alpha), 1.0
    if x < -1.0:
        return x + (1.0 - alpha), 1.0
    return alpha * x, alpha


@njit(**_JIT)
def _rhs(
    law: int,
    a: float,
    c: float,
    alpha: float,
    twomu: float,
    K: float,
    F: float,
    x: float,
    v: float,
    dx: float,
    dv: float,
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """Right-hand side of Eq. (9) and its tangent equation."""
    fh, dfh = law_force(law, a, c, alpha, x)
    return v, -twomu * v - K * fh + F, dv, -twomu * dv - K * dfh * dx


@njit(**_JIT)
def run_rk4(
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
    use_table: bool,
    T: float,
    N: int,
    n_trans: int,
    n_rec: int,
    stride: int,
    bound: float,
):  # pragma: no cover - compiled
    """Classical RK4 of Eq. (9) + tangent over n_trans + n_rec intervals T of N steps.

    Args:
        law, a, c, alpha: backlash law (0 cubic -a x + c x^3, 1 piecewise Eq. 8 with slope alpha).
        mu: damping ratio; x0, v0: initial state at t = 0.
        kc, fm, fc: forcing coefficients (module docstring).
        use_table: tabulate the forcing once per period (requires T-periodic forcing); otherwise
            evaluate it at absolute time.
        T: sampling interval T0; N: steps per T0; n_trans, n_rec: intervals (transient, recorded).
        stride: record (x, v) every ``stride`` steps of the recorded part.
        bound: divergence bound on |x| and |v|.

    Returns:
        xs, vs: strobes at the end of each recorded interval, shape (n_rec,);
        logs: log of the tangent norm before each renormalisation, shape (n_rec,);
        hx, hv: (x, v) after recorded steps stride, 2 stride, ..., shape (n_rec N // stride,);
        xmin, xmax: extremes of x over every recorded step;
        done: intervals completed (< n_trans + n_rec when diverged);
        x, v: final state.
    """
    h = T / N
    h2 = 0.5 * h
    h6 = h / 6.0
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
    xmin, xmax = np.inf, -np.inf
    done = 0
    count = 0
    ih = 0
    for n in range(n_trans + n_rec):
        rec = n >= n_trans
        tn = n * T
        for j in range(N):
            if use_table:
                K0, F0 = Kt[2 * j], Ft[2 * j]
                K1, F1 = Kt[2 * j + 1], Ft[2 * j + 1]
                K2, F2 = Kt[2 * j + 2], Ft[2 * j + 2]
            else:
                t0 = tn + j * h
                K0, F0 = forcing_at(t0, kc, fm, fc)
                K1, F1 = forcing_at(t0 + h2, kc, fm, fc)
                K2, F2 = forcing_at(t0 + h, kc, fm, fc)
            a1, b1, c1, d1 = _rhs(law, a, c, alpha, twomu, K0, F0, x, v, dx, dv)
            a2, b2, c2, d2 = _rhs(
                law,
                a,
                c,
                alpha,
                twomu,
                K1,
                F1,
                x + h2 * a1,
                v + h2 * b1,
                dx + h2 * c1,
                dv + h2 * d1,
            )
            a3, b3, c3, d3 = _rhs(
                law,
                a,
                c,
                alpha,
                twomu,
                K1,
                F1,
                x + h2 * a2,
                v + h2 * b2,
                dx + h2 * c2,
                dv + h2 * d2,
            )
            a4, b4, c4, d4 = _rhs(
                law, a, c, alpha, twomu, K2, F2, x + h * a3, v + h * b3, dx + h * c3, dv + h * d3
            )
            x += h6 * (a1 + 2.0 * (a2 + a3) + a4)
            v += h6 * (b1 + 2.0 * (b2 + b3) + b4)
            dx += h6 * (c1 + 2.0 * (c2 + c3) + c4)
            dv += h6 * (d1 + 2.0 * (d2 + d3) + d4)
            xmin = min(xmin, x)
            xmax = max(xmax, x)
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
    return xs, vs, logs, hx, hv, xmin, xmax, done, x, v


# --- kink-aware RK4 for the piecewise law (port of gear_ref.c --kink, general alpha) --------


@njit(**_JIT)
def _region(x: float) -> int:  # pragma: no cover - compiled
    """Region of Eq. (8): 1 for x > 1, -1 for x < -1, 0 inside the clearance."""
    return 1 if x > 1.0 else (-1 if x < -1.0 else 0)


@njit(**_JIT)
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
    if reg > 0:
        fh, dfh = x - (1.0 - alpha), 1.0
    elif reg < 0:
        fh, dfh = x + (1.0 - alpha), 1.0
    else:
        fh, dfh = alpha * x, alpha
    return v, -twomu * v - K * fh + F, dv, -twomu * dv - K * dfh * dx


@njit(**_JIT)
def _rk4_region(
    reg: int,
    alpha: float,
    twomu: float,
    kc: np.ndarray,
    fm: float,
    fc: np.ndarray,
    t: float,
    dt: float,
    x: float,
    v: float,
    dx: float,
    dv: float,
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """One RK4 step of length dt from time t in region ``reg``, forcing at absolute time."""
    K0, F0 = forcing_at(t, kc, fm, fc)
    K1, F1 = forcing_at(t + 0.5 * dt, kc, fm, fc)
    K2, F2 = forcing_at(t + dt, kc, fm, fc)
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


@njit(**_JIT)
def _kink_step(
    reg: int,
    alpha: float,
    twomu: float,
    kc: np.ndarray,
    fm: float,
    fc: np.ndarray,
    t: float,
    h: float,
    x: float,
    v: float,
    dx: float,
    dv: float,
) -> tuple[float, float, float, float, int]:  # pragma: no cover - compiled
    """Advance (x, v, dx, dv) from t by h, splitting at every switching time |x| = 1."""
    rem = h
    tc = t
    for _ in range(16):
        if not rem > 0.0:
            return x, v, dx, dv, reg
        x1, v1, dx1, dv1 = _rk4_region(reg, alpha, twomu, kc, fm, fc, tc, rem, x, v, dx, dv)
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
            if _region(xh) != reg:
                kfound = k
                b = float(reg) if reg != 0 else (1.0 if xh > 1.0 else -1.0)
                break
        if kfound == 0:
            return x1, v1, dx1, dv1, reg
        # g(theta) = side (x(theta) - b) > 0 inside the current region
        side = float(reg) if reg != 0 else -b
        lo = (kfound - 1) / 8.0
        hi = kfound / 8.0
        xlo = x
        if lo > 0.0:
            xlo = _rk4_region(reg, alpha, twomu, kc, fm, fc, tc, lo * rem, x, v, dx, dv)[0]
        xhi = _rk4_region(reg, alpha, twomu, kc, fm, fc, tc, hi * rem, x, v, dx, dv)[0]
        glo = side * (xlo - b)
        ghi = side * (xhi - b)
        if not (glo > 0.0) or not (ghi < 0.0):
            if side * (x1 - b) < 0.0 and side * (x - b) > 0.0:
                lo, hi, glo, ghi = 0.0, 1.0, side * (x - b), side * (x1 - b)
            else:  # grazing excursion not confirmed by RK4: accept the substep
                return x1, v1, dx1, dv1, reg
        # Illinois regula falsi on theta in (lo, hi)
        last = 0
        for _it in range(60):
            th = (lo * ghi - hi * glo) / (ghi - glo)
            if not (th > lo and th < hi):
                th = 0.5 * (lo + hi)
            gm = side * (
                _rk4_region(reg, alpha, twomu, kc, fm, fc, tc, th * rem, x, v, dx, dv)[0] - b
            )
            if gm > 0.0:
                lo, glo = th, gm
                if last == -1:
                    ghi *= 0.5
                last = -1
            else:
                hi, ghi = th, gm
                if last == 1:
                    glo *= 0.5
                last = 1
            if (hi - lo) * rem < 1e-13 * h or gm == 0.0:
                break
        dt = hi * rem  # just across the boundary
        x, v, dx, dv = _rk4_region(reg, alpha, twomu, kc, fm, fc, tc, dt, x, v, dx, dv)
        x = b  # exactly on the switching point
        tc += dt
        rem -= dt
        # new region from the direction of motion
        reg = (1 if v > 0.0 else 0) if b > 0.0 else (-1 if v < 0.0 else 0)
    if rem > 0.0:  # more than 16 crossings in one step: finish without splitting
        x, v, dx, dv = _rk4_region(reg, alpha, twomu, kc, fm, fc, tc, rem, x, v, dx, dv)
        reg = _region(x)
    return x, v, dx, dv, reg


@njit(**_JIT)
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
):  # pragma: no cover - compiled
    """Kink-splitting RK4 of Eq. (9) with the piecewise law of Eq. (8); outputs as ``run_rk4``."""
    h = T / N
    twomu = 2.0 * mu
    xs = np.zeros(n_rec)
    vs = np.zeros(n_rec)
    logs = np.zeros(n_rec)
    hx = np.zeros(n_rec * N // stride)
    hv = np.zeros(n_rec * N // stride)
    x, v, dx, dv = x0, v0, SQRT1_2, SQRT1_2
    reg = _region(x)
    xmin, xmax = np.inf, -np.inf
    done = 0
    count = 0
    ih = 0
    # The per-period bookkeeping below repeats run_rk4's on purpose: factoring it into
    # inline="always" helpers returning tuples made run_rk4 45 % slower (26 vs 18 ns per step).
    for n in range(n_trans + n_rec):
        rec = n >= n_trans
        for j in range(N):
            x, v, dx, dv, reg = _kink_step(
                reg, alpha, twomu, kc, fm, fc, n * T + j * h, h, x, v, dx, dv
            )
            xmin = min(xmin, x)
            xmax = max(xmax, x)
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
    return xs, vs, logs, hx, hv, xmin, xmax, done, x, v


# --- lock-step batch over parameter points (cubic law) ------------------------------------


@njit(**_JIT, parallel=True)
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
    identical to the single kernel. Chunks of ``LANES`` points run in parallel (prange); inside a
    chunk the loop over lanes is vectorised (SIMD over points). The last chunk is padded with
    copies of the last point.

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
