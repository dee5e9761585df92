"""A circumferential backlash band (a fit table's j_t,min .. j_t,max) to the half backlash b of
Eq. (6).

The fit tables (DIN 3967, ISO/TR 10064-2:1996) give the circumferential backlash j_t, measured
along the reference (operating pitch) circle in the transverse plane. The model's clearance 2b
lies along the line of action; for a spur pair the normal backlash is j_n = j_t cos(alpha_wt)
(ISO/TR 10064-2, 5.1, with beta_b = 0), so

    b = j_t cos(alpha_wt) / 2.

A fit table states limits, not a distribution: the half backlash is drawn uniformly between the
limits of the band (the assumption: every backlash within the band is as likely).
"""

from __future__ import annotations

import math


def half_backlash(circumferential: float, operating_pressure_angle: float) -> float:
    """b = j_t cos(alpha_wt) / 2 [m] from the circumferential backlash j_t [m] and the operating
    transverse pressure angle alpha_wt [rad]."""
    return circumferential * math.cos(operating_pressure_angle) / 2.0


def half_backlash_band(
    j_min: float, j_max: float, operating_pressure_angle: float
) -> tuple[float, float]:
    """(b_min, b_max) [m] of a circumferential band [j_min, j_max] [m]; ValueError unless
    0 < j_min < j_max."""
    if not 0.0 < j_min < j_max:
        raise ValueError("tolerances.backlash: give 0 < min < max (circumferential backlash)")
    return (
        half_backlash(j_min, operating_pressure_angle),
        half_backlash(j_max, operating_pressure_angle),
    )
