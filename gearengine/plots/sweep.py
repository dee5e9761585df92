"""Figures of a sweep (matplotlib, Agg): PNG or SVG bytes.

* One axis, the bifurcation diagram: x of the stroboscopic (Poincare) points against the
  parameter, the largest Lyapunov exponent underneath, the Melnikov threshold marked and the
  range where the Melnikov function changes sign shaded (paper Figs. 6, 13).
* Two axes, the chaos map: each point coloured by its LLE, the Melnikov boundary (zero of the
  sign-change strength, ``thresholds.sign_change_strength``) overlaid with the chaos-possible
  side hatched, and a table of agreement between the numerical and the Melnikov verdicts.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import TwoSlopeNorm
from matplotlib.figure import Figure

from gearengine.homoclinic.boundary import chaos_intervals_from, flips, strength_at
from gearengine.homoclinic.grid import strength_grid
from gearengine.model.aliases import ALIASES, get_alias
from gearengine.model.fields import is_integer_field
from gearengine.model.params import GearParams
from gearengine.model.units import display_unit
from gearengine.plots.envelope import axis_label, envelope_map
from gearengine.plots.style import LLE_LABEL, SYMBOLS, ImageFormat, figure_bytes
from gearengine.studies.sweep.axes import is_dimensionless
from gearengine.studies.sweep.export import agreement_table
from gearengine.studies.sweep.points import SweepBifurcation, SweepPoint
from gearengine.studies.sweep.request import SweepRequest

BOUNDARY_GRID = 160
"""Samples per axis of the sign-change strength for the Melnikov boundary."""
PHYSICAL_BOUNDARY_GRID = 60
"""Samples along a physical axis (each one converts the design)."""


def sweep_figure(
    request: SweepRequest,
    points: Sequence[SweepPoint],
    fmt: ImageFormat,
    bifurcations: Sequence[SweepBifurcation] | None = None,
) -> bytes:
    """The sweep's figure, bifurcation diagram or chaos map, as PNG or SVG bytes; the located
    ``bifurcations`` (``SweepResult.bifurcations``) are marked on a bifurcation diagram."""
    if len(request.axes) == 1:
        fig = bifurcation(request, points, bifurcations)
    elif all(is_dimensionless(a.parameter) for a in request.axes):
        fig = chaos_map(request, points)
    else:
        fig = envelope_map(request, points)
    return figure_bytes(fig, fmt)


def bifurcation_label(b: SweepBifurcation) -> str:
    """E.g. "1T→2T at F_e1 = 0.21194" (the period after is "?" when none was found)."""
    after = f"{b.period_after}T" if b.period_after is not None else "?"
    return f"{b.period_before}T→{after} at {b.parameter} = {b.value:.5f}"


def _mark_bifurcations(top: Axes, bottom: Axes, bifurcations: Sequence[SweepBifurcation]) -> None:
    """Vertical lines at the located points, labelled on the diagram (``bifurcation_label``)."""
    for b in bifurcations:
        if b.value is None:
            continue
        colour = "tab:green" if b.branch == "up" else "tab:purple"
        for ax in (top, bottom):
            ax.axvline(b.value, c=colour, ls=":", lw=0.9)
        top.annotate(
            bifurcation_label(b), (b.value, 0.98), xycoords=("data", "axes fraction"),
            rotation=90, ha="right", va="top", fontsize=7, color=colour,
        )  # fmt: skip


def _fixed(request: SweepRequest) -> str:
    """The design's other parameters, for the title."""
    swept = {a.parameter for a in request.axes}
    parts = []
    for alias in ALIASES:
        value = get_alias(request.params, alias)
        if alias not in swept and value:
            parts.append(f"{SYMBOLS[alias]} = {value:g}")
    return ", ".join(parts)


def _settings_note(request: SweepRequest) -> str:
    s = request.settings
    x0 = ", ".join(f"{v:g}" for v in s.initial_state)
    how = "continuation" if request.continuation else f"$(x, \\dot x)_0$ = ({x0})"
    return f"RK4, {s.steps_per_period} steps per $T_0$, {s.lengths_text()}, {how}"


def bifurcation(
    request: SweepRequest,
    points: Sequence[SweepPoint],
    bifurcations: Sequence[SweepBifurcation] | None = None,
) -> Figure:
    """Poincare x against the parameter, the LLE underneath, the Melnikov threshold marked, and
    the located bifurcation points (continuation sweeps) as labelled vertical lines."""
    axis = request.axes[0]
    name = axis.parameter
    physical = not is_dimensionless(name)
    factor = display_unit(name)[1] if physical else 1.0
    fig = Figure(figsize=(8.0, 6.4), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[2.2, 1.0])
    colours = {None: "black", "up": "tab:blue", "down": "tab:orange"}
    branches = sorted({p.branch for p in points}, key=lambda b: b or "")
    for branch in branches:
        mine = [p for p in points if p.branch == branch]
        xs = [p.values[name] * factor for p in mine for _ in p.poincare_x or []]
        ys = [x for p in mine for x in p.poincare_x or []]
        suffix = f", branch {branch}" if branch else ""
        top.scatter(xs, ys, s=0.6, c=colours[branch], marker=".", linewidths=0,
                    label="Poincaré points" + suffix)  # fmt: skip
        lle = sorted((p.values[name] * factor, p.lle) for p in mine if p.lle is not None)
        bottom.plot(*zip(*lle, strict=True), lw=0.9, c=colours[branch],
                    label=r"$\lambda_{\max}$" + suffix)  # fmt: skip
    grid = request.grids()[0]
    lo, hi = min(grid), max(grid)

    def path(v: float) -> GearParams:
        return request.point({name: v})

    # the boundary of the points themselves: each point's verdict is /v1/melnikov's for it
    if request.design is not None and is_integer_field(request.design, name):
        # a tooth count has no values between the grid's: no threshold to locate, only the
        # verdict of each whole value, shaded over its unit cell
        crossings: list[float] = []
        chaos = [[v - 0.5, v + 0.5] for v in grid if strength_at(path(v)) > 0.0]
    else:
        crossings = flips(path, lo, hi, PHYSICAL_BOUNDARY_GRID if physical else BOUNDARY_GRID)
        chaos = chaos_intervals_from(path, [lo, *crossings, hi])
    symbol = axis_label(name) if physical else SYMBOLS[name]
    for ax in (top, bottom):
        for e0, e1 in chaos:
            ax.axvspan(e0 * factor, e1 * factor, color="tab:red", alpha=0.08, lw=0)
        for k, v in enumerate(crossings):
            label = f"Melnikov threshold {symbol} = {v * factor:.4g}" if k == 0 else None
            ax.axvline(v * factor, c="tab:red", ls="--", lw=1.0, label=label)
    _mark_bifurcations(top, bottom, bifurcations or [])
    bottom.axhline(0.0, c="grey", lw=0.6)
    top.set_ylabel(r"$x$ at $\tau = n T_0$ (units of $b$)")
    bottom.set_ylabel(LLE_LABEL)
    bottom.set_xlabel(symbol if physical else f"{symbol} (dimensionless)")
    bottom.set_xlim(lo * factor, hi * factor)
    top.legend(loc="best", markerscale=12, fontsize=8, framealpha=0.9)
    bottom.legend(loc="best", fontsize=8, framealpha=0.9)
    top.set_title(
        f"Bifurcation diagram in {symbol}: {_fixed(request)}\n"
        f"{_settings_note(request)}; shaded: Melnikov function changes sign",
        fontsize=10,
    )
    return fig


def chaos_map(request: SweepRequest, points: Sequence[SweepPoint]) -> Figure:
    """The (axis 0, axis 1) plane coloured by LLE, the Melnikov boundary and an agreement
    table. With both branches a cell shows the larger LLE of the two."""
    ax0, ax1 = request.axes
    s0, s1 = request.grids()
    v0, v1 = np.array(s0), np.array(s1)
    lle = np.full((ax1.num, ax0.num), np.nan)
    index0 = {v: i for i, v in enumerate(s0)}
    index1 = {v: i for i, v in enumerate(s1)}
    for p in points:
        if p.lle is None:
            continue
        i, j = index0[p.values[ax0.parameter]], index1[p.values[ax1.parameter]]
        lle[j, i] = p.lle if np.isnan(lle[j, i]) else max(lle[j, i], p.lle)
    fig = Figure(figsize=(8.4, 7.2), layout="constrained")
    ax, tab = fig.subplots(2, 1, height_ratios=[5.0, 1.0])
    finite = lle[np.isfinite(lle)]
    span = float(np.max(np.abs(finite))) if finite.size else 1.0
    norm = TwoSlopeNorm(0.0, -span or -1.0, span or 1.0)
    mesh = ax.pcolormesh(v0, v1, np.ma.masked_invalid(lle), cmap="RdBu_r", norm=norm,
                         shading="nearest")  # fmt: skip
    ax.set_facecolor("0.7")
    fig.colorbar(mesh, ax=ax, label=LLE_LABEL + "; grey: diverged", shrink=0.9)
    g0 = np.linspace(v0.min(), v0.max(), BOUNDARY_GRID)
    g1 = np.linspace(v1.min(), v1.max(), BOUNDARY_GRID)
    assert request.params is not None
    strength = strength_grid(request.params, (ax0.parameter, ax1.parameter), g0, g1, request.point)
    if np.nanmin(strength) < 0.0 < np.nanmax(strength):
        ax.contourf(g0, g1, strength, levels=[0.0, np.inf], colors="none", hatches=["//"])
        ax.contour(g0, g1, strength, levels=[0.0], colors="black", linewidths=1.6)
    ax.plot([], [], c="black", lw=1.6, label="Melnikov boundary (hatched: chaos possible)")
    outside = np.isnan(strength)  # no saddle there (|F_m| >= F_crit): the criterion does not apply
    if outside.any():
        ax.contourf(g0, g1, outside.astype(float), levels=[0.5, 1.5], colors="none",
                    hatches=["."])  # fmt: skip
        label = "Melnikov criterion does not apply (no saddle)"
        ax.fill([], [], fill=False, hatch=".", label=label)
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    ax.set_xlabel(f"{SYMBOLS[ax0.parameter]} (dimensionless)")
    ax.set_ylabel(f"{SYMBOLS[ax1.parameter]} (dimensionless)")
    ax.set_title(
        f"Chaos map, colour = largest Lyapunov exponent: {_fixed(request)}\n"
        f"{_settings_note(request)}",
        fontsize=10,
    )
    agree = agreement_table(points)
    tab.axis("off")
    tab.table(
        cellText=[
            ["numerically chaotic", agree.chaotic_inside, agree.chaotic_outside],
            [
                "not chaotic (periodic, quasi-periodic, diverged)",
                agree.regular_inside,
                agree.regular_outside,
            ],
        ],
        colLabels=["points", "inside Melnikov region", "outside Melnikov region"],
        colWidths=[0.5, 0.25, 0.25],
        cellLoc="center",
        bbox=[0.0, 0.0, 1.0, 1.0],
    )
    tab.set_title("Agreement of the numerical and the Melnikov verdicts", fontsize=9)
    return fig
