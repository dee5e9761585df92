"""The fast paths of the Melnikov verdict give the numbers of the paths they replace.

``loops.sampled_extremes`` evaluates the 4001-sample grid of ``perturbations.loop_extremes`` only
next to the peaks of the speed and the force along the loops; here against the whole grid,
evaluated with numpy from the loop's closed form (the implementation it replaced), on a grid of
loads up to 0.99 F_crit of both signs and several cubic laws. The compiled coefficients of every
excitation are pinned against the loaded loops' integrals (``loops.loop_integrals``) and against
QUADPACK along the loop (``method="quadrature"``). All to 1e-9 relative.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearengine.homoclinic import coefficients as mk
from gearengine.homoclinic import loops
from gearengine.homoclinic.perturbations import SAMPLES, loop_extremes

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
    xs, alpha, p, cos_t, _ = loops.loop_shape(a, c, fm, s)
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
