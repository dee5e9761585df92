"""The Poincare period of a design comes from the design (every excitation is a multiple of the
shaft speed), and the search for ``params`` reads the fundamentals, not their harmonics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearengine.homoclinic.extrema import extrema
from gearengine.homoclinic.verdict import melnikov
from gearengine.model.aliases import with_aliases
from gearengine.model.design import Design
from gearengine.model.frequencies import MAX_DENOMINATOR, forcing_period, poincare_frequency
from gearengine.model.params import GearParams
from gearengine.model.reduction import convert_design
from gearengine.studies.sweep import run_local, validated
from gearengine.systems.spur_pair.forcing import step_plan

LIGHT = {"transient_periods": 40, "record_periods": 40, "steps_per_period": 64}


def geometry_design(teeth: int) -> dict:
    """A geometry-form pair with ISO 6336 stiffness (5 harmonics of the mesh) and torque ripple at
    shaft order 1: the highest harmonic runs at 5 z x shaft (a small pinion profile-shifted
    against undercut)."""
    gear = {"module": "2.5 mm", "face_width": "30 mm"}
    return {
        "driver": {"teeth": teeth, "profile_shift": 0.5 if teeth < 17 else 0.0, **gear},
        "driven": {"teeth": 67, **gear},
        "speed": "3000 rpm",
        "torque": "50 N*m",
        "mesh": {"stiffness": "iso6336", "damping_ratio": 0.05, "half_backlash": "40 um"},
        "transmission_error": {"harmonics": [{"amplitude": "5 um"}]},
        "torque_fluctuation": {"order": 1, "harmonics": [{"amplitude": "5 N*m"}]},
    }


@pytest.mark.parametrize("teeth", [23, 13, 97])
def test_a_design_s_period_is_one_shaft_revolution(teeth: int) -> None:
    """T0 = 2 pi / (shaft speed / omega_n): the torque ripple at shaft order sets it, whatever
    the teeth (97 > MAX_DENOMINATOR: no search would find it)."""
    params = convert_design(Design.model_validate(geometry_design(teeth))).params
    shaft = params.torque.frequency
    assert len([h for h in params.stiffness.harmonics if h.amplitude]) == 5
    assert poincare_frequency(params) == pytest.approx(shaft, rel=1e-12)
    plan = step_plan(params, 512)  # 64 would leave the contact under-resolved (h omega > 0.5)
    assert plan.omega0 == pytest.approx(shaft, rel=1e-12) and plan.steps == 512 * teeth


def test_the_design_s_period_reaches_a_sweep_over_speed() -> None:
    """Before: every point quasi_periodic (the denominator 115 of 1/(5 z) over the bound)."""
    axes = [{"parameter": "speed", "start": "1000 rpm", "stop": "6000 rpm", "num": 3}]
    result = run_local(validated({"design": geometry_design(23), "settings": LIGHT, "axes": axes}))
    assert {p.classification for p in result.points} != {"quasi_periodic"}
    assert all(p.period is not None for p in result.points if p.classification == "periodic")


def test_params_search_reads_the_fundamentals() -> None:
    """Stiffness harmonics r Omega_k do not count against the denominator bound: fundamentals
    Omega_k and Omega_k / 23 are commensurate (the old search over 5 Omega_k failed at q = 115)."""
    params = GearParams.model_validate({
        "damping": 0.05,
        "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.02}] * 5},
        "torque": {"frequency": 1.0 / 23.0, "harmonics": [{"amplitude": 0.01}]},
    })  # fmt: skip
    assert poincare_frequency(params) == pytest.approx(1.0 / 23.0, rel=1e-12)


def test_truly_incommensurate_forcing_says_so() -> None:
    irrational = GearParams.model_validate({
        "damping": 0.05,
        "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.1}]},
        "torque": {"frequency": 0.5 * math.sqrt(2.0), "harmonics": [{"amplitude": 0.01}]},
    })  # fmt: skip
    plan = step_plan(irrational, 64)
    assert plan.omega0 is None
    assert f"q <= {MAX_DENOMINATOR}" in plan.notes[0] and "quasi-periodic" in plan.notes[0]
    design = geometry_design(23)
    design["torque_fluctuation"]["order"] = math.sqrt(2.0)
    params = convert_design(Design.model_validate(design)).params
    note = step_plan(params, 64).notes[0]
    assert "truly incommensurate" in note


def test_an_amplitude_axis_keeps_the_design_s_period_a_frequency_axis_searches() -> None:
    params = convert_design(Design.model_validate(geometry_design(97))).params
    shaft = params.torque.frequency
    assert poincare_frequency(with_aliases(params, {"F_e1": 0.05})) == pytest.approx(shaft)
    assert with_aliases(params, {"Omega_p": 2 * shaft}).shaft_orders is None


def test_the_melnikov_result_shows_the_design_s_period() -> None:
    """The verdict's T0 and its extrema come from the design's shaft orders (before: the search
    over 5 z x shaft gave no period, and the extrema were the supremum)."""
    design = geometry_design(23) | {"torque": "10 N*m"}  # 50 N m: no saddle, not applicable
    params = convert_design(Design.model_validate(design)).params
    assert forcing_period(params.active_frequencies()) is None  # what the search finds
    result = melnikov(params)
    assert result.forcing_period == pytest.approx(2.0 * math.pi / params.torque.frequency, 1e-12)
    assert {b.extrema for b in result.branches.values()} == {"exact"}
    m = result.coefficients["plus"].trig_sum()
    exact = extrema(m, result.forcing_period)
    assert extrema(m).method == "supremum" and extrema(m).minimum.value <= exact.minimum.value
    assert result.branches["plus"].min == exact.minimum.value
    assert m(np.array([exact.minimum.tau0]))[0] == pytest.approx(exact.minimum.value, abs=1e-12)
