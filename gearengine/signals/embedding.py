"""Delay embedding of a scalar series: the delay by average mutual information, the dimension
by false nearest neighbours.

Delay tau: the first local minimum of the average mutual information

    I(T) = sum_{a,b} p_ab(T) log(p_ab(T) / (p_a p_b))          [nats]

of the pairs (x_n, x_{n+T}) on a 2-D histogram of B = ``mi_bins(n)`` equal bins per axis
(A. M. Fraser, H. L. Swinney, "Independent coordinates for strange attractors from mutual
information", Phys. Rev. A 33 (1986) 1134-1140); if I has no minimum up to ``MAX_DELAY``, the
first T where I falls below I(0) / e.

Dimension m: false nearest neighbours (M. B. Kennel, R. Brown, H. D. I. Abarbanel,
"Determining embedding dimension for phase-space reconstruction using a geometrical
construction", Phys. Rev. A 45 (1992) 3403-3411). The nearest neighbour j of point i in
dimension d is false when adding coordinate d+1 separates them:

    |x_{i+d tau} - x_{j+d tau}| / R_d(i) > R_TOL      (criterion 1, Eq. 4 of Kennel 1992), or
    R_{d+1}(i) / R_A > A_TOL                           (criterion 2, R_A = std of x).

m is the first d whose false fraction is below ``FNN_FRACTION`` (noise never lets it reach
zero), else the first d within a tenth (+ 0.01) of the smallest fraction. Nearest neighbours by
scipy's cKDTree, excluding neighbours closer in time than the delay window (Theiler).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from gearengine.signals.nolds_check import first_decorrelation

MAX_DELAY = 200
"""Largest delay (samples) at which the mutual information is evaluated."""
MI_POINTS = 1 << 16
"""Samples used for the mutual information (the first ones)."""
FNN_POINTS = 4000
"""Points used for the false-nearest-neighbour count (evenly spread over the series)."""
ACF_POINTS = 4096
"""Samples of the autocorrelation's first zero (``first_decorrelation`` is O(n^2))."""
MAX_DIMENSION = 10
R_TOL = 15.0
A_TOL = 2.0
FNN_FRACTION = 0.01


@dataclass(frozen=True)
class Embedding:
    """Delay (samples), dimension and the curves that chose them."""

    delay: int
    dimension: int
    mutual_information: list[float]
    """I(T) for T = 0..len-1, nats."""
    delay_rule: str
    false_neighbours: list[float]
    """False fraction for d = 1..len."""


def mi_bins(n: int) -> int:
    """Bins per axis of the mutual-information histogram: sqrt(n / 5), 8 to 64."""
    return int(min(64, max(8, math.sqrt(n / 5.0))))


def mutual_information(x: np.ndarray, max_delay: int) -> np.ndarray:
    """I(T) for T = 0..max_delay (nats) on equal-width bins of the range of x, shape (T+1,)."""
    x = x[:MI_POINTS]
    bins = mi_bins(x.size)
    lo, hi = float(x.min()), float(x.max())
    idx = np.minimum(((x - lo) / (hi - lo) * bins).astype(np.int64), bins - 1)
    out = np.empty(max_delay + 1)
    for T in range(max_delay + 1):
        a, b = idx[: x.size - T], idx[T:]
        joint = np.bincount(a * bins + b, minlength=bins * bins).astype(float) / a.size
        pa = np.bincount(a, minlength=bins) / a.size
        pb = np.bincount(b, minlength=bins) / a.size
        nz = joint > 0.0
        outer = np.outer(pa, pb).ravel()
        out[T] = float(np.sum(joint[nz] * np.log(joint[nz] / outer[nz])))
    return out


def delay_by_mutual_information(x: np.ndarray) -> tuple[int, np.ndarray, str]:
    """(delay, I(T), rule): the first local minimum of I, else the first drop below I(0)/e;
    never beyond the first zero of the autocorrelation (``first_decorrelation`` on the first
    ``ACF_POINTS`` samples), where a map's or a noise's I only fluctuates at its bias."""
    max_delay = max(1, min(MAX_DELAY, x.size // 20))
    mi = mutual_information(x, max_delay)
    decorrelated = first_decorrelation(x[:ACF_POINTS])
    delay, rule = max_delay, f"no minimum up to {max_delay} samples: the largest delay tried"
    minima = [T for T in range(1, max_delay) if mi[T] < mi[T - 1] and mi[T] <= mi[T + 1]]
    below = np.flatnonzero(mi[1:] < mi[0] / math.e)
    if minima:
        delay, rule = minima[0], "first minimum of the average mutual information"
    elif below.size:
        delay, rule = int(below[0]) + 1, "first drop of the mutual information below I(0)/e"
    if decorrelated < delay:
        delay, rule = decorrelated, "first zero of the autocorrelation (before any minimum of "
        "the mutual information)"
    return delay, mi, rule


def delay_vectors(x: np.ndarray, dimension: int, delay: int) -> np.ndarray:
    """Rows (x_i, x_{i+tau}, ..., x_{i+(m-1)tau}), shape (n - (m-1) tau, m) (a strided view)."""
    n = x.size - (dimension - 1) * delay
    return np.lib.stride_tricks.as_strided(
        x, shape=(n, dimension), strides=(x.strides[0], delay * x.strides[0]), writeable=False
    )


def false_neighbour_fractions(x: np.ndarray, delay: int, max_dimension: int) -> list[float]:
    """Kennel's false fraction for d = 1..max_dimension (criteria 1 and 2 above), up to the
    first d below ``FNN_FRACTION``."""
    x = np.ascontiguousarray(x, dtype=float)
    r_a = float(np.std(x))
    out = []
    for d in range(1, max_dimension + 1):
        n = x.size - d * delay  # points that have a coordinate d+1
        if n < 50:
            break
        vec = delay_vectors(x, d, delay)[:n]
        pick = np.unique(np.linspace(0, n - 1, min(n, FNN_POINTS)).astype(np.int64))
        tree = cKDTree(vec)
        dist, nb = tree.query(vec[pick], k=min(n, 2 + 2 * delay))
        far = np.abs(nb - pick[:, None]) > delay  # Theiler window: not a temporal neighbour
        far[:, 0] &= dist[:, 0] > 0.0
        first = np.argmax(far, axis=1)
        ok = far[np.arange(pick.size), first]
        i, j = pick[ok], nb[np.arange(pick.size), first][ok]
        r_d = np.maximum(dist[np.arange(pick.size), first][ok], 1e-300)
        extra = np.abs(x[i + d * delay] - x[j + d * delay])
        r_next = np.sqrt(r_d**2 + extra**2)
        false = (extra / r_d > R_TOL) | (r_next / r_a > A_TOL)
        out.append(float(np.mean(false)) if false.size else 1.0)
        if out[-1] < FNN_FRACTION:  # embedded: higher dimensions are not needed
            break
    return out


def embedding_dimension(fractions: list[float]) -> int:
    """First d with a false fraction below ``FNN_FRACTION``, else where it stops falling."""
    for d, f in enumerate(fractions, start=1):
        if f < FNN_FRACTION:
            return d
    if not fractions:
        return 1
    floor = min(fractions)
    return next(d for d, f in enumerate(fractions, start=1) if f <= 1.1 * floor + 0.01)


def embed(x: np.ndarray, cap: int | None = None) -> Embedding:
    """Delay and dimension of the series x (shape (n,), n >= 200); the delay at most ``cap``
    samples when given (a quarter of a forced series' cycle)."""
    delay, mi, rule = delay_by_mutual_information(x)
    if cap is not None and delay > cap:
        delay, rule = cap, f"a quarter cycle ({rule} is later)"
    fractions = false_neighbour_fractions(x, delay, MAX_DIMENSION)
    return Embedding(delay, embedding_dimension(fractions), mi.tolist(), rule, fractions)
