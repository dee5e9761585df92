"""The sign-change strength on a grid of two aliases, for the chaos map's Melnikov boundary.

Each value is ``thresholds.strength_at(request.point(...))``, bit for bit, without a validated
``GearParams`` per grid point: the aliases are set on the design's dumped data as
``aliases.with_aliases`` sets them, the active harmonics are read off as ``scan_terms`` reads
them and the compiled ``kernels.scan_strength`` runs on them as in ``sign_change_strength``. A
point whose compiled strength falls back (NaN), and grids over ``Omega``, take ``strength_at``.
"""

from __future__ import annotations

import math

import numpy as np

from gearengine.homoclinic import kernels
from gearengine.homoclinic.coefficients import saddle_loop
from gearengine.homoclinic.thresholds import commensurability, strength_at, terms_table
from gearengine.model.aliases import ALIASES, aliased_data
from gearengine.model.backlash import melnikov_cubic
from gearengine.model.params import EXCITATIONS
from gearengine.sweeps.request import SweepRequest


def _set_aliases(data: dict, values: dict[str, float]) -> dict | None:
    """``aliases.aliased_data``, or None where ``with_aliases`` would raise."""
    try:
        return aliased_data(data, values)
    except ValueError:
        return None


def _terms(data: dict) -> tuple[np.ndarray, ...]:
    """``thresholds.scan_terms`` of the design with dumped ``data``."""
    return terms_table(
        (name, exc["frequency"], [(h["amplitude"], h["phase"]) for h in exc["harmonics"]])
        for name in EXCITATIONS
        if (exc := data.get(name)) is not None
    )


def strength_grid(request: SweepRequest, g0: np.ndarray, g1: np.ndarray) -> np.ndarray:
    """``strength_at(request.point({axis 0: a, axis 1: b}))`` for b in ``g1`` (rows) and a in
    ``g0`` (columns)."""
    p0, p1 = (a.parameter for a in request.axes)

    def slow(a: float, b: float) -> float:
        return strength_at(request.point({p0: a, p1: b}))

    assert request.params is not None
    if p0 not in ALIASES or p1 not in ALIASES:
        return np.array([[slow(a, b) for a in g0] for b in g1])
    a_law, c_law, _ = melnikov_cubic(request.params.backlash)
    if not saddle_loop(a_law, c_law):
        return np.full((g1.size, g0.size), math.nan)
    base = request.params.model_dump()
    ratios: dict[tuple[float, ...], tuple[float, float]] = {}
    out = np.empty((g1.size, g0.size))
    for j, b in enumerate(g1):
        for i, a in enumerate(g0):
            data = _set_aliases(base, {p0: a, p1: b})
            value = math.nan
            if data is not None:
                fund, r, kind, amp, phase = _terms(data)
                key = tuple((r * fund).tolist())
                if key not in ratios:
                    ratios[key] = commensurability(list(key))
                gcd, lcm = ratios[key]
                mu = float(data["damping"])
                value = float(kernels.scan_strength(
                    1.0, 1.0, fund, r, kind, amp, phase, mu, a_law, c_law, gcd, lcm
                ))  # fmt: skip
            out[j, i] = slow(a, b) if math.isnan(value) else value
    return out
