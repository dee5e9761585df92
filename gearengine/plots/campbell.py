"""The Campbell diagram of a gear train (``systems.gear_train.campbell``): natural frequencies
against driver speed, the excitation order lines, and their crossings marked in rpm."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from gearengine.plots.style import ImageFormat, figure_bytes
from gearengine.systems.gear_train.campbell import Campbell

LINE_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2")
"""Colours of the order lines, in the order of ``Campbell.lines``."""


def campbell_figure(result: Campbell, fmt: ImageFormat = "png") -> bytes:
    """The diagram as PNG or SVG bytes: modes as horizontal lines (the mesh mode bold, each
    labelled with its mesh energy share), order lines through the origin, crossings as dots
    with their speed, the design speed and the mesh resonance as vertical lines."""
    lo, hi = result.speed_range_rpm
    fig = Figure(figsize=(9.5, 6.4), layout="constrained")
    ax = fig.add_subplot()
    top = 1.15 * max(m.frequency_hz for m in result.modes.modes)
    for k, mode in enumerate(result.modes.modes):
        mesh = k == result.modes.mesh_mode
        ax.axhline(mode.frequency_hz, color="0.15" if mesh else "0.55", lw=2.0 if mesh else 1.0,
                   zorder=1)  # fmt: skip
        label = f"mode {k + 1}: {mode.frequency_hz:.1f} Hz, mesh {mode.mesh_energy_share:.0%}"
        ax.annotate(label + (" (mesh mode)" if mesh else ""), xy=(lo, mode.frequency_hz),
                    xytext=(4, 3), textcoords="offset points", fontsize=8,
                    fontweight="bold" if mesh else "normal", color="0.15")  # fmt: skip
    speeds = np.linspace(0.0, hi, 2)
    for line, colour in zip(result.lines, LINE_COLOURS * 2, strict=False):
        ax.plot(speeds, line.order * speeds / 60.0, color=colour, lw=1.3, zorder=2,
                label=f"{line.name} (order {line.order:g})")  # fmt: skip
    colours = {line.name: c for line, c in zip(result.lines, LINE_COLOURS * 2, strict=False)}
    for c in result.crossings:
        ax.plot(c.speed_rpm, c.frequency_hz, "o", ms=6 if c.mesh_mode else 4,
                color=colours[c.line], mec="k", mew=0.6, zorder=3)  # fmt: skip
        ax.annotate(f"{c.speed_rpm:,.0f}", xy=(c.speed_rpm, c.frequency_hz), xytext=(3, -10),
                    textcoords="offset points", fontsize=7, color=colours[c.line])  # fmt: skip
    ax.axvline(result.speed_rpm, color="k", ls="--", lw=1.0, zorder=1,
               label=f"design speed {result.speed_rpm:,.0f} rpm")  # fmt: skip
    ax.axvline(result.mesh_resonance_rpm, color="#d62728", ls=":", lw=1.2, zorder=1,
               label=f"mesh resonance {result.mesh_resonance_rpm:,.0f} rpm")  # fmt: skip
    ax.set_xlim(lo, hi)
    ax.set_ylim(0.0, top)
    ax.set_xlabel("driver speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title("Campbell diagram of the gear train (linearised in contact)")
    ax.legend(loc="lower right", fontsize=8, framealpha=0.95, bbox_to_anchor=(1.0, 0.12))
    ax.grid(alpha=0.25)
    return figure_bytes(fig, fmt)
