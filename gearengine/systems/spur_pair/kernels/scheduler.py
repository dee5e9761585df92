"""The lane scheduler of the lock-step kernels, written once: each backlash law is data.

A lock-step kernel deals its runs to streams run in parallel; a stream of ``LANES`` lanes loads
its next run into every free lane, advances all lanes by one interval T0 of N RK4 steps, and
ends the interval of every lane (``intervals.end_intervals``: record, divergence, adaptive
stopping), until its runs are finished. Only the step differs between the laws (as scipy's
``RungeKutta`` writes ``_step_impl`` once and each method is its tableau): a ``LaneLaw`` names
the law's four compiled pieces, and ``lane_kernel`` makes the kernel of one law
(``lockstep.run_batch`` for the cubic law, ``kinklanes.run_kink_batch`` for the piecewise law).

Why a factory and not the step as an argument: numba cannot cache a kernel that passes a
compiled function as a value (it counts as a dynamic global), nor one that closes over it (the
closure's hash holds the dispatcher's per-process id, so every process compiles anew). So
``lane_kernel`` makes one kernel and one stream per law from the one bodies ``_lanes`` and
``_stream``, with the law's pieces as their globals and names of their own
(``<law>_kernel``, ``<law>_stream``): each law's kernel is compiled with the law's steps called
directly, and cached under its name like any kernel.

The law's pieces (``coeffs``: the law's own per-run inputs, a tuple, as the kernel was given
them; ``law_lanes``: the tuple its ``lanes`` made):

* ``lanes(L)``: the law's per-lane arrays, a tuple;
* ``load(lane, p, law_lanes, x0, coeffs)``: run p into ``lane``; p < 0 parks an idle lane;
* ``steps(N, Kl, Fl, PT, owner, lane_state, rates, law_lanes, coeffs, tangent)``: the N RK4
  steps of one interval T0 of every lane, with the forcing rows ``Kl``, ``Fl`` (2N + 1, LANES),
  the run of each lane ``PT`` (-1 idle), ``lane_state`` as in ``intervals`` and ``rates`` =
  (2 mu, h, h / 2, h / 6) per lane; ``tangent`` False is a hint a law may take: the state and
  the extremes of x alone (the tangent vector and the mesh force's extremes left as they are;
  the scheduler passes it as a constant, so each value compiles to its own loop). The cubic
  law takes it; the piecewise law integrates the tangent whatever it says (the same guard in
  its lane loop made it 2.7x slower). Compiled with
  ``inline="always"``: numba puts it into the scheduler's body, where the lanes' arrays are the
  scheduler's own allocations, so LLVM knows they do not overlap and vectorises the lane loop
  without run-time overlap checks. Called as a function, the piecewise steps were not
  vectorised (2.3x the CPU time of the lanes);
* ``keep(lane, p, law_lanes, coeffs)``: what run p carries into a next call beside its tangent
  vector, when it finishes.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from gearengine.systems.spur_pair.kernels.adaptive import ADAPT_SETTLE
from gearengine.systems.spur_pair.kernels.intervals import (
    adaptive_window,
    end_intervals,
    new_outputs,
    new_ring,
    reset_lane,
)
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, SQRT1_2

LANES = 16
"""Lanes advanced together by a stream."""


class LaneLaw(NamedTuple):
    """A backlash law of the lock-step kernels: its name, what its kernel does and with which
    ``coeffs`` (the first lines of the kernel's doc), and its compiled pieces (module doc)."""

    name: str
    doc: str
    lanes: Callable
    load: Callable
    steps: Callable
    keep: Callable


def _stream(
    stream,
    streams,
    mu,
    x0,
    v0,
    dxc,
    dvc,
    Ktab,
    Ftab,
    owner,
    T,
    N,
    n_trans,
    n_rec,
    bound,
    adaptive,
    lle_rel,
    lle_abs,
    tangent,
    xs,
    vs,
    logs,
    xmin,
    xmax,
    fmin,
    fmax,
    done,
    rec,
    diverged,
    xf,
    vf,
    *coeffs,
) -> None:  # pragma: no cover - compiled
    """One stream of lanes: runs ``stream``, ``stream + streams``, ... of the kernel's P runs
    (arguments and outputs of ``lockstep.run_batch``; ``coeffs`` the law's own inputs).
    ``law_lanes``, ``law_load``, ``law_steps`` and ``law_keep`` are the law's pieces, set as
    this body's globals by ``lane_kernel``."""
    P = x0.size
    W = adaptive_window(adaptive, n_rec)
    settle0 = min(n_trans, ADAPT_SETTLE)
    out = (xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf)
    Kl = np.ones((2 * N + 1, LANES))
    Fl = np.zeros((2 * N + 1, LANES))
    PT = np.full(LANES, -1, dtype=np.int64)
    counters = (
        np.zeros(LANES, dtype=np.int64),
        np.zeros(LANES, dtype=np.int64),
        np.zeros(LANES, dtype=np.int64),
    )
    TOL2 = np.zeros(LANES)
    NEED = np.ones(LANES, dtype=np.bool_)
    TM = np.zeros(LANES)
    H = np.zeros(LANES)
    H2 = np.zeros(LANES)
    H6 = np.zeros(LANES)
    rates = (TM, H, H2, H6)
    X = np.zeros(LANES)
    V = np.zeros(LANES)
    DX = np.full(LANES, SQRT1_2)
    DV = np.full(LANES, SQRT1_2)
    XMIN = np.full(LANES, np.inf)
    XMAX = np.full(LANES, -np.inf)
    FMIN = np.full(LANES, np.inf)
    FMAX = np.full(LANES, -np.inf)
    lane_state = (X, V, DX, DV, XMIN, XMAX, FMIN, FMAX)
    ring = new_ring(W, LANES)
    law = law_lanes(LANES)  # noqa: F821 - a global set by lane_kernel
    taken = 0  # runs of this stream loaded so far
    active = 0
    while True:
        for lane in range(LANES):  # load the stream's next run into every free lane
            if not NEED[lane]:
                continue
            NEED[lane] = False
            reset_lane(lane, lane_state, 0.0, 0.0)
            p = stream + taken * streams
            if p >= P:
                PT[lane] = -1  # idle: parked on a harmless state
                law_load(lane, -1, law, x0, coeffs)  # noqa: F821
                continue
            taken += 1
            active += 1
            PT[lane] = p
            for counter in counters:
                counter[lane] = 0
            for s in range(2 * N + 1):
                Kl[s, lane] = Ktab[owner[p], s]
                Fl[s, lane] = Ftab[owner[p], s]
            TM[lane] = 2.0 * mu[p]
            H[lane] = T[p] / N
            H2[lane] = 0.5 * H[lane]
            H6[lane] = H[lane] / 6.0
            X[lane] = x0[p]
            V[lane] = v0[p]
            DX[lane] = dxc[p]
            DV[lane] = dvc[p]
            law_load(lane, p, law, x0, coeffs)  # noqa: F821
        if active == 0:
            break
        if tangent:  # a constant in each call of the steps: two loops, no test in them
            law_steps(N, Kl, Fl, PT, owner, lane_state, rates, law, coeffs, True)  # noqa: F821
        else:
            law_steps(N, Kl, Fl, PT, owner, lane_state, rates, law, coeffs, False)  # noqa: F821
        if end_intervals(PT, lane_state, counters, TOL2, ring, out, T, n_trans, n_rec, W,
                         settle0, bound, lle_rel, lle_abs, NEED):  # fmt: skip
            for lane in range(LANES):  # the lanes whose run finished with this interval
                if NEED[lane]:
                    active -= 1
                    p = PT[lane]
                    dxc[p], dvc[p] = DX[lane], DV[lane]
                    law_keep(lane, p, law, coeffs)  # noqa: F821


def _lanes(
    mu,
    x0,
    v0,
    dxc,
    dvc,
    Ktab,
    Ftab,
    owner,
    T,
    N,
    n_trans,
    n_rec,
    bound,
    adaptive,
    streams,
    lle_rel,
    lle_abs,
    tangent,
    *coeffs,
):  # pragma: no cover - compiled
    """RK4 of Eq. (9) + tangent for P runs advanced together in lanes, by one backlash law.

    The runs are dealt to ``streams`` streams (run p to stream p mod streams, so clustered
    chaotic regions of a map are shared out) run in parallel (prange); a stream keeps ``LANES``
    lanes busy, each lane advancing one run, and loads the stream's next run into a lane as
    soon as its run is finished (lanes run at different interval counts; the forcing table of
    a lane is its point's). With ``adaptive`` a run may finish early by the rule of
    ``kernels.adaptive`` (its last ``ADAPT_WINDOW`` strobes kept in a ring buffer per lane),
    and a chaotic or quasi-periodic one by its LLE rule when ``lle_rel`` or ``lle_abs`` is
    positive; otherwise every run takes ``n_trans + n_rec`` intervals, as ``run_rk4``. The end
    of an interval is ``kernels.intervals.end_intervals``. The mesh force K(t) f_h(x) + 2 mu x'
    is evaluated at every step end and its extremes over the record returned.

    Args:
        mu, x0, v0, T: per-run damping, initial state and period T0, shape (P,).
        dxc, dvc: the tangent vector each run starts from, shape (P,), overwritten with the
            (renormalised) one it ends with: a record continued by a second call from the first
            one's final state and tangent has the numbers of one call running on
            (``numerics.physical``); (1, 1)/sqrt 2 for a fresh start.
        Ktab, Ftab: forcing tables from ``forcing_table`` of the M parameter points, shape
            (M, 2N+1); owner: the point of each run, shape (P,), values in 0..M-1 (the runs of
            a point share its table).
        N, n_trans, n_rec, bound: as in ``run_rk4`` (shared by all runs).
        adaptive: allow early stopping of periodic runs (``kernels.adaptive``).
        streams: parallel streams of lanes (at most the number of threads is useful).
        lle_rel, lle_abs: tolerances of the LLE rule (``kernels.adaptive.lle_known``); 0 and 0
            turn it off.
        tangent: integrate the tangent vector and the mesh force's extremes; False, a hint
            for a transient that reads the strobes and the extremes of x only: a law that takes
            it (the cubic) runs the state alone (``logs`` then hold no LLE, ``fmin`` and
            ``fmax`` no extremes; about 0.65x the CPU), the piecewise law ignores it.
        coeffs: the law's own per-run inputs (its module says which).

    Returns:
        xs, vs, logs: shape (P, n_rec), the record in its first ``rec`` entries; xmin, xmax,
        fmin, fmax (extremes of x and of the mesh force over the record's steps), xf, vf (final
        state): shape (P,); done (intervals run), rec (intervals recorded), diverged (1 if the
        run left ``bound``): shape (P,).
    """
    P = x0.size
    xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf = new_outputs(P, n_rec)
    for stream in prange(streams):
        law_stream(  # noqa: F821 - a global set by lane_kernel
            stream, streams, mu, x0, v0, dxc, dvc, Ktab, Ftab, owner, T, N, n_trans, n_rec,
            bound, adaptive, lle_rel, lle_abs, tangent,
            xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf, *coeffs,
        )  # fmt: skip
    return xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, diverged, xf, vf


def _compiled(template: Callable, name: str, scope: dict, doc: str, **options: bool) -> Callable:
    """``template``'s body compiled under ``name`` with ``scope`` added to its globals."""
    body = types.FunctionType(template.__code__, {**globals(), **scope}, name)
    body.__qualname__ = name
    body.__doc__ = doc
    return njit(**JIT_OPTIONS, **options)(body)


def lane_kernel(law: LaneLaw) -> Callable:
    """The lock-step kernel of ``law`` (``_lanes``, named ``<law.name>_kernel``; arguments
    ``mu, x0, v0, dxc, dvc, Ktab, Ftab, owner, T, N, n_trans, n_rec, bound, adaptive, streams,
    lle_rel, lle_abs, tangent, *coeffs``), over its scheduler ``<law.name>_stream``; numba
    caches each under its name."""
    pieces = {
        "law_lanes": law.lanes,
        "law_load": law.load,
        "law_steps": law.steps,
        "law_keep": law.keep,
    }
    stream = _compiled(_stream, f"{law.name}_stream", pieces, _stream.__doc__)
    doc = f"{law.doc}\n\n{_lanes.__doc__}"
    return _compiled(_lanes, f"{law.name}_kernel", {"law_stream": stream}, doc, parallel=True)
