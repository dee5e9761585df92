"""Commensurability of the excitation frequencies and the Poincare period T0.

The forcing of Eq. (9) is periodic with period T0 = 2 pi / Omega_0 when every active frequency
r Omega is an integer multiple of one frequency Omega_0. Ratios are taken as rationals with
denominators up to ``MAX_DENOMINATOR``; otherwise the forcing is quasi-periodic and no period
exists.
"""

from __future__ import annotations

import math
from fractions import Fraction

MAX_DENOMINATOR = 64
RATIO_TOLERANCE = 1e-9


def commensurability(
    frequencies: list[float], max_denominator: int = MAX_DENOMINATOR
) -> tuple[float, float]:
    """(gcd, lcm) with Omega_0 = top * gcd / lcm, top the fastest frequency; (0, 1) when the
    frequencies are incommensurate at that resolution, or when there are none.

    Each ratio Omega_i / top is taken as the rational p_i / q_i with q_i <= ``max_denominator``
    (within ``RATIO_TOLERANCE`` relative); lcm is the lcm of the q_i and gcd that of the
    p_i lcm / q_i. Scaling every frequency by one factor keeps the ratios, so one answer serves
    a whole running-speed scan.
    """
    freqs = sorted({f for f in frequencies if f > 0.0})
    if not freqs:
        return 0.0, 1.0
    top = freqs[-1]
    ratios = []
    for f in freqs:
        q = Fraction(f / top).limit_denominator(max_denominator)
        if abs(float(q) - f / top) > RATIO_TOLERANCE * (f / top):
            return 0.0, 1.0
        ratios.append(q)
    lcm = math.lcm(*(q.denominator for q in ratios))
    return float(math.gcd(*(q.numerator * (lcm // q.denominator) for q in ratios))), float(lcm)


def common_frequency(
    frequencies: list[float], max_denominator: int = MAX_DENOMINATOR
) -> float | None:
    """Largest Omega_0 of which every frequency is an integer multiple, or None.

    Args:
        frequencies: positive angular frequencies Omega_i (dimensionless, rad per unit tau).
        max_denominator: largest denominator q accepted in Omega_i / Omega_max = p / q.

    Returns:
        Omega_0 (same units), the fastest frequency itself for a single one, ``None`` when the
        frequencies are incommensurate at that resolution. An empty list gives ``None``.
    """
    gcd, lcm = commensurability(frequencies, max_denominator)
    if gcd == 0.0:
        return None
    return max(frequencies) * int(gcd) / int(lcm)


def forcing_period(frequencies: list[float]) -> float | None:
    """Poincare period T0 = 2 pi / Omega_0 of the forcing, or None if quasi-periodic/absent."""
    omega0 = common_frequency(frequencies)
    return None if omega0 is None else 2.0 * math.pi / omega0
