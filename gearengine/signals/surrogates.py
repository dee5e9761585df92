"""Surrogate-data test: is the series more predictable than linear Gaussian noise with its
spectrum and its distribution?

Null hypothesis: the series is a static monotone transform of a linear Gaussian process.
Surrogates that keep both the amplitude spectrum and the distribution of values come from the
iterative amplitude-adjusted Fourier transform (IAAFT, T. Schreiber, A. Schmitz, "Improved
surrogate data for nonlinearity tests", Phys. Rev. Lett. 77 (1996) 635-638; "Surrogate time
series", Physica D 142 (2000) 346-382): start from a random shuffle, then alternately impose the
amplitude spectrum (keeping the phases) and the values (rank order) until the ranks stop
changing or ``MAX_ITERATIONS``.

Statistic: the nearest-neighbour prediction error of the series in its delay embedding (m,
tau), ``delay`` samples ahead, normalised by the standard deviation (E. N. Lorenz's method of
analogues; Schreiber & Schmitz 2000, Sect. 4): deterministic dynamics predict their future
from their past better than any linear noise of the same spectrum. With S surrogates the
one-sided rank test gives p = (1 + #{surrogate errors <= series error}) / (S + 1); the null is
rejected at p <= ``ALPHA``.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from gearengine.signals.embedding import delay_vectors

SURROGATES = 39
"""Number of surrogates: the smallest p is 1/40 = 0.025."""
ALPHA = 0.05
_GLOBAL_RANDOM = threading.Lock()
ITERATIONS = 100
"""IAAFT iterations (Schreiber & Schmitz: the ranks settle within a few dozen)."""
MAX_POINTS = 2048
"""Largest series length tested (the last ones)."""


@dataclass(frozen=True)
class SurrogateTest:
    """The series' statistic, the surrogates' statistics, the p-value and the verdict."""

    statistic: float
    surrogate_statistics: list[float]
    p_value: float
    rejected: bool
    surrogates: int
    points: int


def iaaft(x: np.ndarray, count: int, seed: int) -> np.ndarray:
    """``count`` IAAFT surrogates of x (shape (n,)), shape (count, n): pyunicorn's
    ``Surrogates.refined_AAFT_surrogates`` with ``ITERATIONS`` iterations. pyunicorn draws from
    numpy's global RandomState: it is seeded under a lock, so a request's surrogates depend on
    its seed only, whatever else runs in the process."""
    from pyunicorn.timeseries.surrogates import Surrogates  # ~0.3 s: only when a test runs

    with _GLOBAL_RANDOM, np.errstate(invalid="ignore", divide="ignore"):  # empty FFT bins
        np.random.seed(seed)
        data = np.tile(x, (count, 1))
        return Surrogates(original_data=data, silence_level=2).refined_AAFT_surrogates(ITERATIONS)


def prediction_error(x: np.ndarray, dimension: int, delay: int) -> float:
    """Normalised error of predicting x ``delay`` samples ahead from the nearest neighbour of
    each delay vector (neighbours closer in time than the embedding window excluded)."""
    vec = delay_vectors(np.ascontiguousarray(x, dtype=float), dimension, delay)
    n = vec.shape[0] - delay
    window = dimension * delay
    dist, nb = cKDTree(vec[:n]).query(vec[:n], k=min(n, 2 + 2 * window))
    far = (np.abs(nb - np.arange(n)[:, None]) > window) & np.isfinite(dist)
    first = np.argmax(far, axis=1)
    ok = far[np.arange(n), first]
    i = np.arange(n)[ok]
    j = nb[np.arange(n), first][ok]
    last = (dimension - 1) * delay + delay
    err = x[i + last] - x[j + last]
    return float(np.sqrt(np.mean(err**2)) / (np.std(x) or 1.0))


def surrogate_test(x: np.ndarray, dimension: int, delay: int, seed: int = 0) -> SurrogateTest:
    """Rank test of the prediction error of x against ``SURROGATES`` IAAFT surrogates."""
    x = np.ascontiguousarray(x[-MAX_POINTS:], dtype=float)
    stat = prediction_error(x, dimension, delay)
    stats = [prediction_error(s, dimension, delay) for s in iaaft(x, SURROGATES, seed)]
    p = (1 + sum(s <= stat for s in stats)) / (SURROGATES + 1)
    return SurrogateTest(stat, stats, p, p <= ALPHA, SURROGATES, int(x.size))
