"""Properties of the extrema and threshold machinery (hypothesis)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gearengine.homoclinic.coefficients import melnikov_coefficients
from gearengine.homoclinic.extrema import Interval, TrigSum, extrema, sublevel_interval
from gearengine.homoclinic.verdict import melnikov
from gearengine.model.aliases import with_alias
from gearengine.model.params import GearParams

amp = st.floats(-1.0, 1.0, allow_nan=False)
phase = st.floats(0.0, 2 * math.pi)


@st.composite
def trig_sums(draw: st.DrawFn) -> TrigSum:
    n = draw(st.integers(1, 4))
    base = draw(st.sampled_from([0.1, 0.25, 0.5, 1.0]))
    return TrigSum(
        draw(amp),
        np.array([draw(amp) for _ in range(n)]),
        base * np.array([draw(st.integers(1, 6)) for _ in range(n)], dtype=float),
        np.array([draw(phase) for _ in range(n)]),
    )


@settings(max_examples=60, deadline=None)
@given(trig_sums())
def test_extrema_bound_and_attain_a_dense_sample(m: TrigSum) -> None:
    e = extrema(m)
    taus = np.linspace(0.0, 2 * math.pi / 0.1, 200_001)
    values = m(taus)
    assert e.maximum.value >= values.max() - 1e-12
    assert e.minimum.value <= values.min() + 1e-12
    assert e.maximum.value <= values.max() + 1e-6
    assert e.minimum.value >= values.min() - 1e-6
    if e.method == "exact":
        assert m(np.array([e.maximum.tau0]))[0] == pytest.approx(e.maximum.value, abs=1e-13)


@settings(max_examples=60, deadline=None)
@given(trig_sums(), trig_sums())
def test_sublevel_interval_matches_brute_force(m0: TrigSum, other: TrigSum) -> None:
    g = TrigSum(other.offset, other.amplitudes[: m0.amplitudes.size], m0.frequencies, m0.phases)
    if g.amplitudes.size < m0.amplitudes.size:
        g = TrigSum(g.offset, np.resize(g.amplitudes, m0.amplitudes.size), g.frequencies, g.phases)
    interval = sublevel_interval(m0, g)
    for p in np.linspace(-6.0, 6.0, 97):
        fam = TrigSum(
            m0.offset + p * g.offset, m0.amplitudes + p * g.amplitudes, m0.frequencies, m0.phases
        )
        top = extrema(fam).maximum.value
        inside = interval is not None and interval.contains(float(p))
        if abs(top) > 1e-9:
            assert inside == (top <= 0.0), (p, top, interval)


def test_supremum_interval_of_incommensurate_sum() -> None:
    # phi(p) = -1 + |0.3| + |p| * 1: nonpositive for |p| <= 0.7
    freqs = np.array([1.0, math.sqrt(2)])
    m0 = TrigSum(-1.0, np.array([0.3, 0.0]), freqs, np.zeros(2))
    g = TrigSum(0.0, np.array([0.0, 1.0]), freqs, np.zeros(2))
    assert sublevel_interval(m0, g) == Interval(pytest.approx(-0.7), pytest.approx(0.7))


def amplitude(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Amplitudes of a real design: zero, or at least 1e-6 in size."""
    return st.floats(lo, hi).map(lambda v: 0.0 if abs(v) < 1e-6 else v)


design = st.builds(
    lambda mu, fe, we, kp, wk_ratio, fp: GearParams.model_validate(
        {
            "damping": mu,
            "transmission_error": {"frequency": we, "harmonics": [{"amplitude": fe}]},
            "stiffness": {"frequency": we * wk_ratio, "harmonics": [{"amplitude": kp}]},
            "torque": {"frequency": we / 2, "harmonics": [{"amplitude": fp}]},
        }
    ),
    amplitude(0.0, 0.3),
    amplitude(-0.5, 0.5),
    st.floats(0.1, 2.0),
    amplitude(-0.3, 0.3),
    st.sampled_from([1, 2, 3]),
    amplitude(-0.2, 0.2),
)


@settings(max_examples=40, deadline=None)
@given(design, st.floats(-3.0, 3.0), st.sampled_from(["plus", "minus"]))
def test_melnikov_is_affine_in_amplitudes_and_damping(p: GearParams, s: float, br: str) -> None:
    """M(p0 + s dp) = M(p0) + s (M(p0 + dp) - M(p0)) for damping and every amplitude."""
    tau = np.linspace(0.0, 30.0, 7)
    for name in ("mu", "F_e1", "k_p1", "F_p1"):
        base = with_alias(p, name, 0.1)
        step = with_alias(p, name, 0.2)
        far = (
            with_alias(p, name, 0.1 + 0.1 * abs(s))
            if name == "mu"
            else with_alias(p, name, 0.1 + 0.1 * s)
        )
        k = abs(s) if name == "mu" else s
        m0, m1, ms = (melnikov_coefficients(q, 0.1667, 0.1667, br)(tau) for q in (base, step, far))
        np.testing.assert_allclose(ms, m0 + k * (m1 - m0), atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(design)
def test_thresholds_flip_the_verdict(p: GearParams) -> None:
    r = melnikov(p, omega_scan=(0.5, 1.0, 2))
    for name in ("F_e1", "mu", "k_p1", "F_p1"):
        t = r.thresholds[name]
        # a degenerate interval [p, p] (M identically 0 there) is a point, not a flip
        proper = {e for lo, hi in t.no_chaos if lo != hi for e in (lo, hi) if e is not None}
        for crit in t.critical_values:
            eps = 1e-6 * max(1.0, abs(crit))
            if crit not in proper or (name == "mu" and crit - eps < 0.0):
                continue
            lo = melnikov(with_alias(p, name, crit - eps), omega_scan=(0.5, 1.0, 2))
            hi = melnikov(with_alias(p, name, crit + eps), omega_scan=(0.5, 1.0, 2))
            assert lo.chaos_possible != hi.chaos_possible, (name, crit)


@settings(max_examples=200, deadline=None)
@given(
    st.floats(-2.0, 2.0),
    st.floats(-2.0, 2.0),
    st.lists(st.tuples(amp, amp), min_size=1, max_size=4),
)
def test_supremum_interval_matches_its_piecewise_linear_function(
    offset: float, slope: float, pairs: list[tuple[float, float]]
) -> None:
    """Incommensurate frequencies: phi(p) = offset + p slope + sum_i |a_i + p b_i|, with a
    nonzero slope too (a parameter in both the constant and the sinusoids)."""
    n = len(pairs)
    freqs = np.sqrt(np.array([2.0, 3.0, 5.0, 7.0]))[:n]  # rationally independent
    a = np.array([p[0] for p in pairs])
    b = np.array([p[1] for p in pairs])
    m0 = TrigSum(offset, a, freqs, np.zeros(n))
    g = TrigSum(slope, b, freqs, np.zeros(n))
    interval = sublevel_interval(m0, g)
    for p in np.linspace(-8.0, 8.0, 161):
        phi = offset + p * slope + float(np.abs(a + p * b).sum())
        if abs(phi) > 1e-9:
            inside = interval is not None and interval.contains(float(p))
            assert inside == (phi <= 0.0), (p, phi, interval)
