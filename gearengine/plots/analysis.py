"""Figures engineers read: the four-panel response of an analysis (paper Figs. 7-11, 14-16) and
Melnikov threshold curves (paper Figs. 5, 12, 18), as PNG or SVG bytes.

Rendering only: every number drawn comes from a result object of the engine.
"""

from __future__ import annotations

import numpy as np
from matplotlib import pyplot as plt

from gearengine.analysis import AnalysisResult
from gearengine.homoclinic.schemas import ThresholdCurve
from gearengine.plots.style import ImageFormat, figure_bytes, symbol


def analysis_figure(result: AnalysisResult, fmt: ImageFormat = "png") -> bytes:
    """(a) time history, (b) phase plane, (c) Poincare section, (d) amplitude spectrum."""
    num = result.numerics
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
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
        _spectrum(ax_f, t, x, num.sampling_interval)
    if num.poincare:
        pts = np.asarray(num.poincare)
        ax_p.plot(pts[:, 0], pts[:, 1], "o", ms=3, color="C3", label="Poincaré points")
        ax_p.legend(loc="upper right", fontsize=8)
        ax_s.plot(pts[:, 0], pts[:, 1], "o", ms=2.5, color="C3")
    for ax in (ax_t, ax_p, ax_s):
        for edge in (-1.0, 1.0):  # clearance edges |x| = 1 (Eq. 8)
            (ax.axhline if ax is ax_t else ax.axvline)(edge, color="0.6", lw=0.6, ls=":")
    ax_t.set(title="(a) time history", xlabel=r"$\tau$", ylabel=r"$x$")
    ax_p.set(title="(b) phase plane", xlabel=r"$x$", ylabel=r"$\dot x$")
    ax_s.set(title="(c) Poincaré section", xlabel=r"$x$", ylabel=r"$\dot x$")
    ax_f.set(
        title="(d) amplitude spectrum of x",
        xlabel=r"frequency / $\Omega_0$ (fundamental of the forcing)",
        ylabel="amplitude of x",
    )
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return figure_bytes(fig, fmt)


def _spectrum(ax: plt.Axes, t: np.ndarray, x: np.ndarray, interval: float) -> None:
    """One-sided amplitude spectrum of the displayed history (Hann window, amplitude-corrected)."""
    n = x.size
    if n < 8:
        return
    window = np.hanning(n)
    amp = 2.0 * np.abs(np.fft.rfft((x - x.mean()) * window)) / window.sum()
    omega = 2.0 * np.pi * np.fft.rfftfreq(n, d=float(t[1] - t[0]))
    order = omega * interval / (2.0 * np.pi)
    keep = order <= 4.0
    ax.plot(order[keep], amp[keep], lw=0.9, color="C0")


def threshold_figure(curve: ThresholdCurve, fmt: ImageFormat = "png") -> bytes:
    """Critical values of the parameter against the frequency, the no-chaos band shaded."""
    fig, ax = plt.subplots(figsize=(8, 5.5))
    w = np.asarray(curve.frequencies)
    lo, hi = _band(curve.no_chaos)
    styles = {"plus": ("C3", "-", "+"), "minus": ("C2", "--", "-")}
    for branch, intervals in curve.branches.items():
        blo, bhi = _band(intervals)
        color, ls, sign = styles[branch]
        ax.plot(w, blo, color=color, ls=ls, lw=1.3, label=f"threshold of $M^{sign}$ ({branch})")
        ax.plot(w, bhi, color=color, ls=ls, lw=1.3)
    if curve.value is not None:
        ax.axhline(curve.value, color="k", lw=0.8, ls=":", label="design value")
    sym = symbol(curve.parameter)
    ax.set(
        xlabel=symbol(curve.frequency_parameter),
        ylabel=sym,
        title=f"Melnikov threshold curves of {sym}: chaos possible outside the shaded band",
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
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
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
