"""Compiled inner loops of the Melnikov thresholds (numba, ``cache=True``).

The same arithmetic as ``coefficients`` (corrected Eq. 19) and ``extrema`` (grid + Newton extrema
of M(tau0) = A + sum_i B_i sin(Omega_i tau0 + phi_i)), written on plain arrays so that the
Omega_e scan and the threshold root finding run without Python objects in their loops:

- ``unit_coefficient`` / ``damping_unit``: B per unit amplitude and A per unit mu, Eq. (19), with
  the same operations in the same order as the scalar functions of ``coefficients`` (libm
  ``exp``, ``sqrt`` and ``pow``), so the numbers are bit for bit the same;
- ``trig_max`` / ``grid_extrema`` and ``closed_extrema``: the port of ``extrema.maximum`` /
  ``extrema.extrema``;
- ``scan_strength`` / ``scan_roots``: the sign-change strength max_s min(max M_s, -min M_s) along
  a running-speed scan (every frequency scaled with Omega_e) and its roots by Brent's method
  (a port of scipy's ``brentq``, Brent 1973, *Algorithms for Minimization without Derivatives*,
  ch. 4).

Every kernel takes the Melnikov function in the packed form of ``homoclinic.terms``: ``terms``
of shape (5, n) (rows ``FUNDAMENTAL``, ``HARMONIC``, ``KIND_ROW``, ``AMPLITUDE``, ``PHASE``) and
``system`` of shape (``SYSTEM_SIZE``,) (``MU``, ``A``, ``C``, ``FM``, ``GCD``, ``LCM``).
Excitation kinds are coded as numbers: ``STIFFNESS``, ``TRANSMISSION_ERROR``, ``TORQUE``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from gearengine.homoclinic.loops import loop_shape, shape_integrals

STIFFNESS, TRANSMISSION_ERROR, TORQUE = 0, 1, 2
KIND = {"stiffness": STIFFNESS, "transmission_error": TRANSMISSION_ERROR, "torque": TORQUE}

FUNDAMENTAL, HARMONIC, KIND_ROW, AMPLITUDE, PHASE = range(5)
"""Rows of ``terms``: fundamental Omega, harmonic number r, kind, amplitude, phase [rad]."""
MU, A, C, FM, GCD, LCM, SYSTEM_SIZE = *range(6), 6
"""Entries of ``system``: damping mu, cubic a and c, the mean force F_m carried by the
unperturbed system (0 when it is treated as a perturbation, as in the paper), and the
commensurability (gcd, lcm) of the frequencies (gcd = 0: incommensurate)."""

GRID_PER_CYCLE = 16
MAX_GRID = 1 << 16
NEWTON_STEPS = 5
CANDIDATES = 4
BRENT_RTOL = 4.0 * np.finfo(float).eps
"""scipy's default relative tolerance of brentq."""
BRENT_MAXITER = 100
FALLBACK = np.nan
"""Strength returned when the active set of terms changes along a scan (see ``scan_strength``)."""

jit = numba.njit(cache=True, nogil=True)


@jit
def _sech(z: float) -> float:
    e = math.exp(-abs(z))
    return 2.0 * e / (1.0 + e * e)


@jit
def _csch(z: float) -> float:
    e = math.exp(-abs(z))
    return 2.0 * e / (1.0 - e * e)


@jit
def branch_shape(system, s: float):
    """``loops.loop_shape`` of the system's loaded loop s (zeros for F_m = 0, where the closed
    forms of Eq. 19 need none): computed once per branch, not once per coefficient."""
    if system[FM] == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return loop_shape(system[A], system[C], system[FM], s)


@jit
def damping_unit(system, s: float) -> float:
    """dA/dmu = -2 integral y_h^2 dt on branch s: -(8/3) a^(3/2) / c (Eq. 19, first term) of
    the system's cubic (a, c), both branches; -2 T_2(0) of ``loops.loop_integrals`` on the
    loaded loop s (F_m != 0: the loops differ)."""
    return damping_on(system, s, branch_shape(system, s))


@jit
def damping_on(system, s: float, shape) -> float:
    """``damping_unit`` with the branch's ``branch_shape`` given."""
    a, c, fm = system[A], system[C], system[FM]
    if fm != 0.0:
        return -2.0 * shape_integrals(0.0, c, s, shape)[1]
    return -8.0 / 3.0 * a**1.5 / c


@jit
def unit_coefficient(kind: int, omega: float, system, s: float) -> float:
    """B per unit amplitude at frequency omega = r Omega on branch s = +-1 (corrected Eq. 19)
    for the system's cubic (a, c).

    stiffness: pi Omega^2 (2a - Omega^2) / (3c) csch(sigma); torque: s sqrt(2/c) pi Omega
    sech(sigma); transmission error: Omega^2 times torque; sigma = pi Omega / (2 sqrt a).
    With the mean load F_m in the unperturbed system (F_m != 0), from the loaded loop's
    integrals (``loops.loop_integrals``): torque Omega I_1, transmission error Omega^3 I_1,
    stiffness Omega T_2 - 2 F_m Omega I_1 (Eq. 18 with a x - c x^3 = x'' - F_m on the loop).
    """
    return unit_on(kind, omega, system, s, branch_shape(system, s))


@jit
def unit_on(kind: int, omega: float, system, s: float, shape) -> float:
    """``unit_coefficient`` with the branch's ``branch_shape`` given."""
    a, c, fm = system[A], system[C], system[FM]
    if fm != 0.0:
        i1, t2 = shape_integrals(omega, c, s, shape)
        if kind == STIFFNESS:
            return omega * t2 - 2.0 * fm * omega * i1
        return omega * i1 if kind == TORQUE else omega**3 * i1
    if kind == STIFFNESS:
        w2 = omega**2
        return (
            math.pi
            * w2
            * (2.0 * a - w2)
            / (3.0 * c)
            * _csch(math.pi * omega / (2.0 * math.sqrt(a)))
        )
    sigma = math.pi * omega / (2.0 * math.sqrt(a))
    torque = s * math.sqrt(2.0 / c) * math.pi * omega * _sech(sigma)
    if kind == TORQUE:
        return torque
    return omega**2 * torque


@jit
def trig_eval(offset: float, amps, freqs, phases, tau: float) -> float:
    """M(tau) = offset + sum_i amps_i sin(freqs_i tau + phases_i)."""
    total = 0.0
    for i in range(amps.size):
        total += amps[i] * math.sin(freqs[i] * tau + phases[i])
    return offset + total


@jit
def grid_size(freqs, period: float) -> int:
    """GRID_PER_CYCLE points per fastest cycle over one period (as ``extrema.grid``)."""
    cycles = period * freqs.max() / (2.0 * math.pi)
    return int(min(MAX_GRID, max(64, math.ceil(GRID_PER_CYCLE * cycles))))


@jit
def grid_sines(freqs, phases, period: float):
    """(taus, S) on the uniform grid of one common period, S[k, i] = sin(freqs_i taus_k +
    phases_i): the table is shared by both branches and by every amplitude of a Newton search."""
    n = grid_size(freqs, period)
    taus = np.arange(n) * (period / n)
    return taus, sine_table(freqs, phases, taus)


@jit
def sine_table(freqs, phases, taus):
    """S[k, i] = sin(freqs_i taus_k + phases_i), shape (taus, freqs)."""
    table = np.empty((taus.size, freqs.size))
    for k in range(taus.size):
        for i in range(freqs.size):
            table[k, i] = math.sin(freqs[i] * taus[k] + phases[i])
    return table


@jit
def grid_values(offset: float, amps, table, values):
    """values[k] = offset + sum_i amps_i table[k, i] (M on the grid, ``trig_eval``'s order)."""
    for k in range(values.size):
        total = 0.0
        for i in range(amps.size):
            total += amps[i] * table[k, i]
        values[k] = offset + total


@jit
def trig_max(offset: float, amps, freqs, phases, period: float, taus, values, sign: float):
    """(max, tau*) of sign * M over one period from its grid values (``extrema.maximum``).

    The CANDIDATES best grid peaks are polished by NEWTON_STEPS Newton steps on M'(tau) = 0,
    each kept within one grid step of its start.
    """
    n = taus.size
    step = taus[1] - taus[0]
    cand_v = np.full(CANDIDATES, -np.inf)  # the best peaks so far, ascending
    cand_k = np.full(CANDIDATES, -1)
    best = 0
    for k in range(n):
        v = sign * values[k]
        if v > sign * values[best]:
            best = k
        if v >= sign * values[k - 1] and v >= sign * values[(k + 1) % n] and v > cand_v[0]:
            j = 0
            while j + 1 < CANDIDATES and cand_v[j + 1] < v:
                cand_v[j], cand_k[j] = cand_v[j + 1], cand_k[j + 1]
                j += 1
            cand_v[j], cand_k[j] = v, k
    top, at = -np.inf, 0.0
    for q in range(CANDIDATES):
        if cand_k[q] < 0:
            continue
        start = taus[cand_k[q]]
        tau = start
        for _ in range(NEWTON_STEPS):
            d1, d2 = 0.0, 0.0
            for i in range(amps.size):
                arg = freqs[i] * tau + phases[i]
                wa = sign * amps[i] * freqs[i]
                d1 += math.cos(arg) * wa
                d2 -= math.sin(arg) * (wa * freqs[i])
            newton = d1 / d2 if d2 < 0.0 else 0.0
            tau = min(max(tau - newton, start - step), start + step)
        v = sign * trig_eval(offset, amps, freqs, phases, tau)
        if v > top:
            top, at = v, tau
    if sign * values[best] > top:
        return sign * values[best], taus[best]
    return top, at % period


@jit
def closed_extrema(offset: float, nact: int, spread: float, only: float):
    """(min, max) of M = A + sum_i B_i sin(...) over tau0 without a grid, from its number of
    active terms ``nact``, sum |B_i| ``spread`` and last active B ``only``: constant (none),
    A -/+ |B| (one sinusoid), or the infimum and supremum A -/+ sum |B_i| (incommensurate)."""
    if nact == 0:
        return offset, offset
    if nact == 1:
        return offset - abs(only), offset + abs(only)
    return offset - spread, offset + spread


@jit
def grid_extrema(offset: float, amps, freqs, phases, period: float, taus, table, values):
    """(min, max) of M over tau0 with at least two active terms of commensurate frequencies,
    exact on one period (``extrema.extrema``; ``taus``, ``table`` from ``grid_sines``;
    ``values`` is scratch of the grid's size). Fewer terms, or incommensurate ones:
    ``closed_extrema``."""
    grid_values(offset, amps, table, values)
    top, _ = trig_max(offset, amps, freqs, phases, period, taus, values, 1.0)
    bottom, _ = trig_max(offset, amps, freqs, phases, period, taus, values, -1.0)
    return -bottom, top


@jit
def scan_strength(om: float, value: float, terms, system) -> float:
    """Sign-change strength max_s min(max M_s, -min M_s) at Omega_e = om, every frequency
    scaled by om / value (``thresholds.sign_change_strength`` along a running-speed scan).

    ``terms`` and ``system`` are the packed form of ``homoclinic.terms``. The common frequency
    is Omega_0 = top * gcd / lcm, as ``model.frequencies.commensurability`` gives it (gcd = 0:
    incommensurate). Returns FALLBACK (NaN) when a coefficient underflows to 0 and the active
    set (and so its period) is no longer the given one.
    """
    return _strength(om, value, terms, system, _workspace(terms, system))


@jit
def _workspace(terms, system):
    """What ``_strength`` reuses from one Omega_e of a scan to the next: both branches'
    ``branch_shape`` and damping per unit mu (``damping_on``; both frequency-independent), and
    scratch arrays (frequencies, amplitudes, and the grid of a single or incommensurate set,
    which needs none)."""
    n = terms.shape[1]
    plus, minus = branch_shape(system, 1.0), branch_shape(system, -1.0)
    shapes = (
        (1.0, plus, damping_on(system, 1.0, plus)),
        (-1.0, minus, damping_on(system, -1.0, minus)),
    )
    return shapes, np.empty(n), np.empty(n), np.zeros(2), np.zeros((2, n)), np.empty(2)


@jit
def _strength(om: float, value: float, terms, system, work) -> float:
    """``scan_strength`` with the ``_workspace`` of its scan."""
    shapes, freqs, amps, taus, table, values = work
    n = terms.shape[1]
    gcd, lcm = system[GCD], system[LCM]
    factor = om / value
    for i in range(n):
        freqs[i] = terms[HARMONIC, i] * (terms[FUNDAMENTAL, i] * factor)
    exact = n >= 2 and gcd > 0.0
    period = 2.0 * math.pi / (freqs.max() * gcd / lcm) if exact else 0.0
    if exact:
        taus, table = grid_sines(freqs, terms[PHASE], period)
        values = np.empty(taus.size)
    best = -np.inf
    for s, shape, damping_per_mu in shapes:
        damping = damping_per_mu * system[MU]
        nact, spread, only = 0, 0.0, 0.0
        for i in range(n):
            kind = int(terms[KIND_ROW, i])
            amps[i] = unit_on(kind, freqs[i], system, s, shape) * terms[AMPLITUDE, i]
            if amps[i] != 0.0:
                nact += 1
                spread += abs(amps[i])
                only = amps[i]
        if 2 <= nact < n:
            return FALLBACK
        if exact and nact >= 2:
            lo, hi = grid_extrema(damping, amps, freqs, terms[PHASE], period, taus, table, values)
        else:  # no call with arrays: their reference counts cost more than this branch
            lo, hi = closed_extrema(damping, nact, spread, only)
        best = max(best, min(hi, -lo))
    return best


@jit
def _brentq(value: float, terms, system, work, xa: float, xb: float, xtol: float) -> float:
    """Root of ``scan_strength`` in [xa, xb]: scipy's brentq (Zeros/brentq.c), step for step."""
    xpre, xcur = xa, xb
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _strength(xpre, value, terms, system, work)
    fcur = _strength(xcur, value, terms, system, work)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    for _ in range(BRENT_MAXITER):
        if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + BRENT_RTOL * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
                spre, scur = scur, stry
            else:
                spre, scur = sbis, sbis
        else:
            spre, scur = sbis, sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = _strength(xcur, value, terms, system, work)
        if math.isnan(fcur):
            return np.nan
    return np.nan


@jit
def scan_roots(omegas, xtol: float, value: float, terms, system):
    """Critical Omega_e of a running-speed scan and the no-chaos flag of each piece between them.

    Returns (critical, no_chaos, ok): ``no_chaos[j]`` says the strength is <= 0 in the middle of
    piece j of [start, *critical, stop]; ``ok`` is False when the scan met a FALLBACK point.
    """
    work = _workspace(terms, system)
    m = omegas.size
    vals = np.empty(m)
    for k in range(m):
        vals[k] = _strength(omegas[k], value, terms, system, work)
    critical = [0.0 for _ in range(0)]
    if np.isnan(vals).any():
        return np.empty(0), np.zeros(0, dtype=np.bool_), False
    for k in range(m - 1):
        if (vals[k] > 0.0) != (vals[k + 1] > 0.0):
            root = _brentq(value, terms, system, work, omegas[k], omegas[k + 1], xtol)
            if math.isnan(root):
                return np.empty(0), np.zeros(0, dtype=np.bool_), False
            critical.append(root)
    edges = np.empty(len(critical) + 2)
    edges[0], edges[-1] = omegas[0], omegas[m - 1]
    for j in range(len(critical)):
        edges[j + 1] = critical[j]
    no_chaos = np.zeros(edges.size - 1, dtype=np.bool_)
    for j in range(edges.size - 1):
        mid = _strength(0.5 * (edges[j] + edges[j + 1]), value, terms, system, work)
        if math.isnan(mid):
            return np.empty(0), np.zeros(0, dtype=np.bool_), False
        no_chaos[j] = mid <= 0.0
    return edges[1:-1].copy(), no_chaos, True


@jit
def sublevel_root(m0off, m0amps, goff, gamps, freqs, phases, period, taus, table, p):
    """Root near p of the convex phi(p) = max_tau0 (m0 + p g) (``extrema._newton_root``);
    ``table`` is ``sine_table(freqs, phases, taus)``, built once for every search that shares
    them (the 16 of a verdict's thresholds).

    Newton with phi'(p) = g(tau*) (envelope theorem), monotone from outside the sublevel set;
    at most 30 steps, stopping at a relative step of 1e-14.
    """
    amps = np.empty(m0amps.size)
    values = np.empty(taus.size)
    for _ in range(30):
        off = m0off + p * goff
        for i in range(amps.size):
            amps[i] = m0amps[i] + p * gamps[i]
        grid_values(off, amps, table, values)
        value, tau = trig_max(off, amps, freqs, phases, period, taus, values, 1.0)
        slope = trig_eval(goff, gamps, freqs, phases, tau)
        if slope == 0.0:
            break
        step = value / slope
        p -= step
        if abs(step) <= 1e-14 * max(1.0, abs(p)):
            break
    return p
