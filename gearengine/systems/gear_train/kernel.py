"""Fixed-step RK4 of the dimensionless train with its tangent equation (numba).

In relative coordinates u (n of them, ``model.Dimensionless``) with A^-1 applied once:

    u'' = f + p T(tau) - AK u - AC v - g W,      v = u'
    W = K(tau) f_h(delta) + 2 mu delta',          delta = w . u - e(tau),  delta' = w . v - e'(tau)
    du'' = -AK du - AC dv - g (K(tau) f_h'(delta) w . du + 2 mu w . dv)       (tangent equation)

AK = A^-1 K~, AC = A^-1 C~, g = A^-1 w~, f = A^-1 f~, p = A^-1 p~ (docs/gear-trains.md).
K(tau) = 1 + sum kc0 cos(kc1 tau + kc2) as the pair's kernels (``systems.spur_pair.forcing``);
e(tau) = sum ec0 cos(ec1 tau + ec2) the transmission error in units of b, and
T(tau) = sum tc0 cos(tc1 tau + tc2) the torque fluctuation T_p / (r_p b k_m).

The backlash law is the pair's ``law_force`` (``systems.spur_pair.kernels.smooth``: cubic, or Eq. 8
stepped straight across its kinks). Benettin: the 2n-dimensional tangent vector starts with
equal components and is renormalised every interval T; the log of its norm is recorded.
``flow_train``: the flow over m intervals T with its 2n x 2n Jacobian (the monodromy matrix for
Floquet multipliers), the same RK4 arithmetic with the variational equation of every column.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from gearengine.jitcache import drop_stale
from gearengine.systems.spur_pair.kernels import smooth
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, law_force

_HERE = Path(__file__).parent
drop_stale("kernel", [Path(__file__), Path(smooth.__file__)], _HERE / "__pycache__")
"""Before any kernel runs: numba watches only this file, and ``law_force`` lives in smooth."""


@njit(**JIT_OPTIONS)
def forcing_at_phase(
    psi: float, omega: float, kc: np.ndarray, ec: np.ndarray, tc: np.ndarray
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """K, e, e' and T at driver phase psi turning at the rate omega = dpsi/dtau (orders q in
    row 1 of each table): K = 1 + sum kc0 cos(q psi + kc2), e = sum ec0 cos(q psi + ec2),
    e' = -sum ec0 q omega sin(q psi + ec2), T = sum tc0 cos(q psi + tc2)."""
    K = 1.0
    for i in range(kc.shape[1]):
        K += kc[0, i] * math.cos(kc[1, i] * psi + kc[2, i])
    e = 0.0
    ed = 0.0
    for i in range(ec.shape[1]):
        arg = ec[1, i] * psi + ec[2, i]
        e += ec[0, i] * math.cos(arg)
        ed -= ec[0, i] * ec[1, i] * omega * math.sin(arg)
    T = 0.0
    for i in range(tc.shape[1]):
        T += tc[0, i] * math.cos(tc[1, i] * psi + tc[2, i])
    return K, e, ed, T


@njit(**JIT_OPTIONS)
def train_forcing(
    t: float, kc: np.ndarray, ec: np.ndarray, tc: np.ndarray
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """K(t), e(t), e'(t) and T(t) at dimensionless time t (module docstring): the phase is t
    at unit rate (times 1.0 is exact: the same bits as the sum written out)."""
    return forcing_at_phase(t, 1.0, kc, ec, tc)


@njit(**JIT_OPTIONS)
def forcing_table(
    kc: np.ndarray, ec: np.ndarray, tc: np.ndarray, T: float, N: int
) -> np.ndarray:  # pragma: no cover - compiled
    """(K, e, e', T) at the 2N + 1 stage times s h / 2 of a period T, h = T / N: the table of
    ``run_train``, ``flow_train`` and the lanes."""
    h2 = 0.5 * (T / N)
    table = np.empty((2 * N + 1, 4))
    for q in range(2 * N + 1):
        table[q, 0], table[q, 1], table[q, 2], table[q, 3] = train_forcing(q * h2, kc, ec, tc)
    return table


@njit(**JIT_OPTIONS)
def _field(
    law: int,
    a: float,
    c: float,
    alpha: float,
    twomu: float,
    AK: np.ndarray,
    AC: np.ndarray,
    g: np.ndarray,
    w: np.ndarray,
    f: np.ndarray,
    p: np.ndarray,
    K: float,
    e: float,
    ed: float,
    T: float,
    q: int,
    s: np.ndarray,
    k: np.ndarray,
    stage: int,
) -> None:  # pragma: no cover - compiled
    """The train's field and its tangent at the state s = (u, v, du, dv), shape (4, n), into
    k[stage], with the mean force f[q] of the stage time q (indices, not row views: a view
    costs reference counting every call)."""  # fmt: skip
    n = s.shape[1]
    delta = -e
    deltad = -ed
    wdu = 0.0
    wdv = 0.0
    for i in range(n):
        delta += w[i] * s[0, i]
        deltad += w[i] * s[1, i]
        wdu += w[i] * s[2, i]
        wdv += w[i] * s[3, i]
    fh, dfh = law_force(law, a, c, alpha, delta)
    W = K * fh + twomu * deltad
    dW = K * dfh * wdu + twomu * wdv
    for i in range(n):
        acc = f[q, i] + p[i] * T - g[i] * W
        dacc = -g[i] * dW
        for j in range(n):
            acc -= AK[i, j] * s[0, j] + AC[i, j] * s[1, j]
            dacc -= AK[i, j] * s[2, j] + AC[i, j] * s[3, j]
        k[stage, 0, i] = s[1, i]
        k[stage, 1, i] = acc
        k[stage, 2, i] = s[3, i]
        k[stage, 3, i] = dacc


@njit(**JIT_OPTIONS)
def train_step(
    law: int,
    a: float,
    c: float,
    alpha: float,
    twomu: float,
    AK: np.ndarray,
    AC: np.ndarray,
    g: np.ndarray,
    w: np.ndarray,
    f: np.ndarray,
    p: np.ndarray,
    forcing: np.ndarray,
    y: np.ndarray,
    k: np.ndarray,
    s: np.ndarray,
    h: float,
) -> None:  # pragma: no cover - compiled
    """One classical RK4 step h of the train and its tangent, y = (u, v, du, dv) of shape
    (4, n) in place. ``forcing`` rows (K, e, e', T) and ``f`` rows (the mean force, (n,)) at
    the stage times tau, tau + h/2, tau + h, shapes (3, 4) and (3, n); k (4, 4, n) and s
    (4, n) are scratch. The one step of ``run_train`` and of the run-up's ``ramp.run_ramp``."""
    n = y.shape[1]
    h2 = 0.5 * h
    h6 = h / 6.0
    for stage in range(4):
        step = 0.0 if stage == 0 else (h if stage == 3 else h2)
        for r in range(4):
            for i in range(n):
                s[r, i] = y[r, i] + step * k[stage - 1, r, i] if stage else y[r, i]
        q = 0 if stage == 0 else (2 if stage == 3 else 1)
        _field(
            law, a, c, alpha, twomu, AK, AC, g, w, f, p,
            forcing[q, 0], forcing[q, 1], forcing[q, 2], forcing[q, 3], q, s, k, stage,
        )  # fmt: skip
    for r in range(4):
        for i in range(n):
            y[r, i] += h6 * (k[0, r, i] + 2.0 * (k[1, r, i] + k[2, r, i]) + k[3, r, i])


@njit(**JIT_OPTIONS)
def renormalised(y: np.ndarray) -> tuple[float, float]:  # pragma: no cover - compiled
    """Benettin's renormalisation at the end of an interval of the state y = (u, v, du, dv),
    shape (4, n): the tangent (du, dv) divided by its norm in place; (that norm, the largest
    |u_i|, |v_i|) for the log of its growth and the divergence test."""
    n = y.shape[1]
    nrm = 0.0
    big = 0.0
    for i in range(n):
        nrm += y[2, i] * y[2, i] + y[3, i] * y[3, i]
        big = max(big, abs(y[0, i]), abs(y[1, i]))
    nrm = math.sqrt(nrm)
    for i in range(n):
        y[2, i] /= nrm
        y[3, i] /= nrm
    return nrm, big


@njit(**JIT_OPTIONS)
def run_train(
    law: int,
    a: float,
    c: float,
    alpha: float,
    mu: float,
    AK: np.ndarray,
    AC: np.ndarray,
    g: np.ndarray,
    w: np.ndarray,
    f: np.ndarray,
    p: np.ndarray,
    kc: np.ndarray,
    ec: np.ndarray,
    tc: np.ndarray,
    u0: np.ndarray,
    v0: np.ndarray,
    use_table: bool,
    T: float,
    N: int,
    n_trans: int,
    n_rec: int,
    stride: int,
    bound: float,
):  # pragma: no cover - compiled
    """Classical RK4 of the train + tangent over n_trans + n_rec intervals T of N steps.

    Args:
        law, a, c, alpha: backlash law (0 cubic, 1 piecewise Eq. 8); mu: mesh damping mu~.
        AK, AC (n, n), g, w, f, p (n,): the train (module docstring).
        kc, ec, tc: forcing terms, shape (3, terms): amplitude, omega, phase.
        u0, v0: initial state (n,) at tau = 0.
        use_table: the forcing is T-periodic: tabulate it at the 2N+1 stage times of a period.
        T, N: sampling interval and steps per interval; n_trans, n_rec: intervals.
        stride: record delta, delta' every ``stride`` recorded steps.
        bound: divergence bound on every |u_i|, |v_i|.

    Returns:
        xs, vs: delta, delta' at the end of each recorded interval, shape (n_rec,);
        logs: log of the tangent norm before each renormalisation, (n_rec,);
        hx, hv: delta, delta' every ``stride`` recorded steps, (n_rec N // stride,);
        xmin, xmax: extremes of delta over the recorded steps; done: intervals completed;
        u, v: final state; fmin, fmax: extremes of the mesh force W at the recorded step ends;
        full: the state (u, v) at the end of each recorded interval, shape (n_rec, 2n).
    """  # fmt: skip
    n = u0.size
    h = T / N
    h2 = 0.5 * h
    twomu = 2.0 * mu
    means = np.empty((3, n))  # the mean force at the three stage times: constant here
    for q in range(3):
        means[q] = f
    table = forcing_table(kc, ec, tc, T, N) if use_table else np.empty((0, 4))
    y = np.empty((4, n))  # u, v, du, dv
    start = 1.0 / math.sqrt(2.0 * n)
    for i in range(n):
        y[0, i], y[1, i], y[2, i], y[3, i] = u0[i], v0[i], start, start
    k = np.empty((4, 4, n))  # stage, (u, v, du, dv), component
    s = np.empty((4, n))
    xs = np.zeros(n_rec)
    vs = np.zeros(n_rec)
    full = np.zeros((n_rec, 2 * n))
    logs = np.zeros(n_rec)
    hx = np.zeros(n_rec * N // stride)
    hv = np.zeros(n_rec * N // stride)
    xmin, xmax = np.inf, -np.inf
    fmin, fmax = np.inf, -np.inf
    forcing = np.empty((3, 4))
    done = 0
    count = 0
    ih = 0
    delta = 0.0
    deltad = 0.0
    for it in range(n_trans + n_rec):
        rec = it >= n_trans
        tn = it * T
        for j in range(N):
            for q in range(3):
                if use_table:
                    for r in range(4):
                        forcing[q, r] = table[2 * j + q, r]
                else:
                    forcing[q, 0], forcing[q, 1], forcing[q, 2], forcing[q, 3] = train_forcing(
                        tn + j * h + q * h2, kc, ec, tc
                    )
            train_step(law, a, c, alpha, twomu, AK, AC, g, w, means, p, forcing, y, k, s, h)
            delta = -forcing[2, 1]
            deltad = -forcing[2, 2]
            for i in range(n):
                delta += w[i] * y[0, i]
                deltad += w[i] * y[1, i]
            xmin = min(xmin, delta)
            xmax = max(xmax, delta)
            force = forcing[2, 0] * law_force(law, a, c, alpha, delta)[0] + twomu * deltad
            fmin = min(fmin, force)
            fmax = max(fmax, force)
            count += 1
            if count == stride:
                count = 0
                hx[ih] = delta
                hv[ih] = deltad
                ih = ih + 1 if rec else 0
        nrm, big = renormalised(y)
        if not big < bound:
            break
        if rec:
            r = it - n_trans
            logs[r] = math.log(nrm)
            xs[r] = delta
            vs[r] = deltad
            for i in range(n):
                full[r, i] = y[0, i]
                full[r, n + i] = y[1, i]
        elif it + 1 == n_trans:
            xmin, xmax, count, ih = np.inf, -np.inf, 0, 0
            fmin, fmax = np.inf, -np.inf
        done = it + 1
    return xs, vs, logs, hx, hv, xmin, xmax, done, y[0].copy(), y[1].copy(), fmin, fmax, full


@njit(**JIT_OPTIONS)
def _flow_field(
    law: int,
    a: float,
    c: float,
    alpha: float,
    twomu: float,
    AK: np.ndarray,
    AC: np.ndarray,
    g: np.ndarray,
    w: np.ndarray,
    f: np.ndarray,
    p: np.ndarray,
    K: float,
    e: float,
    ed: float,
    T: float,
    s: np.ndarray,
    D: np.ndarray,
    k: np.ndarray,
    kD: np.ndarray,
    stage: int,
) -> None:  # pragma: no cover - compiled
    """The field at s = (u, v), shape (2, n), and the variational field of every column of
    D = (du, dv), shape (2, n, 2n), into k[stage] and kD[stage] (module docstring)."""
    n = s.shape[1]
    delta = -e
    deltad = -ed
    for i in range(n):
        delta += w[i] * s[0, i]
        deltad += w[i] * s[1, i]
    fh, dfh = law_force(law, a, c, alpha, delta)
    W = K * fh + twomu * deltad
    for i in range(n):
        acc = f[i] + p[i] * T - g[i] * W
        for j in range(n):
            acc -= AK[i, j] * s[0, j] + AC[i, j] * s[1, j]
        k[stage, 0, i] = s[1, i]
        k[stage, 1, i] = acc
    for col in range(D.shape[2]):
        wdu = 0.0
        wdv = 0.0
        for i in range(n):
            wdu += w[i] * D[0, i, col]
            wdv += w[i] * D[1, i, col]
        dW = K * dfh * wdu + twomu * wdv
        for i in range(n):
            dacc = -g[i] * dW
            for j in range(n):
                dacc -= AK[i, j] * D[0, j, col] + AC[i, j] * D[1, j, col]
            kD[stage, 0, i, col] = D[1, i, col]
            kD[stage, 1, i, col] = dacc


@njit(**JIT_OPTIONS)
def flow_train(
    law: int,
    a: float,
    c: float,
    alpha: float,
    mu: float,
    AK: np.ndarray,
    AC: np.ndarray,
    g: np.ndarray,
    w: np.ndarray,
    f: np.ndarray,
    p: np.ndarray,
    kc: np.ndarray,
    ec: np.ndarray,
    tc: np.ndarray,
    u0: np.ndarray,
    v0: np.ndarray,
    T: float,
    N: int,
    m: int,
):  # pragma: no cover - compiled
    """The flow of the train over m intervals T of N RK4 steps (T-periodic forcing, tabulated
    at the 2N+1 stage times of a period as ``run_train`` does, so the strobes are the same
    arithmetic) and its Jacobian, the monodromy matrix for Floquet multipliers.

    Returns:
        u, v: the state after m T, shape (n,) each; Phi: d(u, v)(m T) / d(u0, v0), (2n, 2n).
    """  # fmt: skip
    n = u0.size
    M = 2 * n
    h = T / N
    h2 = 0.5 * h
    h6 = h / 6.0
    twomu = 2.0 * mu
    table = forcing_table(kc, ec, tc, T, N)
    y = np.empty((2, n))
    D = np.zeros((2, n, M))
    for i in range(n):
        y[0, i], y[1, i] = u0[i], v0[i]
        D[0, i, i] = 1.0
        D[1, i, n + i] = 1.0
    k = np.empty((4, 2, n))
    kD = np.empty((4, 2, n, M))
    s = np.empty((2, n))
    sD = np.empty((2, n, M))
    for _ in range(m):
        for j in range(N):
            for stage in range(4):
                step = 0.0 if stage == 0 else (h if stage == 3 else h2)
                for r in range(2):
                    for i in range(n):
                        s[r, i] = y[r, i] + step * k[stage - 1, r, i] if stage else y[r, i]
                        for col in range(M):
                            sD[r, i, col] = (
                                D[r, i, col] + step * kD[stage - 1, r, i, col]
                                if stage
                                else D[r, i, col]
                            )
                q = 2 * j + (0 if stage == 0 else (2 if stage == 3 else 1))
                _flow_field(
                    law, a, c, alpha, twomu, AK, AC, g, w, f, p,
                    table[q, 0], table[q, 1], table[q, 2], table[q, 3], s, sD, k, kD, stage,
                )  # fmt: skip
            for r in range(2):
                for i in range(n):
                    y[r, i] += h6 * (k[0, r, i] + 2.0 * (k[1, r, i] + k[2, r, i]) + k[3, r, i])
                    for col in range(M):
                        D[r, i, col] += h6 * (
                            kD[0, r, i, col]
                            + 2.0 * (kD[1, r, i, col] + kD[2, r, i, col])
                            + kD[3, r, i, col]
                        )
    phi = np.empty((M, M))
    for i in range(n):
        for col in range(M):
            phi[i, col] = D[0, i, col]
            phi[n + i, col] = D[1, i, col]
    return y[0].copy(), y[1].copy(), phi
