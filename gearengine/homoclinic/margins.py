"""A control parameter's no-chaos set and a design's margin to it: the interval algebra of the
sets (intersections over branches and the parameter's domain, their finite ends, the critical
values) and the threshold document of ``thresholds``, with the signed margin of the design's
value (positive on the safe side).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from gearengine.homoclinic.extrema import Interval
from gearengine.homoclinic.schemas import ParameterThreshold


def intersect(xs: list[Interval], ys: list[Interval]) -> list[Interval]:
    """Pairwise intersections of two unions of closed intervals (None: an open end), sorted."""
    out = []
    for x in xs:
        for y in ys:
            lo = _max_end(x.lo, y.lo)
            hi = _min_end(x.hi, y.hi)
            if lo is None or hi is None or lo <= hi:
                out.append(Interval(lo, hi))
    return sorted(out, key=lambda i: -np.inf if i.lo is None else i.lo)


def _max_end(p: float | None, q: float | None) -> float | None:
    return q if p is None else p if q is None else max(p, q)


def _min_end(p: float | None, q: float | None) -> float | None:
    return q if p is None else p if q is None else min(p, q)


def interval_ends(intervals: list[Interval], domain: Interval) -> list[float]:
    """Finite interval ends that are not ends of the parameter's domain."""
    bounds = {domain.lo, domain.hi}
    return sorted({e for i in intervals for e in (i.lo, i.hi) if e is not None and e not in bounds})


AMPLITUDES = frozenset({"F_e1", "k_p1", "F_p1"})
"""Control parameters that are amplitudes: a negative amplitude is the same harmonic shifted by
pi, so a design's amplitude reaches a critical value by growing or shrinking, not through 0."""


def signed_margin(
    parameter: str, value: float, critical: Sequence[float], no_chaos: Sequence[Sequence]
) -> tuple[float | None, float | None, float | None]:
    """(nearest, margin, relative_margin) of a design's value: the nearest critical value (for an
    amplitude, the nearest of its own sign when there is one), the distance |value - nearest|
    signed positive on the safe side (the value lies in a ``no_chaos`` interval [lo, hi], None
    an open end) and negative inside the chaos-possible region, and margin / |nearest| (None if
    nearest is 0). All None without a critical value."""
    if not critical:
        return None, None, None
    pool = list(critical)
    if parameter in AMPLITUDES and value != 0.0:
        pool = [v for v in critical if (v > 0.0) == (value > 0.0)] or pool
    nearest = min(pool, key=lambda v: abs(value - v))
    safe = any((lo is None or value >= lo) and (hi is None or value <= hi) for lo, hi in no_chaos)
    margin = abs(value - nearest) if safe else -abs(value - nearest)
    return nearest, margin, margin / abs(nearest) if nearest != 0.0 else None


def threshold_fields(
    parameter: str,
    value: float | None,
    critical: list[float],
    no_chaos: list,
    force: float | None = None,
    f_crit: float = 1.0,
    **extra: object,
) -> dict:
    """The fields of the threshold document (a ``ParameterThreshold``, validated where it is
    built: alone in ``threshold_document``, or with the verdict it belongs to): critical values
    and the design's margin (``signed_margin``); with ``force``, the largest force along the
    loops per unit of the parameter, the margin in the force scale ``f_crit`` too (margin *
    force / F_crit)."""
    nearest = margin = rel = None
    if value is not None:
        nearest, margin, rel = signed_margin(parameter, value, critical, no_chaos)
    if margin is not None and force is not None:
        extra["margin_in_force_scale"] = margin * force / f_crit
    return {
        "value": value,
        "critical_values": critical,
        "nearest": nearest,
        "margin": margin,
        "relative_margin": rel,
        "no_chaos": no_chaos,
        **extra,
    }


def threshold_document(*args: object, **kwargs: object) -> ParameterThreshold:
    """The ``ParameterThreshold`` of ``threshold_fields(*args, **kwargs)``."""
    return ParameterThreshold(**threshold_fields(*args, **kwargs))
