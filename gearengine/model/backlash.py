"""Backlash laws f_h of the seed paper and cubic fits of the piecewise law.

Piecewise law (Eq. 8), x = x~/b in units of the half backlash b, 0 <= alpha < 1:

    f_h(x) = x - (1 - alpha)    for x > 1
             alpha x            for -1 <= x <= 1
             x + (1 - alpha)    for x < -1

Cubic law (Eq. 9): f_h(x) = -a x + c x^3. The Melnikov analysis needs a > 0 and c > 0 (a
double-well potential with a saddle at x = 0 and centres at x = +-sqrt(a/c)).

Two ways to get (a, c) from the piecewise law are provided (``docs/backlash-fit.md``):

* ``cubic_fit``: least squares over [-x_max, x_max]. The normal equations and the residual are
  evaluated with exact integrals of the piecewise polynomials (no quadrature, no sampling).
* ``collocation_fit``: the odd cubic through (x1, f_h(x1)) and (x2, f_h(x2)). With alpha = 0 and
  nodes x = 1, 2 it passes through (0, 0), (+-1, 0), (+-2, +-1), which gives the paper's
  a = c = 1/6 = 0.1667 (``paper_cubic``). Least squares gives a < 0.611 c and a < 0.123 for every
  range, and a < 0 for x_max > 2.2434, so no least-squares range reproduces a = c = 1/6.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.polynomial import Polynomial
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field

from gearengine.model.params import CubicBacklash

FitMethod = Literal["least_squares", "collocation"]


class CubicFit(BaseModel):
    """Coefficients of f_h(x) ~ -a x + c x^3 fitted to the piecewise law with slope alpha."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    method: FitMethod = Field(
        description="least_squares over [-x_max, x_max], or collocation (interpolation)."
    )
    alpha: float = Field(description="Slope alpha of the piecewise law inside the clearance.")
    a: float = Field(description="Linear coefficient a of -a x + c x^3 (dimensionless).")
    c: float = Field(description="Cubic coefficient c of -a x + c x^3 (dimensionless).")
    x_max: float = Field(
        description="Half-width of the range [-x_max, x_max] (units of b) of the fit and rms."
    )
    rms: float = Field(
        description="RMS of f_h(x) - (-a x + c x^3) over [-x_max, x_max] (units of b)."
    )
    note: str = Field(description="How the coefficients were obtained.")

    def backlash(self) -> CubicBacklash:
        """The fit as the engine's cubic backlash model (raises if a or c is not finite)."""
        return CubicBacklash(a=self.a, c=self.c)


def fh_piecewise(x: ArrayLike, alpha: float = 0.0) -> NDArray[np.float64]:
    """Piecewise backlash law f_h(x) of Eq. (8); x and f_h in units of the half backlash b."""
    x = np.asarray(x, dtype=float)
    beta = 1.0 - alpha
    return np.where(x > 1.0, x - beta, np.where(x < -1.0, x + beta, alpha * x))


def fh_cubic(x: ArrayLike, a: float, c: float) -> NDArray[np.float64]:
    """Cubic backlash law f_h(x) = -a x + c x^3 of Eq. (9); x in units of b."""
    x = np.asarray(x, dtype=float)
    return -a * x + c * x**3


def _pieces(alpha: float, x_max: float) -> list[tuple[float, float, Polynomial]]:
    """(lo, hi, f_h on [lo, hi]) covering [0, x_max]; f_h is odd, so this fixes it everywhere."""
    _check_alpha(alpha)
    if not x_max > 0.0:
        raise ValueError(f"x_max must be > 0, got {x_max}")
    pieces = [(0.0, min(1.0, x_max), Polynomial([0.0, alpha]))]
    if x_max > 1.0:
        pieces.append((1.0, x_max, Polynomial([alpha - 1.0, 1.0])))
    return pieces


def _integral(pieces: list[tuple[float, float, Polynomial]], weight: Polynomial) -> float:
    """Exact integral over [0, x_max] of f_h(x) weight(x), f_h given by ``pieces``."""
    total = 0.0
    for lo, hi, poly in pieces:
        antiderivative = (poly * weight).integ()
        total += antiderivative(hi) - antiderivative(lo)
    return float(total)


def rms_residual(alpha: float, a: float, c: float, x_max: float) -> float:
    """RMS of f_h(x) - (-a x + c x^3) over [-x_max, x_max], exact (units of b)."""
    cubic = Polynomial([0.0, -a, 0.0, c])
    total = 0.0
    for lo, hi, poly in _pieces(alpha, x_max):
        antiderivative = ((poly - cubic) ** 2).integ()
        total += antiderivative(hi) - antiderivative(lo)
    # The residual is odd, its square even: the mean over [-x_max, x_max] is that over [0, x_max].
    return float(np.sqrt(total / x_max))


def cubic_fit(alpha: float = 0.0, x_max: float = 2.0) -> CubicFit:
    """Least-squares fit of -a x + c x^3 to the piecewise f_h over [-x_max, x_max].

    Minimises the integral of (f_h(x) + a x - c x^3)^2 dx over [-x_max, x_max] (continuous least
    squares, uniform weight). The normal equations use exact integrals of the piecewise
    polynomials, so the result carries only rounding error. For x_max <= 1 the law is linear on
    the range and the fit is exact: a = -alpha, c = 0.

    Args:
        alpha: slope of f_h inside the clearance, 0 <= alpha < 1 (paper: 0).
        x_max: half-width of the fitted range, units of the half backlash b (> 0).
    """
    pieces = _pieces(alpha, x_max)
    x, x3 = Polynomial([0.0, 1.0]), Polynomial([0.0, 0.0, 0.0, 1.0])
    gram = np.array(
        [[x_max**3 / 3.0, x_max**5 / 5.0], [x_max**5 / 5.0, x_max**7 / 7.0]]
    )  # integrals of x^2, x^4, x^6 over [0, x_max]
    rhs = np.array([_integral(pieces, x), _integral(pieces, x3)])
    linear, cubic = np.linalg.solve(gram, rhs)
    a, c = -float(linear), float(cubic)
    return CubicFit(
        method="least_squares",
        alpha=alpha,
        a=a,
        c=c,
        x_max=x_max,
        rms=rms_residual(alpha, a, c, x_max),
        note=(
            f"continuous least squares over [-{x_max:g}, {x_max:g}] with exact integrals of "
            "the piecewise polynomials"
        ),
    )


def collocation_fit(alpha: float = 0.0, x1: float = 1.0, x2: float = 2.0) -> CubicFit:
    """Odd cubic -a x + c x^3 interpolating f_h at x = 0, +-x1, +-x2 (0 < x1 < x2).

    Solves -a x_i + c x_i^3 = f_h(x_i) for i = 1, 2. With the default nodes x = 1, 2:
    c = (1 - alpha) / 6 and a = (1 - 7 alpha) / 6, so a > 0 only for alpha < 1/7. The reported
    rms is over [-x2, x2].
    """
    _check_alpha(alpha)
    if not 0.0 < x1 < x2:
        raise ValueError(f"need 0 < x1 < x2, got x1={x1}, x2={x2}")
    nodes = np.array([x1, x2])
    matrix = np.column_stack([-nodes, nodes**3])
    a, c = (float(v) for v in np.linalg.solve(matrix, fh_piecewise(nodes, alpha)))
    return CubicFit(
        method="collocation",
        alpha=alpha,
        a=a,
        c=c,
        x_max=x2,
        rms=rms_residual(alpha, a, c, x2),
        note=f"interpolation of f_h at x = 0, +-{x1:g}, +-{x2:g}",
    )


def paper_cubic() -> CubicFit:
    """The paper's cubic a = c = 1/6 (printed 0.1667), for alpha = 0.

    It is the interpolation of the piecewise law at x = 0, +-1, +-2: (1/6) x (x^2 - 1) vanishes
    at the clearance edges x = +-1 and equals +-1 = f_h(+-2) at x = +-2. It is not a least-squares
    fit: least squares over [-2, 2] gives a = 0.0566, c = 0.1538, and no range gives a = c
    (see ``docs/backlash-fit.md``).
    """
    return collocation_fit(alpha=0.0, x1=1.0, x2=2.0).model_copy(
        update={"note": "paper's a = c = 1/6: interpolation of f_h (alpha = 0) at x = 0, +-1, +-2"}
    )


def _check_alpha(alpha: float) -> None:
    if not 0.0 <= alpha < 1.0:
        raise ValueError(f"alpha must satisfy 0 <= alpha < 1, got {alpha}")
