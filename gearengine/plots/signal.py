"""A signal reading as an engineer reads it: six panels.

(a) the order spectrum (or the frequency spectrum without a speed), lines labelled, the model's
lines overlaid when a design was given; (b) the strobe map (x_k, x_k+1), one point per mesh
period or revolution; (c) the reconstructed attractor (x_i, x_i+tau); (d) the 0-1 test's
(p, q) path, bounded for a regular series and a random walk for a chaotic one; (e) Rosenstein's
divergence <ln d> against time with the fitted stretch; (f) the surrogates' statistic
distribution with the series' value. The verdict is the title.
"""

from __future__ import annotations

import textwrap

from matplotlib.figure import Figure

from gearengine.plots.style import ImageFormat, figure_bytes
from gearengine.signals.schema import SignalResult

VERDICT_COLOURS = {
    "periodic": "#2ca02c",
    "quasi_periodic": "#1f77b4",
    "chaotic": "#d62728",
    "stochastic": "#7f7f7f",
    "undetermined": "#ff7f0e",
}


def _empty(ax, text: str) -> None:  # type: ignore[no-untyped-def]
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, fontsize=8,
            color="#555555", wrap=True)  # fmt: skip
    ax.set_xticks([])
    ax.set_yticks([])


def _spectrum(ax, result: SignalResult) -> None:  # type: ignore[no-untyped-def]
    sp = result.spectrum
    unit = result.record.unit
    ax.semilogy(sp.x, [max(a, 1e-300) for a in sp.amplitude], lw=0.7, color="#333333",
                label="signal")  # fmt: skip
    top = max(sp.amplitude) if sp.amplitude else 1.0
    ax.set_ylim(top * 1e-5, top * 3.0)
    for line in sp.lines[:6]:
        x = line.order if sp.axis == "order" else line.frequency_hz
        ax.annotate(line.label, xy=(x, line.amplitude), xytext=(2, 4), textcoords="offset points",
                    fontsize=6, color="#1f77b4")  # fmt: skip
    if result.model is not None and sp.axis == "order":
        model = [ln for ln in result.model.lines if ln.order is not None]
        if model:
            ax2 = ax.twinx()
            ax2.vlines([ln.order for ln in model], 0.0, [ln.amplitude for ln in model],
                       color="#d62728", lw=1.2, alpha=0.7, label="model")  # fmt: skip
            ax2.set_ylabel("model [µm]", color="#d62728", fontsize=7)
            ax2.tick_params(labelsize=6, colors="#d62728")
    xmax = max(sp.x) if sp.x else 1.0
    if sp.axis == "order" and result.reference.teeth:
        xmax = min(xmax, 3.5 * result.reference.teeth)
    ax.set_xlim(0.0, xmax)
    ax.set_xlabel("order (per shaft revolution)" if sp.axis == "order" else "frequency [Hz]")
    ax.set_ylabel(f"amplitude [{unit}]")
    ax.set_title("(a) spectrum" + (" (red: model)" if result.model else ""), fontsize=8)


def _strobes(ax, result: SignalResult) -> None:  # type: ignore[no-untyped-def]
    s = result.strobes
    if len(s) < 3:
        _empty(ax, "no strobes: no speed, tach\nor harmonic fundamental")
    else:
        ax.plot(s[:-1], s[1:], ".", ms=2.5, color="#333333")
        ax.set_xlabel(f"x_k [{result.record.unit}]")
        ax.set_ylabel("x_k+1")
    cycle = (result.reference.cycle or "cycle").replace("_", " ")
    ax.set_title(f"(b) strobe map, one point per {cycle}", fontsize=8)


def _attractor(ax, result: SignalResult) -> None:  # type: ignore[no-untyped-def]
    emb = result.embedding
    if emb is None or not emb.attractor:
        _empty(ax, "no embedding")
        return
    xs = [p[0] for p in emb.attractor]
    ys = [p[1] for p in emb.attractor]
    ax.plot(xs, ys, lw=0.3, color="#555555")
    ax.set_xlabel(f"x(t) [{result.record.unit}]")
    ax.set_ylabel(f"x(t + {emb.delay_s:.3g} s)")
    ax.set_title(f"(c) attractor, m = {emb.dimension}, tau = {emb.delay_s:.3g} s", fontsize=8)


def _zero_one(ax, result: SignalResult) -> None:  # type: ignore[no-untyped-def]
    z = result.zero_one
    if z is None:
        _empty(ax, "0-1 test not run (too few points)")
        return
    ax.plot(z.p, z.q, lw=0.4, color="#1f77b4")
    ax.set_xlabel("p_c(n)")
    ax.set_ylabel("q_c(n)")
    ax.set_title(f"(d) 0-1 test: K = {z.k:.2f} ({z.points} points)", fontsize=8)


def _divergence(ax, result: SignalResult) -> None:  # type: ignore[no-untyped-def]
    ly = result.lyapunov
    if ly is None or not ly.divergence:
        _empty(ax, "no Lyapunov exponent")
        return
    ax.plot(ly.divergence_t_s, ly.divergence, lw=0.8, color="#333333")
    a, b = ly.fit_range_s
    ax.axvspan(a, b, color="#ffbb78", alpha=0.5, lw=0)
    lam = "-" if ly.per_second is None else f"{ly.per_second:.3g} /s"
    ax.set_xlabel("time [s]")
    ax.set_ylabel("<ln distance>")
    ax.set_title(f"(e) Rosenstein: lambda = {lam} ({ly.implementation})", fontsize=8)


def _surrogates(ax, result: SignalResult) -> None:  # type: ignore[no-untyped-def]
    s = result.surrogates
    if s is None:
        _empty(ax, "surrogate test not run")
        return
    ax.hist(s.surrogate_values, bins=15, color="#c7c7c7", edgecolor="#7f7f7f")
    ax.axvline(s.value, color="#d62728", lw=1.5, label="series")
    ax.set_xlabel("prediction error / std")
    ax.set_ylabel("surrogates")
    verdict = "rejected" if s.rejected else "not rejected"
    ax.set_title(f"(f) {s.surrogates} IAAFT surrogates: p = {s.p_value:.3g}, {verdict}",
                 fontsize=8)  # fmt: skip
    ax.legend(fontsize=6)


def signal_figure(result: SignalResult, fmt: ImageFormat = "png") -> bytes:
    """The six-panel figure of a signal reading, as PNG or SVG bytes."""
    fig = Figure(figsize=(11.0, 7.2))
    axes = fig.subplots(2, 3)
    _spectrum(axes[0, 0], result)
    _strobes(axes[0, 1], result)
    _attractor(axes[0, 2], result)
    _zero_one(axes[1, 0], result)
    _divergence(axes[1, 1], result)
    _surrogates(axes[1, 2], result)
    for ax in axes.flat:
        ax.tick_params(labelsize=6)
        ax.xaxis.label.set_size(7)
        ax.yaxis.label.set_size(7)
    fig.suptitle(textwrap.fill(result.summary, 170), fontsize=8,
                 color=VERDICT_COLOURS[result.verdict])  # fmt: skip
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 0.93))
    return figure_bytes(fig, fmt)
