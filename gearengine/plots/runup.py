"""A run-up as an engineer reads it: driver speed on x, the DTE envelope going up and coming
down in two colours over the quasi-static hysteresis loop, jumps marked, the Melnikov window
shaded, and below it bands of the contact status (drive flank / no contact / both flanks) of
each branch; the finite-time Lyapunov exponent in a third panel.
"""

from __future__ import annotations

from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from gearengine.plots.style import ImageFormat, figure_bytes
from gearengine.studies.runup.results import RunupBranch, RunupResult

COLOURS = {"up": "#1f77b4", "down": "#d62728"}
"""Line colour of each branch."""
CONTACT_COLOURS = {"drive_flank": "#c7e9c0", "separation": "#fdae6b", "both_flanks": "#a50f15"}
"""Band colour of each contact status."""
CONTACT_WORDS = {
    "drive_flank": "drive flank (always in contact)",
    "separation": "loses contact at times (tooth separation)",
    "both_flanks": "both flanks (back-flank impacts)",
}


def _branch_line(ax, branch: RunupBranch, name: str) -> None:  # type: ignore[no-untyped-def]
    xs, ys = [], []
    for b in branch.bins:
        lo, hi = b.speed_rpm
        xs.append(0.5 * (lo + hi))
        ys.append(b.dte_peak_to_peak_um)
    ax.plot(xs, [float("nan") if y is None else y for y in ys], color=COLOURS[name], lw=1.6,
            label=f"run-{name}", zorder=3)  # fmt: skip
    for j in branch.jumps:
        ax.annotate(
            "", xy=(j.speed_rpm, j.to_um), xytext=(j.speed_rpm, j.from_um),
            arrowprops={"arrowstyle": "->", "color": COLOURS[name], "lw": 1.4}, zorder=4,
        )  # fmt: skip
        ax.axvline(j.speed_rpm, color=COLOURS[name], lw=0.8, ls=":", zorder=1)
        lag = "" if j.lag_rpm is None else f" (lag {j.lag_rpm:+.0f})"
        ax.annotate(f"{j.speed_rpm:.0f} rpm{lag}", xy=(j.speed_rpm, 0.5 * (j.from_um + j.to_um)),
                    xytext=(4, 0), textcoords="offset points", color=COLOURS[name],
                    fontsize=7, va="center", ha="left")  # fmt: skip


def runup_figure(result: RunupResult, fmt: ImageFormat = "png", title: str | None = None) -> bytes:
    """The run-up figure as PNG or SVG bytes."""
    fig = Figure(figsize=(9.0, 6.4))
    grid = fig.add_gridspec(3, 1, height_ratios=[3.2, 0.9, 1.3], hspace=0.08)
    ax = fig.add_subplot(grid[0])
    bands = fig.add_subplot(grid[1], sharex=ax)
    lle = fig.add_subplot(grid[2], sharex=ax)
    for lo, hi in result.melnikov_windows_rpm:
        for a in (ax, lle):
            a.axvspan(lo, hi, color="#e0d4f5", alpha=0.55, lw=0, zorder=0)
    qs = result.quasi_static
    for name in ("up", "down"):
        pts = getattr(qs, name).points
        ax.plot([p.speed_rpm for p in pts],
                [float("nan") if p.dte_peak_to_peak_um is None else p.dte_peak_to_peak_um
                 for p in pts],
                color=COLOURS[name], lw=4.0, alpha=0.22, zorder=2,
                label=f"quasi-static {name} (continuation)")  # fmt: skip
    rows = []
    for name in ("up", "down"):
        branch = getattr(result, name)
        if branch is None:
            continue
        _branch_line(ax, branch, name)
        rows.append(name)
        for b in branch.bins:
            colour = CONTACT_COLOURS.get(b.contact or "", "#bdbdbd")
            y = len(rows) - 1
            bands.barh(y, b.speed_rpm[1] - b.speed_rpm[0], left=b.speed_rpm[0], height=0.8,
                       color=colour, lw=0)  # fmt: skip
        lle.plot([0.5 * sum(b.speed_rpm) for b in branch.bins],
                 [float("nan") if b.lle is None else b.lle for b in branch.bins],
                 color=COLOURS[name], lw=1.2)  # fmt: skip
    bands.set_yticks(range(len(rows)), [f"run-{r}" for r in rows], fontsize=8)
    bands.set_ylim(-0.6, len(rows) - 0.4)
    bands.tick_params(axis="x", labelbottom=False)
    ax.tick_params(axis="x", labelbottom=False)
    lle.axhline(0.0, color="black", lw=0.6)
    lle.set_ylabel("FTLE\n(per unit τ)", fontsize=8)
    lle.set_xlabel("driver speed [rpm]")
    ax.set_ylabel("DTE peak to peak [µm]")
    ax.grid(alpha=0.3)
    lle.grid(alpha=0.3)
    handles, _ = ax.get_legend_handles_labels()
    handles += [Patch(color=c, label=CONTACT_WORDS[k]) for k, c in CONTACT_COLOURS.items()]
    if result.melnikov_windows_rpm:
        handles.append(Patch(color="#e0d4f5", label="Melnikov: chaos possible"))
    handles.append(Line2D([], [], color="grey", ls=":", label="jump (arrow: from -> to)"))
    ax.legend(handles=handles, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title(title or f"Run-up over {result.duration_s:g} s: DTE envelope against speed",
                 fontsize=10)  # fmt: skip
    return figure_bytes(fig, fmt)
