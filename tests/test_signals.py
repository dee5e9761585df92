"""Known series read by gearengine.signals give the known answer (issue 33, "Done when")."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gearengine.rig import signal
from gearengine.signals import reading
from gearengine.signals.embedding import delay_vectors, embed
from gearengine.signals.rosenstein import divergence, divergence_kdtree
from gearengine.signals.zero_one import zero_one_test

LORENZ_LLE = 0.9056
"""Largest Lyapunov exponent of the Lorenz system (sigma 10, rho 28, beta 8/3), 1/s
(Sprott, Chaos and Time-Series Analysis, 2003, Table A.1)."""


def logistic(r: float, n: int = 3000, x0: float = 0.3) -> np.ndarray:
    x = np.empty(n + 500)
    x[0] = x0
    for i in range(1, x.size):
        x[i] = r * x[i - 1] * (1.0 - x[i - 1])
    return x[500:]


def lorenz_x(seconds: float, rate: float = 100.0) -> np.ndarray:
    """x(t) of the Lorenz system sampled at ``rate`` after a 30 s transient (DOP853, 1e-10)."""

    def rhs(_: float, y: np.ndarray) -> list[float]:
        return [10.0 * (y[1] - y[0]), y[0] * (28.0 - y[2]) - y[1], y[0] * y[1] - 8.0 / 3.0 * y[2]]

    t = np.arange(0.0, seconds + 30.0, 1.0 / rate)
    sol = solve_ivp(rhs, (0.0, t[-1]), [1.0, 1.0, 1.0], t_eval=t, method="DOP853",
                    rtol=1e-10, atol=1e-10)  # fmt: skip
    return sol.y[0][round(30.0 * rate) :]


def ar1(n: int, phi: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    e = rng.normal(size=n + 200)
    x = np.zeros_like(e)
    for i in range(1, e.size):
        x[i] = phi * x[i - 1] + e[i]
    return x[200:]


def test_logistic_map_at_3_5_is_periodic_with_period_4() -> None:
    r = signal(logistic(3.5), 1.0)
    assert r.verdict == "periodic"
    assert r.reference.source == "spectrum" and r.reference.cycle_hz == pytest.approx(0.25)
    assert r.periodicity is not None and r.periodicity.seconds == pytest.approx(4.0)
    assert r.zero_one is not None and r.zero_one.k < 0.1


def test_logistic_map_at_3_97_is_chaotic() -> None:
    r = signal(logistic(3.97), 1.0)
    assert r.verdict == "chaotic", r.summary
    assert r.zero_one is not None and r.zero_one.k > 0.9
    assert r.surrogates is not None and r.surrogates.rejected
    assert r.lyapunov is not None and r.lyapunov.per_second is not None
    assert r.lyapunov.per_second > 0.3  # the map's exponent is ~0.6 per iteration


def test_lorenz_x_at_100_hz_is_chaotic_with_its_exponent() -> None:
    r = signal(lorenz_x(200.0), "100 Hz")
    assert r.verdict == "chaotic", r.summary
    assert r.lyapunov is not None and r.lyapunov.per_second is not None
    assert r.lyapunov.per_second == pytest.approx(LORENZ_LLE, rel=0.15)
    assert r.lyapunov.implementation == "cKDTree"  # 200 s decimated: over nolds' bound
    assert r.embedding is not None and r.embedding.dimension == 3


@pytest.mark.parametrize("series", ["ar1", "white"])
def test_linear_noise_is_stochastic(series: str) -> None:
    x = ar1(6000, 0.9, 1) if series == "ar1" else np.random.default_rng(2).normal(size=6000)
    r = signal(x, "1 kHz")
    assert r.verdict == "stochastic", r.summary
    assert r.surrogates is not None and not r.surrogates.rejected


def test_tones_with_noise_are_periodic() -> None:
    t = np.arange(20000) / 1000.0
    rng = np.random.default_rng(3)
    x = (np.sin(2 * np.pi * 50 * t) + 0.5 * np.sin(2 * np.pi * 150 * t + 1.0)
         + 0.2 * np.sin(2 * np.pi * 25 * t) + 0.05 * rng.normal(size=t.size))  # fmt: skip
    r = signal(x, "1 kHz")
    assert r.verdict == "periodic", r.summary
    assert r.reference.cycle_hz == pytest.approx(25.0, rel=1e-4)
    assert r.periodicity is not None and r.periodicity.cycles == 1


def test_two_incommensurate_tones_are_quasi_periodic() -> None:
    t = np.arange(20000) / 1000.0
    x = np.sin(2 * np.pi * 50 * t) + 0.7 * np.sin(2 * np.pi * 50 * math.sqrt(2) * t)
    r = signal(x, "1 kHz")
    assert r.verdict == "quasi_periodic", r.summary
    assert r.zero_one is not None and r.zero_one.k < 0.1


def test_kdtree_divergence_is_nolds_divergence() -> None:
    x = np.ascontiguousarray(lorenz_x(60.0)[::4][-2500:])
    by_nolds = divergence(x, 3, 4, 19, 150)
    assert by_nolds.implementation == "nolds.lyap_r"
    by_tree = divergence_kdtree(delay_vectors(x, 3, 4), 19, 150)
    np.testing.assert_allclose(by_tree, by_nolds.curve, rtol=0, atol=1e-12)


def test_embedding_of_lorenz_and_of_a_map() -> None:
    lor = embed(lorenz_x(100.0))
    assert lor.dimension == 3 and 10 <= lor.delay <= 20  # 0.1-0.2 s: Fraser & Swinney's ~0.16
    assert embed(logistic(3.97)).delay == 1


def test_zero_one_is_reproducible_and_seeded() -> None:
    x = logistic(3.97, 1000)
    a, b = zero_one_test(x, 7), zero_one_test(x, 7)
    assert a.k == b.k and a.c_path == b.c_path
    assert zero_one_test(x, 8).c_path != a.c_path


def test_tach_resampling_reads_a_run_up_in_orders() -> None:
    """A speed ramp 1200 -> 1800 rpm: in time the mesh line smears over 360-540 Hz, per
    revolution (tach once a turn) it is one line at order 18, and the response is periodic."""
    fs, seconds, teeth = 20000.0, 4.0, 18
    t = np.arange(round(fs * seconds)) / fs
    revs = 20.0 * t + 0.5 * 5.0 * t**2  # 20 -> 40 rev/s... 1200 -> 2400 rpm
    x = np.sin(2 * np.pi * teeth * revs) + 0.3 * np.sin(2 * np.pi * 2 * teeth * revs)
    x += 0.01 * np.random.default_rng(4).normal(size=t.size)
    pulses = np.array([(-20.0 + math.sqrt(400.0 + 10.0 * k)) / 5.0 for k in range(1, 119)])
    r = signal(x, fs, teeth=teeth, tach={"times": pulses.tolist(), "per_revolution": 1})
    assert r.reference.source == "tach"
    top = r.spectrum.lines[0]
    assert top.order == pytest.approx(18.0, abs=0.05) and top.label == "mesh harmonic 1"
    assert r.verdict == "periodic", r.summary


def test_summary_states_the_verdict_and_its_evidence() -> None:
    r = signal(logistic(3.5), 1.0)
    assert r.summary.startswith(reading.WORDS["periodic"] + ": the average over 1 fundamental")
    assert r.evidence and r.evidence[0] in r.summary


def test_same_cycle_matches_a_cycle_at_any_phase_and_nothing_less() -> None:
    """``same_cycle`` is a set test: a period-2 cycle strobed from its other point is itself; a
    fixed point on one of its strobes, or a cycle moved by more than ``tol``, is not; the
    n-dimensional branch (a train's state) answers as the n = 2 one does."""
    from gearengine.signals.periodicity import same_cycle

    cycle = np.array([[0.8, -0.1], [-0.3, 0.4]])
    assert same_cycle(cycle, cycle[::-1], 1e-6)  # strobed half a cycle later
    assert not same_cycle(cycle, cycle[:1], 1e-6)  # the other strobe has no partner
    assert not same_cycle(cycle[:1], cycle, 1e-6)  # the set test runs both ways
    moved = cycle + np.array([0.0, 2e-6])
    assert same_cycle(cycle, moved, 3e-6) and not same_cycle(cycle, moved, 1e-6)
    lifted = np.hstack([cycle, np.array([[0.2], [0.5]])])  # n = 3: the norm branch
    assert same_cycle(lifted, lifted[::-1], 1e-6)
    assert not same_cycle(lifted, lifted + np.array([0.0, 0.0, 1e-3]), 1e-6)
