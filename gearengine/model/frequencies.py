"""Commensurability of the excitation frequencies and the Poincare period T0.

The forcing of Eq. (9) is periodic with period T0 = 2 pi / Omega_0 when every active frequency
r Omega is an integer multiple of one frequency Omega_0.

* A design knows it exactly: every excitation runs at an integer (or rational) multiple of the
  driver speed (mesh = z x shaft, stiffness harmonics r x mesh, transmission error at its order,
  torque ripple at order x shaft), so the conversion records each excitation's fundamental as a
  multiple of the shaft speed (``GearParams.shaft_orders``) and Omega_0 follows from those
  rationals, with no float search. Orders that are not rationals with denominators up to
  ``MAX_ORDER_DENOMINATOR`` make the forcing truly incommensurate.
* Dimensionless ``params`` carry no such record: the ratio of each excitation's fundamental to
  the fastest fundamental is read as a rational p / q with q <= ``MAX_DENOMINATOR`` when it lies
  within ``COMMENSURABILITY_TOLERANCE`` (relative) of it; harmonics r Omega are multiples of their
  fundamental and do not count against the bound. Otherwise the forcing is quasi-periodic at that
  resolution and no period exists.

Either way Omega_0 = f_top gcd(p_i) / lcm(q_i) for the ratios p_i / q_i of every active frequency
to the fastest one f_top (the same float operations for both, so a design found commensurate by
the search gets the same T0 bit for bit).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction

from gearengine.model.params import GearParams

MAX_DENOMINATOR = 64
"""Largest denominator q of a ratio of two fundamentals of ``params`` (p / q) accepted."""
COMMENSURABILITY_TOLERANCE = 1e-9
"""Largest relative distance of a frequency ratio from its rational p / q accepted (the tolerance
of the units boundary's third kind, beside ``model.units``' radius-ratio and torque-balance
tolerances)."""
MAX_ORDER_DENOMINATOR = 1000
"""Largest denominator of a design's order (multiple of the shaft speed) read as a rational."""


def rational(x: float, max_denominator: int) -> Fraction | None:
    """``x`` as p / q with q <= ``max_denominator`` within ``COMMENSURABILITY_TOLERANCE``
    (relative), or None."""
    q = Fraction(x).limit_denominator(max_denominator)
    return q if abs(float(q) - x) <= COMMENSURABILITY_TOLERANCE * abs(x) else None


def _gcd_lcm(ratios: Sequence[Fraction]) -> tuple[int, int]:
    """(gcd, lcm) of ratios p_i / q_i: lcm of the q_i, gcd of the p_i lcm / q_i, so that the
    frequencies top p_i / q_i are integer multiples of top gcd / lcm."""
    lcm = math.lcm(*(q.denominator for q in ratios))
    return math.gcd(*(q.numerator * (lcm // q.denominator) for q in ratios)), lcm


def commensurability(
    frequencies: list[float], max_denominator: int = MAX_DENOMINATOR
) -> tuple[float, float]:
    """(gcd, lcm) with Omega_0 = top * gcd / lcm, top the fastest frequency; (0, 1) when the
    frequencies are incommensurate at that resolution, or when there are none.

    Each ratio Omega_i / top is taken as the rational p_i / q_i with q_i <= ``max_denominator``
    (``rational``); lcm is the lcm of the q_i and gcd that of the p_i lcm / q_i. Scaling every
    frequency by one factor keeps the ratios, so one answer serves a whole running-speed scan.
    """
    freqs = sorted({f for f in frequencies if f > 0.0})
    if not freqs:
        return 0.0, 1.0
    if len(freqs) == 1:  # its ratio to itself is 1 = 1 / 1, as below without the search
        return 1.0, 1.0
    ratios = [rational(f / freqs[-1], max_denominator) for f in freqs]
    if None in ratios:
        return 0.0, 1.0
    gcd, lcm = _gcd_lcm(ratios)  # type: ignore[arg-type]
    return float(gcd), float(lcm)


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


def _fundamental_ratios(params: GearParams) -> dict[str, Fraction] | None:
    """Each active excitation's fundamental as a rational multiple of a common unit: the design's
    shaft orders, else the ratio to the fastest fundamental (``MAX_DENOMINATOR``); None when
    incommensurate."""
    active = {name: exc.frequency for name, exc in params.excitations() if any(exc.active())}
    orders = params.shaft_orders
    if orders is not None:
        exact = {name: rational(orders[name], MAX_ORDER_DENOMINATOR) for name in active}
        return None if None in exact.values() else exact  # type: ignore[return-value]
    fastest = max(active.values())
    ratios = {name: rational(f / fastest, MAX_DENOMINATOR) for name, f in active.items()}
    return None if None in ratios.values() else ratios  # type: ignore[return-value]


def poincare_frequency(params: GearParams) -> float | None:
    """Omega_0 of the forcing of ``params`` (module docstring), None when incommensurate or
    without an active excitation."""
    active = params.active_frequencies()
    if not active:
        return None
    if len(active) == 1 and params.shaft_orders is None:
        return active[0]  # one harmonic: top * gcd / lcm with gcd = lcm = 1, as below
    fundamentals = _fundamental_ratios(params)
    if fundamentals is None:
        return None
    terms = [
        (r * exc.frequency, r * fundamentals[name])
        for name, exc in params.excitations()
        for r, _ in exc.active()
    ]
    top, top_ratio = max(terms, key=lambda t: (t[0], t[1]))
    gcd, lcm = _gcd_lcm(sorted({ratio / top_ratio for _, ratio in terms}))
    return top * gcd / lcm


def poincare_period(params: GearParams) -> float | None:
    """T0 = 2 pi / Omega_0 of the forcing of ``params`` (``poincare_frequency``), or None."""
    omega0 = poincare_frequency(params)
    return None if omega0 is None else 2.0 * math.pi / omega0


def incommensurate_reason(params: GearParams) -> str:
    """Why ``poincare_frequency`` found no common period, in words."""
    if params.shaft_orders is not None:
        return (
            "the design's excitation orders are not rational multiples of the shaft speed "
            f"(denominators up to {MAX_ORDER_DENOMINATOR}): truly incommensurate forcing"
        )
    return (
        "no ratio p / q of the excitations' fundamentals with q <= "
        f"{MAX_DENOMINATOR} lies within {COMMENSURABILITY_TOLERANCE:g} (relative)"
    )


def forcing_period(frequencies: list[float]) -> float | None:
    """Poincare period T0 = 2 pi / Omega_0 of the forcing, or None if quasi-periodic/absent."""
    omega0 = common_frequency(frequencies)
    return None if omega0 is None else 2.0 * math.pi / omega0
