"""What the figures draw: the spectrum panel shows the JSON's spectrum, the lines and axes say
what they are, the design is a point, one legend entry per drawn threshold line."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from matplotlib.figure import Figure

import gearengine.plots.analysis as plots
from gearengine.analysis import AnalysisRequest, analyze
from gearengine.homoclinic.thresholds import threshold_curve
from gearengine.model.params import GearParams
from tests.conftest import PAPER_PARAMS


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    """The figures the plot functions render, kept instead of turned into bytes."""
    figures: list[Figure] = []

    def keep(fig: Figure, fmt: str) -> bytes:
        figures.append(fig)
        return b""

    monkeypatch.setattr(plots, "figure_bytes", keep)
    return figures


def chaotic() -> Any:
    te = {"frequency": 0.5, "harmonics": [{"amplitude": 0.28}]}
    params = {**PAPER_PARAMS, "transmission_error": te}
    return analyze(AnalysisRequest.model_validate({"params": params}))


def test_the_spectrum_panel_draws_the_reported_peaks(drawn: list[Figure]) -> None:
    result = chaotic()
    plots.analysis_figure(result)
    (fig,) = drawn
    ax_f = fig.axes[3]
    (stems,) = ax_f.collections
    segments = stems.get_segments()
    peaks = result.numerics.spectrum_peaks
    assert [(s[1][0], s[1][1]) for s in segments] == [(p.order, p.amplitude) for p in peaks]
    top = max(peaks, key=lambda p: p.amplitude)
    assert top.amplitude == pytest.approx(max(s[1][1] for s in segments))
    # the panel says what is plotted
    words = ax_f.get_title() + " ".join(t.get_text() for t in ax_f.texts)
    assert result.numerics.record is not None  # the periods actually recorded
    recorded = f"last {result.numerics.record.periods} periods"
    for needed in ("amplitude spectrum of x", "Hann window", "amplitude-corrected", recorded):
        assert needed in words, needed
    # |x| = 1 lines are labelled and x, x' carry their units
    assert "|x| = 1: clearance edges" in [t.get_text() for t in fig.legends[0].get_texts()]
    assert "half backlash" in fig.axes[0].get_ylabel()
    assert "per unit" in fig.axes[1].get_ylabel()


def curve_figure(drawn: list[Figure], params: dict[str, Any], frequency: float) -> Figure:
    curve = threshold_curve(GearParams.model_validate(params), "F_e1", "Omega_e", 0.2, 2.0, 40)
    plots.threshold_figure(curve, "png", design_frequency=frequency)
    return drawn[-1]


def legend_labels(fig: Figure) -> list[str]:
    return [t.get_text() for t in fig.axes[0].get_legend().get_texts()]


def test_threshold_figure_marks_the_design_and_labels_each_line(drawn: list[Figure]) -> None:
    fig = curve_figure(drawn, {**PAPER_PARAMS, "mean_force": 0.0}, 0.5)
    labels = legend_labels(fig)
    design = [line for line in fig.axes[0].lines if line.get_label().startswith("design:")]
    assert len(design) == 1 and list(design[0].get_xydata()[0]) == [0.5, 0.2]
    # no mean load, symmetric forcing: the two branches are one line, so one entry
    assert sum("threshold" in label for label in labels) == 1
    # a mean force with a second harmonic splits the branches: two lines, two entries
    split = {
        **PAPER_PARAMS,
        "mean_force": 0.05,
        "transmission_error": {
            "frequency": 0.5,
            "harmonics": [{"amplitude": 0.2}, {"amplitude": 0.05, "phase": 1.0}],
        },
    }
    fig = curve_figure(drawn, split, 0.5)
    thresholds = [label for label in legend_labels(fig) if "threshold" in label]
    lines = {
        tuple(np.round(line.get_ydata(), 9))
        for line in fig.axes[0].lines
        if line.get_label() in thresholds
    }
    assert len(thresholds) == len(lines) == 2, (thresholds, lines)


def test_a_design_is_drawn_in_gear_units(drawn: list[Figure]) -> None:
    """A design's four panels: time in ms, x b in µm, velocity in mm/s, spectrum in Hz and µm,
    each scale agreeing with the JSON's engineering block (computed by another path)."""
    doc = json.loads((Path(__file__).parents[1] / "examples" / "design-direct.json").read_text())
    doc["settings"] = {"transient_periods": 100, "record_periods": 100, "steps_per_period": 128}
    result = analyze(AnalysisRequest.model_validate(doc))
    eng, num = result.engineering, result.numerics
    assert eng is not None and eng.response is not None and num.time_history is not None
    plots.analysis_figure(result)
    (fig,) = drawn
    ax_t, ax_p, _, ax_f = fig.axes
    assert (ax_t.get_xlabel(), ax_p.get_ylabel(), ax_f.get_xlabel()) == (
        "time (ms)", "relative velocity (mm/s)", "frequency (Hz)"
    )  # fmt: skip
    assert "µm" in ax_t.get_ylabel() and "µm" in ax_f.get_ylabel()
    t = ax_t.lines[0].get_xdata()
    tau = num.time_history.t
    assert t[-1] - t[0] == pytest.approx((tau[-1] - tau[0]) * eng.time_scale_s * 1e3)
    b_um = eng.half_backlash_um
    assert b_um == pytest.approx(50.0)  # the design's "half_backlash": "50 um"
    x = ax_t.lines[0].get_ydata()
    assert x.max() - x.min() <= eng.response.dte_peak_to_peak_um * (1 + 1e-12)
    (stems,) = ax_f.collections
    tops = max(stems.get_segments(), key=lambda s: s[1][1])
    assert tops[1][0] == pytest.approx(eng.response.dominant_frequency_hz)
    assert tops[1][1] == pytest.approx(num.spectrum_peaks[0].amplitude * b_um)
    edges = sorted(line.get_ydata()[0] for line in ax_t.lines[1:])
    assert edges == pytest.approx([-b_um, b_um])  # the clearance edges at the half backlash
