"""The probability map of a robustness study: over speed x torque (two axes) each panel colours
one outcome's probability, each cell labelled with its 95 % upper bound; over one axis the
probability with its interval band. Rendering only (``studies.robustness.study`` computes).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from gearengine.model.units import display_unit
from gearengine.plots.style import ImageFormat, figure_bytes
from gearengine.studies.robustness.results import RobustnessResult
from gearengine.studies.robustness.study import RobustnessRequest

PANELS = ("chaotic", "separation", "back_flank", "dynamic_factor_above_limit")
TITLES = {
    "chaotic": "P(chaotic)",
    "separation": "P(tooth separation)",
    "back_flank": "P(back-flank impacts)",
    "dynamic_factor_above_limit": "P(dynamic factor > {limit:g})",
}


def _axis_label(name: str) -> str:
    return f"{name} [{display_unit(name)[0]}]"


def robustness_figure(
    request: RobustnessRequest, result: RobustnessResult, fmt: ImageFormat = "png"
) -> bytes:
    """The probability map (two axes), curves (one axis) or bars (one point) of ``result``."""
    axes = [a.parameter for a in request.axes]
    fig = Figure(figsize=(12.0, 8.0) if len(axes) == 2 else (10.0, 6.5), layout="constrained")
    grid = fig.subplots(2, 2, squeeze=False)
    n = result.points[0].samples if result.points else 0
    fig.suptitle(
        f"Robustness over the tolerances: {n} samples (seed {result.seed}) per point; "
        "numbers in the cells: 95 % upper bound",
        fontsize=11,
    )
    for ax, name in zip(grid.flat, PANELS, strict=True):
        title = TITLES[name].format(limit=request.dynamic_factor_limit)
        probs = [p.probabilities[name] for p in result.points]
        value = np.array([np.nan if p.value is None else p.value for p in probs])
        upper = np.array([np.nan if p.interval is None else p.interval[1] for p in probs])
        if len(axes) == 2:
            xs = sorted({p.shown[axes[0]] for p in result.points})
            ys = sorted({p.shown[axes[1]] for p in result.points})
            shape = (len(ys), len(xs))
            mesh = ax.pcolormesh(xs, ys, value.reshape(shape), vmin=0.0, vmax=1.0,
                                 cmap="magma_r", shading="nearest")  # fmt: skip
            for k, p in enumerate(result.points):
                if not np.isnan(upper[k]):
                    dark = value[k] > 0.55
                    ax.text(p.shown[axes[0]], p.shown[axes[1]], f"{upper[k]:.2f}".lstrip("0"),
                            ha="center", va="center", fontsize=5.5,
                            color="white" if dark else "black")  # fmt: skip
            ax.set_xlabel(_axis_label(axes[0]))
            ax.set_ylabel(_axis_label(axes[1]))
            fig.colorbar(mesh, ax=ax, label="probability")
        elif len(axes) == 1:
            xs = [p.shown[axes[0]] for p in result.points]
            lower = [np.nan if p.interval is None else p.interval[0] for p in probs]
            ax.fill_between(xs, lower, upper, alpha=0.3, label="95 % interval")
            ax.plot(xs, value, marker="o", ms=3, label="estimate")
            ax.set_xlabel(_axis_label(axes[0]))
            ax.set_ylim(-0.02, 1.02)
            ax.legend(fontsize=8)
        else:
            ax.bar([0], value, yerr=[[value[0] - probs[0].interval[0]],
                   [upper[0] - value[0]]], capsize=6)  # fmt: skip
            ax.set_xticks([])
            ax.set_ylim(0.0, 1.0)
        ax.set_title(title, fontsize=10)
    return figure_bytes(fig, fmt)
