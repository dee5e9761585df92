"""Gear diagnostics: the contact regime from the extremes of x."""

from __future__ import annotations

import pytest

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.signals.diagnostics import impact_regime


@pytest.mark.parametrize(
    ("xmin", "xmax", "regime"),
    [
        (1.2, 1.5, "no_impact"),  # drive-side contact throughout
        (-1.6, -1.1, "no_impact"),  # back-side contact throughout
        (0.4, 1.5, "single_sided"),  # separation, drive side hit
        (-1.5, 0.2, "single_sided"),  # separation, back side hit
        (-0.5, 0.5, "single_sided"),  # free flight inside the clearance
        (-1.5, 1.5, "double_sided"),
    ],
)
def test_regime_from_extremes(xmin: float, xmax: float, regime: str) -> None:
    assert impact_regime(xmin, xmax) == regime


def test_permanent_back_side_contact_is_no_impact() -> None:
    """Found in review: a design resting on the back flank was called double_sided."""
    doc = {
        "params": {"damping": 0.07, "mean_force": -0.3, "backlash": {"model": "piecewise"}},
        "settings": {"initial_state": [-1.5, 0.0], "transient_periods": 50, "record_periods": 50},
    }
    num = analyze(AnalysisRequest.model_validate(doc)).numerics
    assert num.impact_regime == "no_impact" and num.x_peak_to_peak < 1e-6
