"""Backlash laws and the cubic fits of the piecewise law (where the paper's 1/6 comes from)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gearengine.model.backlash import (
    collocation_fit,
    cubic_fit,
    fh_cubic,
    fh_piecewise,
    paper_cubic,
    rms_residual,
)
from gearengine.model.params import PAPER_A, CubicBacklash


def test_piecewise_branches() -> None:
    x = np.array([-3.0, -1.0, -0.5, 0.0, 0.5, 1.0, 3.0])
    assert fh_piecewise(x, 0.0) == pytest.approx([-2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0])
    assert fh_piecewise(x, 0.25) == pytest.approx([-2.25, -0.25, -0.125, 0.0, 0.125, 0.25, 2.25])


@pytest.mark.parametrize("alpha", [0.0, 0.3, 0.9])
def test_piecewise_is_continuous_odd_and_matches_clip_form(alpha: float) -> None:
    x = np.linspace(-4.0, 4.0, 8001)
    f = fh_piecewise(x, alpha)
    assert f == pytest.approx(x - (1.0 - alpha) * np.clip(x, -1.0, 1.0), abs=1e-15)
    assert fh_piecewise(-x, alpha) == pytest.approx(-f, abs=1e-15)
    for edge in (-1.0, 1.0):
        assert fh_piecewise(edge + 1e-12, alpha) == pytest.approx(alpha * edge, abs=1e-11)
        assert fh_piecewise(edge - 1e-12, alpha) == pytest.approx(alpha * edge, abs=1e-11)


def test_cubic_law() -> None:
    assert fh_cubic([0.0, 1.0, 2.0, -2.0], 0.5, 0.25) == pytest.approx([0.0, -0.25, 1.0, -1.0])


def test_paper_cubic_is_interpolation_at_0_1_2() -> None:
    fit = paper_cubic()
    assert fit.method == "collocation"
    assert fit.a == pytest.approx(1.0 / 6.0, rel=1e-14)
    assert fit.c == pytest.approx(1.0 / 6.0, rel=1e-14)
    assert round(fit.a, 4) == round(fit.c, 4) == PAPER_A
    nodes = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
    assert fh_cubic(nodes, fit.a, fit.c) == pytest.approx([-1.0, 0.0, 0.0, 0.0, 1.0], abs=1e-14)
    assert fit.backlash() == CubicBacklash(a=fit.a, c=fit.c)


@pytest.mark.parametrize("alpha", [0.0, 0.1, 0.5])
def test_collocation_closed_form(alpha: float) -> None:
    fit = collocation_fit(alpha)
    assert fit.c == pytest.approx((1.0 - alpha) / 6.0, rel=1e-13)
    assert fit.a == pytest.approx((1.0 - 7.0 * alpha) / 6.0, abs=1e-14)
    nodes = np.array([1.0, 2.0])
    assert fh_cubic(nodes, fit.a, fit.c) == pytest.approx(fh_piecewise(nodes, alpha), abs=1e-14)


def _dense_lstsq(alpha: float, x_max: float, n: int = 400_000) -> tuple[float, float, float]:
    """(a, c, rms) from discrete least squares on n midpoints of [-x_max, x_max]."""
    h = 2.0 * x_max / n
    x = -x_max + h * (np.arange(n) + 0.5)
    f = x - (1.0 - alpha) * np.clip(x, -1.0, 1.0)
    design = np.column_stack([-x, x**3])
    (a, c), *_ = np.linalg.lstsq(design, f, rcond=None)
    rms = float(np.sqrt(np.mean((f - design @ [a, c]) ** 2)))
    return float(a), float(c), rms


@pytest.mark.parametrize("alpha", [0.0, 0.2])
@pytest.mark.parametrize("x_max", [1.5, 2.0, 2.5, 3.0])
def test_least_squares_matches_dense_lstsq(alpha: float, x_max: float) -> None:
    fit = cubic_fit(alpha, x_max)
    a, c, rms = _dense_lstsq(alpha, x_max)
    assert fit.a == pytest.approx(a, abs=1e-8)
    assert fit.c == pytest.approx(c, abs=1e-8)
    assert fit.rms == pytest.approx(rms, abs=1e-8)


def test_least_squares_matches_polyfit() -> None:
    x = np.linspace(-2.0, 2.0, 400_001)
    x = 0.5 * (x[1:] + x[:-1])
    coef = np.polyfit(x, fh_piecewise(x, 0.0), 3)  # highest power first
    fit = cubic_fit(0.0, 2.0)
    assert coef[0] == pytest.approx(fit.c, abs=1e-8)
    assert -coef[2] == pytest.approx(fit.a, abs=1e-8)
    assert coef[1] == pytest.approx(0.0, abs=1e-10)  # even terms vanish: f_h is odd
    assert coef[3] == pytest.approx(0.0, abs=1e-10)


# Values quoted in docs/backlash-fit.md (alpha = 0).
DOC_TABLE = [
    (1.5, 0.12191, 0.20005, 0.02996),
    (2.0, 0.05664, 0.15381, 0.04303),
    (2.5, -0.06156, 0.09878, 0.08213),
    (3.0, -0.17284, 0.06401, 0.11842),
]


@pytest.mark.parametrize(("x_max", "a", "c", "rms"), DOC_TABLE)
def test_documented_table(x_max: float, a: float, c: float, rms: float) -> None:
    fit = cubic_fit(0.0, x_max)
    assert (fit.a, fit.c, fit.rms) == pytest.approx((a, c, rms), abs=6e-6)


def test_least_squares_over_2_is_exact_rational() -> None:
    fit = cubic_fit(0.0, 2.0)
    assert fit.a == pytest.approx(29.0 / 512.0, rel=1e-13)
    assert fit.c == pytest.approx(315.0 / 2048.0, rel=1e-13)


def test_no_least_squares_range_gives_the_paper_cubic() -> None:
    fits = [cubic_fit(0.0, x_max) for x_max in np.linspace(1.01, 20.0, 2000)]
    a = np.array([f.a for f in fits])
    c = np.array([f.c for f in fits])
    assert np.all(a < 0.611 * c)  # a = c never happens (max a / c = 0.6101)
    assert a.max() < 0.123 < 1.0 / 6.0
    x_zero = 2.2434  # a changes sign here: no double well for wider ranges
    assert cubic_fit(0.0, x_zero - 1e-3).a > 0.0 > cubic_fit(0.0, x_zero + 1e-3).a


@pytest.mark.parametrize("alpha", [0.0, 0.4])
def test_narrow_range_is_exact(alpha: float) -> None:
    fit = cubic_fit(alpha, 0.8)
    assert fit.a == pytest.approx(-alpha, abs=1e-14)
    assert fit.c == pytest.approx(0.0, abs=1e-13)
    assert fit.rms == pytest.approx(0.0, abs=1e-7)


def test_paper_cubic_rms_is_worse_than_least_squares() -> None:
    assert paper_cubic().rms == pytest.approx(rms_residual(0.0, 1 / 6, 1 / 6, 2.0), rel=1e-14)
    assert paper_cubic().rms > 2.0 * cubic_fit(0.0, 2.0).rms


@settings(max_examples=60, deadline=None)
@given(
    alpha=st.floats(0.0, 0.95),
    x_max=st.floats(0.5, 5.0),
    da=st.floats(-0.1, 0.1),
    dc=st.floats(-0.1, 0.1),
)
def test_least_squares_is_optimal(alpha: float, x_max: float, da: float, dc: float) -> None:
    fit = cubic_fit(alpha, x_max)
    perturbed = rms_residual(alpha, fit.a + da, fit.c + dc, x_max)
    assert perturbed >= fit.rms - 1e-12


@pytest.mark.parametrize(
    "call",
    [
        lambda: cubic_fit(alpha=1.0),
        lambda: cubic_fit(alpha=-0.1),
        lambda: cubic_fit(x_max=0.0),
        lambda: collocation_fit(x1=2.0, x2=1.0),
        lambda: collocation_fit(x1=0.0),
    ],
)
def test_bad_arguments_raise(call) -> None:
    with pytest.raises(ValueError):
        call()
