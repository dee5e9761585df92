"""Largest Lyapunov exponent of a scalar series by Rosenstein's method.

In the delay embedding Y_i (dimension m, delay tau samples) each point's nearest neighbour Y_j
with |i - j| > ``min_tsep`` (a mean period: no neighbour on the same stretch of trajectory) is
followed for k = 0..L-1 steps; the mean log distance

    y(k) = < ln |Y_{i+k} - Y_{j+k}| >_i                    (Rosenstein et al. 1993, Eq. 10)

grows as y(0) + lambda_1 k dt over a linear range before it saturates at the attractor's size.
lambda_1 is the slope of a least-squares line over the fit range (``fit_range``: the steepest
straight stretch of two mean periods before the plateau), per second when dt is the sample
spacing in seconds.

Two implementations of the same y(k): ``nolds.lyap_r`` (C. Schölzel, nolds 0.6,
doi:10.5281/zenodo.3814723), which builds the full n x n distance matrix (8 n^2 bytes, ~3 GB at
20,000 points), for series up to ``NOLDS_MAX_POINTS`` points; above it the neighbours come from
scipy's cKDTree (memory O(n)), which finds the same neighbours as nolds' masked argmin (the
tests compare both where both run). nolds returns its own fit over the whole trajectory; the
fit range here is applied to its divergence curve (``debug_data``), as ``fit_offset`` and a
shorter ``trajectory_len`` would.

Reference: M. T. Rosenstein, J. J. Collins, C. J. De Luca, "A practical method for calculating
largest Lyapunov exponents from small data sets", Physica D 65 (1993) 117-134.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.spatial import cKDTree

from gearengine.signals.embedding import delay_vectors

NOLDS_MAX_POINTS = 3000
"""Largest series given to nolds.lyap_r: its distance matrix is then <= 72 MB (twice that while
it is built)."""
MAX_POINTS = 10000
"""Largest series followed with the KD tree (the last points of a longer one)."""
PLATEAU_RISE = 0.9
"""The fit ends before y(k) has risen 90 % of its way to the plateau."""
PLATEAU_TAIL = 0.25
"""The plateau is the mean of the last quarter of y(k)."""


@dataclass(frozen=True)
class Divergence:
    """y(k) for k = 0..L-1 and how it was computed."""

    curve: np.ndarray
    implementation: Literal["nolds.lyap_r", "cKDTree"]
    points: int


@dataclass(frozen=True)
class Rosenstein:
    """lambda_1 (per second), the fit range (steps) and the divergence curve."""

    exponent: float
    fit_range: tuple[int, int]
    divergence: Divergence
    min_tsep: int
    trajectory_len: int


def nearest_neighbours(vectors: np.ndarray, min_tsep: int) -> np.ndarray:
    """For each row i, the nearest row j with |i - j| > min_tsep (shape (n,)), as nolds'
    masked argmin; -1 where every other row is that close in time."""
    n = vectors.shape[0]
    tree = cKDTree(vectors)
    result = np.full(n, -1, dtype=np.int64)
    todo = np.arange(n)
    k = min(n, 2 * min_tsep + 8)
    while todo.size:
        _, nb = tree.query(vectors[todo], k=k)
        far = np.abs(nb - todo[:, None]) > min_tsep
        far &= nb < n  # cKDTree pads missing neighbours with n
        found = far.any(axis=1)
        first = np.argmax(far, axis=1)
        result[todo[found]] = nb[np.arange(todo.size), first][found]
        todo = todo[~found]
        if k >= n:
            break
        k = min(n, 2 * k)
    return result


def divergence_kdtree(vectors: np.ndarray, min_tsep: int, trajectory_len: int) -> np.ndarray:
    """y(k), k = 0..L-1, with the neighbours of ``nearest_neighbours`` among the first
    n - L + 1 rows (those that can be followed L steps), zero distances left out as nolds."""
    ntraj = vectors.shape[0] - trajectory_len + 1
    nb = nearest_neighbours(vectors[:ntraj], min_tsep)
    i = np.flatnonzero(nb >= 0)
    j = nb[i]
    out = np.empty(trajectory_len)
    for k in range(trajectory_len):
        d = np.sqrt(np.sum((vectors[i + k] - vectors[j + k]) ** 2, axis=1))
        d = d[d != 0.0]
        out[k] = np.mean(np.log(d)) if d.size else -np.inf
    return out


def divergence(
    x: np.ndarray, dimension: int, delay: int, min_tsep: int, trajectory_len: int
) -> Divergence:
    """y(k) of the series x (shape (n,)): nolds for n <= NOLDS_MAX_POINTS, else the KD tree."""
    x = np.ascontiguousarray(x[-MAX_POINTS:], dtype=float)
    if x.size <= NOLDS_MAX_POINTS:
        import nolds  # loads pkg_resources (~0.1 s): only when it runs

        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            _, (ks, curve, _) = nolds.lyap_r(
                x, emb_dim=dimension, lag=delay, min_tsep=min_tsep, tau=1.0,
                trajectory_len=trajectory_len, fit="poly", debug_data=True,
            )  # fmt: skip
        full = np.full(trajectory_len, -np.inf)
        full[np.asarray(ks, dtype=np.int64)] = curve
        return Divergence(full, "nolds.lyap_r", int(x.size))
    vectors = delay_vectors(x, dimension, delay)
    return Divergence(divergence_kdtree(vectors, min_tsep, trajectory_len), "cKDTree", int(x.size))


def fit_range(curve: np.ndarray, window: int) -> tuple[int, int]:
    """[start, start + window) of the steepest straight stretch of y(k) (least-squares slope
    over ``window`` steps), among those starting at k >= 1 and ending before y has risen
    ``PLATEAU_RISE`` of its way from y(1) to the plateau (the mean of its last quarter).

    Not from k = 0: the nearest neighbours are chosen there, where measurement noise makes
    them look closer than they are, and y jumps at the first step by the noise alone. The
    window spans whole cycles of the series (two mean periods, or two mesh periods of a gear),
    over which the modulation of the divergence by the forcing averages out."""
    y = np.where(np.isfinite(curve), curve, np.nan)
    window = max(3, min(window, y.size - 1))
    tail = y[-max(1, int(PLATEAU_TAIL * y.size)) :]
    if y.size < 4 or not np.isfinite(y[1]) or not np.any(np.isfinite(tail)):
        return 0, min(3, y.size)
    base = float(y[1])
    risen = np.flatnonzero(y >= base + PLATEAU_RISE * (float(np.nanmean(tail)) - base))
    end = int(risen[0]) + 1 if risen.size else y.size
    last = max(1, min(end, y.size) - window)
    k = np.arange(window, dtype=float) - 0.5 * (window - 1)
    best, start = -math.inf, 1
    for a in range(1, last + 1):
        seg = y[a : a + window]
        if np.all(np.isfinite(seg)):
            slope = float(np.dot(k, seg - seg.mean()) / np.dot(k, k))
            if slope > best:
                best, start = slope, a
    return start, start + window


def largest_exponent(
    x: np.ndarray, dt: float, dimension: int, delay: int, min_tsep: int, trajectory_len: int
) -> Rosenstein:
    """lambda_1 [1/s] of x (samples spaced dt seconds) in the embedding (dimension, delay);
    ``min_tsep`` (samples) is the mean period, or a gear's cycle, and sets the fit window."""
    div = divergence(x, dimension, delay, min_tsep, trajectory_len)
    start, stop = fit_range(div.curve, 2 * min_tsep)
    k = np.arange(start, stop)
    y = div.curve[start:stop]
    ok = np.isfinite(y)
    slope = float(np.polyfit(k[ok], y[ok], 1)[0]) if ok.sum() >= 2 else math.nan
    return Rosenstein(slope / dt, (start, stop), div, min_tsep, trajectory_len)
