"""Figures engineers read: the four-panel response of an analysis (paper Figs. 7-11, 14-16) and
Melnikov threshold curves (paper Figs. 5, 12, 18), as PNG or SVG bytes.

Rendering only: every number drawn comes from a result object of the engine.
"""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from gearengine.analysis import AnalysisResult
from gearengine.homoclinic.schemas import ThresholdCurve
from gearengine.numerics.results import SpectrumPeak
from gearengine.plots.style import ImageFormat, figure_bytes, symbol


def analysis_figure(result: AnalysisResult, fmt: ImageFormat = "png") -> bytes:
    """(a) time history, (b) phase plane, (c) Poincare section, (d) amplitude spectrum."""
    num = result.numerics
    fig = Figure(figsize=(10, 7.5), layout="constrained")
    axes = fig.subplots(2, 2)
    (ax_t, ax_p), (ax_s, ax_f) = axes
    hist = num.time_history
    period = f"{num.period}T-periodic" if num.period else num.classification.replace("_", "-")
    lle = "n/a" if num.lle is None else f"{num.lle:+.4f} ± {num.lle_stderr or 0.0:.4f}"
    mel = result.melnikov.chaos_possible
    fig.suptitle(
        f"{period} response   LLE λ₁ = {lle} per unit τ   "
        f"Melnikov: chaos {'possible' if mel else 'not possible' if mel is False else 'n/a'}",
        fontsize=11,
    )
    if hist is not None and hist.t:
        t, x, v = (np.asarray(a) for a in (hist.t, hist.x, hist.v))
        ax_t.plot(t, x, lw=0.8, color="C0")
        ax_p.plot(x, v, lw=0.6, color="C0")
    if num.poincare:
        pts = np.asarray(num.poincare)
        ax_p.plot(pts[:, 0], pts[:, 1], "o", ms=3, color="C3", label="Poincaré points")
        ax_s.plot(pts[:, 0], pts[:, 1], "o", ms=2.5, color="C3")
    for ax in (ax_t, ax_p, ax_s):
        for edge in (-1.0, 1.0):  # clearance edges |x| = 1 (Eq. 8)
            (ax.axhline if ax is ax_t else ax.axvline)(
                edge, color="0.45", lw=0.7, ls=":", label=CLEARANCE if edge > 0 else None
            )
    # one legend for panels (a)-(c), under them, where it hides no data
    fig.legend(*ax_p.get_legend_handles_labels(), loc="outside lower center", ncols=2, fontsize=8.5)
    x_label, v_label = (
        r"$x$ (units of the half backlash $b$)",
        r"$\dot x = dx/d\tau$ ($b$ per unit $\tau$)",
    )
    ax_t.set(title="(a) time history", xlabel=r"$\tau$ (dimensionless time)", ylabel=x_label)
    ax_p.set(title="(b) phase plane", xlabel=x_label, ylabel=v_label)
    ax_s.set(title="(c) Poincaré section (one point per $T_0$)", xlabel=x_label, ylabel=v_label)
    _spectrum(ax_f, num.spectrum_peaks, result.settings.record_periods)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    return figure_bytes(fig, fmt)


CLEARANCE = "|x| = 1: clearance edges"


def _spectrum(ax: Axes, peaks: list[SpectrumPeak], record_periods: int) -> None:
    """The spectrum the JSON reports (``numerics.spectrum_peaks``): its largest peaks as stems,
    so the figure and the numbers agree; computed over the whole record (``record_periods``
    sampling intervals), Hann window, amplitude-corrected (a sinusoid A cos wt peaks at A)."""
    ax.set(
        title="(d) amplitude spectrum of x: largest peaks",
        xlabel=r"order: frequency / $\Omega_0$ (fundamental of the forcing)",
        ylabel="amplitude of x (units of b)",
    )
    ax.text(
        0.98, 0.97,
        f"x over the last {record_periods} periods $T_0$,\nHann window, amplitude-corrected\n"
        "(numerics.spectrum_peaks)",
        transform=ax.transAxes, ha="right", va="top", fontsize=7.5,
        bbox={"boxstyle": "round", "fc": "white", "ec": "0.8", "alpha": 0.85},
    )  # fmt: skip
    if not peaks:
        return
    order = np.array([p.order for p in peaks])
    amp = np.array([p.amplitude for p in peaks])
    ax.vlines(order, 0.0, amp, color="C0", lw=1.6)
    ax.plot(order, amp, "o", color="C0", ms=4)
    top = int(np.argmax(amp))
    ax.annotate(
        f"{amp[top]:.3g} at order {order[top]:.3g}",
        (order[top], amp[top]), xytext=(6, -2), textcoords="offset points", fontsize=8,
    )  # fmt: skip
    ax.set_xlim(0.0, max(1.05 * order.max(), 1.0))
    ax.set_ylim(0.0, 1.35 * amp.max())


def threshold_figure(
    curve: ThresholdCurve, fmt: ImageFormat = "png", design_frequency: float | None = None
) -> bytes:
    """Critical values of the parameter against the frequency, the no-chaos band shaded, and
    the design as a point at (``design_frequency``, ``curve.value``) when both are known."""
    fig = Figure(figsize=(8, 5.5), layout="constrained")
    ax = fig.subplots()
    w = np.asarray(curve.frequencies)
    lo, hi = _band(curve.no_chaos)
    sym, fsym = symbol(curve.parameter), symbol(curve.frequency_parameter)
    bands = {branch: _band(intervals) for branch, intervals in curve.branches.items()}
    styles = {"plus": ("C3", "-", "+"), "minus": ("C2", "--", "-")}
    if len(bands) == 2 and all(
        np.array_equal(a, b, equal_nan=True) for a, b in zip(*bands.values(), strict=True)
    ):  # one line drawn: one legend entry
        bands = {"both": next(iter(bands.values()))}
        styles["both"] = ("C3", "-", "\\pm")
    for branch, (blo, bhi) in bands.items():
        color, ls, sign = styles[branch]
        label = (
            "threshold of $M^+$ and $M^-$ (the branches coincide)"
            if branch == "both"
            else f"threshold of $M^{sign}$ ({branch} branch)"
        )
        ax.plot(w, blo, color=color, ls=ls, lw=1.3, label=label)
        ax.plot(w, bhi, color=color, ls=ls, lw=1.3)
    if curve.value is not None:
        ax.axhline(curve.value, color="k", lw=0.8, ls=":", label=f"design value of {sym}")
        if design_frequency is not None:
            ax.plot(
                design_frequency, curve.value, "*", ms=13, color="k", mfc="gold", zorder=5,
                label=f"design: {fsym} = {design_frequency:.4g}, {sym} = {curve.value:.4g}",
            )  # fmt: skip
    ax.set(
        xlabel=f"{fsym} (dimensionless frequency)",
        ylabel=sym,
        title=f"Melnikov thresholds of {sym} over {fsym}\nchaos possible outside the shaded band",
    )
    finite = np.abs(np.concatenate([lo, hi]))
    finite = finite[np.isfinite(finite) & (finite > 0.0)]
    # damping thresholds peak and fall; amplitude thresholds grow without bound at both ends
    span = (
        1.0
        if not finite.size
        else 1.15 * finite.max()
        if curve.parameter == "mu"
        else 5.0 * finite.min()
    )
    if curve.value is not None:
        span = max(span, 1.15 * abs(curve.value))
    bottom = 0.0 if curve.parameter == "mu" else -span
    ax.set_ylim(bottom, span)
    ax.fill_between(
        w, np.clip(lo, bottom, span), np.clip(hi, bottom, span), color="C0", alpha=0.18, lw=0,
        label="no sign change: no chaos",
    )  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    return figure_bytes(fig, fmt)


def _band(rows: list[list[tuple[float | None, float | None]]]) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper ends of the first interval per row (NaN where empty, +-inf unbounded)."""
    lo = np.full(len(rows), np.nan)
    hi = np.full(len(rows), np.nan)
    for i, intervals in enumerate(rows):
        if intervals:
            a, b = intervals[0]
            lo[i] = -np.inf if a is None else a
            hi[i] = np.inf if b is None else b
    return lo, hi
