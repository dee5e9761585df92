"""Piecewise lanes (``kernels.run_kink_batch``) against the scalar kink kernel, and the adaptive
LLE rule (``kernels.adaptive.lle_known``) of both lock-step kernels against fixed length."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearengine.model.params import GearParams
from gearengine.numerics.batch import run_lanes, step_plans
from gearengine.numerics.runs import integrate
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import simulate
from gearengine.signals.classify import DIVERGENCE_BOUND
from gearengine.signals.lyapunov import BLOCKS
from gearengine.systems.spur_pair import kernels
from gearengine.systems.spur_pair.forcing import packed_forcing
from gearengine.systems.spur_pair.kernels import intervals, kinklanes, lockstep, scheduler
from gearengine.systems.spur_pair.kernels.adaptive import ADAPT_LLE_MIN_RECORD
from gearengine.systems.spur_pair.laws import LAWS, fresh_carry, law
from tests._gear_cases import paper

STARTS = [(0.01, 0.01), (1.5, 0.0), (-1.2, 0.3)]
"""Inside the clearance, in contact on the drive side, on the back side."""


def piecewise_points() -> list[GearParams]:
    """No impact (small TE), single-sided and double-sided impacts, periodic and chaotic, with
    alpha 0 and 0.3, and a design with stiffness, torque and TE harmonics (several forcing
    terms, K(t) != 1)."""
    points = [
        paper(0.02, model="piecewise"),
        paper(0.1, model="piecewise", alpha=0.3),
        paper(0.2, model="piecewise"),
        paper(0.3, mu=0.05, model="piecewise"),
        paper(0.6, mu=0.1, model="piecewise"),
        paper(1.0, model="piecewise", alpha=0.3),
    ]
    several = {
        "damping": 0.06,
        "mean_force": 0.05,
        "backlash": {"model": "piecewise", "alpha": 0.1},
        "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.1}, {"amplitude": 0.03}]},
        "torque": {"frequency": 0.5, "harmonics": [{"amplitude": 0.02}]},
        "transmission_error": {
            "frequency": 1.0,
            "harmonics": [{"amplitude": 0.1}, {"amplitude": 0.02, "phase": 0.4}],
        },
    }
    return [*points, GearParams.model_validate(several)]


def test_piecewise_lanes_equal_the_scalar_kink_kernel_bit_for_bit() -> None:
    points = piecewise_points()
    lanes = [(i, s) for i in range(len(points)) for s in STARTS]
    settings = SimulationSettings(transient_periods=60, record_periods=60, adaptive=False)
    out = run_lanes(points, lanes, settings)
    regimes, classes = set(), set()
    for (i, start), o in zip(lanes, out, strict=True):
        run = integrate(points[i], settings, start)  # run_kink with its forcing table
        assert o.final_state == [run.final[0], run.final[1]]
        assert o.x_peak_to_peak == run.xmax - run.xmin
        assert (o.force_min, o.force_max) == (run.fmin, run.fmax)
        assert o.poincare[-1] == [run.xs[-1], run.vs[-1]]
        assert o.periods_run == run.done == 120
        regimes.add(o.impact_regime)
        classes.add(o.classification)
    assert regimes == {"no_impact", "single_sided", "double_sided"}
    assert {"periodic", "chaotic"} <= classes


def test_piecewise_lanes_give_simulates_verdicts() -> None:
    points = piecewise_points()
    settings = SimulationSettings(
        transient_periods=60,
        record_periods=60,
        adaptive=False,
        initial_states=[list(s) for s in STARTS],
    )
    lanes = [(i, s) for i in range(len(points)) for s in STARTS]
    out = run_lanes(points, lanes, settings)
    for i, p in enumerate(points):
        single = simulate(p, settings)
        assert single.method.endswith("forcing table")
        for k, summary in enumerate(single.starts):
            o = out[i * len(STARTS) + k]
            assert (o.classification, o.period) == (summary.classification, summary.period)
            assert (o.lle, o.lle_stderr) == (summary.lle, summary.lle_stderr)


@pytest.mark.parametrize(
    "point",
    [paper(0.25), paper(0.2, model="piecewise"), paper(0.6, mu=0.1, model="piecewise")],
    ids=["cubic", "piecewise-single-sided", "piecewise-double-sided"],
)
def test_chaotic_lane_stops_once_its_lle_is_known(point: GearParams) -> None:
    fixed_settings = SimulationSettings(adaptive=False)
    adaptive_settings = SimulationSettings(physical_time=False)  # the kernels' LLE rule
    (fixed,) = run_lanes([point], [(0, (0.01, 0.01))], fixed_settings)
    (early,) = run_lanes([point], [(0, (0.01, 0.01))], adaptive_settings)
    assert fixed.classification == early.classification == "chaotic"
    assert fixed.periods_run == 1000
    assert 500 + ADAPT_LLE_MIN_RECORD <= early.periods_run < 1000
    assert (early.periods_run - 500) % BLOCKS == 0
    tol = max(adaptive_settings.lle_stderr_abs, adaptive_settings.lle_stderr_rel * early.lle)
    assert early.lle_stderr <= tol
    assert abs(early.lle - fixed.lle) <= 3.0 * early.lle_stderr
    assert early.lle - 3.0 * early.lle_stderr > 0.0


def test_lle_rule_off_runs_the_full_length_bit_for_bit() -> None:
    point = paper(0.2, model="piecewise")
    off = SimulationSettings(lle_stderr_rel=0.0, lle_stderr_abs=0.0, physical_time=False)
    (a,) = run_lanes([point], [(0, (0.01, 0.01))], off)
    (f,) = run_lanes([point], [(0, (0.01, 0.01))], SimulationSettings(adaptive=False))
    assert a == f and a.periods_run == 1000


def test_both_lock_step_kernels_run_the_one_lane_scheduler() -> None:
    """Streams, refill, interval ends and adaptive stopping are written once
    (``kernels.scheduler``): the cubic and the piecewise kernels are its one kernel and stream
    bodies with their law's steps."""
    kernels = (lockstep.run_batch, kinklanes.run_kink_batch)
    assert all(k.py_func.__code__ is scheduler._lanes.__code__ for k in kernels)
    streams = [k.py_func.__globals__["law_stream"] for k in kernels]
    assert all(s.py_func.__code__ is scheduler._stream.__code__ for s in streams)
    laws = [s.py_func.__globals__["law_steps"] for s in streams]
    assert laws == [lockstep._cubic_steps, kinklanes._kink_steps]


def test_one_call_ends_the_interval_of_every_lane_of_a_stream() -> None:
    """``intervals.end_intervals`` ends an interval of all the lanes of a stream at once (one
    call per interval, not one per lane: a call costs ~60 reference-count operations): it
    renormalises every tangent, records the running lanes, and marks and counts the lanes whose
    run finished (at its last interval, or diverged), leaving idle and running lanes unmarked."""
    lane_state = (
        np.array([0.0, 0.5, 1e9, -0.25]),  # X: idle, last interval, diverged, running
        np.array([0.0, 0.1, 0.0, 0.2]),  # V
        np.array([3.0, 1.0, 2.0, 0.0]),  # DX
        np.array([4.0, 1.0, 0.0, 5.0]),  # DV
        np.full(4, -1.0),
        np.full(4, 1.0),
        np.full(4, -2.0),
        np.full(4, 2.0),
    )
    counters = (np.array([0, 1, 0, 0]), np.zeros(4, dtype=np.int64), np.zeros(4, dtype=np.int64))
    out = intervals.new_outputs(3, 2)
    need = np.zeros(4, dtype=np.bool_)
    ended = intervals.end_intervals(np.array([-1, 0, 1, 2]), lane_state, counters, np.zeros(4),
                                    intervals.new_ring(0, 4), out, np.ones(3), 0, 2, 0, 0, 10.0,
                                    0.0, 0.0, need)  # fmt: skip
    xs, _, logs, xmin, _, _, _, done, rec, diverged, xf, _ = out
    assert ended == 2 and need.tolist() == [False, True, True, False]
    assert np.allclose(np.hypot(lane_state[2], lane_state[3]), 1.0)
    assert done.tolist() == [2, 0, 0] and rec.tolist() == [2, 0, 0]
    assert diverged.tolist() == [0, 1, 0] and xf[0] == 0.5
    assert xs[0, 1] == 0.5 and xs[2, 0] == -0.25 and logs[2, 0] == pytest.approx(math.log(5.0))
    assert counters[0].tolist() == [0, 2, 0, 1] and xmin[2] == -1.0


def _lanes(point: GearParams, n: int, tangent: bool) -> tuple[tuple, tuple]:
    """The lock-step kernel of ``point``'s law run n intervals from ``STARTS``, as the
    physical-time driver calls it (no transient in the call, no early stop): (outputs, carry)."""
    plan = step_plans([point], 200)[0]
    kc, fm, fc = packed_forcing(point)
    table = kernels.forcing_table(plan.period, plan.steps, kc, fm, fc)
    L = len(STARTS)
    owner = np.zeros(L, dtype=np.int64)
    x0, v0 = (np.array([s[i] for s in STARTS]) for i in (0, 1))
    shared = (np.full(L, plan.period), plan.steps, 0, n, DIVERGENCE_BOUND, False, 1, 0.0, 0.0,
              tangent)  # fmt: skip
    carry = fresh_carry(L)
    lanes = LAWS[point.backlash.model].lanes
    assert lanes is not None
    out = lanes([law(point)], owner, [(kc, fm, fc)], np.full(L, point.damping), x0, v0,
                (table[0][None], table[1][None], owner), shared, carry)  # fmt: skip
    return out, carry


@pytest.mark.parametrize("point", [paper(0.2), paper(0.6, mu=0.1, model="piecewise")],
                         ids=["cubic", "piecewise"])  # fmt: skip
def test_a_transient_without_the_tangent_has_the_same_states(point: GearParams) -> None:
    """``tangent=False`` (the physical-time driver's transient chunks, which read no LLE and no
    mesh force) skips the tangent's stages and the force's extremes in the lanes' whole steps
    and gives the same states, strobes, extremes of x and end states, bit for bit (the state
    never depends on the tangent)."""
    full, _ = _lanes(point, 60, True)
    bare, carry = _lanes(point, 60, False)
    for i in (0, 1, 3, 4, 7, 8, 9, 10, 11):  # xs, vs, xmin, xmax, done, rec, diverged, xf, vf
        assert np.array_equal(full[i], bare[i])
    assert np.all(full[2] != 0.0) and np.isfinite(full[5]).all()  # logs, fmin with it
    if point.backlash.model == "cubic":  # no whole step moved the tangent or saw the force
        assert np.all(carry[0] == kernels.SQRT1_2) and np.all(bare[2] == 0.0)
        assert np.all(bare[5] == np.inf)
