"""Extrema over tau0 of a sum of sinusoids, M(tau0) = A + sum_i B_i sin(Omega_i tau0 + phi_i).

A branch of the Melnikov function has a simple zero iff min M < 0 < max M. With commensurate
frequencies M is periodic with period 2 pi / Omega_0 and the extrema are found exactly: a dense
grid over one period, then Newton on M'(tau0) = 0 from the best grid points. With
incommensurate frequencies the phases fill a torus densely (Kronecker), so the supremum is
A + sum |B_i| and the infimum A - sum |B_i|: they are approached, not attained.

``sublevel_interval`` gives the set of a control parameter p for which max_tau0 (M0 + p g) <= 0,
the building block of the thresholds (Eqs. 23, 24, 28-30 generalised).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np

from gearengine.homoclinic import kernels
from gearengine.homoclinic.kernels import CANDIDATES, GRID_PER_CYCLE, MAX_GRID, NEWTON_STEPS
from gearengine.model.frequencies import forcing_period

NEGLIGIBLE = 1e-200
"""Coefficients smaller than this are treated as zero by the threshold search."""

ExtremaMethod = Literal["exact", "supremum", "constant"]


@dataclass(frozen=True)
class TrigSum:
    """M(tau0) = offset + sum_i amplitudes[i] sin(frequencies[i] tau0 + phases[i]).

    Arrays have shape (n,), frequencies > 0 (rad per unit dimensionless time).
    """

    offset: float
    amplitudes: np.ndarray
    frequencies: np.ndarray
    phases: np.ndarray

    def __call__(self, tau0: np.ndarray) -> np.ndarray:
        arg = np.multiply.outer(tau0, self.frequencies) + self.phases
        return self.offset + np.sin(arg) @ self.amplitudes

    def negated(self) -> TrigSum:
        """-M: the same frequencies and phases, offset and amplitudes negated."""
        return TrigSum(-self.offset, -self.amplitudes, self.frequencies, self.phases)


@dataclass(frozen=True)
class Extremum:
    """The extremum value and where it is reached (tau0 is None for a supremum)."""

    value: float
    tau0: float | None


@dataclass(frozen=True)
class Extrema:
    """min and max of M over tau0, with the method used."""

    minimum: Extremum
    maximum: Extremum
    method: ExtremaMethod


def grid(frequencies: np.ndarray, period: float) -> np.ndarray:
    """Uniform tau0 grid over one common period, GRID_PER_CYCLE points per fastest cycle."""
    cycles = period * float(frequencies.max()) / (2.0 * math.pi)
    n = int(min(MAX_GRID, max(64, math.ceil(GRID_PER_CYCLE * cycles))))
    return np.arange(n) * (period / n)


def maximum(
    m: TrigSum, period: float, taus: np.ndarray | None = None, values: np.ndarray | None = None
) -> Extremum:
    """Exact max of a periodic trig sum over one period (``values``: m on ``taus``, if known).

    The best grid peaks are polished together by Newton on M'(tau0) = 0 (quadratic convergence
    from a grid of GRID_PER_CYCLE points per cycle), each kept within one grid step.
    """
    taus = grid(m.frequencies, period) if taus is None else taus
    values = m(taus) if values is None else values
    step = taus[1] - taus[0]
    peaks = np.flatnonzero((values >= np.roll(values, 1)) & (values >= np.roll(values, -1)))
    start = taus[peaks[np.argsort(values[peaks])[-CANDIDATES:]]]
    tau = start.copy()
    wa = m.amplitudes * m.frequencies
    wa2 = wa * m.frequencies
    for _ in range(NEWTON_STEPS):
        arg = np.multiply.outer(tau, m.frequencies) + m.phases
        d1, d2 = np.cos(arg) @ wa, -(np.sin(arg) @ wa2)
        newton = np.divide(d1, d2, out=np.zeros_like(d1), where=d2 < 0.0)
        tau = np.clip(tau - newton, start - step, start + step)
    polished = m(tau)
    j = int(np.argmax(polished))
    best = int(np.argmax(values))
    if values[best] > polished[j]:
        return Extremum(float(values[best]), float(taus[best]))
    return Extremum(float(polished[j]), float(tau[j] % period))


def extrema(m: TrigSum, period: float | None = None) -> Extrema:
    """min and max over tau0: exact when commensurate, supremum/infimum otherwise.

    ``period``: a common period of the frequencies known beforehand (a design's exact T0,
    ``model.frequencies.poincare_period``); None searches one from the frequencies.
    """
    active = m.amplitudes != 0.0
    if not active.any():
        const = Extremum(m.offset, None)
        return Extrema(const, const, "constant")
    m = TrigSum(m.offset, m.amplitudes[active], m.frequencies[active], m.phases[active])
    if m.amplitudes.size == 1:
        b, om, ph = float(m.amplitudes[0]), float(m.frequencies[0]), float(m.phases[0])
        return single_extrema(m.offset, b, om, ph)
    period = _period(tuple(m.frequencies.tolist())) if period is None else period
    if period is None:
        spread = float(np.abs(m.amplitudes).sum())
        return Extrema(
            Extremum(m.offset - spread, None), Extremum(m.offset + spread, None), "supremum"
        )
    taus = grid(m.frequencies, period)
    values = m(taus)  # one grid evaluation serves both extremes
    top = maximum(m, period, taus, values)
    bottom = maximum(m.negated(), period, taus, -values)
    return Extrema(Extremum(-bottom.value, bottom.tau0), top, "exact")


def single_extrema(offset: float, b: float, om: float, ph: float) -> Extrema:
    """A + B sin(Omega tau0 + phi) with A = ``offset``, B = ``b`` != 0, Omega = ``om`` > 0 and
    phi = ``ph`` [rad], on floats: extrema A -/+ |B| where the sine is -/+ sign(B)."""
    period = 2.0 * math.pi / om
    up = ((math.copysign(0.5 * math.pi, b) - ph) / om) % period
    down = (up + 0.5 * period) % period
    return Extrema(Extremum(offset - abs(b), down), Extremum(offset + abs(b), up), "exact")


# --- Sets of a control parameter ----------------------------------------------------------------


class Interval(NamedTuple):
    """Closed interval [lo, hi]; None marks an unbounded end (a tuple: a verdict builds a few
    dozen, and a frozen dataclass costs three times as much to build)."""

    lo: float | None
    hi: float | None

    def contains(self, p: float) -> bool:
        return (self.lo is None or p >= self.lo) and (self.hi is None or p <= self.hi)


def sublevel_interval(m0: TrigSum, g: TrigSum) -> Interval | None:
    """{p : max_tau0 (m0 + p g) <= 0} for a control parameter p entering M affinely.

    m0 and g must share frequencies and phases (g holds the per-unit coefficients of p, m0 the
    rest). The max over tau0 of an affine family is convex in p, so the set is an interval
    (possibly empty: None). Exact method: grid estimate by the envelope of lines, then Newton on
    phi(p) = max_tau0 (m0 + p g) = 0 with phi'(p) = g(tau*) (envelope theorem, compiled in
    ``kernels.sublevel_root``). Supremum method (incommensurate), and the closed form of a single
    sinusoid, whose maximum is attained: phi(p) = m0.offset + p g.offset + sum_i |m0_i + p g_i|,
    solved exactly (Eqs. 23-24 are this case). Coefficients below NEGLIGIBLE (e.g. sech of a huge
    argument, underflowing through the subnormals) are taken as 0, so that -m0 / g cannot
    overflow.
    """
    if m0.amplitudes.size <= 1:
        return one_sinusoid_interval(*one_sinusoid(m0, g))
    m0, g = _flushed(m0), _flushed(g)
    freqs = m0.frequencies
    active = (m0.amplitudes != 0.0) | (g.amplitudes != 0.0)
    if not active.any():
        return _affine_nonpositive(m0.offset, g.offset)
    period = None if active.sum() == 1 else _period(tuple(freqs[active].tolist()))
    if period is None:
        return _supremum_interval(m0, g, active)
    taus = grid(freqs[active], period)
    # g's own extrema join the samples: a sign of g missed by the grid still bounds p
    g_ext = extrema(g)
    probes = np.concatenate([taus, [e.tau0 for e in (g_ext.minimum, g_ext.maximum) if e.tau0]])
    table = _sines(probes.tobytes(), freqs.tobytes(), m0.phases.tobytes())  # m0's and g's
    mv, gv = m0.offset + table @ m0.amplitudes, g.offset + table @ g.amplitudes
    lo, hi = _line_envelope(mv, gv)
    if (lo is not None and lo == np.inf) or (hi is not None and hi == -np.inf):
        return None  # a bound beyond every float: the set is empty
    lo = None if lo is not None and lo == -np.inf else lo  # overflowed: unbounded there
    hi = None if hi is not None and hi == np.inf else hi
    if lo is not None and hi is not None and lo > hi:
        return None
    table = _root_table(taus.tobytes(), freqs.tobytes(), m0.phases.tobytes())
    args = (m0.offset, m0.amplitudes, g.offset, g.amplitudes, freqs, m0.phases, period, taus, table)
    lo = None if lo is None else float(kernels.sublevel_root(*args, lo))
    hi = None if hi is None else float(kernels.sublevel_root(*args, hi))
    if lo is not None and hi is not None and lo > hi:
        return None
    return Interval(lo, hi)


SINE_TABLES = 64
"""Sine tables kept (``_sines``): the 16 threshold searches of one verdict (4 parameters x 2
branches x both signs) share a grid, frequencies and phases."""


@functools.lru_cache(maxsize=SINE_TABLES)
def _sines(probes: bytes, frequencies: bytes, phases: bytes) -> np.ndarray:
    """sin(Omega_i tau_j + phi_i), shape (taus, terms), of the float64 arrays whose bytes are
    given (a key that hashes): the table ``TrigSum.__call__`` builds, the same bits, built once
    for the sums that share frequencies and phases (M0 and g of every control parameter)."""
    tau = np.frombuffer(probes, dtype=np.float64)
    arg = np.multiply.outer(tau, np.frombuffer(frequencies, dtype=np.float64))
    table = np.sin(arg + np.frombuffer(phases, dtype=np.float64))
    table.flags.writeable = False
    return table


@functools.lru_cache(maxsize=SINE_TABLES)
def _root_table(taus: bytes, frequencies: bytes, phases: bytes) -> np.ndarray:
    """``kernels.sine_table`` of the float64 arrays whose bytes are given, for
    ``kernels.sublevel_root``: built once for the searches that share them."""

    def array(b: bytes) -> np.ndarray:
        return np.frombuffer(b, dtype=np.float64).copy()  # writable: the compiled type

    return kernels.sine_table(array(frequencies), array(phases), array(taus))


@functools.lru_cache(maxsize=4096)
def _period(frequencies: tuple[float, ...]) -> float | None:
    """``forcing_period`` of a set of frequencies, remembered (thresholds ask for the same sets)."""
    return forcing_period(list(frequencies))


def _flush(v: float) -> float:
    return 0.0 if abs(v) < NEGLIGIBLE else v


def one_sinusoid(m0: TrigSum, g: TrigSum) -> tuple[float, float, float, float]:
    """(m0.offset, g.offset, a, b) of sums with at most one sinusoid (a, b its amplitudes in
    m0 and g, 0 when there is none) as Python floats, for ``one_sinusoid_interval``."""
    a = float(m0.amplitudes[0]) if m0.amplitudes.size else 0.0
    b = float(g.amplitudes[0]) if g.amplitudes.size else 0.0
    return float(m0.offset), float(g.offset), a, b


def one_sinusoid_interval(off0: float, offg: float, a: float, b: float) -> Interval | None:
    """``sublevel_interval`` of sums with at most one sinusoid, on the Python floats of
    ``one_sinusoid`` (negated, they give the set where the minimum stays >= 0).

    phi(p) = (off0 + p offg) + |a + p b| is convex piecewise linear with one kink k = -a / b
    (Eqs. 23-24 are its roots); the steps and roundings are those of ``_supremum_interval`` for
    one term, without arrays.
    """
    off0, offg, a, b = _flush(off0), _flush(offg), _flush(a), _flush(b)
    if b == 0.0:
        return _affine_nonpositive(off0 + abs(a) if a != 0.0 else off0, offg)
    base = off0 + 0.0
    kink = -a / b
    sign = 1.0 if b > 0.0 else -1.0
    left = (base - sign * a, offg - sign * b, -math.inf, kink)  # the pieces either side
    right = (base + sign * a, offg + sign * b, kink, math.inf)  # of the kink
    return _union_of_pieces((left, right))


def _union_of_pieces(pieces: Iterable[tuple[float, float, float, float]]) -> Interval | None:
    """The union of {p in [left, right] : alpha + beta p <= 0} over the linear pieces
    (alpha, beta, left, right) of a convex piecewise-linear function: an interval, or None."""
    lo, hi = math.inf, -math.inf
    for alpha, beta, left, right in pieces:
        if beta > 0.0:
            right = min(right, -alpha / beta)
        elif beta < 0.0:
            left = max(left, -alpha / beta)
        elif alpha > 0.0:
            continue
        if left <= right:
            lo, hi = min(lo, left), max(hi, right)
    if lo > hi:
        return None
    return Interval(None if lo == -math.inf else float(lo), None if hi == math.inf else float(hi))


def _flushed(m: TrigSum) -> TrigSum:
    """m with every coefficient of magnitude below NEGLIGIBLE set to 0."""

    def flush(v: np.ndarray | float) -> np.ndarray:
        return np.where(np.abs(v) < NEGLIGIBLE, 0.0, v)

    return TrigSum(float(flush(m.offset)), flush(m.amplitudes), m.frequencies, m.phases)


def _line_envelope(mv: np.ndarray, gv: np.ndarray) -> tuple[float | None, float | None]:
    """Bounds of {p : mv_j + p gv_j <= 0 for all j} (lo > hi means empty)."""
    if np.any((gv == 0.0) & (mv > 0.0)):
        return 1.0, 0.0
    neg, pos = gv < 0.0, gv > 0.0
    with np.errstate(over="ignore"):  # a ratio past the float range is a bound at +-inf
        lo = float(np.max(-mv[neg] / gv[neg])) if neg.any() else None
        hi = float(np.min(-mv[pos] / gv[pos])) if pos.any() else None
    return lo, hi


def _affine_nonpositive(offset: float, slope: float) -> Interval | None:
    """{p : offset + p slope <= 0}."""
    if slope == 0.0:
        return Interval(None, None) if offset <= 0.0 else None
    root = -offset / slope
    return Interval(root, None) if slope < 0.0 else Interval(None, root)


def _supremum_interval(m0: TrigSum, g: TrigSum, active: np.ndarray) -> Interval | None:
    """{p : phi(p) <= 0}, phi(p) = m0.offset + p g.offset + sum_i |m0_i + p g_i|.

    phi is convex and piecewise linear with kinks k_i = -m0_i / g_i. On the piece between two
    sorted kinks every sign s_i of m0_i + p g_i = g_i (p - k_i) is known from the kink order, so
    phi = alpha + beta p there exactly (no subtraction of huge kinks); the union of the pieces'
    solutions is the interval.
    """
    a, b = m0.amplitudes[active], g.amplitudes[active]
    base = m0.offset + float(np.abs(a[b == 0.0]).sum())
    a, b = a[b != 0.0], b[b != 0.0]
    if not b.size:
        return _affine_nonpositive(base, g.offset)
    order = np.argsort(-a / b)
    a, b = a[order], b[order]
    kinks = np.concatenate([[-np.inf], -a / b, [np.inf]])

    def piece(j: int) -> tuple[float, float, float, float]:  # between kinks j-1 and j (sorted)
        signs = np.sign(b) * np.where(np.arange(b.size) < j, 1.0, -1.0)
        return base + float(signs @ a), g.offset + float(signs @ b), kinks[j], kinks[j + 1]

    return _union_of_pieces(piece(j) for j in range(b.size + 1))
