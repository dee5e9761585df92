"""Diagnostics of the recorded response x(t): contact regime, amplitudes, spectrum, samples.

Contact regime from the extremes of x over every recorded step (Eq. 8, x in units of b):
x > 1 tooth contact, |x| <= 1 separation (inside the backlash), x < -1 back-side contact.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

ImpactRegime = Literal["no_impact", "single_sided", "double_sided"]

POINCARE_CAP = 256
"""Largest number of Poincare points returned (the last ones)."""
HISTORY_CAP = 2000
"""Largest number of (t, x, v) samples of the returned time history."""
HISTORY_PERIODS = 20
"""Sampling intervals T0 covered by the returned time history (the last ones)."""
N_PEAKS = 8
"""Largest number of spectrum peaks returned."""
PEAK_FLOOR = 1e-3
"""Peaks below this fraction of the largest one are dropped."""


def impact_regime(xmin: float, xmax: float) -> ImpactRegime:
    """Contact regime from the extremes of x over the record (x in units of b, Eq. 8).

    no_impact: the teeth never separate, x > 1 throughout (drive-side contact) or x < -1
    throughout (permanent back-side contact); double_sided: both flanks are hit (x > 1 and
    x < -1 both occur); single_sided: separation with contact on at most one flank.
    """
    if xmin > 1.0 or xmax < -1.0:
        return "no_impact"
    if xmax > 1.0 and xmin < -1.0:
        return "double_sided"
    return "single_sided"


def rms(x: np.ndarray) -> float:
    """Root mean square sqrt(mean x^2) of the samples (about 0, mean included)."""
    return float(math.sqrt(np.mean(x * x)))


def spectrum_peaks(x: np.ndarray, dt: float, omega_ref: float) -> list[dict[str, float]]:
    """Largest local maxima of the one-sided amplitude spectrum of x - mean(x).

    A Hann window is applied; amplitudes are scaled so a sinusoid A cos(w t) gives a peak of A.

    Args:
        x: samples, shape (n,), spaced ``dt`` time units.
        omega_ref: reference angular frequency (Omega_0, or the fastest excitation frequency when
            the forcing has no common period).

    Returns:
        Up to ``N_PEAKS`` dicts sorted by decreasing amplitude: ``frequency`` (angular, rad per
        unit time, bin centre), ``amplitude`` (units of x) and ``order`` = frequency / omega_ref.
    """
    if x.size < 8:
        return []
    w = np.hanning(x.size)
    amp = 2.0 * np.abs(np.fft.rfft((x - x.mean()) * w)) / w.sum()
    omega = 2.0 * math.pi * np.fft.rfftfreq(x.size, dt)
    top = amp.max()
    if not top > 0.0:
        return []
    inner = np.flatnonzero(
        (amp[1:-1] >= amp[:-2]) & (amp[1:-1] > amp[2:]) & (amp[1:-1] > PEAK_FLOOR * top)
    )
    idx = inner[np.argsort(amp[inner + 1])[::-1][:N_PEAKS]] + 1
    return [
        {
            "frequency": float(omega[i]),
            "amplitude": float(amp[i]),
            "order": float(omega[i] / omega_ref),
        }
        for i in idx
    ]


def poincare_points(xs: np.ndarray, vs: np.ndarray) -> list[list[float]]:
    """The last ``POINCARE_CAP`` strobes as [[x, v], ...]."""
    return np.column_stack([xs, vs])[-POINCARE_CAP:].tolist()


def time_history(
    t0: float, dt: float, hx: np.ndarray, hv: np.ndarray, period: float
) -> dict[str, list[float]]:
    """The last ``HISTORY_PERIODS`` intervals of the samples, decimated to <= ``HISTORY_CAP``.

    Args:
        t0: time of sample 0; dt: sample spacing (time units); hx, hv: samples, shape (n,).
        period: sampling interval T0.

    Returns:
        {"t": [...], "x": [...], "v": [...]}, equal lengths.
    """
    n_tail = min(hx.size, max(1, round(HISTORY_PERIODS * period / dt)))
    start = hx.size - n_tail
    step = max(1, math.ceil(n_tail / HISTORY_CAP))
    idx = np.arange(hx.size - 1, start - 1, -step)[::-1]  # ends on the last sample
    return {"t": (t0 + dt * idx).tolist(), "x": hx[idx].tolist(), "v": hv[idx].tolist()}
