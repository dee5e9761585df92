"""Verdicts of the lanes of one lock-step group (``kernels.run_batch``), array-wise.

The LLE and its standard error of every lane come from ``lyapunov.benettin_rows`` (the same
sums as ``benettin``, so the same bits), the period from the compiled ``detect_period`` per lane,
and each lane's ``BatchPoint`` is built without a ``Run`` or ``StartSummary``: the numbers equal
those of ``runs.start_verdict`` + ``batch.run_verdict``.
"""

from __future__ import annotations

import math

import numpy as np

from gearengine.numerics.results import BATCH_POINCARE, BatchPoint
from gearengine.numerics.runs import finite_or_none
from gearengine.signals.classify import classify
from gearengine.signals.diagnostics import impact_regime
from gearengine.signals.lyapunov import benettin_rows
from gearengine.signals.periodicity import attractor_size, detect_period


def lane_lle(
    logs: np.ndarray, rec: np.ndarray, diverged: np.ndarray, per: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """LLE and stderr (NaN where none) of every lane that did not diverge, grouped by the
    length of its record (``kernels.adaptive`` stops lanes early)."""
    lle = np.full(rec.size, np.nan)
    stderr = np.full(rec.size, np.nan)
    alive = np.flatnonzero(np.logical_not(diverged))
    lengths = rec[alive]
    for k in np.unique(lengths):
        idx = alive[lengths == k]
        lle[idx], stderr[idx] = benettin_rows(logs[idx, : int(k)], per[idx])
    return lle, stderr


def lane_verdicts(out: tuple, per: np.ndarray) -> list[tuple]:
    """(classification, period, LLE, stderr) of every lane, as ``runs.start_verdict`` gives
    them (LLE and stderr NaN where there is none)."""
    xs, vs, logs, xmin, xmax, _, _, _, rec, diverged, _, _ = out
    lle, stderr = lane_lle(logs, rec, diverged, per)
    verdicts: list[tuple] = []
    for lane in range(rec.size):
        if diverged[lane]:
            verdicts.append(("diverged", None, math.nan, math.nan))
            continue
        k = int(rec[lane])
        size = attractor_size(float(xmin[lane]), float(xmax[lane]))
        period = detect_period(xs[lane, :k], vs[lane, :k], size)
        e, s = float(lle[lane]), float(stderr[lane])
        verdict = classify(False, period, e, None if math.isnan(s) else s)
        verdicts.append((verdict, period, e, s))
    return verdicts


def last_strobes(out: tuple, lanes: list[int], x_only: bool = False) -> list[list]:
    """The last ``BATCH_POINCARE`` recorded strobes [x, v] of each of ``lanes`` (fewer when the
    record is shorter), one gather and one ``tolist`` for the lanes with a full window; with
    ``x_only`` their x alone, one flat list a lane (64 small lists a lane cost ~0.1 ms, mostly
    in the garbage collector, whose full passes they trigger and lengthen)."""
    xs, vs, rec = out[0], out[1], out[8]
    n_ok = rec[lanes].astype(np.int64)
    strobes: list[list] = [[] for _ in lanes]
    full = np.flatnonzero(n_ok >= BATCH_POINCARE)
    if full.size:
        rows = np.asarray(lanes)[full][:, None]
        cols = n_ok[full][:, None] - BATCH_POINCARE + np.arange(BATCH_POINCARE)
        window = xs[rows, cols] if x_only else np.stack([xs[rows, cols], vs[rows, cols]], axis=2)
        for k, w in zip(full.tolist(), window.tolist(), strict=True):
            strobes[k] = w
    for k in np.flatnonzero(n_ok < BATCH_POINCARE).tolist():
        lane, n = lanes[k], int(n_ok[k])
        short = xs[lane, :n] if x_only else np.column_stack([xs[lane, :n], vs[lane, :n]])
        strobes[k] = short.tolist()
    return strobes


def lane_point(
    out: tuple, lane: int, start_index: int, verdict: tuple, strobes: list,
    periods_run: int | None = None, x_only: bool = False,
) -> BatchPoint:  # fmt: skip
    """The ``BatchPoint`` of ``lane`` (as ``batch.run_verdict`` gives it), numbered
    ``start_index``, with that lane's last ``strobes`` (``last_strobes``: their x alone in
    ``poincare_x`` with ``x_only``); ``periods_run`` when the lane ran more than this call's
    intervals (``batch.physical_lanes``: its transient), else this call's."""
    _, _, _, xmin, xmax, fmin, fmax, done, _, diverged, xf, vf = out
    classification, period, lle, stderr = verdict
    dead = bool(diverged[lane])
    lo, hi = float(xmin[lane]), float(xmax[lane])
    final = [finite_or_none(float(xf[lane])), finite_or_none(float(vf[lane]))]
    return BatchPoint.model_construct(
        classification=classification,
        period=period,
        lle=None if dead else finite_or_none(lle),
        lle_stderr=None if dead else finite_or_none(stderr),
        final_state=None if dead or None in final else final,
        impact_regime=None if dead else impact_regime(lo, hi),
        poincare=[] if x_only else strobes,
        poincare_x=strobes if x_only else None,
        start_index=start_index,
        x_peak_to_peak=None if dead else finite_or_none(hi - lo),
        periods_run=int(done[lane]) if periods_run is None else periods_run,
        force_max=None if dead else finite_or_none(float(fmax[lane])),
        force_min=None if dead else finite_or_none(float(fmin[lane])),
    )
