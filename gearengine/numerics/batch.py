"""Verdicts of many parameter points at once: the sweeps' path to the kernels.

Points with commensurate forcing are grouped by backlash law and steps per T0 and advanced in
lock-step by the SIMD kernels ``kernels.run_batch`` (cubic law) and ``kernels.run_kink_batch``
(piecewise law, split at the kinks lane by lane), parallel over chunks of lanes, and their
verdicts are taken array-wise (``numerics.lanes``); a ``System`` with a lock-step kernel of its
own (``System.lane_group``: a gear train's) runs its groups there; other points (incommensurate
forcing) run one by one in the single kernels (``numerics.runs``). Numbers equal those of
``simulate``.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Sequence

import numba
import numpy as np

from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.params import GearParams
from gearengine.numerics import physical
from gearengine.numerics.lanes import lane_point, lane_verdicts, last_strobes
from gearengine.numerics.results import BATCH_POINCARE, BatchPoint
from gearengine.numerics.runs import (
    Run,
    as_system,
    finite_or_none,
    history_stride,
    integrate,
    start_verdict,
)
from gearengine.numerics.settings import SimulationSettings, check_work
from gearengine.signals.classify import DIVERGENCE_BOUND, severity
from gearengine.systems.base import System
from gearengine.systems.spur_pair import kernels
from gearengine.systems.spur_pair.forcing import StepPlan, packed_forcing, step_plan
from gearengine.systems.spur_pair.laws import LAWS, Carry, fresh_carry, law

Lane = tuple[int, tuple[float, float]]
"""One run of a request: (index of its parameter point, initial state (x0, v0))."""
Point = GearParams | System
"""A point of a request: a parameter point of Eq. (9) (lock-step lanes) or any ``System`` (its
own integrator, run by run, from ``System.start_state(x0, v0)``)."""


def run_verdict(run: Run, start: Sequence[float], plan: StepPlan, lane: int) -> BatchPoint:
    """The ``BatchPoint`` of one run of the single kernels (``runs.integrate``), numbered
    ``lane``.

    Built with ``model_construct``: the fields come typed and finite from ``start_verdict`` and
    ``finite_or_none``, so validating them again would only cost time (~0.1 ms a point).
    """
    v = start_verdict(run, start, plan.period, plan.omega0 is not None)
    n_ok = run.recorded
    return BatchPoint.model_construct(
        classification=v.classification,
        period=v.period,
        lle=v.summary.lle,
        lle_stderr=v.summary.lle_stderr,
        final_state=v.summary.final_state,
        impact_regime=v.summary.impact_regime,
        poincare=_strobes(run)[:n_ok][-BATCH_POINCARE:].tolist(),
        start_index=lane,
        x_peak_to_peak=None if run.diverged else finite_or_none(run.xmax - run.xmin),
        periods_run=int(run.done),
        force_max=None if run.diverged else finite_or_none(run.fmax),
        force_min=None if run.diverged else finite_or_none(run.fmin),
    )


def _strobes(run: Run) -> np.ndarray:
    """The strobes of a run, shape (k, n): (x, v) for the pair, the full state otherwise."""
    return np.column_stack([run.xs, run.vs]) if run.strobes is None else run.strobes


def step_plans(points: Sequence[Point], steps_per_period: int) -> list[StepPlan]:
    """``step_plan`` of each point, computed once per process for each set of active harmonics
    (``PLANS``): the plan depends only on the excitations' frequencies and which of their
    harmonics are active (a ``System`` point's own ``plan``)."""
    plans = []
    for p in points:
        if isinstance(p, System):
            plans.append(p.plan(steps_per_period))
            continue
        key = (*(
            (name, exc.frequency, tuple(r for r, _ in exc.active()))
            for name, exc in p.excitations()
        ), str(p.shaft_orders), steps_per_period)  # fmt: skip
        plan = _plans.get(key)
        if plan is None:
            plan = step_plan(p, steps_per_period)
            with _plans_lock:
                _plans[key] = plan
                while len(_plans) > PLANS:
                    _plans.pop(next(iter(_plans)))
        plans.append(plan)
    return plans


PLANS = 4096
"""Step plans kept in this process (``step_plans``): an envelope's speeds give the same
frequencies at every torque and every lever value of a remedies search, so its checks, their
refinements and the basin starts of a chunk find the plan of an earlier call (the search for
Omega_0 over the active frequencies costs ~1.5 ms a point)."""
_plans: dict[tuple, StepPlan] = {}
_plans_lock = threading.Lock()

TABLES = 128
"""Forcing tables kept in this process (``forcing_table``; 2N + 1 values of K and F each,
~94 kB at N = 2,944, at most ~12 MB): the gate's refinement, the hints of a remedies search and
a lever that leaves the forcing as it is (the damping) run the same points again."""


@functools.lru_cache(maxsize=TABLES)
def _table(period: float, N: int, kc: bytes, fm: float, fc: bytes) -> tuple[np.ndarray, np.ndarray]:
    """``kernels.forcing_table`` of the packed forcing whose arrays (3, n) are the bytes
    ``kc`` and ``fc`` (a key that hashes), computed once per process for the same bits."""
    k = np.frombuffer(kc, dtype=np.float64).reshape(3, -1).copy()  # writable: the compiled type
    f = np.frombuffer(fc, dtype=np.float64).reshape(3, -1).copy()
    return kernels.forcing_table(period, N, k, fm, f)


def run_lanes(
    points: Sequence[Point],
    lanes: Sequence[Lane],
    settings: SimulationSettings | None = None,
    plans: list[StepPlan] | None = None,
    sets: Sequence[int] | None = None,
) -> list[BatchPoint]:
    """The verdict of every lane: the one door of ensembles into the kernels.

    Every run of a request (point x start x sample) is a lane ``(i, (x0, v0))``: parameter
    point ``points[i]`` from the initial state (x0, v0). Lanes of points with commensurate
    forcing are grouped by backlash law and steps per T0 and advanced together in the lock-step
    SIMD kernels (``kernels.run_batch``, cubic; ``kernels.run_kink_batch``, piecewise), those
    of systems with a lock-step kernel (``System.lane_group``) in theirs over the settings'
    fixed lengths; the others run one by one in the single kernels (``runs.integrate``). With
    ``settings.adaptive`` a lane may stop early (``kernels.adaptive``: settled periodic orbits,
    and chaotic or quasi-periodic ones once their LLE's stderr is within the settings'
    tolerances); otherwise, and in the single kernels, the numbers equal those of ``simulate``
    for the same point and start, unless ``sets`` lets starts share a record.

    Args:
        points: the parameter points, shape (P,).
        lanes: the runs, shape (L,); a point may appear in any number of lanes.
        settings: periods, steps and adaptive stopping shared by all lanes (their starts are
            ignored: each lane carries its own).
        plans: the points' ``step_plans`` when the caller has them (made here otherwise).
        sets: the set of starts of each lane, shape (L,): lanes of one point and set that
            settle on one cycle in physical time share one record (``physical.lengths``'
            ``kin``: a point's basin starts, whose attractors are what is asked); None: every
            lane records its own, as independent samples must.

    Returns:
        One ``BatchPoint`` per lane, in order, shape (L,); its ``start_index`` is the lane's
        index in ``lanes``.
    """
    settings = settings or SimulationSettings()
    plans = step_plans(points, settings.steps_per_period) if plans is None else plans
    return _run_lanes(points, plans, lanes, settings, range(len(lanes)), sets=sets)


def _run_lanes(
    points: Sequence[Point],
    plans: list[StepPlan],
    lanes: Sequence[Lane],
    settings: SimulationSettings,
    numbers: Sequence[int],
    x_only: bool = False,
    sets: Sequence[int] | None = None,
) -> list[BatchPoint]:
    """``run_lanes`` with each lane's ``start_index`` given (``numbers``, shape (L,)), so no
    verdict is copied to be renumbered (three copies a point cost ~0.05 ms); with ``x_only``
    the lock-step lanes keep the x of their last strobes alone (``lanes.last_strobes``).
    ``sets``: the set of starts of each lane, shape (L,) (a point's own starts and its basin
    starts, run together as they would run apart); the lanes of one point and set settling on
    one cycle share a record (``physical.lengths``' ``kin``). None: none share."""
    results: list[BatchPoint | None] = [None] * len(lanes)
    groups: dict[tuple[str, int, float], list[int]] = {}
    systems: dict[tuple, list[int]] = {}
    for k, (i, s) in enumerate(lanes):
        plan, point = plans[i], points[i]
        name = point.backlash.model if isinstance(point, GearParams) else ""
        key = point.lane_group(plan) if isinstance(point, System) else None
        if name and LAWS[name].lanes is not None and plan.omega0 is not None:
            groups.setdefault((name, plan.steps, plan.fast_periods), []).append(k)
        elif key is not None:
            systems.setdefault(key, []).append(k)
        else:
            start = as_system(point).start_state(*s)
            results[k] = run_verdict(integrate(point, settings, start, plan), s, plan, numbers[k])
    for ks in systems.values():
        for k, point in zip(ks, system_lanes(points, plans, [lanes[k] for k in ks], settings),
                            strict=True):  # fmt: skip
            results[k] = point.model_copy(update={"start_index": numbers[k]})
    for (name, N, r), ks in groups.items():
        owner = np.array([lanes[k][0] for k in ks], dtype=np.int64)
        members, inverse = np.unique(owner, return_inverse=True)
        packed = [packed_forcing(points[i]) for i in members.tolist()]
        tables = [_table(plans[i].period, N, kc.tobytes(), fm, fc.tobytes())
                  for i, (kc, fm, fc) in zip(members.tolist(), packed, strict=True)]  # fmt: skip
        per = np.array([plans[i].period for i in members.tolist()])[inverse]
        mu = np.array([points[i].damping for i in members.tolist()])[inverse]
        starts = np.array([lanes[k][1] for k in ks], dtype=np.float64).reshape(-1, 2)
        x0, v0 = starts[:, 0].copy(), starts[:, 1].copy()
        tabled = (
            np.array([kt for kt, _ in tables]),
            np.array([ft for _, ft in tables]),
            inverse.astype(np.int64),
        )  # one table per point, shared by its lanes
        lanes_of = LAWS[name].lanes
        assert lanes_of is not None
        laws = [law(points[i]) for i in members.tolist()]
        if physical.applies(settings, plans[members[0]], 0.0):
            group = (lanes_of, laws, inverse, packed, mu, tabled, per, N, r)
            mine = [numbers[k] for k in ks]
            kin = None if sets is None else np.array([sets[k] for k in ks]) * len(ks) + inverse
            got = physical_lanes(group, x0, v0, settings, mine, x_only, kin)
            for k, point in zip(ks, got, strict=True):
                results[k] = point
            continue
        streams = max(1, min(numba.get_num_threads(), -(-len(ks) // kernels.LANES)))
        shared = (per, N, settings.transient_periods, settings.record_periods, DIVERGENCE_BOUND,
                  settings.adaptive, streams, *lle_tolerances(settings), True)  # fmt: skip
        out = lanes_of(laws, inverse, packed, mu, x0, v0, tabled, shared, fresh_carry(len(ks)))
        verdicts = lane_verdicts(out, per)
        strobes = last_strobes(out, list(range(len(ks))), x_only)
        for j, k in enumerate(ks):
            results[k] = lane_point(out, j, numbers[k], verdicts[j], strobes[j], x_only=x_only)
    return results  # type: ignore[return-value]


def system_lanes(
    points: Sequence[Point], plans: list[StepPlan], group: list[Lane],
    settings: SimulationSettings,
) -> list[BatchPoint]:  # fmt: skip
    """The ``BatchPoint`` of every lane of one lock-step group of systems (``System.lane_group``:
    a train's), run by its ``System.run_lanes`` over the settings' fixed lengths, as their own
    runs (``integrate``) would give them."""
    owner = np.array([i for i, _ in group], dtype=np.int64)
    members, inverse = np.unique(owner, return_inverse=True)
    chosen = [points[i] for i in members.tolist()]
    assert all(isinstance(p, System) for p in chosen)
    head = chosen[0]
    assert isinstance(head, System)
    starts = np.array([as_system(points[i]).start_state(*s) for i, s in group],
                      dtype=np.float64)  # fmt: skip
    mine = [plans[i] for i in members.tolist()]
    stride = history_stride(settings, mine[0].steps)
    out = head.run_lanes(chosen, inverse.astype(np.int64), starts, mine,  # type: ignore[arg-type]
                         settings.transient_periods, settings.record_periods, stride)  # fmt: skip
    per = np.array([pl.period for pl in mine])[inverse]
    verdicts = lane_verdicts(out, per)
    strobes = last_strobes(out, list(range(len(group))))
    return [lane_point(out, j, j, verdicts[j], strobes[j]) for j in range(len(group))]


def physical_lanes(
    group: tuple, x0: np.ndarray, v0: np.ndarray, settings: SimulationSettings,
    numbers: Sequence[int], x_only: bool = False, kin: np.ndarray | None = None,
) -> list[BatchPoint]:  # fmt: skip
    """The ``BatchPoint`` of every lane of one lock-step group, its lengths decided in physical
    time (``numerics.physical``): the transient and the record run in chunks through the same
    lock-step kernel (no early stopping inside it; the transient's without the tangent,
    ``settle``), a longer record on from the end of the shorter (``extend``: state and
    ``Carry`` from the kernel, the outputs ``joined``); ``periods_run`` counts both.

    Args:
        group: (lanes kernel, laws of the points, point of each lane (L,), packed forcing,
            damping (L,), forcing tables, T0 (L,), steps N per T0, mesh periods r per T0
            (``StepPlan.fast_periods``)), as ``_run_lanes`` has them.
        x0, v0: the lanes' starts, shape (L,).
        settings: caps and tolerances.
        numbers: the ``start_index`` of each lane's ``BatchPoint``, shape (L,).
        x_only: keep the x of the last strobes alone (``lanes.last_strobes``).
        kin: lanes that may share a record, shape (L,) (``physical.lengths``); None: none.
    """
    lanes_of, laws, inverse, packed, mu, tabled, per, N, r = group

    def call(idx: np.ndarray, xa: np.ndarray, va: np.ndarray, n: int, carry: Carry,
             tangent: bool = True) -> tuple:  # fmt: skip
        streams = max(1, min(numba.get_num_threads(), -(-idx.size // kernels.LANES)))
        owner = inverse[idx].astype(np.int64)
        shared = (per[idx], N, 0, n, DIVERGENCE_BOUND, False, streams, 0.0, 0.0, tangent)
        return lanes_of(laws, owner, packed, mu[idx], xa.copy(), va.copy(),
                        (tabled[0], tabled[1], owner), shared, carry)  # fmt: skip

    def chunk(out: tuple, carry: Carry, idx: np.ndarray) -> physical.Chunk:
        xs, vs, logs, xmin, xmax, _, _, _, _, diverged, xf, vf = out
        per_of = per[idx]
        keep = [(out, j, per_of, carry) for j in range(idx.size)]
        return physical.Chunk(xs, vs, logs, xmin, xmax, xf, vf, diverged.astype(bool), keep)

    def advance(idx: np.ndarray, xa: np.ndarray, va: np.ndarray, n: int) -> physical.Chunk:
        carry = fresh_carry(idx.size)
        return chunk(call(idx, xa, va, n, carry), carry, idx)

    def settle(idx: np.ndarray, xa: np.ndarray, va: np.ndarray, n: int) -> physical.Chunk:
        carry = fresh_carry(idx.size)  # the state alone where the law takes the hint: the
        # cubic steps at 0.65x their CPU; the piecewise steps integrate the tangent anyway
        return chunk(call(idx, xa, va, n, carry, False), carry, idx)

    def extend(idx: np.ndarray, keeps: list[tuple], n: int) -> physical.Chunk:
        rows = [(out, j) for out, j, _, _ in keeps]
        dx, dv, reg = (np.array([c[i][j] for _, j, _, c in keeps]) for i in range(3))
        xf, vf = (np.array([out[i][j] for out, j in rows]) for i in (10, 11))
        carry = (dx, dv, reg)  # where each record ended: the kernel runs it on from there
        return chunk(joined(rows, call(idx, xf, vf, n, carry)), carry, idx)

    spans = physical.lengths(advance, x0, v0, per, mu, r, settings, extend, settle, kin)
    verdicts: dict[int, list[tuple]] = {}
    rows: dict[int, list[int]] = {}
    for s in spans:  # one verdict and one gather of strobes per kernel call
        out, j, per_of, _ = s.keep
        if id(out) not in verdicts:
            verdicts[id(out)], rows[id(out)] = lane_verdicts(out, per_of), []
        rows[id(out)].append(j)
    outs = {id(s.keep[0]): s.keep[0] for s in spans}
    strobes: dict[tuple[int, int], list] = {}
    for key, out in outs.items():
        got = last_strobes(out, rows[key], x_only)
        strobes.update({(key, j): w for j, w in zip(rows[key], got, strict=True)})
    points = []
    records: dict[tuple[int, int], int] = {}  # each record of the call, numbered
    for s, number in zip(spans, numbers, strict=True):
        out, j, _, _ = s.keep
        n = out[0].shape[1]
        before = s.transient - (n if s.transient_reason == "diverged" else 0)
        bp = lane_point(out, j, number, verdicts[id(out)][j], strobes[(id(out), j)],
                        before + int(out[7][j]), x_only)  # fmt: skip
        bp._record = records.setdefault((id(out), j), len(records))
        points.append(bp)
    return points


def joined(before: list[tuple[tuple, int]], after: tuple) -> tuple:
    """The kernel outputs of records run on: lane k's earlier record, row ``before[k][1]`` of
    the outputs ``before[k][0]``, followed by row k of ``after`` (the call that ran it on):
    strobes and logs joined, extremes over both, intervals summed, the end state ``after``'s."""

    def rows(i: int) -> np.ndarray:
        return np.array([out[i][j] for out, j in before])

    xs, vs, logs = (np.concatenate([rows(i), after[i]], axis=1) for i in range(3))
    lows = (np.minimum(rows(i), after[i]) for i in (3, 5))
    highs = (np.maximum(rows(i), after[i]) for i in (4, 6))
    (xmin, fmin), (xmax, fmax) = lows, highs
    done, rec = rows(7) + after[7], rows(8) + after[8]
    return xs, vs, logs, xmin, xmax, fmin, fmax, done, rec, after[9], after[10], after[11]


def lle_tolerances(settings: SimulationSettings) -> tuple[float, float]:
    """(relative, absolute) tolerance of the adaptive LLE rule (``kernels.adaptive``); (0, 0),
    the rule off, with ``adaptive`` false."""
    if not settings.adaptive:
        return 0.0, 0.0
    return settings.lle_stderr_rel, settings.lle_stderr_abs


def simulate_batch(
    points: Sequence[Point], settings: SimulationSettings | None = None, x_only: bool = False
) -> list[BatchPoint]:
    """Verdict (period, LLE, final state, last strobes) for each parameter point of a sweep.

    Each point runs from every start of ``settings.starts()``, one lane per point and start
    (``run_lanes``); the point's verdict is its worst start's (``classify.severity``, the first
    such start on a tie), whose index in ``settings.starts()`` is ``start_index``. Numbers equal
    those of ``simulate`` for the same point and start. ``x_only``: the lock-step lanes keep
    the x of their last strobes alone, in ``poincare_x`` (what a map's points show).
    """
    return simulate_batch_with(points, settings or SimulationSettings(), [], x_only)[0]


def simulate_batch_with(
    points: Sequence[Point], settings: SimulationSettings, more: Sequence[Lane],
    x_only: bool = False,
) -> tuple[list[BatchPoint], list[BatchPoint]]:  # fmt: skip
    """``simulate_batch`` of ``points`` and ``run_lanes`` of ``more`` lanes of the same points
    (a chunk's basin starts), in one call of the kernels: one forcing table a point and one
    pass of the lock-step chunks for both. The same numbers as two calls: a lane's run does
    not depend on other points, nor on the other set (each own start records its own; the
    basin starts of a point may share records among themselves); ``x_only`` as
    ``simulate_batch``'s."""
    starts = settings.starts()
    plans = step_plans(points, settings.steps_per_period)
    for plan in plans:
        check_work(settings, plan.steps)
    lanes = [(i, s) for i in range(len(points)) for s in starts]
    S = len(starts)
    numbers = [*(j for _ in points for j in range(S)), *range(len(more))]
    # as two calls: each own start on its own (simulate's numbers), the basin starts one set
    sets = [*(j for _ in points for j in range(S)), *(S for _ in more)]
    per_lane = _run_lanes(points, plans, [*lanes, *more], settings, numbers, x_only, sets)
    worst = []
    for i in range(len(points)):
        block = per_lane[i * S : (i + 1) * S]
        j = max(range(S), key=lambda j: severity(block[j].classification, block[j].period))
        worst.append(block[j])
    return worst, per_lane[len(lanes) :]


def threads_may_share_kernels() -> bool:
    """True when several threads may run the parallel kernel ``run_batch`` at once.

    numba's OpenMP and TBB threading layers allow it; its fallback, the workqueue layer (where
    neither library is installed), aborts the process instead ("Concurrent access has been
    detected"). The layer is chosen on the first parallel run, so a tiny one runs if needed.
    """
    try:
        return numba.threading_layer() != "workqueue"
    except ValueError:  # no parallel kernel has run in this process yet
        tiny = SimulationSettings(transient_periods=1, record_periods=4, steps_per_period=8)
        point = GearParams.model_validate(PAPER_SECTION_41)
        simulate_batch([point, point], tiny)
        return numba.threading_layer() != "workqueue"
