"""A gear's series read per revolution: angle-domain resampling, order spectrum, strobes and
the period found by synchronous averaging.

Angle domain (order tracking): with a shaft speed (constant) or a tachometer (pulse times,
``per_revolution`` pulses a turn: the time of each angle a cubic spline through the pulses), the
series is interpolated (cubic spline) at ``samples_per_rev`` equal angle steps, a whole number of
samples per mesh period when the teeth are known, so that every ``per_cycle``-th sample is one
strobe (one per mesh period, or per revolution without teeth). Without speed or tach the
"cycle" is the fundamental read from the line spectrum (``fundamental``), or there is none.

Line spectrum: the one-sided amplitude spectrum with a Hann window (a sinusoid of amplitude A
gives a peak A), a local maximum is a line when it stands ``LINE_RATIO`` times above the median
of its ``FLOOR_BINS`` neighbours on each side; its position is refined by the parabola through
the log amplitudes of its three bins (error below 0.05 bin for a clean line).

Period: time-synchronous averaging (the gear-NVH estimator of the periodic part, P. D.
McFadden, "A revised model for the extraction of periodic waveforms by time domain averaging",
Mech. Syst. Signal Process. 1 (1987) 83-95): over n cycles (P = n per_cycle samples, M = len /
P whole periods), the average waveform explains the periodic part; the unexplained fraction

    u_n = var(y - TSA_n(y)) / var(y) * M / (M - 1)

(the factor removes the 1/M of noise that the average keeps) is ~ the noise's share of the
variance for a periodic series, and stays large for a chaotic, quasi-periodic or random one.
The period is the smallest n <= ``MAX_PERIOD`` with u_n <= ``PERIODIC_FRACTION``, no more than
the record's white noise (``noise_share``) leaves, within the noise of the best n
(``period_of``), and at least ``MIN_AVERAGES`` periods in the record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

MAX_PERIOD = 64
"""Longest period tested, in cycles (as the simulation's ``periodicity.MAX_PERIOD``)."""
MIN_AVERAGES = 8
"""Fewest whole periods a synchronous average needs."""
PERIODIC_FRACTION = 0.05
"""Largest unexplained variance of a periodic series (signal-to-noise ratio >= 13 dB)."""
NOISE_FACTOR = 1.5
NOISE_FLOOR = 1e-3
"""Unexplained share accepted of a periodic record without white noise (30 dB): the angle
resampling, speed jitter between tach pulses, rounding."""
NOISE_MARGIN = 0.002
"""A period's average may leave this much more variance than the best one (``period_of``)."""
LINE_RATIO = 10.0
"""A line stands 10 x (20 dB) above its local floor."""
FLOOR_BINS = 32
MAX_LINES = 12
CANDIDATES = 20 * MAX_LINES
"""Local maxima whose floor is measured (the strongest)."""
MAX_HARMONIC = 8
"""The lowest line of a periodic series is at most this harmonic of its fundamental."""
HARMONIC_TOLERANCE = 0.25
"""Largest distance (bins) of a line from a harmonic of the fundamental."""


@dataclass(frozen=True)
class Line:
    """A spectral line: frequency [Hz], amplitude [unit of the values], height over the
    local floor (ratio)."""

    frequency: float
    amplitude: float
    ratio: float


def amplitude_spectrum(y: np.ndarray) -> np.ndarray:
    """Hann-windowed one-sided amplitude spectrum of y - mean(y), shape (n // 2 + 1,)."""
    w = np.hanning(y.size)
    return 2.0 * np.abs(np.fft.rfft((y - y.mean()) * w)) / w.sum()


def lines(amp: np.ndarray, bin_width: float) -> list[Line]:
    """The ``MAX_LINES`` strongest lines of an amplitude spectrum whose bins are
    ``bin_width`` apart (Hz, or orders), strongest first."""
    if amp.size < 8:
        return []
    inner = np.flatnonzero((amp[1:-1] >= amp[:-2]) & (amp[1:-1] > amp[2:])) + 1
    inner = inner[inner >= 2]
    # the floors of the strongest maxima only: lines are among them (a median each)
    inner = inner[np.argsort(amp[inner])[::-1][:CANDIDATES]]
    if not inner.size:
        return []
    lo = np.maximum(inner - FLOOR_BINS, 1)
    hi = np.minimum(inner + FLOOR_BINS + 1, amp.size)
    floors = np.array([np.median(amp[a:b]) for a, b in zip(lo, hi, strict=True)])
    ratio = amp[inner] / np.maximum(floors, 1e-300)
    keep = inner[ratio >= LINE_RATIO]
    ratio = ratio[ratio >= LINE_RATIO]
    order = np.argsort(amp[keep])[::-1][:MAX_LINES]
    out = []
    for k, r in zip(keep[order], ratio[order], strict=True):
        a, b, c = np.log(np.maximum(amp[k - 1 : k + 2], 1e-300))
        shift = 0.5 * (a - c) / (a - 2.0 * b + c) if a - 2.0 * b + c < 0.0 else 0.0
        out.append(Line(float((k + shift) * bin_width), float(amp[k]), float(r)))
    return out


def fundamental(found: list[Line], bin_width: float, duration: float) -> float | None:
    """The largest f0 of which every line is a harmonic (within ``HARMONIC_TOLERANCE`` bins),
    the lowest line being at most the ``MAX_HARMONIC``-th and the record holding
    ``MIN_AVERAGES`` periods of f0; None without lines or without such an f0."""
    if not found:
        return None
    freqs = np.array([ln.frequency for ln in found])
    lowest = float(freqs.min())
    for h in range(1, MAX_HARMONIC + 1):
        f0 = lowest / h
        if f0 * duration < MIN_AVERAGES:
            return None
        # refine f0 on every line: least squares of f_i = k_i f0
        k = np.maximum(np.round(freqs / f0), 1.0)
        f0 = float(np.sum(k * freqs) / np.sum(k * k))
        if np.all(np.abs(freqs - k * f0) <= HARMONIC_TOLERANCE * bin_width):
            return f0
    return None


def angle_resample(
    x: np.ndarray, fs: float, samples_per_rev: int, shaft_hz: float | None,
    tach_revs: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:  # fmt: skip
    """x (shape (n,), fs samples per second) at ``samples_per_rev`` equal angle steps.

    Constant speed: revolution r at time r / shaft_hz. Tach: ``tach_revs`` = (pulse times
    [s], revolutions at those times), the time of an angle a cubic spline through the pulses
    (a speed ramp makes the angle quadratic in time: linear interpolation between once-a-turn
    pulses would jitter the mesh phase); only the span between the first and the last pulse
    inside the record is kept."""
    t = np.arange(x.size) / fs
    if tach_revs is None:
        assert shaft_hz is not None
        ratio = fs / (shaft_hz * samples_per_rev)
        if abs(ratio - round(ratio)) < 1e-9 and round(ratio) >= 1:
            return np.ascontiguousarray(x[:: round(ratio)], dtype=float)  # already per angle
        revs_total = t[-1] * shaft_hz
        angles = np.arange(math.floor(revs_total * samples_per_rev) + 1) / samples_per_rev
        times = angles / shaft_hz
    else:
        pulse_t, pulse_r = tach_revs
        inside = (pulse_t >= t[0]) & (pulse_t <= t[-1])
        pulse_t, pulse_r = pulse_t[inside], pulse_r[inside]
        first = math.ceil(pulse_r[0] * samples_per_rev)
        last = math.floor(pulse_r[-1] * samples_per_rev)
        angles = np.arange(first, last + 1) / samples_per_rev
        times = CubicSpline(pulse_r, pulse_t)(angles)
    return CubicSpline(t, x)(times)


def synchronous_residuals(y: np.ndarray, per_cycle: int, max_period: int) -> list[float]:
    """u_n for n = 1..max_period (fewer when the record holds fewer than MIN_AVERAGES
    periods): the unexplained variance fraction of the n-cycle synchronous average."""
    var = float(np.var(y))
    out = []
    for n in range(1, max_period + 1):
        p = n * per_cycle
        m = y.size // p
        if m < MIN_AVERAGES:
            break
        block = y[y.size - m * p :].reshape(m, p)
        resid = block - block.mean(axis=0)
        out.append(float(np.mean(resid**2) / max(var, 1e-300) * m / (m - 1)))
    return out


def noise_share(y: np.ndarray) -> float:
    """The share of var(y) that is white measurement noise, estimated from the upper half of
    the band (above a quarter of the sample rate, where a gear's response has died out): the
    periodogram |Y_k|^2 / n of white noise of variance s^2 is exponential with mean s^2, so
    s^2 = median / ln 2 there."""
    power = np.abs(np.fft.rfft(y - y.mean())) ** 2 / y.size
    upper = power[power.size // 2 : -1]
    if not upper.size:
        return 1.0
    return float(min(1.0, np.median(upper) / math.log(2.0) / max(float(np.var(y)), 1e-300)))


def periodic_bound(residuals: list[float], noise: float) -> float:
    """The most a periodic record's average may leave: PERIODIC_FRACTION, no more than
    max(NOISE_FACTOR x the noise's share, NOISE_FLOOR) (``noise_share``: a chaotic band that
    hugs a 4T orbit leaves 0.1-1 % of the variance, a periodic record only its noise), and
    max(2 u_min, u_min + NOISE_MARGIN) (a 4T orbit just past its period doubling is nearly 2T,
    u_2 ~ 1 %, and only the 4-cycle average leaves the noise alone)."""
    floor = min(residuals) if residuals else 0.0
    return min(PERIODIC_FRACTION, max(NOISE_FACTOR * noise, NOISE_FLOOR),
               max(2.0 * floor, floor + NOISE_MARGIN))  # fmt: skip


def period_of(residuals: list[float], bound: float) -> int | None:
    """Smallest n with u_n <= bound (``periodic_bound``), else None."""
    for n, u in enumerate(residuals, start=1):
        if u <= bound:
            return n
    return None


def less_average(s: np.ndarray, n: int) -> np.ndarray:
    """The last whole n-periods of s less their n-periodic average (shape (m n,))."""
    m = s.size // n
    block = s[s.size - m * n :].reshape(m, n)
    return np.ascontiguousarray((block - block.mean(axis=0)).ravel())


def strobes(y: np.ndarray, per_cycle: int) -> np.ndarray:
    """One sample per cycle: y[0], y[per_cycle], ... (shape (len // per_cycle,))."""
    return np.ascontiguousarray(y[::per_cycle])
