"""Where the Melnikov verdict flips along a path through parameter space.

A path is any function from a number to a design's dimensionless parameters: an alias set on
the design, a change of running speed (every excitation frequency scaled together), a physical
field of a design converted at each value. The verdict flips where the sign-change strength
(``thresholds.sign_change_strength``: > 0 iff some homoclinic branch changes sign) crosses zero;
a scan of ``num`` values brackets each crossing and brentq locates it. Sweep plots, speed
windows and ``/v1/melnikov`` thus draw one boundary: the verdict of each point of the path.

The speed windows of a design (``speed_window_scan``) follow the speed path: the design at its
speed moved to each driver speed [rpm] by scaling every excitation frequency together
(``model.aliases.with_speed_factor``; F~_er = e_r / b and F~_pr do not depend on speed).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np

from gearengine.homoclinic.coefficients import MeanLoad
from gearengine.homoclinic.schemas import MelnikovResult
from gearengine.homoclinic.thresholds import strength_at
from gearengine.model.aliases import with_speed_factor
from gearengine.model.design import Design
from gearengine.model.params import GearParams
from gearengine.model.reduction import DesignConversion, iso_mesh_stiffness
from gearengine.model.units import to_physical

Path = Callable[[float], GearParams]
"""A path through parameter space: value -> dimensionless parameters."""

WINDOW_SCAN = 240
"""Speeds sampled in the Melnikov window scan before brentq refines each edge."""
WINDOW_BOUND = 10.0
"""The window scan goes on past the requested range, while the last window is open, up to this
multiple of the design speed (beyond which no gear pair of the design runs): a window still
open there is reported open-ended."""


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


def speed_path(params: GearParams, speed_rpm: float) -> Path:
    """The design at ``speed_rpm`` moved to each speed [rpm] (every frequency scaled)."""
    return lambda rpm: with_speed_factor(params, rpm / speed_rpm)


def speed_windows(
    params: GearParams,
    speed_rpm: float,
    lo: float,
    hi: float,
    mean_load: MeanLoad = "unperturbed",
    num: int = WINDOW_SCAN,
) -> list[list[float]]:
    """Driver speeds [rpm] in [lo, hi] where some Melnikov branch changes sign: the design at
    ``speed_rpm`` moved to each speed by scaling every excitation frequency together."""
    return chaos_intervals(speed_path(params, speed_rpm), lo, hi, num, mean_load)


def speed_window_scan(
    params: GearParams,
    speed_rpm: float,
    lo: float,
    hi: float,
    mean_load: MeanLoad = "unperturbed",
    find: bool = True,
) -> tuple[list[list[float]], float]:
    """(the speed windows [rpm], the end of the scan [rpm]) of the design at ``speed_rpm``: the
    scan ends at ``hi``, doubled while the criterion still allows chaos there, up to
    ``WINDOW_BOUND`` times the design speed; ``WINDOW_SCAN`` speeds sample [lo, hi] and as
    many per rpm the scan beyond it. ``find=False``: the end alone, no windows."""
    path = speed_path(params, speed_rpm)
    bound = max(hi, WINDOW_BOUND * speed_rpm)
    top = hi
    while top < bound and strength_at(path(top), mean_load=mean_load) > 0.0:
        top = min(2.0 * top, bound)
    if not find:
        return [], top
    scan = WINDOW_SCAN if top == hi else math.ceil(WINDOW_SCAN * (top - lo) / (hi - lo))
    return chaos_intervals(path, lo, top, scan, mean_load), top


def design_windows(
    params: GearParams, speed_rpm: float, rpm_range: tuple[float, float],
    mel: MelnikovResult, find: bool = True,
) -> tuple[list[list[float]], float] | None:  # fmt: skip
    """``speed_window_scan`` of the design at ``speed_rpm`` over ``rpm_range`` [rpm] with the
    mean load of its verdict ``mel``; None when the mean load F~_m (Eq. 9) leaves no saddle
    (|F~_m| >= F_crit, mean load in the unperturbed system): the criterion does not apply at
    this load and there are no windows to look for. Computed once at the top (``analysis``)
    and handed to the engineering block."""
    f_crit = mel.critical_mean_force
    if mel.mean_load == "unperturbed" and f_crit is not None and abs(params.mean_force) >= f_crit:
        return None
    lo, hi = rpm_range
    return speed_window_scan(params, speed_rpm, lo, hi, mel.mean_load, find)


def critical_torque(conv: DesignConversion, mel: MelnikovResult,
                    design: Design | None = None) -> float | None:  # fmt: skip
    """T_crit [N m]: the mean driver torque whose static mesh force T / r_a (balanced torques,
    Eq. 7) reaches F_crit b k_m; None without a critical load (no cubic with a, c > 0).

    With the ISO 6336 stiffness of ``design``, k_m grows with the load (below 100 N/mm), so
    the design's own k_m would give a T_crit that depends on the torque it was converted at:
    the answer is the torque at which it holds at its own stiffness, T = F_crit b k_m(T) r_a,
    by fixed-point iteration (a contraction: k_m ~ T^0.25 there), to 1e-9 relative."""
    if mel.critical_mean_force is None:
        return None
    r_a = float(conv.derived["base_radius_driver"].value)  # type: ignore[arg-type]
    t = to_physical("mesh_force", mel.critical_mean_force, conv.scales) * r_a
    if design is None or design.mesh.stiffness != "iso6336" or design.train is not None:
        return t
    per_stiffness = t / conv.mesh_stiffness_n_per_m
    for _ in range(LOAD_ITERATIONS):
        t, last = per_stiffness * iso_mesh_stiffness(design, t), t
        if abs(t - last) <= 1e-9 * t:
            break
    return t


LOAD_ITERATIONS = 60
"""At most this many fixed-point steps of a load-dependent T_crit (each the pair's ISO 6336
geometry at one torque, ``iso_mesh_stiffness``; a contraction by 1/4 a step needs about 15 for
1e-9)."""
