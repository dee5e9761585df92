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
    freqs = sorted({f for f in frequencies if f > 0.0})
    if not freqs:
        return None
    top = freqs[-1]
    ratios = []
    for f in freqs:
        q = Fraction(f / top).limit_denominator(max_denominator)
        if abs(float(q) - f / top) > RATIO_TOLERANCE * (f / top):
            return None
        ratios.append(q)
    lcm = math.lcm(*(q.denominator for q in ratios))
    numerators = [q.numerator * (lcm // q.denominator) for q in ratios]
    return top * math.gcd(*numerators) / lcm


def forcing_period(frequencies: list[float]) -> float | None:
    """Poincare period T0 = 2 pi / Omega_0 of the forcing, or None if quasi-periodic/absent."""
    omega0 = common_frequency(frequencies)
    return None if omega0 is None else 2.0 * math.pi / omega0
