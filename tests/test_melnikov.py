"""Melnikov analysis: closed form against quadrature of Eq. (18), paper numbers, the erratum."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from gearengine.homoclinic import coefficients as mk
from gearengine.homoclinic.verdict import melnikov
from gearengine.model.aliases import with_alias, with_aliases
from gearengine.model.params import GearParams

OMEGAS = np.linspace(0.05, 3.0, 14)
PAPER_LOAD = "perturbation"
"""The paper's treatment of the mean force (section 3.1), under which its numbers reproduce."""
SHAPES = [(0.1667, 0.1667), (1.0, 0.5), (0.3, 2.0), (2.0, 0.2)]
KINDS = ["stiffness", "torque", "transmission_error"]


def te_only(fe: float, omega: float, mu: float) -> GearParams:
    return GearParams.model_validate(
        {
            "damping": mu,
            "mean_force": 0.01,
            "transmission_error": {"frequency": omega, "harmonics": [{"amplitude": fe}]},
        }
    )


@pytest.mark.parametrize(("a", "c"), SHAPES)
@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("branch", ["plus", "minus"])
def test_closed_form_matches_quadrature(a: float, c: float, kind: str, branch: str) -> None:
    """Every term of the corrected Eq. (19) equals quadrature of Eq. (18) to 1e-8 relative."""
    for omega in OMEGAS:
        closed = mk.closed_form_coefficient(kind, omega, a, c, branch)
        quad = mk.quadrature_coefficient(kind, omega, a, c, branch)
        # the stiffness term vanishes at Omega^2 = 2a: compare against its scale there
        scale = abs(closed) if kind != "stiffness" else max(abs(closed), 1e-3 * omega**2 / c)
        assert abs(closed - quad) <= 1e-8 * scale, (kind, omega, closed, quad)


@pytest.mark.parametrize(("a", "c"), SHAPES)
def test_damping_matches_quadrature(a: float, c: float) -> None:
    assert mk.damping_coefficient(a, c) == pytest.approx(mk.quadrature_damping(a, c), rel=1e-10)


def eq18(params: GearParams, a: float, c: float, branch: str, tau0: float) -> float:
    """Eq. (18) integrated literally: y_h times q2 along the orbit (independent of the engine)."""
    s = 1.0 if branch == "plus" else -1.0
    sq = math.sqrt(a)

    def integrand(t: float) -> float:
        sech = 1.0 / math.cosh(sq * t)
        x = s * math.sqrt(2 * a / c) * sech
        y = -s * math.sqrt(2 / c) * a * sech * math.tanh(sq * t)
        q2 = -2 * params.damping * y + params.mean_force
        for name, exc in params.excitations():
            for r, h in enumerate(exc.harmonics, start=1):
                w = r * exc.frequency
                cos = math.cos(w * (t + tau0) + h.phase)
                if name == "stiffness":
                    q2 += 2 * h.amplitude * cos * (a * x - c * x**3)
                elif name == "torque":
                    q2 += h.amplitude * cos
                else:
                    q2 += w**2 * h.amplitude * cos
        return y * q2

    span = 60.0 / sq
    value, _ = integrate.quad(integrand, -span, span, limit=2000, epsabs=1e-13, epsrel=1e-12)
    return value


RICH = GearParams.model_validate(
    {
        "damping": 0.05,
        "mean_force": 0.02,
        "stiffness": {
            "frequency": 1.0,
            "harmonics": [{"amplitude": 0.1, "phase": 0.3}, {"amplitude": 0.04, "phase": -1.0}],
        },
        "transmission_error": {
            "frequency": 1.0,
            "harmonics": [{"amplitude": 0.15, "phase": 0.7}, {"amplitude": 0.02, "phase": 2.0}],
        },
        "torque": {"frequency": 0.25, "harmonics": [{"amplitude": 0.08, "phase": 1.1}]},
    }
)


@pytest.mark.parametrize("branch", ["plus", "minus"])
@pytest.mark.parametrize(("a", "c"), [(0.1667, 0.1667), (0.5, 1.5)])
def test_full_melnikov_function_matches_eq18(branch: str, a: float, c: float) -> None:
    """All terms, several harmonics and phases, and the mean force (which integrates to 0)."""
    coef = mk.melnikov_coefficients(RICH, a, c, branch)
    for tau0 in (0.0, 0.9, 2.5, 7.1):
        assert coef(tau0) == pytest.approx(eq18(RICH, a, c, branch, tau0), rel=1e-8, abs=1e-12)


def test_quadrature_method_gives_same_verdict() -> None:
    closed = melnikov(RICH, omega_scan=(0.5, 1.5, 3))
    quad = melnikov(RICH, method="quadrature", omega_scan=(0.5, 1.5, 3))
    for br in ("plus", "minus"):
        assert quad.branches[br].max == pytest.approx(closed.branches[br].max, rel=1e-8)
        assert quad.branches[br].min == pytest.approx(closed.branches[br].min, rel=1e-8)


def printed_eq19_stiffness(omega: float, a: float, c: float) -> float:
    """The paper's printed stiffness coefficient of Eq. (19), per unit k_p1."""
    csch = 1.0 / math.sinh(math.pi * omega / (2 * math.sqrt(a)))
    first = 4 * a * math.sqrt(a / c**2) * math.pi * csch * omega**2 / (2 * a**1.5)
    second = (
        8 * a * math.sqrt(1 / c) * (a / c) ** 1.5 * c * math.pi * csch * omega**2
        * (4 * a + omega**2) / (24 * a**2.5)
    )  # fmt: skip
    return first - second


def test_erratum_printed_stiffness_term_disagrees_with_quadrature() -> None:
    """Eq. (19)'s printed stiffness term is wrong for the paper's own a = c = 0.1667."""
    a = c = 0.1667
    for omega in (0.5, 1.0, 2.0):
        quad = mk.quadrature_coefficient("stiffness", omega, a, c, "plus")
        printed = printed_eq19_stiffness(omega, a, c)
        assert abs(printed - quad) > 0.5 * abs(quad), (omega, printed, quad)
    # at Omega = 1 the printed form even has the wrong sign
    assert (
        printed_eq19_stiffness(1.0, a, c)
        * mk.closed_form_coefficient("stiffness", 1.0, a, c, "plus")
        < 0.0
    )


def test_printed_stiffness_term_is_right_only_when_a_is_one() -> None:
    for omega in (0.5, 1.3):
        assert printed_eq19_stiffness(omega, 1.0, 0.7) == pytest.approx(
            mk.closed_form_coefficient("stiffness", omega, 1.0, 0.7, "plus"), rel=1e-12
        )


# --- Paper numbers, section 4.1 ----------------------------------------------------------------


def test_paper_fe1_threshold_at_omega_half() -> None:
    """Omega_e = 0.5, mu = 7 (epsilon = 0.01: mu~ = 0.07): f_e1 >= 19.59 (paper: 'f_e1 >= 20')."""
    t = melnikov(te_only(0.2, 0.5, 0.07), mean_load=PAPER_LOAD).thresholds["F_e1"]
    assert t.critical_values == pytest.approx([-0.19588, 0.19588], abs=5e-5)
    scaled = melnikov(te_only(20.0, 0.5, 7.0), mean_load=PAPER_LOAD).thresholds["F_e1"]
    assert scaled.nearest == pytest.approx(19.59, abs=5e-3)


def test_paper_mu_threshold_at_omega_07() -> None:
    """Omega_e = 0.7, f_e1 = 30: chaos possible for mu <= 13.86 (15 outside, 13.5 and 12 in)."""
    r = melnikov(te_only(0.3, 0.7, 0.15), mean_load=PAPER_LOAD)
    assert r.thresholds["mu"].nearest == pytest.approx(0.1386, abs=5e-5)
    assert r.chaos_possible is False
    assert melnikov(te_only(0.3, 0.7, 0.135), mean_load=PAPER_LOAD).chaos_possible is True
    assert melnikov(te_only(0.3, 0.7, 0.12), mean_load=PAPER_LOAD).chaos_possible is True


def test_eq23_and_eq24_closed_forms() -> None:
    """The single-harmonic thresholds of Eqs. (23)-(24) equal the root-found ones."""
    a = c = 0.1667
    for omega in (0.2, 0.5, 1.0, 2.0):
        mu = 0.07
        f1 = (
            8 / (3 * math.sqrt(2)) * mu * math.sqrt(c) * a**2
            / (math.pi * omega**3 * c * math.sqrt(a))
            * math.cosh(math.pi * omega / (2 * math.sqrt(a)))
        )  # fmt: skip
        t = melnikov(te_only(0.1, omega, mu), mean_load=PAPER_LOAD).thresholds
        assert t["F_e1"].critical_values == pytest.approx([-f1, f1], rel=1e-10)
        fe = 0.3
        mu1 = (
            3 * c / (8 * a**2) * math.sqrt(2 * a / c) * fe * math.pi
            / math.cosh(math.pi * omega / (2 * math.sqrt(a))) * omega**3
        )  # fmt: skip
        t = melnikov(te_only(fe, omega, 0.1), mean_load=PAPER_LOAD).thresholds
        assert t["mu"].critical_values == pytest.approx([mu1], rel=1e-10)


def test_verdict_flips_across_each_threshold() -> None:
    for name, t in melnikov(RICH).thresholds.items():
        if name == "Omega_e":
            continue
        for crit in t.critical_values:
            below = melnikov(with_alias(RICH, name, crit - 1e-6 * max(1.0, abs(crit))))
            above = melnikov(with_alias(RICH, name, crit + 1e-6 * max(1.0, abs(crit))))
            assert below.chaos_possible != above.chaos_possible, (name, crit)


def test_omega_scan_critical_frequencies_flip_the_verdict() -> None:
    params = te_only(0.2, 0.5, 0.07)
    crit = melnikov(params, mean_load=PAPER_LOAD).thresholds["Omega_e"].critical_values
    assert crit == pytest.approx([0.4912, 1.1813], abs=1e-4)
    for om in crit:
        lo, hi = te_only(0.2, om - 1e-6, 0.07), te_only(0.2, om + 1e-6, 0.07)
        flags = [melnikov(p, mean_load=PAPER_LOAD).chaos_possible for p in (lo, hi)]
        assert flags[0] != flags[1]
    for om in melnikov(params).thresholds["Omega_e"].critical_values:  # loaded: its own flips
        lo, hi = te_only(0.2, om - 1e-6, 0.07), te_only(0.2, om + 1e-6, 0.07)
        assert melnikov(lo).chaos_possible != melnikov(hi).chaos_possible


# --- Domain, incommensurate forcing, piecewise law --------------------------------------------


@pytest.mark.parametrize(("a", "c"), [(-0.1, 0.2), (0.1, 0.0), (0.0, 0.1), (0.2, -0.3)])
def test_not_applicable_without_saddle_loop(a: float, c: float) -> None:
    data = te_only(0.2, 0.5, 0.07).model_dump()
    params = GearParams.model_validate({**data, "backlash": {"model": "cubic", "a": a, "c": c}})
    r = melnikov(params)
    assert r.applicable is False
    assert r.chaos_possible is None and r.branches is None
    assert any("a > 0 and" in n for n in r.notes)


def test_incommensurate_frequencies_use_the_supremum() -> None:
    params = GearParams.model_validate(
        {
            "damping": 0.1,
            "transmission_error": {"frequency": 1.0, "harmonics": [{"amplitude": 0.1}]},
            "torque": {"frequency": math.sqrt(2) / 10, "harmonics": [{"amplitude": 0.05}]},
        }
    )
    r = melnikov(params, omega_scan=(0.5, 1.5, 3))
    coef = r.coefficients["plus"]
    spread = sum(abs(t.coefficient) for t in coef.terms)
    assert r.branches["plus"].extrema == "supremum"
    assert r.branches["plus"].max == pytest.approx(coef.damping + spread, rel=1e-14)
    assert r.forcing_period is None
    assert any("incommensurate" in n for n in r.notes)


def test_piecewise_law_uses_the_paper_cubic_fit() -> None:
    params = GearParams.model_validate(
        {
            "damping": 0.07,
            "backlash": {"model": "piecewise", "alpha": 0.0},
            "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]},
        }
    )
    r = melnikov(params)
    assert r.a == pytest.approx(1 / 6) and r.c == pytest.approx(1 / 6)
    assert any("cubic fit" in n for n in r.notes)


def test_commensurate_extrema_are_attained_and_exact() -> None:
    r = melnikov(RICH)
    coef = mk.melnikov_coefficients(RICH, 0.1667, 0.1667, "plus", fm=RICH.mean_force)
    taus = np.linspace(0.0, r.forcing_period, 400_001)
    values = coef(taus)
    b = r.branches["plus"]
    assert b.extrema == "exact"
    assert b.max == pytest.approx(values.max(), abs=1e-9) and b.max >= values.max() - 1e-12
    assert b.min == pytest.approx(values.min(), abs=1e-9) and b.min <= values.min() + 1e-12
    assert coef(b.tau0_max) == pytest.approx(b.max, abs=1e-14)


def test_omega_scan_with_several_excitations_finds_only_real_flips() -> None:
    """Found in review: moving Omega_e alone jumped between exact extrema (rational ratios) and
    the supremum, giving a false critical value at 0.25. The scan scales every frequency."""
    params = GearParams.model_validate(
        {
            "damping": 0.07,
            "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]},
            "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.3}]},
        }
    )
    crit = melnikov(params).thresholds["Omega_e"].critical_values
    assert crit and all(abs(om - 0.25) > 1e-3 for om in crit)

    def at(om: float) -> bool | None:
        scaled = with_aliases(params, {"Omega_e": om, "Omega_k": 2.0 * om})
        return melnikov(scaled, omega_scan=(0.5, 1.0, 2)).chaos_possible

    for om in crit:
        assert at(om - 1e-6) != at(om + 1e-6), om
