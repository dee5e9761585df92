"""The fast paths of the Melnikov verdict give the numbers of the paths they replace.

``loops.sampled_extremes`` evaluates the 4001-sample grid of ``perturbations.loop_extremes`` only
next to the peaks of the speed and the force along the loops; here against the whole grid,
evaluated with numpy from the loop's closed form (the implementation it replaced), on a grid of
loads up to 0.99 F_crit of both signs and several cubic laws. The compiled coefficients of every
excitation are pinned against the loaded loops' integrals (``loops.loop_integrals``) and against
QUADPACK along the loop (``method="quadrature"``), and the compiled strength and Omega_e scan
against the same algorithm on the coefficient documents. All to 1e-9 relative.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearengine.homoclinic import coefficients as mk
from gearengine.homoclinic import loops
from gearengine.homoclinic.extrema import extrema
from gearengine.homoclinic.perturbations import SAMPLES, loop_extremes
from gearengine.homoclinic.terms import packed_terms
from gearengine.homoclinic.thresholds import (
    CONTROL_PARAMETERS,
    OMEGA_SCAN,
    _family,
    _scan_compiled,
    _scan_python,
)
from gearengine.model.params import GearParams

LAWS = [(0.1667, 0.1667), (1.0, 0.7), (0.3, 2.0), (2.0, 0.05), (0.01, 5.0)]
LOADS = [*np.linspace(-0.99, 0.99, 23), 0.0, 1e-9, 0.999]
"""Mean loads as fractions of F_crit."""
EXCITATIONS = ("stiffness", "transmission_error", "torque")


def numpy_orbit(t: np.ndarray, a: float, c: float, fm: float, s: float) -> tuple:
    """(x_h, y_h) on loop s with numpy: Eq. (15) for F_m = 0, else x_s + s P / (cosh(k t) +
    cos theta_s) (the implementation ``loops.orbit`` replaced)."""
    if fm == 0.0:
        z = math.sqrt(a) * t
        sech = 1.0 / np.cosh(z)
        return s * math.sqrt(2.0 * a / c) * sech, -s * math.sqrt(2.0 / c) * a * sech * np.tanh(z)
    xs, alpha, p, cos_t, *_ = loops.loop_shape(a, c, fm, s)
    k = math.sqrt(alpha)
    den = np.cosh(k * t) + cos_t
    return xs + s * p / den, -s * p * k * np.sinh(k * t) / den**2


def whole_grid_extremes(a: float, c: float, fm: float) -> tuple[float, float]:
    """max |y_h| and max |a x_h - c x_h^3| over both loops on all SAMPLES grid times."""
    k = math.sqrt(a - 3.0 * c * loops.saddle(a, c, fm) ** 2)
    t = np.linspace(-40.0 / k, 40.0 / k, SAMPLES)
    speed = force = 0.0
    for s in (1.0, -1.0):
        x, y = numpy_orbit(t, a, c, fm, s)
        speed = max(speed, float(np.max(np.abs(y))))
        force = max(force, float(np.max(np.abs(a * x - c * x**3))))
    return speed, force


@pytest.mark.parametrize("a, c", LAWS)
def test_sampled_extremes_equal_the_whole_grid(a: float, c: float) -> None:
    f_crit = mk.critical_mean_force(a, c)
    for load in LOADS:
        fm = load * f_crit
        assert loop_extremes(a, c, fm) == pytest.approx(whole_grid_extremes(a, c, fm), rel=1e-9)


@pytest.mark.parametrize("fm", [0.0, 0.02, -0.045])
def test_compiled_orbit_equals_numpy(fm: float) -> None:
    t = np.linspace(-50.0, 50.0, 2001)
    for br, s in mk.BRANCH_SIGN.items():
        x, y = mk.homoclinic_orbit(t, 0.1667, 0.1667, br, fm)
        x0, y0 = numpy_orbit(t, 0.1667, 0.1667, fm, s)
        np.testing.assert_allclose(x, x0, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(y, y0, rtol=1e-9, atol=1e-15)
        assert mk.homoclinic_orbit(1.3, 0.1667, 0.1667, br, fm) == pytest.approx(
            (x[1026], y[1026]), rel=1e-12
        )


def loop_reference(excitation: str, omega: float, a: float, c: float, fm: float, s: float):
    """B per unit amplitude on the loaded loop s from ``loops.loop_integrals`` (Eq. 18): torque
    Omega I_1, transmission error Omega^3 I_1, stiffness Omega T_2 - 2 F_m Omega I_1."""
    i1, t2 = loops.loop_integrals(omega, a, c, fm, s)
    return {
        "torque": omega * i1,
        "transmission_error": omega**3 * i1,
        "stiffness": omega * t2 - 2.0 * fm * omega * i1,
    }[excitation]


@pytest.mark.parametrize("a, c", LAWS[:3])
def test_coefficients_on_loaded_loops(a: float, c: float) -> None:
    """The compiled coefficients (each branch's loop shape computed once) equal the loaded
    loops' integrals, and the damping part -2 T_2(0), at every load and excitation."""
    f_crit = mk.critical_mean_force(a, c)
    for load in LOADS:
        fm = load * f_crit
        if fm == 0.0:
            continue
        for br, s in mk.BRANCH_SIGN.items():
            damping = -2.0 * loops.loop_integrals(0.0, a, c, fm, s)[1]
            assert mk.damping_coefficient(a, c, fm, br) == pytest.approx(damping, rel=1e-12)
            for excitation in EXCITATIONS:
                for omega in (0.05, 0.5, 1.3, 3.0):
                    got = mk.closed_form_coefficient(excitation, omega, a, c, br, fm)
                    want = loop_reference(excitation, omega, a, c, fm, s)
                    assert got == pytest.approx(want, rel=1e-12, abs=1e-300)


@pytest.mark.parametrize("load", [-0.99, -0.5, 0.0, 0.3, 0.7, 0.99])
def test_coefficients_against_quadrature(load: float) -> None:
    """Every excitation's coefficient and the damping part against QUADPACK along the loop."""
    a = c = 0.1667
    fm = load * mk.critical_mean_force(a, c)
    for br in mk.BRANCH_SIGN:
        assert mk.damping_coefficient(a, c, fm, br) == pytest.approx(
            mk.quadrature_damping(a, c, fm, br), rel=1e-9
        )
        for excitation in EXCITATIONS:
            for omega in (0.5, 1.3):
                assert mk.closed_form_coefficient(excitation, omega, a, c, br, fm) == pytest.approx(
                    mk.quadrature_coefficient(excitation, omega, a, c, br, fm), rel=1e-9
                )


def design(fm: float, excitations: tuple[str, ...]) -> GearParams:
    """The paper's cubic with damping 0.07, load ``fm`` and the named excitations (frequencies
    0.5, 1.0, 0.25: commensurate)."""
    given = {
        "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]},
        "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.1, "phase": 0.3}]},
        "torque": {"frequency": 0.25, "harmonics": [{"amplitude": 0.08, "phase": 1.1}]},
    }
    return GearParams.model_validate(
        {
            "damping": 0.07,
            "mean_force": fm,
            "backlash": {"model": "cubic", "a": 0.1667, "c": 0.1667},
            **{name: given[name] for name in excitations},
        }
    )


SETS = [(name,) for name in EXCITATIONS] + [EXCITATIONS]


@pytest.mark.parametrize("excitations", SETS)
def test_compiled_scan_equals_the_documents(excitations: tuple[str, ...]) -> None:
    """The compiled strength and Omega_e scan (scratch and loop shapes reused along the scan)
    against the same algorithm on the coefficient documents (``_scan_python``)."""
    f_crit = mk.critical_mean_force(0.1667, 0.1667)
    for load in (-0.99, -0.4, 0.0, 0.5, 0.99):
        p = design(load * f_crit, excitations)
        fm = p.mean_force
        strengths = []
        for br in mk.BRANCH_SIGN:
            coef = mk.melnikov_coefficients(p, 0.1667, 0.1667, br, fm=fm)
            ext = extrema(coef.trig_sum())
            strengths.append(min(ext.maximum.value, -ext.minimum.value))
        compiled = packed_terms(p, 0.1667, 0.1667, fm).strength()
        assert compiled == pytest.approx(max(strengths), rel=1e-9, abs=1e-15)
        if "transmission_error" in excitations:
            value = p.transmission_error.frequency
            found = _scan_compiled(p, 0.1667, 0.1667, fm, OMEGA_SCAN, value)
            assert found is not None
            python = _scan_python(p, 0.1667, 0.1667, OMEGA_SCAN, value, "closed_form", fm)
            assert found[0] == pytest.approx(python[0], rel=1e-9)
            assert np.array(found[1]) == pytest.approx(np.array(python[1]), rel=1e-9)


@pytest.mark.parametrize("load", [-0.6, 0.0, 0.8])
def test_one_sinusoid_floats_equal_the_arrays(load: float) -> None:
    """A branch of one sinusoid is read as floats, without arrays (``BranchCoefficients.extrema``
    and ``thresholds._family`` with no trig sum): the extrema bit for bit those of its
    ``TrigSum``, and each control parameter's family (its harmonic present, inactive with a zero
    amplitude, or absent) the same m0 and g as the family split from the arrays, for every
    excitation, amplitude sign and phase."""
    a, c, omega = 0.1667, 0.1667, 0.7
    fm = load * mk.critical_mean_force(a, c)
    taus = np.linspace(0.0, 2.0 * math.pi / omega, 7)
    for name in EXCITATIONS:
        for amplitude, phase in ((0.2, 0.0), (-0.15, 1.3), (0.0, 0.4)):
            harmonic = {"amplitude": amplitude, "phase": phase}
            p = GearParams.model_validate(
                {
                    "damping": 0.05,
                    "mean_force": fm,
                    name: {"frequency": omega, "harmonics": [harmonic]},
                }
            )
            for br in mk.BRANCH_SIGN:
                units = mk.melnikov_coefficients(p, a, c, br, include_inactive=True, fm=fm)
                active = mk.active_only(units, p)
                assert active.extrema(2.0 * math.pi / omega) == extrema(active.trig_sum())
                for parameter in CONTROL_PARAMETERS:
                    floats = _family(units, None, parameter)
                    arrays = _family(units, units.trig_sum(), parameter)
                    if arrays is None:
                        assert floats is None
                        continue
                    off0, offg, a0, ag = floats
                    sine = np.sin(omega * taus + units.terms[0].phase)
                    assert arrays[0](taus).tolist() == (off0 + a0 * sine).tolist()
                    assert arrays[1](taus).tolist() == (offg + ag * sine).tolist()
