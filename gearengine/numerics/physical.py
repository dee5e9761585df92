"""Transient and record in physical time: how long a run integrates before and while it
records, decided by the response (``SimulationSettings.adaptive`` with ``physical_time``).

Counted in Poincare periods T0, a fixed transient and record cost r = T0 / T_f times more for
a design whose T0 is r periods T_f = 2 pi / Omega_fast of its fastest excitation (the mesh; one
shaft revolution is z mesh periods) than for its twin without shaft-order forcing, though both
settle in the same physical time. Here lengths are set in mesh periods T_f and run in whole
intervals T0, so the strobes stay on the Poincare section and the forcing table stays in phase.

**Transient** (``lengths``), run from the start in chunks of ``CHUNK_MESH`` mesh periods (at
least one T0), twice and then four times as long after two and four chunks; the same chunks for
every lane, so a lane's numbers do not depend on the other points of its kernel call:

1. at least ``DAMPING_TIMES`` damping time constants 1/(zeta omega_n) = 1/mu (tau units): a
   linear transient has decayed by e^-10 = 4.5e-5 by then;
2. then it ends ("settled") when the T0 strobes of the last ``SETTLE_WINDOW_MESH`` mesh periods
   (at least 3 strobes; longer as the transient grows, up to 3 ``SETTLE_MAX_PERIOD``) repeat with
   a period p <= min(``SETTLE_MAX_PERIOD``, strobes / 3), every lag-p pair within the tolerance
   of ``signals.periodicity`` (REL_TOL x the peak-to-peak of x over those chunks), and the
   distance left to the cycle, extrapolated from how fast the lag-p mismatch decays over the
   window, is below ``SETTLE_TOL`` x that size (near a bifurcation the decay is slow and the
   transient runs on). A T0 strobe is the state at one phase of the cycle; the flow over one
   T0 is continuous, so the whole cycle has settled with it;
3. otherwise ("cap") after ``transient_periods`` intervals T0, today's fixed length. A response
   that has not settled on a cycle (chaotic, quasi-periodic, a long cycle) keeps the whole
   transient: no statistic of a finite window tells a chaotic transient from chaos (at 5,250
   rpm, 2 N m, TE 1.21 um the design of examples/envelope-map.json is chaotic for ~1,000 mesh
   periods, periodic 3T after 500 T0), so a chaotic verdict never rests on less transient than
   the fixed-length run's.

**Starts of one point that settle on one cycle** (``kin``, the lock-step lanes): a lane whose
transient settles on the cycle of one of its kin (another basin start of its point), settled
at the same check or an earlier one (same period, every strobe of its last cycle within the
period test's ``REL_TOL`` x size of one of the other's, both converged to ``SETTLE_TOL``), is
``joined`` to it: it records nothing and its record is that start's, as Attractors.jl's
recurrence mapper labels a start by the attractor it reaches without recording it again (a
record that does not find the period back leaves the lanes joined to it to record their own).
The record of a settled cycle was ~2/3 of its lane's steps, and a point's 16 basin starts
mostly settle on one or two cycles. Two records of one cycle give its extremes and strobes to
the convergence tolerance (DTE and forces within 1e-7 over a 45 x 9 gate of the z = 23/67
pair, every class, period and basin count the same), and LLE estimates that differ by the
estimate's own spread (up to 5 %: a record's tangent starts fresh), so the starts that share a
record are one estimate of the attractor's LLE (``BatchPoint._record``), not several
independent ones. A lane's numbers depend on its kin, never on other points or sets.

**Record**, from the transient's end state: R0 = ``RECORD_MESH`` mesh periods, at least
``BLOCKS`` periods p of the settled cycle (one cycle per block of the LLE's standard error),
rounded up to a multiple of ``BLOCKS`` p; a response that did not settle on a cycle records at
least ``LLE_RECORD_MESH`` mesh periods (2 ``BLOCKS`` intervals). The record is made twice as
long (one uninterrupted record, so its LLE sums are a fixed-length run's) until

* ``detect_period`` finds a period <= 64 in it ("period");
* no period and the LLE's standard error over ``BLOCKS`` blocks is within the settings'
  tolerances max(lle_stderr_abs, lle_stderr_rel |lle|) with the verdict clear by 3 standard
  errors, chaotic or not ("lle_stderr");
* no period but an LLE clearly below zero: an unfinished transient (or a cycle longer than 64
  T0); the record's intervals join the transient ("transient_extended") and the record starts
  again from its end, while the transient's cap allows;
* ``record_periods`` intervals ("cap").

A run that leaves the divergence bound stops there ("diverged"). The driver is the same for the
single kernels (``simulate``) and the lock-step lanes (``batch.run_lanes``): ``advance`` runs a
set of lanes a given number of recorded intervals from given states through the existing
kernels. A longer record runs on from the end of the shorter one where the kernels can carry
the state, tangent vector and extremes across calls (``Extend``, the lock-step lanes): the same
bits as running the longer record from the same start, at the cost of the extra intervals only;
otherwise (the single kernels) it is run again from the record's start.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearengine.numerics.results import RunLength
from gearengine.numerics.settings import SimulationSettings
from gearengine.signals.classify import LLE_FLOOR
from gearengine.signals.lyapunov import BLOCKS, benettin
from gearengine.signals.periodicity import REL_TOL, attractor_size, detect_period, same_cycle
from gearengine.systems.base import StepPlan

DAMPING_TIMES = 10.0
"""Damping time constants 1/mu (tau) a transient lasts at least."""
CHUNK_MESH = 40
"""Mesh periods run between two checks of the transient (at least one T0)."""
SETTLE_WINDOW_MESH = 60
"""Mesh periods of strobes that must repeat for the transient to count as settled."""
SETTLE_MAX_PERIOD = 12
"""Longest cycle (in T0) the transient test recognises; longer ones run to the cap."""
SETTLE_TOL = 1e-7
"""Largest distance left to the cycle, relative to its size, extrapolated geometrically from
the decay of the strobes' mismatch (near a bifurcation the decay is slow and the transient
runs on); ten times below the period test's REL_TOL."""
NOISE_TOL = 1e-10
"""Mismatch (relative to the size) that is the integration's noise: converged as it stands."""
RECORD_MESH = 160
"""Shortest record of a settled cycle, in mesh periods (rounded up to BLOCKS cycles)."""
LLE_RECORD_MESH = 400
"""Shortest record of a response that did not settle on a cycle, in mesh periods."""
NEGATIVE_LLE = 0.01
"""An LLE below -NEGATIVE_LLE (per tau, by 3 standard errors) with no period: unfinished."""


def run_length(periods: int, plan: StepPlan, reason: str) -> RunLength:
    """``periods`` intervals T0 of ``plan`` as a ``RunLength``."""
    return RunLength(
        periods=int(periods),
        mesh_periods=periods * plan.fast_periods,
        tau=periods * plan.period,
        reason=reason,
    )


def in_seconds(length: RunLength | None, time_scale: float) -> RunLength | None:
    """``length`` with ``seconds`` from the design's time scale (s per unit tau)."""
    if length is None:
        return None
    return length.model_copy(update={"seconds": length.tau * time_scale})


def applies(settings: SimulationSettings, plan: StepPlan, damping: float | None) -> bool:
    """True when a run's lengths are decided in physical time: ``adaptive`` and
    ``physical_time`` set, commensurate forcing (a Poincare section) and a known damping."""
    return (
        settings.adaptive
        and settings.physical_time
        and plan.omega0 is not None
        and damping is not None
    )


@dataclass
class Chunk:
    """What ``advance`` gives for m lanes run n recorded intervals: strobes, logs (m, n);
    extremes of x over the steps, final state and divergence flag (m,); ``keep`` one opaque
    handle per lane (the caller's record of that lane's run)."""

    xs: np.ndarray
    vs: np.ndarray
    logs: np.ndarray
    xmin: np.ndarray
    xmax: np.ndarray
    xf: np.ndarray
    vf: np.ndarray
    diverged: np.ndarray
    keep: list[Any]


Advance = Callable[[np.ndarray, np.ndarray, np.ndarray, int], Chunk]
"""advance(lanes, x0, v0, n): the lanes (indices, shape (m,)) run n intervals T0 from (x0, v0),
all recorded (no transient), through the kernels."""

Extend = Callable[[np.ndarray, list[Any], int], Chunk]
"""extend(lanes, keeps, n): the lanes run n more recorded intervals on from the end of the
chunks whose handles are ``keeps`` (one a lane: state, tangent vector and the kernels' own state
carried), the returned ``Chunk`` their whole records (the earlier intervals and the n new ones),
with the numbers of one call running them all."""


@dataclass
class Lengths:
    """The decided lengths of one lane: transient and record (intervals T0), the reasons, and
    ``keep``, the handle of the chunk that is its record (or where it diverged)."""

    transient: int = 0
    transient_reason: str = ""
    record: int = 0
    record_reason: str = ""
    keep: Any = None
    period: int | None = None
    record_period: int | None = None
    """The period its record found (``detect_period``), None when it found none."""
    joined: int | None = None
    """The lane whose record is this one's (``kin``: a start of the same point and set that
    settled on the same cycle), None when the lane records its own."""


def lengths(
    advance: Advance,
    x0: np.ndarray,
    v0: np.ndarray,
    period: np.ndarray,
    mu: np.ndarray,
    mesh_per_T0: float,
    settings: SimulationSettings,
    extend: Extend | None = None,
    settle: Advance | None = None,
    kin: np.ndarray | None = None,
) -> list[Lengths]:
    """Run the transient and the record of every lane in physical time (see the module doc).

    Args:
        advance: runs lanes through the kernels (``Advance``).
        x0, v0: starts, shape (L,).
        period: T0 of each lane's point (tau), shape (L,).
        mu: damping ratio of each lane's point, shape (L,).
        mesh_per_T0: r = T0 / T_f, shared by the lanes (same steps per T0).
        settings: caps (transient_periods, record_periods) and the LLE tolerances.
        extend: runs records on (``Extend``); None: a longer record runs again from its start.
        settle: runs the transient's chunks (an ``Advance`` whose chunks need only the strobes,
            the extremes of x, the end states and the divergence flags: no tangent, no LLE);
            None: ``advance``.
        kin: lanes that may share a record, shape (L,): one number for the starts of one point
            in one set (a point's basin starts); a lane settling on the cycle of one of its kin
            takes that lane's record (``Lengths.joined``). None: every lane records its own.
    """
    out = [Lengths() for _ in range(x0.size)]
    x, v = _settle(settle or advance, x0.copy(), v0.copy(), period, mu, mesh_per_T0, settings,
                   out, kin)  # fmt: skip
    run = (advance, extend)
    _record(run, x, v, period, mesh_per_T0, settings, out, [s.joined is None for s in out])
    unconfirmed = [s.joined is not None and not _confirmed(out[s.joined]) for s in out]
    for lane in np.flatnonzero(unconfirmed).tolist():
        out[lane].joined = None  # its cycle was not the record's: it records its own
    _record(run, x, v, period, mesh_per_T0, settings, out, unconfirmed)
    for s in out:
        if s.joined is not None:
            leader = out[s.joined]
            s.record, s.record_reason, s.keep = leader.record, "joined", leader.keep
    return out


def _confirmed(leader: Lengths) -> bool:
    """The record of a settled lane found the period it settled with (the cycle the lanes
    joined to it share); otherwise they record their own."""
    return (leader.transient_reason == "settled" and leader.record_reason == "period"
            and leader.record_period == leader.period)  # fmt: skip


def _settle(advance: Advance, x: np.ndarray, v: np.ndarray, period: np.ndarray, mu: np.ndarray,
            r: float, settings: SimulationSettings, out: list[Lengths],
            kin: np.ndarray | None = None) -> tuple:  # fmt: skip
    """The transient of every lane; returns the states at its end. With ``kin`` a lane that
    settles on a cycle one of its kin settled on is ``joined`` to that lane.

    A lane still running has run every round so far (the active lanes only ever shrink) and
    the rounds are the same for every lane, so the window of strobes a check reads is the same
    rounds for every lane: gathered once a round for all of them (``_periods``)."""
    cap = settings.transient_periods
    floor = np.ceil(DAMPING_TIMES / (np.maximum(mu, 1e-12) * period))
    n_min = np.minimum(floor, cap).astype(np.int64)
    chunk = max(1, math.ceil(CHUNK_MESH / r))
    active = np.ones(x.size, dtype=bool)
    if cap == 0:
        active[:] = False
        for s in out:
            s.transient_reason = "cap"
    ran, rounds = 0, 0
    history: list[tuple[np.ndarray, Chunk]] = []  # each round's lanes and chunk
    cycles: dict[int, list[tuple[int, int, np.ndarray, float]]] = {}  # a kin's settled cycles
    while active.any():
        idx = np.flatnonzero(active)
        # the same chunk boundaries for a lane in any company: 1, 1, 2, 2, 4, 4, 4 ... chunks
        n = min(chunk * 2 ** min(rounds // 2, 2), cap - ran)
        rounds += 1
        c = advance(idx, x[idx], v[idx], n)
        ran += n
        x[idx], v[idx] = c.xf, c.vf
        history.append((idx, c))
        lanes, dead = idx.tolist(), np.asarray(c.diverged, dtype=bool)
        for j in np.flatnonzero(dead).tolist():
            s = out[lanes[j]]
            s.transient, s.transient_reason, s.keep = ran, "diverged", c.keep[j]
        active[idx[dead]] = False
        checked = idx[np.logical_and(np.logical_not(dead), n_min[idx] <= ran)]
        for lane, p, cycle, size in _periods(history, checked, ran, r):
            s = out[lane]
            s.transient, s.period, s.transient_reason = ran, p, "settled"
            active[lane] = False
            if kin is not None:
                known = cycles.setdefault(int(kin[lane]), [])
                same = (k for k, q, c, z in known
                        if q == p and same_cycle(c, cycle, REL_TOL * max(z, size)))  # fmt: skip
                s.joined = next(same, None)
                if s.joined is None:
                    known.append((lane, p, cycle, size))
        if ran >= cap:
            for lane in np.flatnonzero(active).tolist():
                out[lane].transient, out[lane].transient_reason = ran, "cap"
            active[:] = False
    return x, v


def _periods(history: list[tuple[np.ndarray, Chunk]], lanes: np.ndarray, ran: int, r: float
             ) -> list[tuple[int, int, np.ndarray, float]]:  # fmt: skip
    """(lane, period p, its last p strobes (p, 2), size) of each of ``lanes`` (still running
    after ``ran`` intervals of rounds ``history``) whose transient may end here: the T0 strobes
    of its last rounds repeat with a period p and approach their cycle (``_converged``), in
    lane order."""
    want = max(3, math.ceil(SETTLE_WINDOW_MESH / r), min(ran // 2, 3 * SETTLE_MAX_PERIOD))
    k, got = len(history), 0
    while k > 0 and got < want:
        k -= 1
        got += history[k][1].xs.shape[1]
    if got < 3 or lanes.size == 0:
        return []
    parts, lo, hi = [], [], []
    for idx, c in history[k:]:
        j = np.searchsorted(idx, lanes)  # the lanes' rows in that round
        parts.append(np.stack([c.xs[j], c.vs[j]], axis=2))
        lo.append(c.xmin[j])
        hi.append(c.xmax[j])
    window = np.concatenate(parts, axis=1)  # (lanes, got, 2)
    lows, highs = np.stack(lo).T.tolist(), np.stack(hi).T.tolist()
    found = []
    for i, lane in enumerate(lanes.tolist()):
        size = attractor_size(min(lows[i]), max(highs[i]))
        w = window[i]
        p = detect_period(w[:, 0], w[:, 1], size, max_period=min(SETTLE_MAX_PERIOD, got // 3))
        if p is not None and _converged(w, p, size):
            found.append((lane, p, w[-p:], size))
    return found


def _converged(window: np.ndarray, p: int, size: float) -> bool:
    """The strobes (k, 2) approach their cycle of period p closer than ``SETTLE_TOL`` x size:
    the lag-p mismatch d shrinks by lambda per cycle (from the window's first and last cycle),
    so the distance left to the cycle is at most d_last lambda / (1 - lambda). A mismatch at
    the integration's noise (``NOISE_TOL`` x size) is converged as it stands."""
    d = np.hypot(window[p:, 0] - window[:-p, 0], window[p:, 1] - window[:-p, 1])
    first, last = float(d[:p].max()), float(d[-p:].max())
    if last <= NOISE_TOL * size:
        return True
    cycles = (d.size - p) / p
    if first <= last or cycles < 1:
        return False
    lam = (last / first) ** (1.0 / cycles)
    return last * lam / (1.0 - lam) < SETTLE_TOL * size


def _first_record(s: Lengths, r: float, cap: int) -> int:
    """R0 of a lane (see the module doc), at most ``cap``."""
    if s.period is not None:
        unit = BLOCKS * s.period
        n = max(unit, math.ceil(RECORD_MESH / r))
    else:
        unit = BLOCKS
        n = max(2 * BLOCKS, math.ceil(LLE_RECORD_MESH / r))
    return min(cap, unit * math.ceil(n / unit))


def _record(run: tuple[Advance, Extend | None], x: np.ndarray, v: np.ndarray, period: np.ndarray,
            r: float, settings: SimulationSettings, out: list[Lengths], chosen: list[bool],
            ) -> None:  # fmt: skip
    """The record of every ``chosen`` lane (shape (L,)) that did not diverge in its transient:
    ``run`` is (advance, extend) of ``lengths``."""
    advance, extend = run
    cap = settings.record_periods
    want = {lane: _first_record(s, r, cap) for lane, s in enumerate(out)
            if chosen[lane] and s.transient_reason != "diverged"}  # fmt: skip
    recorded: dict[int, int] = {}  # lanes whose record runs on: intervals recorded so far
    while want:
        by_length: dict[tuple[int, int], list[int]] = {}
        for lane, n in want.items():
            by_length.setdefault((n, recorded.get(lane, 0)), []).append(lane)
        want, recorded = {}, {}
        for (n, before), lanes in by_length.items():
            idx = np.array(lanes, dtype=np.int64)
            if before and extend is not None:
                c = extend(idx, [out[lane].keep for lane in lanes], n - before)
            else:
                c = advance(idx, x[idx], v[idx], n)
            for j, lane in enumerate(lanes):
                s = out[lane]
                s.record, s.keep = n, c.keep[j]
                if c.diverged[j]:
                    s.record_reason = "diverged"
                    continue
                nxt = _next(c, j, n, float(period[lane]), s, settings)
                if nxt is None:
                    continue
                if nxt < 0:  # unfinished transient: the record joins it, recorded again
                    s.transient += n
                    s.transient_reason = "transient_extended"
                    x[lane], v[lane] = c.xf[j], c.vf[j]
                    nxt = n
                elif extend is not None:
                    recorded[lane] = n
                want[lane] = nxt


def _next(c: Chunk, j: int, n: int, T0: float, s: Lengths, settings: SimulationSettings
          ) -> int | None:  # fmt: skip
    """After a record of n intervals: None (done, ``s.record_reason`` set), the next record
    length, or -1 (move the record into the transient and record again)."""
    cap = settings.record_periods
    size = attractor_size(float(c.xmin[j]), float(c.xmax[j]))
    s.record_period = detect_period(c.xs[j], c.vs[j], size)
    if s.record_period is not None:
        s.record_reason = "period"
        return None
    est = benettin(c.logs[j], T0)
    e, se = est.lle, est.stderr or 0.0
    tol = max(settings.lle_stderr_abs, settings.lle_stderr_rel * abs(e))
    if e + 3.0 * se < -NEGATIVE_LLE and s.transient + n <= settings.transient_periods:
        return -1
    clear = e - 3.0 * se > LLE_FLOOR or e + 3.0 * se < LLE_FLOOR
    if est.stderr is not None and se <= tol and clear:
        s.record_reason = "lle_stderr"
        return None
    if n >= cap:
        s.record_reason = "cap"
        return None
    return min(cap, 2 * n)
