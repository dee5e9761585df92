"""Figures engineers read: the four-panel response of an analysis (paper Figs. 7-11, 14-16) and
Melnikov threshold curves (paper Figs. 5, 12, 18), as PNG or SVG bytes.

Rendering only: every number drawn comes from a result object of the engine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from gearengine.analysis import AnalysisResult
from gearengine.engineering.thresholds import ThresholdUnits
from gearengine.homoclinic.schemas import ThresholdCurve
from gearengine.numerics.results import SpectrumPeak
from gearengine.plots.style import ImageFormat, figure_bytes, symbol


@dataclass(frozen=True)
class Units:
    """How the four-panel figure shows x, x', tau and frequencies: factors from the
    dimensionless quantities of Eq. (9) and axis labels. A design's analysis is drawn in gear
    units (x b in µm, time in ms, velocity in mm/s, frequency in Hz); params in Eq. (9)'s own."""

    x: float
    v: float
    t: float
    f: float
    x_label: str
    v_label: str
    t_label: str
    f_label: str
    amplitude: str
    lle: float
    lle_unit: str
    mesh_hz: float | None
    edges: str

    @classmethod
    def of(cls, result: AnalysisResult) -> Units:
        eng = result.engineering
        if eng is None:
            return cls(
                1.0, 1.0, 1.0, 1.0,
                r"$x$ (units of the half backlash $b$)",
                r"$\dot x = dx/d\tau$ ($b$ per unit $\tau$)",
                r"$\tau$ (dimensionless time)",
                r"order: frequency / $\Omega_0$ (fundamental of the forcing)",
                "units of b",
                1.0, "per unit τ", None, CLEARANCE,
            )  # fmt: skip
        b_um, tau_s = eng.half_backlash_um, eng.time_scale_s
        return cls(
            b_um, 1e-3 * b_um / tau_s, 1e3 * tau_s, 1.0 / (2.0 * math.pi * tau_s),
            f"relative displacement $x\\,b$ (µm; b = {b_um:.3g} µm)",
            "relative velocity (mm/s)",
            "time (ms)",
            "frequency (Hz)",
            "µm",
            1.0 / tau_s, "per s", eng.mesh_frequency_hz,
            f"x b = ±b = ±{b_um:.3g} µm: clearance edges",
        )  # fmt: skip


def analysis_figure(result: AnalysisResult, fmt: ImageFormat = "png") -> bytes:
    """(a) time history, (b) phase plane, (c) Poincare section, (d) amplitude spectrum; in gear
    units for a design (``Units``)."""
    num = result.numerics
    u = Units.of(result)
    fig = Figure(figsize=(10, 7.5), layout="constrained")
    axes = fig.subplots(2, 2)
    (ax_t, ax_p), (ax_s, ax_f) = axes
    hist = num.time_history
    period = f"{num.period}T-periodic" if num.period else num.classification.replace("_", "-")
    lle = "n/a"
    if num.lle is not None:
        spread = (num.lle_stderr or 0.0) * u.lle
        lle = f"{num.lle * u.lle:+.4g} ± {spread:.2g} {u.lle_unit}"
    mel = result.melnikov.chaos_possible
    at = "" if result.engineering is None else f" at {result.engineering.speed_rpm:,.0f} rpm"
    fig.suptitle(
        f"{period} response{at}   LLE λ₁ = {lle}   "
        "Melnikov: "
        + {True: "chaos possible", False: "chaos not possible"}.get(mel, "not applicable"),
        fontsize=11,
    )
    if hist is not None and hist.t:
        t, x, v = (np.asarray(a) for a in (hist.t, hist.x, hist.v))
        ax_t.plot(t * u.t, x * u.x, lw=0.8, color="C0")
        ax_p.plot(x * u.x, v * u.v, lw=0.6, color="C0")
        _no_zoom_into_noise(ax_p, v * u.v, VELOCITY_FLOOR * u.v)
    if num.poincare:
        pts = np.asarray(num.poincare)
        ax_p.plot(pts[:, 0] * u.x, pts[:, 1] * u.v, "o", ms=3, color="C3", label="Poincaré points")
        ax_s.plot(pts[:, 0] * u.x, pts[:, 1] * u.v, "o", ms=2.5, color="C3")
        _no_zoom_into_noise(ax_s, pts[:, 1] * u.v, VELOCITY_FLOOR * u.v)
    for ax in (ax_t, ax_p, ax_s):
        for edge in (-u.x, u.x):  # clearance edges |x| = 1 (Eq. 8), |x b| = b
            (ax.axhline if ax is ax_t else ax.axvline)(
                edge, color="0.45", lw=0.7, ls=":", label=u.edges if edge > 0 else None
            )
    # one legend for panels (a)-(c), under them, where it hides no data
    fig.legend(*ax_p.get_legend_handles_labels(), loc="outside lower center", ncols=2, fontsize=8.5)
    ax_t.set(title="(a) time history", xlabel=u.t_label, ylabel=u.x_label)
    ax_p.set(title="(b) phase plane", xlabel=u.x_label, ylabel=u.v_label)
    ax_s.set(title="(c) Poincaré section (one point per $T_0$)", xlabel=u.x_label, ylabel=u.v_label)
    recorded = result.settings.record_periods if num.record is None else num.record.periods
    _spectrum(ax_f, num.spectrum_peaks, recorded, u)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    return figure_bytes(fig, fmt)


CLEARANCE = "|x| = 1: clearance edges"
"""Legend of the clearance edges in Eq. (9)'s units."""

NOISE = 1e-6
"""Relative spread below which the strobes of a section count as one point (a 1T orbit)."""
VELOCITY_FLOOR = 1e-3
"""Smallest velocity scale drawn, b per unit tau: below it a velocity axis shows rest."""


def _no_zoom_into_noise(ax: Axes, values: np.ndarray, floor: float) -> None:
    """The vertical axis around the values' level when they are one value up to rounding: a
    periodic orbit's strobes agree to ~1e-11 (and a resting pair's velocity is ~1e-16), and
    matplotlib would otherwise zoom into that noise (ticks under an offset like
    1e-11-3.426e-1). ``floor``: the smallest half-height shown, in the axis' unit."""
    ax.ticklabel_format(axis="y", useOffset=False)
    level = float(np.mean(values))
    scale = max(abs(level), float(np.max(np.abs(values))), floor)
    if float(np.ptp(values)) < NOISE * scale:
        half = 0.1 * scale
        ax.set_ylim(level - half, level + half)


def _spectrum(ax: Axes, peaks: list[SpectrumPeak], record_periods: int, u: Units) -> None:
    """The spectrum the JSON reports (``numerics.spectrum_peaks``): its largest peaks as stems,
    so the figure and the numbers agree; computed over the whole record (``record_periods``
    sampling intervals), Hann window, amplitude-corrected (a sinusoid A cos wt peaks at A).
    Dimensionless: against the order of the forcing fundamental; in gear units: in Hz."""
    ax.set(
        title="(d) amplitude spectrum of x: largest peaks",
        xlabel=u.f_label,
        ylabel=f"amplitude of x ({u.amplitude})",
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
    where = order if u.mesh_hz is None else np.array([p.frequency for p in peaks]) * u.f
    amp = np.array([p.amplitude for p in peaks]) * u.x
    ax.vlines(where, 0.0, amp, color="C0", lw=1.6)
    ax.plot(where, amp, "o", color="C0", ms=4)
    top = int(np.argmax(amp))
    text = f"{amp[top]:.3g} at order {order[top]:.3g}"
    if u.mesh_hz is not None:
        text = f"{amp[top]:.3g} µm at {where[top]:,.0f} Hz (order {order[top]:.3g})"
    ax.annotate(
        text, (where[top], amp[top]), xytext=(6, -2), textcoords="offset points", fontsize=8,
    )  # fmt: skip
    if u.mesh_hz is not None:
        ax.axvline(u.mesh_hz, color="0.45", lw=0.8, ls=":",
                   label=f"mesh frequency {u.mesh_hz:,.0f} Hz")  # fmt: skip
        ax.legend(loc="upper left", fontsize=8)
    ax.set_xlim(0.0, 1.05 * max(where.max(), u.mesh_hz or 0.0, 1.0 / 1.05))
    ax.set_ylim(0.0, 1.35 * amp.max())


def threshold_figure(
    curve: ThresholdCurve,
    fmt: ImageFormat = "png",
    design_frequency: float | None = None,
    units: ThresholdUnits | None = None,
) -> bytes:
    """Critical values of the parameter against the frequency, the no-chaos band shaded, and
    the design as a point at (``design_frequency``, ``curve.value``) when both are known; with
    ``units`` (a design) in gear units: the parameter in its unit over the driver speed."""
    fig = Figure(figsize=(8, 5.5), layout="constrained")
    ax = fig.subplots()
    kx, ky = (1.0, 1.0) if units is None else (units.rpm_per_frequency, units.parameter_scale)
    w = kx * np.asarray(curve.frequencies)
    lo, hi = (ky * b for b in _band(curve.no_chaos))
    value = None if curve.value is None else ky * curve.value
    if design_frequency is not None:
        design_frequency *= kx
    sym, fsym = symbol(curve.parameter), symbol(curve.frequency_parameter)
    if units is not None:
        sym, fsym = units.parameter_label, "driver speed [rpm]"
    bands = {
        branch: tuple(ky * b for b in _band(intervals))
        for branch, intervals in curve.branches.items()
    }
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
    if value is not None:
        ax.axhline(value, color="k", lw=0.8, ls=":", label=f"design value of {sym}")
        if design_frequency is not None:
            ax.plot(
                design_frequency, value, "*", ms=13, color="k", mfc="gold", zorder=5,
                label=f"design: {fsym} = {design_frequency:.4g}, {sym} = {value:.4g}",
            )  # fmt: skip
    ax.set(
        xlabel=fsym if units is not None else f"{fsym} (dimensionless frequency)",
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
    if value is not None:
        span = max(span, 1.15 * abs(value))
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
