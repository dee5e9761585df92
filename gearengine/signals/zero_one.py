"""The 0-1 test for chaos, correlation method (Gottwald & Melbourne).

For a series phi(j), j = 1..N, and a frequency c in (0, pi), the translation variables

    p_c(n) = sum_{j<=n} phi(j) cos(j c),   q_c(n) = sum_{j<=n} phi(j) sin(j c)       (Eq. 2)

stay bounded for a regular series and diffuse like a random walk for a chaotic one. The mean
square displacement, less its oscillatory term,

    M_c(n) = 1/N sum_{j=1}^{N} [p_c(j+n) - p_c(j)]^2 + [q_c(j+n) - q_c(j)]^2          (Eq. 3)
    D_c(n) = M_c(n) - (mean phi)^2 (1 - cos n c) / (1 - cos c)                         (Eq. 5)

is correlated with n for n = 1..n_cut = N / 10: K_c = corr(n, D_c(n)) (Eq. 6), near 0 for a
regular series and near 1 for a chaotic one. K is the median of K_c over ``N_FREQUENCIES``
frequencies c drawn uniformly in [pi/5, 4 pi/5] (the median discards the few c that resonate
with a period). As the implementations of reference (Matthews' z1test.m, R ``Chaos01``,
ChaosTools.jl ``testchaos01``), the sum in Eq. 3 runs over j <= N - n_cut.

The test assumes a series sampled near the decorrelation time: a flow sampled finely makes
a chaotic series look regular, so a gear's series is read once per mesh or shaft period
(``orders.strobes``), another flow at its embedding delay.

References: G. A. Gottwald, I. Melbourne, "A new test for chaos in deterministic systems",
Proc. R. Soc. Lond. A 460 (2004) 603-611; "On the implementation of the 0-1 test for chaos",
SIAM J. Appl. Dyn. Syst. 8 (2009) 129-145 (the correlation method and D_c).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

N_FREQUENCIES = 100
C_LOW, C_HIGH = math.pi / 5.0, 4.0 * math.pi / 5.0
MAX_POINTS = 5000
"""Largest series length tested (the last ones); the cost is O(N^2 / 10) per frequency."""
MIN_POINTS = 100
"""Shortest series the test reads (n_cut = 10)."""


@dataclass(frozen=True)
class ZeroOne:
    """K (median over c), its quartiles and extremes, the c used, and one (p, q) path."""

    k: float
    k_quartiles: tuple[float, float]
    k_range: tuple[float, float]
    frequencies: int
    points: int
    c_path: float
    p: np.ndarray
    q: np.ndarray


@njit(cache=True, nogil=True)
def _k_of_c(phi: np.ndarray, c: float, n_cut: int) -> float:  # pragma: no cover - compiled
    """K_c of Eq. 6: corr(n, D_c(n)), n = 1..n_cut (Eq. 2, 3, 5)."""
    size = phi.size
    p = np.empty(size)
    q = np.empty(size)
    sp = 0.0
    sq = 0.0
    mean = 0.0
    for j in range(size):
        sp += phi[j] * math.cos((j + 1) * c)
        sq += phi[j] * math.sin((j + 1) * c)
        p[j] = sp
        q[j] = sq
        mean += phi[j]
    mean /= size
    span = size - n_cut
    d = np.empty(n_cut)
    for n in range(1, n_cut + 1):
        acc = 0.0
        for j in range(span):
            dp = p[j + n] - p[j]
            dq = q[j + n] - q[j]
            acc += dp * dp + dq * dq
        d[n - 1] = acc / span - mean * mean * (1.0 - math.cos(n * c)) / (1.0 - math.cos(c))
    xm = (n_cut + 1) / 2.0
    dm = 0.0
    for n in range(n_cut):
        dm += d[n]
    dm /= n_cut
    sxy = 0.0
    sxx = 0.0
    syy = 0.0
    for n in range(n_cut):
        a = n + 1 - xm
        b = d[n] - dm
        sxy += a * b
        sxx += a * a
        syy += b * b
    if syy <= 0.0:
        return 0.0
    return sxy / math.sqrt(sxx * syy)


def translation(phi: np.ndarray, c: float) -> tuple[np.ndarray, np.ndarray]:
    """(p_c(n), q_c(n)) of Eq. 2, shape (N,) each."""
    j = np.arange(1, phi.size + 1)
    return np.cumsum(phi * np.cos(j * c)), np.cumsum(phi * np.sin(j * c))


def zero_one_test(phi: np.ndarray, seed: int = 0) -> ZeroOne:
    """K of the series ``phi`` (shape (N,), MIN_POINTS <= N; the last MAX_POINTS used)."""
    phi = np.ascontiguousarray(phi[-MAX_POINTS:], dtype=np.float64)
    phi = (phi - phi.mean()) / (phi.std() or 1.0) + 0.0  # K is invariant; conditioned sums
    cs = np.random.default_rng(seed).uniform(C_LOW, C_HIGH, N_FREQUENCIES)
    n_cut = phi.size // 10
    ks = np.array([_k_of_c(phi, float(c), n_cut) for c in cs])
    p, q = translation(phi, float(cs[0]))
    q1, med, q3 = np.percentile(ks, [25, 50, 75])
    return ZeroOne(float(med), (float(q1), float(q3)), (float(ks.min()), float(ks.max())),
                   N_FREQUENCIES, int(phi.size), float(cs[0]), p, q)  # fmt: skip
