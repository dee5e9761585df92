"""Adaptive stopping of a run: the early-exit test at the end of a sampling interval T0.

A run may stop before ``n_trans + n_rec`` intervals when its last ``ADAPT_WINDOW`` strobes are a
settled periodic orbit with a converged, clearly negative LLE. The rule is checked at the end of
every interval after the first ``min(n_trans, ADAPT_SETTLE) + ADAPT_MAX_PERIOD``; a run stops at
the earliest after ``min(n_trans, ADAPT_SETTLE) + ADAPT_WINDOW`` intervals:

1. **Candidate period** (a cheap prefilter). The tolerance is the one of
   ``signals.periodicity``: ``REL_TOL`` x the peak-to-peak of x over every step of the last
   ``ADAPT_WINDOW`` intervals (floored by ``SIZE_FLOOR``; refreshed every ``ADAPT_PROBE``
   intervals). The current strobe X_m is compared with X_{m-q}, q = 1..ADAPT_MAX_PERIOD; the
   smallest q with |X_m - X_{m-q}| < tol is the candidate. A streak counts the consecutive
   intervals whose candidate was the same q (probed every ``ADAPT_PROBE`` intervals while no
   lag matches).
2. **Repetition.** When the streak reaches ``ADAPT_WINDOW - q`` every lag-q pair of the window has
   matched; the window is then re-checked at once (steps 2 to 4; if they fail, again after
   ``ADAPT_RECHECK`` more matches) with the exact tolerance of the window, as
   ``periodicity.detect_period`` will check it (every lag-q pair matches; for every r < q some
   lag-r pair does not), so the verdict computed afterwards on the window is period q. Near a
   period doubling the strobes of a period-q orbit alternate around it and decay slowly, so
   they match at lag 2q long before they match at lag q: every shorter lag's mismatch, summed
   over one cycle, must therefore be stationary (at the window's end at least 1 -
   ``ADAPT_DRIFT`` of its value at the start), not a decaying transient. The window
   holds at least ADAPT_WINDOW / ADAPT_MAX_PERIOD = 10 repetitions of the cycle, all after a
   discarded transient of at least ``min(n_trans, ADAPT_SETTLE)`` intervals.
3. **Converged LLE.** The Benettin logs of the window, split as ``signals.lyapunov.benettin``
   splits them (``BLOCKS`` equal blocks of ADAPT_WINDOW / BLOCKS = 12 intervals, a multiple of
   periods 1, 2, 3, 4, 6 and 12), give lle and the standard error of the block estimates; the run
   stops only if stderr <= max(``ADAPT_LLE_STDERR``, ``ADAPT_LLE_REL`` |lle|) (converged) and
   lle + 3 stderr < -``ADAPT_MIN_CONTRACTION`` (a clearly attracting orbit: perturbations
   shrink by e within 100 time units, so the strobes stay within the tolerance).
4. **Within the transient.** A run stops only while its window lies in the transient part
   (after at most ``n_trans`` intervals). A run that has not settled by then keeps the whole
   fixed-length record: its transient's tail is part of that record, and cutting the record
   to the settled window would change the verdict the fixed-length run gives.

The record of a stopped run is then its last ``ADAPT_WINDOW`` intervals (strobes, logs and the
extremes of x and of the mesh force over their steps); chaotic, quasi-periodic, long-period
(> ``ADAPT_MAX_PERIOD``) and undecided runs never satisfy the rule. Runs with
``n_rec < ADAPT_WINDOW`` never stop early by it.

**The LLE rule** (chaotic and quasi-periodic runs, ``lle_known``): in the record, whenever the
number k of recorded intervals is a multiple of ``BLOCKS`` and at least ``ADAPT_LLE_MIN_RECORD``,
the Benettin estimate over those k intervals, lle = sum l_i / (k T0), and its standard error
over ``BLOCKS`` equal blocks (as ``signals.lyapunov.benettin``) are taken; the run stops when

    stderr <= max(lle_stderr_abs, lle_stderr_rel |lle|)        (the tolerances of the settings)

and the verdict they give cannot change within three standard errors: lle - 3 stderr >
``LLE_FLOOR`` (chaotic) or lle + 3 stderr < ``LLE_FLOOR`` (not chaotic), both also at k - 10 and
k - 20 (``ADAPT_LLE_CONFIRM``), and the k strobes have
no period <= ``MAX_PERIOD`` (``periodicity.detect_period``; a longer record, holding these
pairs, would have none either). The record of such a run is its first k intervals, so its LLE
is the fixed-length run's estimate truncated to k intervals: it differs from the fixed-length
LLE by about its stated stderr (or less). Runs that never satisfy it run to the end with the
fixed-length record, bit for bit.

Only the lock-step kernels ``run_batch`` and ``run_kink_batch`` apply the rules (through
``kernels.intervals``); ``run_rk4`` and ``run_kink`` always run the full length. The kernels
compile the helpers and constants here into their own code; an edit here drops their numba
cache (``gearengine.jitcache``), so they are compiled again on their next call.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gearengine.signals.classify import LLE_FLOOR
from gearengine.signals.lyapunov import BLOCKS
from gearengine.signals.periodicity import MAX_PERIOD, REL_TOL, SIZE_FLOOR, _smallest_period
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS

ADAPT_WINDOW = 120
"""Intervals T0 of the record of an early-stopped run (a multiple of ``BLOCKS``)."""
ADAPT_MAX_PERIOD = 12
"""Largest period (in T0) that may stop a run early; longer ones run to the end."""
ADAPT_SETTLE = 20
"""Intervals discarded before the window at least (fewer if n_trans is smaller)."""
ADAPT_PROBE = 4
"""Until a lag matches, the streak is probed every ADAPT_PROBE intervals (and the prefilter's
tolerance refreshed as often): the probe must cost little beside N vectorised steps."""
ADAPT_RECHECK = 30
"""Intervals of further matches before the rule is tried again after it failed."""
ADAPT_DRIFT = 0.05
"""Largest relative decay, over the window, of a shorter lag's mismatch (summed over one cycle)."""
ADAPT_MIN_CONTRACTION = 0.01
"""Smallest -lle (per unit tau) of an orbit that may stop a run: weaker contraction (near a
bifurcation, where a transient's residue decays over hundreds of periods and the fixed-length
verdict still depends on it) runs to the end."""
ADAPT_LLE_STDERR = 1e-3
"""Standard error (per unit tau) of the window's LLE that always counts as converged."""
ADAPT_LLE_REL = 0.1
"""Standard error relative to |lle| that counts as converged (10 %): the per-interval logs of
an orbit whose multipliers are complex (a focus) oscillate, so their block estimates scatter by
a few per cent of lle even when the orbit has settled."""
ADAPT_LLE_MIN_RECORD = 200
"""Recorded intervals before the LLE rule applies (blocks of at least 20 intervals, several
correlation times of the chaotic responses of Eq. 9). At 100 the stated stderr covered the
fixed-length LLE within 3 stderr on 98.8 % of the chaotic points of the 200 x 200 map (the
misses mostly intermittent responses), at 200 on 99.2 % (benchmarks/README.md)."""
ADAPT_LLE_CONFIRM = 3
"""Consecutive checks (every ``BLOCKS`` intervals) at which the LLE tests must hold: a single
check stops too often where the 10-block stderr happens to be low (it has 9 degrees of
freedom), and then the stated stderr covers the fixed-length LLE less often than it should."""


@njit(**JIT_OPTIONS)
def window_tol(
    rxmin: np.ndarray, rxmax: np.ndarray, lane: int, W: int
) -> float:  # pragma: no cover
    """``REL_TOL`` x the peak-to-peak of x over the W intervals held in the ring (column lane)."""
    lo = np.inf
    hi = -np.inf
    for i in range(W):
        lo = min(lo, rxmin[i, lane])
        hi = max(hi, rxmax[i, lane])
    return REL_TOL * max(hi - lo, SIZE_FLOOR)


@njit(**JIT_OPTIONS)
def smallest_lag(
    rx: np.ndarray, rv: np.ndarray, lane: int, slot: int, W: int, tol2: float
) -> int:  # pragma: no cover - compiled
    """Smallest q <= ADAPT_MAX_PERIOD with |X_m - X_{m-q}|^2 < tol2 (X_m in ring slot), else
    0. Squared distances: this runs every interval, ``settled`` decides with hypot."""
    x = rx[slot, lane]
    v = rv[slot, lane]
    for q in range(1, ADAPT_MAX_PERIOD + 1):
        o = (slot - q + W) % W
        dx = x - rx[o, lane]
        dv = v - rv[o, lane]
        if dx * dx + dv * dv < tol2:
            return q
    return 0


@njit(**JIT_OPTIONS)
def _lag_sum(
    rx: np.ndarray, rv: np.ndarray, lane: int, slot: int, W: int, r: int, first: int, count: int
) -> float:  # pragma: no cover - compiled
    """Sum of |X_{i+r} - X_i| over window positions i = first .. first + count - 1."""
    total = 0.0
    for i in range(first, first + count):
        o1 = (slot + 1 + i) % W
        o2 = (slot + 1 + i + r) % W
        total += math.hypot(rx[o2, lane] - rx[o1, lane], rv[o2, lane] - rv[o1, lane])
    return total


@njit(**JIT_OPTIONS)
def settled(
    rx: np.ndarray,
    rv: np.ndarray,
    rl: np.ndarray,
    lane: int,
    slot: int,
    W: int,
    q: int,
    tol: float,
    T: float,
) -> bool:  # pragma: no cover - compiled
    """Steps 2 and 3 of the rule on the full ring (newest strobe in ``slot``)."""
    for r in range(1, q + 1):
        every = True
        for i in range(W - r):
            o1 = (slot + 1 + i) % W
            o2 = (slot + 1 + i + r) % W
            if not (math.hypot(rx[o2, lane] - rx[o1, lane], rv[o2, lane] - rv[o1, lane]) < tol):
                every = False
                break
        if every != (r == q):
            return False
        if r < q and _lag_sum(rx, rv, lane, slot, W, r, W - r - q, q) < (
            1.0 - ADAPT_DRIFT
        ) * _lag_sum(rx, rv, lane, slot, W, r, 0, q):
            return False  # the lag-r mismatch is a decaying transient, not the orbit's shape
    size = W // BLOCKS
    total = 0.0
    for i in range(W):
        total += rl[i, lane]
    lle = total / (W * T)
    var = 0.0
    for b in range(BLOCKS):
        s = 0.0
        for i in range(b * size, (b + 1) * size):
            s += rl[(slot + 1 + i) % W, lane]
        var += (s / (size * T) - lle) ** 2
    stderr = math.sqrt(var / (BLOCKS - 1) / BLOCKS)
    converged = stderr <= max(ADAPT_LLE_STDERR, ADAPT_LLE_REL * abs(lle))
    return converged and lle + 3.0 * stderr < -ADAPT_MIN_CONTRACTION


@njit(**JIT_OPTIONS)
def _lle_clear(
    logs: np.ndarray, k: int, T: float, rel: float, abs_tol: float
) -> bool:  # pragma: no cover - compiled
    """The LLE tests of the rule on the first k logs (k a multiple of ``BLOCKS``)."""
    total = 0.0
    for i in range(k):
        total += logs[i]
    lle = total / (k * T)
    size = k // BLOCKS
    var = 0.0
    for b in range(BLOCKS):
        s = 0.0
        for i in range(b * size, (b + 1) * size):
            s += logs[i]
        var += (s / (size * T) - lle) ** 2
    stderr = math.sqrt(var / (BLOCKS - 1) / BLOCKS)
    if not stderr <= max(abs_tol, rel * abs(lle)):
        return False
    return lle - 3.0 * stderr > LLE_FLOOR or lle + 3.0 * stderr < LLE_FLOOR


@njit(**JIT_OPTIONS)
def lle_known(
    xs: np.ndarray,
    vs: np.ndarray,
    logs: np.ndarray,
    k: int,
    xmin: float,
    xmax: float,
    T: float,
    rel: float,
    abs_tol: float,
) -> bool:  # pragma: no cover - compiled
    """The LLE rule (module doc) on the first k entries of one record (strobes xs, vs, logs;
    x extremes xmin, xmax over its steps; T: the interval T0)."""
    if k < ADAPT_LLE_MIN_RECORD or k % BLOCKS != 0:
        return False
    for c in range(ADAPT_LLE_CONFIRM):  # the record of k, k - 10, ... intervals
        if not _lle_clear(logs, k - BLOCKS * c, T, rel, abs_tol):
            return False
    tol = REL_TOL * max(xmax - xmin, SIZE_FLOOR)
    return _smallest_period(xs[:k], vs[:k], tol, min(MAX_PERIOD, k - 1)) == 0
