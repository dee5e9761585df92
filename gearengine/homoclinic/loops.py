"""The saddle and the two homoclinic loops of the loaded unperturbed system, in closed form.

With the mean load in the unperturbed system (``docs/melnikov-under-load.md``),

    x'' = a x - c x^3 + F_m,        a > 0, c > 0,

has three equilibria while |F_m| < F_crit = (2a/3) sqrt(a/(3c)) (the peak of the cubic's
restoring force, at x = sqrt(a/(3c))); the middle one, x_s (``saddle``: the root of
c x^3 - a x - F_m = 0 with 3 c x_s^2 < a), is a saddle. Above F_crit only one well is left: no
saddle, no homoclinic orbit. About the saddle, u = x - x_s obeys

    u'' = alpha u + (3/2) beta u^2 + 2 gamma u^3,   u'^2 = alpha u^2 + beta u^3 + gamma u^4,
    alpha = a - 3 c x_s^2,  beta = -2 c x_s,  gamma = -c / 2,

and w = 1/u obeys w'' = alpha w + beta / 2, so both loops are elementary (s = +1: u > 0, the
loop on the side x > x_s; s = -1 the other one):

    u_s(t) = s P / (cosh(k t) + cos(theta_s)),   k = sqrt(alpha),  P = 2 alpha / sqrt(Delta),
    Delta = beta^2 + 2 alpha c,  cos(theta_s) = -s beta / sqrt(Delta),  sin(theta_s) =
    sqrt(2 alpha c / Delta).

For F_m = 0: x_s = 0, theta = pi/2 and u_s = s sqrt(2a/c) sech(sqrt(a) t) (Eq. 15). The
Fourier integrals along the loop follow from Gradshteyn & Ryzhik 3.983.2,

    integral cos(nu z) / (cosh z + cos theta) dz = 2 pi sinh(nu theta) / (sin theta sinh(pi nu)),

its derivative in cos(theta) (the square of the denominator), and the recursion of
I_n = integral u^n cos(Omega t) dt obtained from integral (u^n)'' cos(Omega t) dt = -Omega^2 I_n:

    -Omega^2 I_n = n^2 alpha I_n + n (n + 1/2) beta I_{n+1} + n (n + 1) gamma I_{n+2}.

``loop_integrals`` returns I_1 and T_2 = integral u'^2 cos(Omega t) dt = alpha I_2 + beta I_3 +
gamma I_4, from which ``kernels.unit_coefficient`` builds the Melnikov coefficients of Eq. (18)
(tests/test_melnikov_load.py checks them against scipy's DOP853 along the loop). ``orbit``
gives the loops themselves (x_h, y_h) and ``sampled_extremes`` the largest speed and force along
them (``perturbations``). Compiled (numba); ``kernels`` calls them, so this file is in the
kernels' cache group (``gearengine.jitcache``).
"""

from __future__ import annotations

import math

import numba
import numpy as np

jit = numba.njit(cache=True, nogil=True)


@jit
def critical_load(a: float, c: float) -> float:
    """F_crit = (2a/3) sqrt(a/(3c)): the largest |F_m| with a saddle (the cubic's peak force)."""
    return 2.0 * a / 3.0 * math.sqrt(a / (3.0 * c))


@jit
def saddle(a: float, c: float, fm: float) -> float:
    """x_s: the middle root of c x^3 - a x - F_m = 0 (|F_m| < F_crit), by Viete's trigonometric
    form x = 2 sqrt(a/(3c)) cos(acos(F_m/F_crit)/3 - 2 pi/3), polished by three Newton steps."""
    if fm == 0.0:
        return 0.0
    ratio = min(1.0, max(-1.0, fm / critical_load(a, c)))
    x = 2.0 * math.sqrt(a / (3.0 * c)) * math.cos(math.acos(ratio) / 3.0 - 2.0 * math.pi / 3.0)
    for _ in range(3):
        slope = 3.0 * c * x * x - a
        if slope == 0.0:
            break
        x -= (c * x * x * x - a * x - fm) / slope
    return x


@jit
def loop_shape(a: float, c: float, fm: float, s: float):
    """(x_s, alpha, P, cos theta_s, sin theta_s, k, theta_s) of loop s (u_s = s P / (cosh(k t) +
    cos theta_s), k = sqrt(alpha)): what every frequency's integrals of the loop share."""
    xs = saddle(a, c, fm)
    alpha = a - 3.0 * c * xs * xs
    beta = -2.0 * c * xs
    root = math.sqrt(beta * beta + 2.0 * alpha * c)
    cos_t, sin_t = -s * beta / root, math.sqrt(2.0 * alpha * c) / root
    return xs, alpha, 2.0 * alpha / root, cos_t, sin_t, math.sqrt(alpha), math.atan2(sin_t, cos_t)


@jit
def _ratios(nu: float, theta: float):
    """(sinh(nu theta) / sinh(pi nu), nu cosh(nu theta) / sinh(pi nu)), overflow-free; their
    limits (theta / pi, 1 / pi) at nu = 0."""
    if nu == 0.0:
        return theta / math.pi, 1.0 / math.pi
    decay = math.exp(-nu * (math.pi - theta))
    den = -math.expm1(-2.0 * math.pi * nu)
    return (
        decay * -math.expm1(-2.0 * nu * theta) / den,
        nu * decay * (1.0 + math.exp(-2.0 * nu * theta)) / den,
    )


@jit
def loop_integrals(omega: float, a: float, c: float, fm: float, s: float):
    """(I_1, T_2) on loop s at frequency omega >= 0: I_1 = integral u_s cos(omega t) dt and
    T_2 = integral u_s'^2 cos(omega t) dt over the whole line (module docstring)."""
    return shape_integrals(omega, c, s, loop_shape(a, c, fm, s))


@jit
def shape_integrals(omega: float, c: float, s: float, shape):
    """``loop_integrals`` on the loop of ``shape`` (``loop_shape(a, c, F_m, s)``, computed once
    for every frequency of a scan)."""
    xs, alpha, p, cos_t, sin_t, k, theta = shape
    r, nq = _ratios(omega / k, theta)
    base = 2.0 * math.pi / k
    i1 = s * p * base * r / sin_t
    i2 = p * p * base * (nq * sin_t - r * cos_t) / sin_t**3
    beta, gamma, w2 = -2.0 * c * xs, -0.5 * c, omega * omega
    i3 = -((w2 + alpha) * i1 + 1.5 * beta * i2) / (2.0 * gamma)
    i4 = -((w2 + 4.0 * alpha) * i2 + 5.0 * beta * i3) / (6.0 * gamma)
    return i1, alpha * i2 + beta * i3 + gamma * i4


@jit
def _state(t: float, a: float, c: float, fm: float, s: float, shape) -> tuple[float, float]:
    """(x_h, y_h) at time t on loop s of shape ``loop_shape``: Eq. (15) for F_m = 0, else
    x_s + u_s(t) with u_s = s P / (cosh(k t) + cos theta_s), overflow-free through
    e = exp(-k |t|): cosh(k t) + cos theta_s = (1 + 2 cos theta_s e + e^2) / (2 e)."""
    sign = (t > 0.0) - (t < 0.0)
    if fm == 0.0:
        z = math.sqrt(a) * t
        e = math.exp(-abs(z))
        sech = 2.0 * e / (1.0 + e * e)
        return s * math.sqrt(2.0 * a / c) * sech, -s * math.sqrt(2.0 / c) * a * sech * math.tanh(z)
    xs, alpha, p, cos_t = shape[0], shape[1], shape[2], shape[3]
    e = math.exp(-(math.sqrt(alpha) * abs(t)))
    den = 1.0 + 2.0 * cos_t * e + e * e
    u = s * p * 2.0 * e / den
    du = -s * p * math.sqrt(alpha) * 2.0 * e * (1.0 - e * e) / den**2  # u' for t >= 0
    return xs + u, sign * du


@jit
def orbit(t, a: float, c: float, fm: float, s: float):
    """(x_h, y_h) at the times ``t`` (1-D array, dimensionless time) on loop s = +-1 of
    x'' = a x - c x^3 + F_m (|F_m| < F_crit): two arrays of t's shape."""
    shape = loop_shape(a, c, fm, s)
    x, y = np.empty(t.size), np.empty(t.size)
    for i in range(t.size):
        x[i], y[i] = _state(t[i], a, c, fm, s, shape)
    return x, y


@jit
def _near(tau: float, start: float, step: float, last: int, picks) -> None:
    """Mark in ``picks`` the grid indices within three steps of times -tau and tau."""
    for centre in (-tau, tau):
        j = math.floor((centre - start) / step)
        for i in range(max(0, j - 3), min(last, j + 4) + 1):
            picks[i] = True


@jit
def sampled_extremes(a: float, c: float, fm: float, samples: int) -> tuple[float, float]:
    """(max |y_h|, max |a x_h - c x_h^3|) over both loops on the grid t = linspace(-40/k,
    40/k, samples), k = sqrt(alpha) the saddle's rate, as sampling the whole grid gives them.

    Along loop s, u_s(|t|) is monotone, so a local maximum of either function of t lies at
    t = 0 (the turning point), at the grid's ends, or where the continuous function peaks:
    |y_h| where d(u'^2)/du = u (2 alpha + 3 beta u + 4 gamma u^2) = 0 (the root of the sign of
    s: u'^2 = u^2 (alpha + beta u + gamma u^2) rises from the saddle, then falls to 0 at the
    turn), |a x - c x^3| where x = +-sqrt(a / (3c)) lies on the loop (its zeros are minima).
    The largest grid value lies within a step of one of these (a grid point higher than both
    neighbours brackets a local maximum), so only the grid points within three steps of them
    are evaluated, with the grid's own times (numpy.linspace's arithmetic).
    """
    xs = saddle(a, c, fm)
    k = math.sqrt(a - 3.0 * c * xs**2)
    start, stop = -40.0 / k, 40.0 / k
    last = samples - 1
    step = (stop - start) / last
    beta, gamma = -2.0 * c * xs, -0.5 * c
    peak = math.sqrt(a / (3.0 * c))
    speed = force = 0.0
    for s in (1.0, -1.0):
        shape = loop_shape(a, c, fm, s)
        p, cos_t = shape[2], shape[3]
        picks = np.zeros(samples, dtype=np.bool_)
        picks[0] = picks[last] = True
        root = math.sqrt(9.0 * beta * beta - 32.0 * gamma * shape[1])
        us = [(-3.0 * beta + root) / (8.0 * gamma), (-3.0 * beta - root) / (8.0 * gamma)]
        us += [peak - xs, -peak - xs]
        _near(0.0, start, step, last, picks)
        for u in us:
            arg = s * p / u - cos_t if s * u > 0.0 else 0.0  # cosh(k t) where u_s(t) = u
            if arg >= 1.0:
                _near(math.acosh(arg) / k, start, step, last, picks)
        for i in range(samples):
            if picks[i]:
                t = stop if i == last else i * step + start
                x, y = _state(t, a, c, fm, s, shape)
                speed = max(speed, abs(y))
                force = max(force, abs(a * x - c * x**3))
    return speed, force
