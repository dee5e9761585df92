"""The sign-change strength on a grid of two parameters, for the chaos map's Melnikov boundary.

Each value is ``thresholds.strength_at(point({axis 0: a, axis 1: b}))``, without a validated
``GearParams`` per grid point: the aliases are set on the design's dumped data as
``aliases.with_aliases`` sets them, and the packed form of ``terms`` (the one door into the
kernels, as ``sign_change_strength`` takes it) is built from that data. A point whose compiled
strength falls back (NaN), and grids over a parameter that is not an alias (``Omega``), take
``strength_at`` of ``point``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from gearengine.homoclinic.coefficients import MeanLoad, loop_load, saddle_loop
from gearengine.homoclinic.terms import packed_data
from gearengine.homoclinic.thresholds import strength_at
from gearengine.model.aliases import ALIASES, aliased_data
from gearengine.model.params import GearParams
from gearengine.systems.spur_pair.laws import melnikov_cubic


def _set_aliases(data: dict, values: dict[str, float]) -> dict | None:
    """``aliases.aliased_data``, or None where ``with_aliases`` would raise."""
    try:
        return aliased_data(data, values)
    except ValueError:
        return None


def strength_grid(
    params: GearParams,
    axes: tuple[str, str],
    g0: np.ndarray,
    g1: np.ndarray,
    point: Callable[[dict[str, float]], GearParams],
    mean_load: MeanLoad = "unperturbed",
) -> np.ndarray:
    """``strength_at(point({axes[0]: a, axes[1]: b}))`` for b in ``g1`` (rows) and a in ``g0``
    (columns), shape (g1.size, g0.size); NaN where the criterion does not apply.

    Args:
        params: the design the grid is drawn around (its other parameters stay fixed).
        axes: the two parameters (aliases of ``model.aliases``, or any name ``point`` knows).
        g0, g1: the values of each axis.
        point: the dimensionless parameters at one grid point (a sweep's ``point``).
        mean_load: where F_m goes (``coefficients.MeanLoad``).
    """
    p0, p1 = axes

    def slow(a: float, b: float) -> float:
        return strength_at(point({p0: a, p1: b}), mean_load=mean_load)

    if p0 not in ALIASES or p1 not in ALIASES:
        return np.array([[slow(a, b) for a in g0] for b in g1])
    a_law, c_law, _ = melnikov_cubic(params.backlash)
    if not saddle_loop(a_law, c_law):
        return np.full((g1.size, g0.size), math.nan)
    base = params.model_dump()
    out = np.empty((g1.size, g0.size))
    for j, b in enumerate(g1):
        for i, a in enumerate(g0):
            data = _set_aliases(base, {p0: a, p1: b})
            value = math.nan
            if data is not None:
                fm = loop_load(data, mean_load)
                if not saddle_loop(a_law, c_law, fm):
                    out[j, i] = math.nan  # |F_m| >= F_crit: the criterion does not apply
                    continue
                value = packed_data(data, a_law, c_law, fm).strength()
            out[j, i] = slow(a, b) if math.isnan(value) else value
    return out
