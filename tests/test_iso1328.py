"""ISO 1328-1:2013 flank tolerances and the backlash band, against worked values.

The worked values are not from this code: (1) an independent public implementation's worked
example, m_n = 3 mm, z = 40, b = 30 mm, class 6: f_pT = 9.0 µm (8.94 rounded to 0.5 µm in the
5-10 µm band), F_pT = 29 µm (28.80 to 1 µm), F_alpha = 12 µm; its rounding cases 12.49 -> 12,
10.4 -> 10, 7.3 -> 7.5, 7.2 -> 7.0, 4.96 -> 5.0, 4.94 -> 4.9; (2) hand arithmetic of Eq. (5)-(12)
for m_n = 2.5 mm, z = 23, b = 20 mm (d = 57.5 mm), written out below digit by digit.
"""

from __future__ import annotations

import math

import pytest

from gearengine.model.errors import InputError
from gearengine.model.standards import backlash, iso1328


def test_the_published_worked_example_class_6() -> None:
    t = iso1328.tolerances(6, 40, 3.0, 30.0)
    assert (t.f_pT, t.F_pT, t.F_alpha) == (9.0, 29.0, 12.0)


@pytest.mark.parametrize(
    ("raw", "shown"),
    [(12.49, 12.0), (10.4, 10.0), (7.3, 7.5), (7.2, 7.0), (4.96, 5.0), (4.94, 4.9), (10.0, 10.0)],
)
def test_rounding_of_5_2_3(raw: float, shown: float) -> None:
    assert iso1328.rounded(raw) == shown


def test_class_5_by_hand_and_the_sqrt2_class_step() -> None:
    """Class 5 (step 1), m_n = 2.5, z = 23, b = 20, d = 57.5 mm:
    f_pT = 0.0575 + 1.0 + 5 = 6.0575 -> 6.0; F_pT = 0.115 + 0.55*7.5829 + 1.75 + 12 = 18.0356
    -> 18; f_Ha = 1.0 + 0.0575 + 4 = 5.0575 -> 5.0; f_fa = 1.375 + 5 = 6.375 -> 6.5;
    F_a = hypot(5.0575, 6.375) = 8.1375 -> 8.0 (from unrounded parts: hypot(5.0, 6.5) = 8.2 would
    round to 8.0 too, so class 9 below tells them apart); f_Hb = 0.05*7.5829 + 0.35*4.4721 + 4
    = 5.9444 -> 6.0; f_fb = 0.07*7.5829 + 0.45*4.4721 + 4 = 6.5433 -> 6.5; F_b = hypot = 8.8402
    -> 9.0."""
    t = iso1328.tolerances(5, 23, 2.5, 20.0)
    assert (t.f_pT, t.F_pT, t.f_Halpha, t.f_falpha, t.F_alpha) == (6.0, 18.0, 5.0, 6.5, 8.0)
    assert (t.f_Hbeta, t.f_fbeta, t.F_beta) == (6.0, 6.5, 9.0)
    assert t.unrounded["F_pT"] == pytest.approx(18.0356, abs=1e-4)
    # each class is sqrt(2) times the one before it, on the unrounded values
    for grade in range(1, 11):
        lo, hi = (
            iso1328.tolerances(grade, 23, 2.5, 20.0),
            iso1328.tolerances(grade + 1, 23, 2.5, 20.0),
        )
        for name, value in lo.unrounded.items():
            assert hi.unrounded[name] / value == pytest.approx(math.sqrt(2.0))
    # class 9 (step 4): f_pT = 24.23 -> 24; f_fa = 25.5 -> 26 (halves up); F_a = 32.55 -> 33
    t9 = iso1328.tolerances(9, 23, 2.5, 20.0)
    assert (t9.f_pT, t9.f_falpha, t9.F_alpha) == (24.0, 26.0, 33.0)
    # class 1 (step 1/4): f_pT = 1.514 -> 1.5 (0.1 µm below 5 µm)
    assert iso1328.tolerances(1, 23, 2.5, 20.0).f_pT == 1.5


@pytest.mark.parametrize(
    ("args", "field"),
    [((12, 23, 2.5, 20.0), "class"), ((0, 23, 2.5, 20.0), "class"), ((7, 23, 0.3, 20.0), "module"),
     ((7, 23, 2.5, 2.0), "face_width"), ((7, 4, 2.5, 20.0), "teeth")],
)  # fmt: skip
def test_outside_the_range_of_validity_is_refused(args: tuple, field: str) -> None:
    """A typed refusal: the design field in ``path``, the standard's quantity in ``message``."""
    with pytest.raises(InputError) as refusal:
        iso1328.tolerances(*args)
    assert refusal.value.path.startswith("design.")
    assert refusal.value.message.startswith(f"{field}:")


def test_backlash_band_to_half_backlash() -> None:
    """j_t = 100 µm at alpha_wt = 20 deg: b = 100 cos(20 deg) / 2 = 46.985 µm."""
    assert backlash.half_backlash(100e-6, math.radians(20.0)) == pytest.approx(46.9846e-6, rel=1e-5)
    lo, hi = backlash.half_backlash_band(80e-6, 120e-6, math.radians(20.0))
    assert (lo, hi) == pytest.approx((37.5877e-6, 56.3816e-6), rel=1e-5)
    with pytest.raises(ValueError, match=r"tolerances\.backlash"):
        backlash.half_backlash_band(120e-6, 80e-6, 0.3)
