"""Largest Lyapunov exponent from the Benettin renormalisation logs of the kernels.

The tangent vector is renormalised every interval T0; with l_k = log |d_k| over the n_rec
recorded intervals,

    lambda = sum_k l_k / (n_rec T0)            (per unit dimensionless time tau)

The standard error comes from B = ``BLOCKS`` contiguous block estimates lambda_b (each the same
formula over its block): stderr = std(lambda_b, ddof=1) / sqrt(B). The estimate is called
converged when the first-half estimate agrees with the whole one:
|lambda_half - lambda| <= max(3 stderr, 0.05 |lambda|, ABS_TOL).

Reference: G. Benettin, L. Galgani, A. Giorgilli, J.-M. Strelcyn, "Lyapunov characteristic
exponents for smooth dynamical systems and for Hamiltonian systems; a method for computing all of
them", Meccanica 15 (1980) 9-30 (the renormalised tangent vector); A. Wolf, J. B. Swift,
H. L. Swinney, J. A. Vastano, "Determining Lyapunov exponents from a time series", Physica D 16
(1985) 285-317 (the same renormalisation, described for practitioners).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

BLOCKS = 10
"""Number of blocks of the standard error."""
ABS_TOL = 1e-4
"""Absolute agreement (per unit time) accepted between half and whole record."""


@dataclass(frozen=True)
class LyapunovEstimate:
    """Largest Lyapunov exponent (per unit time) with its error estimates."""

    lle: float
    stderr: float | None
    first_half: float | None
    converged: bool


def _blocks(logs: np.ndarray, b: int) -> list[np.ndarray]:
    """``np.array_split(logs, b)`` for a 1-d array, without its generic overhead (the same
    views, so the same sums): the first ``n % b`` blocks hold one element more."""
    each, extra = divmod(logs.size, b)
    parts, start = [], 0
    for k in range(b):
        stop = start + each + (1 if k < extra else 0)
        parts.append(logs[start:stop])
        start = stop
    return parts


def benettin(logs: np.ndarray, period: float, blocks: int = BLOCKS) -> LyapunovEstimate:
    """LLE from renormalisation logs l_k, shape (n_rec,), taken every ``period`` time units."""
    n = logs.size
    total = np.cumsum(logs)  # sequential sum, as gear_ref.c
    lle = float(total[-1] / (n * period))
    half = n // 2
    first_half = float(total[half - 1] / (half * period)) if half >= 1 else None
    b = min(blocks, n)
    stderr = None
    if b >= 2:
        estimates = [part.sum() / (part.size * period) for part in _blocks(logs, b)]
        stderr = float(np.std(estimates, ddof=1) / math.sqrt(b))
    converged = (
        first_half is not None
        and stderr is not None
        and abs(first_half - lle) <= max(3.0 * stderr, 0.05 * abs(lle), ABS_TOL)
    )
    return LyapunovEstimate(lle, stderr, first_half, converged)


def benettin_rows(logs: np.ndarray, period: np.ndarray, blocks: int = BLOCKS) -> tuple:
    """``benettin``'s LLE and stderr for many records of one length at once.

    ``logs`` has shape (m, n), n >= 1, one record per row taken every ``period[row]``. The sums
    run as ``benettin``'s (a sequential cumsum for the total, numpy's row sums for the blocks),
    so the numbers are the same bit for bit. Returns (lle, stderr) arrays; stderr is NaN where
    ``benettin`` gives None (fewer than two blocks).
    """
    n = logs.shape[1]
    lle = np.cumsum(logs, axis=1)[:, -1] / (n * period)
    b = min(blocks, n)
    if b < 2:
        return lle, np.full(lle.shape, np.nan)
    each, extra = divmod(n, b)
    estimates = np.empty((logs.shape[0], b))
    start = 0
    for k in range(b):
        stop = start + each + (1 if k < extra else 0)
        estimates[:, k] = logs[:, start:stop].sum(axis=1) / ((stop - start) * period)
        start = stop
    return lle, np.std(estimates, axis=1, ddof=1) / math.sqrt(b)
