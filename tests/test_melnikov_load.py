"""The Melnikov verdict with the mean load in the unperturbed system x'' = a x - c x^3 + F_m.

The closed forms of the loaded loops (``homoclinic.loops``) against an independent integration:
the saddle and the turning point found by brentq, the loop by scipy's DOP853 (rtol 1e-12) from
the turning point towards the saddle, its last stretch by the linearised saddle, and the
integrals of Eq. (18) by QUADPACK; the thresholds per loop agree to 1e-6 relative.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, optimize

from gearengine.homoclinic import coefficients as mk
from gearengine.homoclinic import loops
from gearengine.homoclinic.batch import melnikov_batch
from gearengine.homoclinic.thresholds import chaos_possible, parameter_threshold, strength_at
from gearengine.homoclinic.verdict import melnikov
from gearengine.model.params import GearParams
from tests.conftest import PAPER_PARAMS

A = C = 0.1667
F_CRIT = (2 * A / 3) * math.sqrt(A / (3 * C))
SIGN = {"plus": 1.0, "minus": -1.0}
EXCITATION = {"F_e1": "transmission_error", "F_p1": "torque", "k_p1": "stiffness"}


def loaded(fm: float, parameter: str = "F_e1", omega: float = 0.5, a: float = A, c: float = C):
    return GearParams.model_validate(
        {
            "damping": 0.07,
            "mean_force": fm,
            "backlash": {"model": "cubic", "a": a, "c": c},
            EXCITATION[parameter]: {"frequency": omega, "harmonics": [{"amplitude": 0.05}]},
        }
    )


def scipy_loop_coefficients(a: float, c: float, fm: float, branch: str, omega: float) -> dict:
    """A per unit mu and B per unit amplitude of each excitation on one loaded loop, by DOP853
    along the loop and QUADPACK on Eq. (18), independent of ``homoclinic.loops``."""
    s = SIGN[branch]
    r = math.sqrt(a / (3 * c))
    xs = optimize.brentq(lambda x: a * x - c * x**3 + fm, -r, r, xtol=1e-15)
    k = math.sqrt(a - 3 * c * xs**2)

    def potential(x: float) -> float:
        return -a * x**2 / 2 + c * x**4 / 4 - fm * x

    far = xs + s * 10 * math.sqrt(a / c)
    near = xs + s * 1e-3
    turn = optimize.brentq(lambda x: potential(x) - potential(xs), near, far, xtol=1e-15)
    u_end = 1e-5 * abs(turn - xs)
    sol = integrate.solve_ivp(
        lambda t, z: [z[1], a * z[0] - c * z[0] ** 3 + fm],
        (0.0, 60.0 / k),
        [turn, 0.0],
        method="DOP853",
        rtol=1e-12,
        atol=1e-15,
        dense_output=True,
        events=lambda t, z: abs(z[0] - xs) - u_end,
    )
    t_end = float(sol.t_events[0][0])

    def quad(f) -> float:
        return integrate.quad(f, 0.0, t_end, limit=2000, epsabs=1e-15, epsrel=1e-13)[0]

    def y(t: float) -> float:
        return sol.sol(t)[1]

    def force(t: float) -> float:
        x = sol.sol(t)[0]
        return a * x - c * x**3

    # beyond t_end the loop is the saddle's stable direction: u = u_T exp(-k (t - t_end))
    u_t = float(sol.sol(t_end)[0] - xs)

    def tail(rate: float) -> float:  # integral_T^inf exp(-rate (t - T)) sin(omega t) dt
        return (rate * math.sin(omega * t_end) + omega * math.cos(omega * t_end)) / (
            rate**2 + omega**2
        )

    y_sin = quad(lambda t: y(t) * math.sin(omega * t)) - k * u_t * tail(k)
    # a x - c x^3 = -F_m + alpha u near the saddle, alpha = k^2
    stiff_sin = quad(lambda t: 2 * y(t) * force(t) * math.sin(omega * t)) + 2 * k * u_t * (
        fm * tail(k) - k**2 * u_t * tail(2 * k)
    )
    y2 = quad(lambda t: y(t) ** 2) + k * u_t**2 / 2
    return {
        "damping": -4.0 * y2,
        "torque": -2.0 * y_sin,
        "transmission_error": -2.0 * omega**2 * y_sin,
        "stiffness": -2.0 * stiff_sin,
    }


LOADS = [0.002, 0.01, 0.03, 0.05, 0.062]


@pytest.mark.parametrize("fm", LOADS)
@pytest.mark.parametrize(("parameter", "omega"), [("F_e1", 0.5), ("F_p1", 0.8), ("k_p1", 0.4)])
def test_thresholds_per_loop_agree_with_scipy(fm: float, parameter: str, omega: float) -> None:
    """Each loop's critical amplitude |A_s| / |B_s| (one sinusoid, Eq. 23) matches DOP853 +
    QUADPACK along that loaded loop to 1e-6 relative."""
    params = loaded(fm, parameter, omega)
    t = parameter_threshold(params, parameter, A, C)
    for br in ("plus", "minus"):
        ref = scipy_loop_coefficients(A, C, fm, br, omega)
        expected = abs(0.07 * ref["damping"]) / abs(ref[EXCITATION[parameter]])
        assert t.branches is not None
        assert max(t.branches[br].critical_values) == pytest.approx(expected, rel=1e-6), br


def test_other_cubic_and_a_negative_load() -> None:
    """Another cubic (a = 0.3, c = 0.1) under a negative load (coast side), both loops."""
    a, c = 0.3, 0.1
    fm = -0.5 * loops.critical_load(a, c)
    params = loaded(fm, "F_e1", 0.9, a, c)
    t = parameter_threshold(params, "F_e1", a, c)
    for br in ("plus", "minus"):
        ref = scipy_loop_coefficients(a, c, fm, br, 0.9)
        expected = abs(0.07 * ref["damping"]) / abs(ref["transmission_error"])
        assert t.branches is not None
        assert max(t.branches[br].critical_values) == pytest.approx(expected, rel=1e-6), br


@pytest.mark.parametrize("branch", ["plus", "minus"])
def test_loaded_closed_form_matches_quadrature_along_the_loop(branch: str) -> None:
    """The engine's two methods agree under load: closed form vs QUADPACK on the loaded orbit."""
    for kind in ("stiffness", "torque", "transmission_error"):
        for omega in (0.1, 0.6, 1.7):
            closed = mk.closed_form_coefficient(kind, omega, A, C, branch, 0.03)
            quad = mk.quadrature_coefficient(kind, omega, A, C, branch, 0.03)
            assert closed == pytest.approx(quad, rel=1e-8)
    assert mk.damping_coefficient(A, C, 0.03, branch) == pytest.approx(
        mk.quadrature_damping(A, C, 0.03, branch), rel=1e-9
    )


def test_zero_load_reproduces_todays_closed_form() -> None:
    """The loaded-loop integrals at F_m = 0 are the closed form of Eq. (19) to 1e-8."""
    for omega in np.linspace(0.05, 3.0, 12):
        for br, s in SIGN.items():
            i1, t2 = loops.loop_integrals(omega, A, C, 0.0, s)
            pairs = [
                (omega * i1, mk.closed_form_coefficient("torque", omega, A, C, br)),
                (omega**3 * i1, mk.closed_form_coefficient("transmission_error", omega, A, C, br)),
                (omega * t2, mk.closed_form_coefficient("stiffness", omega, A, C, br)),
            ]
            for new, old in pairs:
                assert new == pytest.approx(old, rel=1e-8, abs=1e-14)
    assert -2 * loops.loop_integrals(0.0, A, C, 0.0, 1.0)[1] == pytest.approx(
        mk.damping_coefficient(A, C), rel=1e-8
    )
    zero = GearParams.model_validate({**PAPER_PARAMS, "mean_force": 0.0})
    assert melnikov(zero).thresholds == melnikov(zero, mean_load="perturbation").thresholds


def test_paper_section_41_as_a_perturbation() -> None:
    """mean_load perturbation reproduces the paper's F~_e1 threshold 0.19588 (section 4.1); the
    loaded default gives each loop its own threshold, several percent either side."""
    paper = GearParams.model_validate(PAPER_PARAMS)
    first_order = melnikov(paper, mean_load="perturbation").thresholds["F_e1"]
    assert first_order.critical_values[-1] == pytest.approx(0.19588, abs=5e-6)
    loaded_t = melnikov(paper).thresholds["F_e1"]
    assert loaded_t.branches is not None
    plus, minus = (max(loaded_t.branches[b].critical_values) for b in ("plus", "minus"))
    assert abs(plus - minus) > 0.02
    assert min(plus, minus) == pytest.approx(loaded_t.critical_values[-1])


@pytest.mark.parametrize("factor", [1 - 1e-9, 1 + 1e-9])
def test_applicable_exactly_below_the_critical_load(factor: float) -> None:
    """|F_m| < F_crit applies, |F_m| >= F_crit does not: the verdict, chaos_possible, the
    strength and the batch agree at both sides of the edge, for either sign of the load."""
    for sign in (1.0, -1.0):
        params = loaded(sign * factor * F_CRIT)
        result = melnikov(params)
        inside = factor < 1
        assert result.applicable is inside
        assert (result.chaos_possible is None) is not inside
        assert (chaos_possible(params) is None) is not inside
        assert math.isnan(strength_at(params)) is not inside
        assert (melnikov_batch([params])[0]["chaos_possible"] is None) is not inside
        if not inside:
            assert any("F_crit" in n and "numerical verdict still applies" in n
                       for n in result.notes)  # fmt: skip
        # the paper's treatment stays applicable, and says it is outside its domain there
        first = melnikov(params, mean_load="perturbation")
        assert first.applicable
        assert any("outside its domain" in n for n in first.notes) is not inside


def test_batch_matches_the_verdict_under_load() -> None:
    """The batch's compiled closed forms take the stricter loop: margins equal the verdict's."""
    designs = [
        loaded(fm, p, w) for fm in (0.0, 0.01, 0.04) for p, w in (("F_e1", 0.5), ("F_p1", 0.8))
    ]
    for p, got in zip(designs, melnikov_batch(designs), strict=True):
        full = melnikov(p)
        assert got["chaos_possible"] == full.chaos_possible
        for q in ("F_e1", "mu", "F_p1"):
            want, have = full.thresholds[q].margin, got["margins"][q]["margin"]
            assert (have is None) == (want is None), q
            assert want is None or have == pytest.approx(want, rel=1e-12), q


def test_perturbation_sizes_and_caveat() -> None:
    """Sizes against F_crit: the paper's transmission error (0.25 x 0.2) is 0.78 F_crit, which
    is not small, and the notes say so in plain words."""
    result = melnikov(GearParams.model_validate(PAPER_PARAMS))
    assert result.perturbation_sizes is not None
    assert result.perturbation_sizes["transmission_error"] == pytest.approx(0.05 / F_CRIT)
    assert any("first-order theory is stretched" in n for n in result.notes)
    fe1 = result.thresholds["F_e1"]  # the margin as a force, (Omega_e^2 dF_e1) / F_crit
    assert fe1.margin_in_force_scale == pytest.approx(fe1.margin * 0.25 / F_CRIT)
    small = GearParams.model_validate(
        {**PAPER_PARAMS, "damping": 0.005,
         "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.01}]}}
    )  # fmt: skip
    assert not any("stretched" in n for n in melnikov(small).notes)


@pytest.mark.parametrize("s", [1.0, -1.0])
@pytest.mark.parametrize("fm", [0.6 * F_CRIT, -0.3 * F_CRIT, 0.05 * F_CRIT])
def test_loop_integrals_closed_form_against_quadrature(fm: float, s: float) -> None:
    """I_1 = int u_s cos(omega t) dt and T_2 = int u_s'^2 cos(omega t) dt of ``loops``
    (G&R 3.983.2 and the recursion; k and theta_s shared through ``loop_shape``) against
    QUADPACK's cosine-weighted integral of the loop itself, u_s = s P / (cosh(k t) + cos
    theta_s), over [0, 80/k] (doubled: both integrands are even)."""
    _, alpha, p, cos_t, sin_t, k, theta = loops.loop_shape(A, C, fm, s)
    assert k == math.sqrt(alpha) and theta == pytest.approx(math.atan2(sin_t, cos_t))

    def u(t: float) -> float:
        return s * p / (math.cosh(k * t) + cos_t)

    def du2(t: float) -> float:
        return (s * p * k * math.sinh(k * t) / (math.cosh(k * t) + cos_t) ** 2) ** 2

    for omega in (0.0, 0.3, 1.1, 2.5):
        i1, t2 = loops.loop_integrals(omega, A, C, fm, s)
        weight = {"weight": "cos", "wvar": omega} if omega else {}
        q1 = 2 * integrate.quad(u, 0.0, 80 / k, limit=500, epsabs=1e-14, **weight)[0]
        q2 = 2 * integrate.quad(du2, 0.0, 80 / k, limit=500, epsabs=1e-14, **weight)[0]
        assert i1 == pytest.approx(q1, rel=1e-9, abs=1e-13)
        assert t2 == pytest.approx(q2, rel=1e-9, abs=1e-13)
