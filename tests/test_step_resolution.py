"""The RK4 step resolves the teeth's own oscillation, not only the forcing (``systems.base.
resolving``, ``H_OMEGA``): at low speed a forcing period holds many natural periods.

A new-user review found the design-geometry pair at 400 rpm / 60 N*m answered "periodic 1T,
impacts on both flanks, DTE 1.87e+07 um": 128 steps a mesh period left two steps for each
natural period, and RK4 blew up. In contact the pair is a linear oscillator with a constant
damping term, so its two Lyapunov exponents are equal and sum to trace J = -2 zeta (Liouville):
the LLE is -zeta exactly, a closed form the analysis must meet at any speed."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.model.reduction import convert_design
from gearengine.systems.base import H_OMEGA
from gearengine.systems.spur_pair.forcing import contact_frequency, step_plan

ROOT = Path(__file__).resolve().parents[1]
GEOMETRY = json.loads((ROOT / "examples" / "design-geometry.json").read_text())
ZETA = GEOMETRY["design"]["mesh"]["damping_ratio"]


def design_at(rpm: float) -> dict:
    return {**GEOMETRY["design"], "speed": f"{rpm} rpm"}


@pytest.mark.parametrize("rpm", [300, 400, 6000])
def test_the_step_resolves_the_contact_at_every_speed(rpm: float) -> None:
    """h omega_max <= H_OMEGA whatever the speed; a note says when the steps were raised; near
    resonance the plan is the forcing's alone, as before."""
    from gearengine.model.design import Design

    params = convert_design(Design.model_validate(design_at(rpm))).params
    plan, omega = step_plan(params, 128), contact_frequency(params)
    assert omega > 1.0  # the stiffness harmonics of ISO 6336 stiffen the contact
    assert plan.h * omega <= H_OMEGA
    raised = any("the teeth in contact" in n for n in plan.notes)
    assert raised == (rpm < 6000)
    if not raised:
        assert plan.steps == 128


@pytest.mark.parametrize("rpm", [300, 400])
def test_a_slow_pair_in_contact_decays_at_minus_zeta(rpm: float) -> None:
    """The LLE of the pair in contact is -zeta (module docstring) and its DTE is a few um, at
    the envelope's 128 steps a period (before: LLE -0.0858, back-flank impacts, DTE 1.9e7 um at
    400 rpm; diverged at 300 rpm)."""
    settings = {"steps_per_period": 128}
    result = analyze(AnalysisRequest.model_validate({"design": design_at(rpm),
                                                     "settings": settings}))  # fmt: skip
    numerics = result.numerics
    assert numerics.classification == "periodic" and numerics.impact_regime == "no_impact"
    assert numerics.lle == pytest.approx(-ZETA, rel=2e-3)
    # T0 is one mesh period here: the raised steps do not change how many mesh periods a T0
    # holds (they read 46.9 mesh periods for 6 T0, the steps' ratio, before)
    for length in (numerics.transient, numerics.record):
        assert length is not None and length.mesh_periods == length.periods
    response = result.engineering.response
    assert response is not None and math.isfinite(response.dte_peak_to_peak_um)
    assert response.dte_peak_to_peak_um < 10.0
