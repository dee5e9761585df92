"""The basin picture of one design: the plane of initial states (x, v) coloured by the attractor
each start settles on (``numerics.basins.labels``), each attractor's own strobes drawn on top,
the legend giving its basin fraction with its 95 % interval. Axes in µm and mm/s for a design
(x b, v b omega_n), in half backlashes and b omega_n for dimensionless params.
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from gearengine.analysis import AnalysisResult
from gearengine.numerics.results import BasinCounts
from gearengine.plots.style import ImageFormat, figure_bytes

CHAOTIC_COLOURS = ["#d62728", "#ff9896", "#8c1c13"]
"""Colours of chaotic (and quasi-periodic) attractors, in their order: reds, as on the maps."""
REGULAR_COLOURS = ["#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
                   "#bcbd22"]  # fmt: skip
"""Colours of periodic attractors in their order; more attractors cycle through them."""
DIVERGED_COLOUR, UNSETTLED_COLOUR = "#000000", "#d9d9d9"


def basin_scales(result: AnalysisResult) -> tuple[float, float, str, str]:
    """(x factor, v factor, x label, v label): display units per dimensionless unit."""
    eng = result.engineering
    if eng is None:
        return 1.0, 1.0, "x (half backlashes b)", r"v = dx/d$\tau$ (b $\omega_n$)"
    b_um = eng.half_backlash_um
    return (b_um, b_um / eng.time_scale_s * 1e-3, "relative displacement x b [µm]",
            "relative velocity v b ω_n [mm/s]")  # fmt: skip


def starts_words(counts: BasinCounts) -> str:
    """ "256 starts (16 x 16 grid) over x -30..30 µm, v -250..250 mm/s": the starts used and
    their box, in gear units with a design (``BasinCounts.box_um_mm_s``), else dimensionless."""
    how = "random" if counts.grid is None else f"{counts.grid[0]} x {counts.grid[1]} grid"
    if counts.box_um_mm_s is not None:
        (x0, x1), (v0, v1) = counts.box_um_mm_s
        box = f"x {x0:g}..{x1:g} µm, v {v0:g}..{v1:g} mm/s"
    else:
        (x0, x1), (v0, v1) = counts.box
        box = f"x {x0:g}..{x1:g} b, v {v0:g}..{v1:g} b ω_n"
    return f"{counts.starts} starts ({how}) over {box}"


def basins_figure(result: AnalysisResult, fmt: ImageFormat = "png") -> bytes:
    """The basin picture of an analysis run with ``settings.basins`` (PNG or SVG bytes).

    Raises ValueError when the analysis has no basins.
    """
    num = result.numerics
    if num.basins is None or num.attractors is None:
        raise ValueError("settings.basins: the basin picture needs an analysis with basins")
    counts, found = num.basins, num.attractors
    fx, fv, xlabel, vlabel = basin_scales(result)
    colours, seen = [], {True: 0, False: 0}
    for a in found:
        regular = a.classification == "periodic"
        palette = REGULAR_COLOURS if regular else CHAOTIC_COLOURS
        colours.append(palette[seen[regular] % len(palette)])
        seen[regular] += 1
    cmap = ListedColormap([UNSETTLED_COLOUR, DIVERGED_COLOUR, *colours])
    index = np.asarray(counts.labels) + 2  # unsettled (-2) 0, diverged (-1) 1, attractor k k + 2
    (x0, x1), (v0, v1) = counts.box
    fig = Figure(figsize=(7.2, 5.6))
    ax = fig.add_subplot()
    extent = (x0 * fx, x1 * fx, v0 * fv, v1 * fv)
    if counts.grid is not None:
        nx, nv = counts.grid
        ax.imshow(index.reshape(nv, nx), origin="lower", extent=extent, aspect="auto",
                  cmap=cmap, vmin=-0.5, vmax=cmap.N - 0.5, interpolation="nearest")  # fmt: skip
    else:
        assert result.settings.basins is not None
        eng = result.engineering
        b = 1.0 if eng is None else eng.half_backlash_um * 1e-6
        xy = np.asarray(result.settings.basins.states(b, b / (eng.time_scale_s if eng else 1.0)))
        xy = xy * (fx, fv)
        ax.scatter(xy[:, 0], xy[:, 1], c=index, cmap=cmap, vmin=-0.5, vmax=cmap.N - 0.5, s=12)
    for a, colour in zip(found, colours, strict=True):
        pts = np.asarray(a.strobes).reshape(-1, 2) * (fx, fv)
        ax.scatter(pts[:, 0], pts[:, 1], s=40 if a.period else 9, color=colour,
                   edgecolors="black", linewidths=0.9, zorder=3)  # fmt: skip
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(vlabel)
    handles = [
        Patch(color=c, label=f"{a.label}: {100 * a.fraction:.0f} % "
              f"[{100 * a.interval[0]:.0f}, {100 * a.interval[1]:.0f}]")
        for a, c in zip(found, colours, strict=True)
    ]  # fmt: skip
    for n, colour, what in ((counts.diverged, DIVERGED_COLOUR, "diverged"),
                            (counts.unsettled, UNSETTLED_COLOUR, "unsettled")):  # fmt: skip
        if n:
            handles.append(Patch(color=colour, label=f"{what}: {n} start{'s' * (n > 1)}"))
    ax.legend(
        handles=handles,
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
        title="attractor: basin fraction [95 % CI]",
        title_fontsize=8,
        frameon=False,
    )
    where = "" if result.engineering is None else f" at {result.engineering.speed_rpm:,.0f} rpm"
    ax.set_title(f"Basins of attraction{where}: {starts_words(counts)}\n"
                 "dots = each attractor's strobes", fontsize=9)  # fmt: skip
    return figure_bytes(fig, fmt)
