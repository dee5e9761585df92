"""The operating envelope of a design: a map over two physical axes (driver speed in rpm and
mean torque in N m, say), each grid cell coloured by its response, its contact marked, and the
Melnikov boundary drawn, with a legend an engineer reads without the paper.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

from gearengine.model.units import display_unit, field_label
from gearengine.studies.sweep.axes import is_dimensionless
from gearengine.studies.sweep.points import SweepPoint
from gearengine.studies.sweep.request import SweepRequest

CLASSES: list[tuple[str, str]] = [
    ("periodic 1T", "#c6dbef"),
    ("periodic 2T", "#6baed6"),
    ("periodic 4T", "#2171b5"),
    ("periodic, longer period", "#08306b"),
    ("quasi-periodic", "#fdae6b"),
    ("chaotic", "#d62728"),
    ("diverged", "#636363"),
]
"""Response classes of the map, in legend order, with their colours."""


def response_class(p: SweepPoint) -> int:
    """Index in ``CLASSES`` of a point's response."""
    if p.classification == "periodic":
        return {1: 0, 2: 1, 4: 2}.get(p.period or 0, 3)
    return {"quasi_periodic": 4, "chaotic": 5}.get(p.classification, 6)


def axis_label(name: str) -> str:
    """ "driver speed [rpm]", "half backlash [µm]" (``model.units.field_label``), or the alias
    for a dimensionless axis."""
    return f"{name} (dimensionless)" if is_dimensionless(name) else field_label(name)


def _grid(request: SweepRequest) -> tuple[np.ndarray, np.ndarray]:
    """Both axes' grids in display units."""
    out = []
    for axis, values in zip(request.axes, request.grids(), strict=True):
        factor = 1.0 if is_dimensionless(axis.parameter) else display_unit(axis.parameter)[1]
        out.append(np.asarray(values) * factor)
    return out[0], out[1]


COEXIST_COLOUR = "#6a3d9a"
"""Hatch colour of the cells where the basin starts found more than one attractor."""


def _hatch_cells(ax: Axes, g0: np.ndarray, g1: np.ndarray, cells: list[tuple[int, int]]) -> None:
    """Hatch the grid cells (i, j) (centred on g0[i], g1[j], as pcolormesh's nearest shading)."""
    for i, j in cells:
        x0, x1 = _cell_edges(g0, i)
        y0, y1 = _cell_edges(g1, j)
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, facecolor="none", linewidth=0,
                               edgecolor=COEXIST_COLOUR, hatch="\\\\", zorder=2))  # fmt: skip


def _cell_edges(g: np.ndarray, i: int) -> tuple[float, float]:
    """Edges of cell i of a grid of centres g (half-way to the neighbours)."""
    step = float(g[1] - g[0]) if g.size > 1 else 1.0
    lo = g[i] - (g[i] - g[i - 1]) / 2 if i > 0 else g[i] - step / 2
    hi = g[i] + (g[i + 1] - g[i]) / 2 if i + 1 < g.size else g[i] + step / 2
    return float(lo), float(hi)


def envelope_map(request: SweepRequest, points: Sequence[SweepPoint]) -> Figure:
    """The map: response classes as colours, tooth separation and back-flank impacts as
    markers, the Melnikov boundary (where the criterion starts allowing chaos) as a black line
    with the chaos-possible side hatched, and with basins the cells where several attractors
    coexist cross-hatched in purple."""
    ax0, ax1 = request.axes
    g0, g1 = _grid(request)
    s0, s1 = request.grids()
    i0 = {v: i for i, v in enumerate(s0)}
    i1 = {v: i for i, v in enumerate(s1)}
    cls = np.full((len(g1), len(g0)), np.nan)
    mel = np.full((len(g1), len(g0)), np.nan)  # NaN: the criterion does not apply there
    marks: dict[str, list[tuple[float, float]]] = {"single_sided": [], "double_sided": []}
    several: list[tuple[int, int]] = []  # cells where basins found coexisting attractors
    for p in points:
        if p.branch == "down":
            continue
        i, j = i0[p.values[ax0.parameter]], i1[p.values[ax1.parameter]]
        cls[j, i] = response_class(p)
        if p.melnikov_chaos_possible is not None:
            mel[j, i] = 1.0 if p.melnikov_chaos_possible else 0.0
        if p.impact_regime in marks:
            marks[p.impact_regime].append((g0[i], g1[j]))
        if p.attractors is not None and len(p.attractors) > 1:
            several.append((i, j))
    fig = Figure(figsize=(10.0, 6.4), layout="constrained")
    ax = fig.subplots()
    cmap = ListedColormap([c for _, c in CLASSES])
    norm = BoundaryNorm(np.arange(len(CLASSES) + 1) - 0.5, cmap.N)
    ax.pcolormesh(g0, g1, np.ma.masked_invalid(cls), cmap=cmap, norm=norm, shading="nearest")
    for regime, style in (("single_sided", ("o", "white", 9)), ("double_sided", ("x", "k", 22))):
        if marks[regime]:
            xs, ys = zip(*marks[regime], strict=True)
            ax.scatter(xs, ys, marker=style[0], c=style[1], s=style[2], linewidths=0.8,
                       edgecolors="k" if style[0] == "o" else None, zorder=3)  # fmt: skip
    _hatch_cells(ax, g0, g1, several)
    applies = np.isfinite(mel)
    if len(g0) > 1 and len(g1) > 1:
        judged = np.ma.masked_invalid(mel)  # the region and its boundary only where it applies
        if np.nanmax(mel, initial=0.0) > 0.5:
            ax.contourf(g0, g1, judged, levels=[0.5, 1.5], colors="none", hatches=["//"])
        if np.nanmin(mel, initial=1.0) < 0.5 < np.nanmax(mel, initial=0.0):
            ax.contour(g0, g1, judged, levels=[0.5], colors="black", linewidths=1.6)
        if applies.any() and not applies.all():  # a map wholly outside says so in the legend
            ax.contourf(g0, g1, (~applies).astype(float), levels=[0.5, 1.5], colors="none",
                        hatches=["."])  # fmt: skip
    ax.set_xlabel(axis_label(ax0.parameter))
    ax.set_ylabel(axis_label(ax1.parameter))
    s = request.settings
    ax.set_title(
        "Operating envelope: response of the gear pair at each operating point\n"
        f"RK4, {s.steps_per_period} steps per excitation period, {s.lengths_text()} per point",
        fontsize=10,
    )
    present = sorted({int(c) for c in cls[np.isfinite(cls)]})
    handles = [
        Patch(facecolor=CLASSES[k][1], edgecolor="0.4", label=CLASSES[k][0]) for k in present
    ]
    handles += [
        Line2D([], [], ls="", marker="o", mfc="white", mec="k", ms=4,
               label="teeth separate (impacts on the drive flank)"),
        Line2D([], [], ls="", marker="x", c="k", ms=5, label="back-flank impacts"),
        Patch(facecolor="none", edgecolor="k", hatch="//",
              label="Melnikov criterion: chaos possible\n(black line: its boundary)"),
    ]  # fmt: skip
    if not applies.any():
        handles[-1] = Patch(facecolor="none", edgecolor="none", label=(
            "Melnikov criterion: does not apply anywhere\non this map (mean load above the "
            "critical\ntorque: no saddle, no homoclinic orbit)"))  # fmt: skip
    elif not applies.all():
        words = "Melnikov criterion does not apply\n(mean load above the critical torque:\n"
        handles.append(Patch(facecolor="none", edgecolor="k", hatch=".",
                             label=words + "no saddle, no homoclinic orbit)"))  # fmt: skip
    if several:
        handles.append(Patch(facecolor="none", edgecolor=COEXIST_COLOUR, hatch="\\\\",
                             label="attractors coexist\n(basins: several found)"))  # fmt: skip
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8,
              title="response", title_fontsize=9, frameon=False)  # fmt: skip
    return fig
