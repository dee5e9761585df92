"""Where the Melnikov verdict flips along a path through parameter space.

A path is any function from a number to a design's dimensionless parameters: an alias set on
the design, a change of running speed (every excitation frequency scaled together), a physical
field of a design converted at each value. The verdict flips where the sign-change strength
(``thresholds.sign_change_strength``: > 0 iff some homoclinic branch changes sign) crosses zero;
a scan of ``num`` values brackets each crossing and brentq locates it. Sweep plots, speed
windows and ``/v1/melnikov`` thus draw one boundary: the verdict of each point of the path.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np

from gearengine.homoclinic.coefficients import MeanLoad
from gearengine.homoclinic.thresholds import strength_at
from gearengine.model.params import GearParams

Path = Callable[[float], GearParams]
"""A path through parameter space: value -> dimensionless parameters."""


def flips(
    path: Path,
    lo: float,
    hi: float,
    num: int,
    xtol: float = 1e-10,
    mean_load: MeanLoad = "unperturbed",
) -> list[float]:
    """Values in [lo, hi] where the Melnikov verdict along ``path`` flips (flips closer than one
    of the ``num`` scan steps may be missed); ``xtol`` relative to the larger end; ``mean_load``
    where F_m goes (``coefficients.MeanLoad``)."""
    from scipy import optimize  # scipy loads in ~0.2 s; only root finding here needs it

    grid = np.linspace(min(lo, hi), max(lo, hi), num)
    s = [strength_at(path(float(v)), mean_load=mean_load) for v in grid]
    tol = xtol * max(abs(lo), abs(hi), 1e-300)
    return [
        float(
            optimize.brentq(lambda v: strength_at(path(v), mean_load=mean_load), g0, g1, xtol=tol)
        )
        for g0, g1, s0, s1 in zip(grid, grid[1:], s, s[1:], strict=False)
        if np.isfinite(s0) and np.isfinite(s1) and (s0 > 0.0) != (s1 > 0.0)
    ]


def chaos_intervals_from(
    path: Path, edges: list[float], mean_load: MeanLoad = "unperturbed"
) -> list[list[float]]:
    """The [a, b] pieces between consecutive ``edges`` (ascending: the ends and the flips)
    where the Melnikov criterion allows chaos along ``path``."""
    return [
        [a, b]
        for a, b in itertools.pairwise(edges)
        if strength_at(path(0.5 * (a + b)), mean_load=mean_load) > 0.0
    ]


def chaos_intervals(
    path: Path, lo: float, hi: float, num: int, mean_load: MeanLoad = "unperturbed"
) -> list[list[float]]:
    """[a, b] intervals of [lo, hi] where the Melnikov criterion allows chaos along ``path``."""
    edges = [min(lo, hi), *flips(path, lo, hi, num, mean_load=mean_load), max(lo, hi)]
    return chaos_intervals_from(path, edges, mean_load)
