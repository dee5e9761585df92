"""Shared pieces of the kernels and the smooth RK4 kernel ``run_rk4`` (see the package doc)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

SQRT1_2 = 0.7071067811865476
"""Initial tangent components (1/sqrt 2, 1/sqrt 2), as in gear_ref.c."""

JIT_OPTIONS = {"cache": True, "nogil": True, "error_model": "numpy", "boundscheck": False}


@njit(**JIT_OPTIONS)
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


@njit(**JIT_OPTIONS)
def stiffness_at(t: float, kc: np.ndarray) -> float:  # pragma: no cover - compiled
    """K(t) of Eq. (9) alone at absolute time t (the mesh force's stiffness factor)."""
    K = 1.0
    for i in range(kc.shape[1]):
        K += kc[0, i] * math.cos(kc[1, i] * t + kc[2, i])
    return K


@njit(**JIT_OPTIONS)
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


@njit(**JIT_OPTIONS)
def region(x: float) -> int:  # pragma: no cover - compiled
    """Region of Eq. (8): 1 for x > 1, -1 for x < -1, 0 inside the clearance."""
    return 1 if x > 1.0 else (-1 if x < -1.0 else 0)


@njit(**JIT_OPTIONS)
def region_force(reg: int, alpha: float, x: float) -> tuple[float, float]:  # pragma: no cover
    """f_h(x) and f_h'(x) of Eq. (8) with the linear law of region ``reg`` (extended beyond
    its boundary, as the kink-splitting steps need): the one definition of the piecewise law."""
    if reg > 0:
        return x - (1.0 - alpha), 1.0
    if reg < 0:
        return x + (1.0 - alpha), 1.0
    return alpha * x, alpha


@njit(**JIT_OPTIONS)
def law_force(
    law: int, a: float, c: float, alpha: float, x: float
) -> tuple[float, float]:  # pragma: no cover - compiled
    """f_h(x) and f_h'(x): cubic -a x + c x^3 (law 0) or Eq. (8) (law 1); codes from
    ``gearengine.systems.spur_pair.laws.LAWS``."""
    if law == 0:
        x2 = x * x
        return x * (c * x2 - a), 3.0 * c * x2 - a
    return region_force(region(x), alpha, x)


@njit(**JIT_OPTIONS)
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


@njit(**JIT_OPTIONS)
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

    One long loop on purpose: the stages, the strobes and the Benettin renormalisation stay in
    one compiled body; splitting the per-period bookkeeping into helpers returning tuples cost
    45 % (26 vs 18 ns per step, measured).

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
        x, v: final state;
        fmin, fmax: extremes of the dimensionless mesh force K(t) f_h(x) + 2 mu x' at the
            recorded step ends (a few flops per step).
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
    fmin, fmax = np.inf, -np.inf
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
            force = K2 * law_force(law, a, c, alpha, x)[0] + twomu * v  # mesh force
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
            fmin, fmax = np.inf, -np.inf
        done = n + 1
    return xs, vs, logs, hx, hv, xmin, xmax, done, x, v, fmin, fmax
