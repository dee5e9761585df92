"""A gear train's ensembles in the lock-step kernel (issue 32: "the lanes run in the lock-step
kernels"): ``run_lanes`` advances every lane of trains with one state dimension, law and N
together (``systems.gear_train.lanes``), with each lane's numbers those of its own run."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gearengine.model.design import Design
from gearengine.numerics.batch import run_lanes, run_verdict, step_plans
from gearengine.numerics.runs import integrate
from gearengine.numerics.settings import SimulationSettings
from gearengine.systems.designs import design_model
from gearengine.systems.gear_train.kernel import forcing_table, run_train
from gearengine.systems.gear_train.lanes import run_train_lanes
from gearengine.systems.gear_train.system import TrainSystem
from gearengine.systems.spur_pair.laws import law

ROOT = Path(__file__).resolve().parents[1]
TRAIN = json.loads((ROOT / "examples" / "design-train.json").read_text())["design"]
SETTINGS = SimulationSettings(transient_periods=15, record_periods=25, steps_per_period=128)


def points() -> list[TrainSystem]:
    """Trains at three speeds and two torques (one N per T0: 18 teeth x 128 steps)."""
    out = []
    for rpm in (1000, 3500, 6000):
        for torque in ("20 N*m", "40 N*m"):
            design = Design.model_validate({**TRAIN, "speed": f"{rpm} rpm", "torque": torque})
            system, _ = design_model(design)
            assert isinstance(system, TrainSystem)
            out.append(system)
    return out


def test_train_lanes_are_their_own_runs_bit_for_bit() -> None:
    """Every lane (6 points x 3 starts, one group) equals the ``BatchPoint`` of its own run:
    period, LLE and its error, DTE, forces, final state and strobes, to the last bit."""
    trains = points()
    plans = step_plans(trains, SETTINGS.steps_per_period)
    assert len({p.steps for p in plans}) == 1
    starts = [(0.01, 0.01), (1.5, -0.3), (-0.8, 0.6)]
    lanes = [(i, s) for i in range(len(trains)) for s in starts]
    got = run_lanes(trains, lanes, SETTINGS)
    for k, ((i, s), point) in enumerate(zip(lanes, got, strict=True)):
        run = integrate(trains[i], SETTINGS, trains[i].start_state(*s))
        assert point.model_dump() == run_verdict(run, s, plans[i], k).model_dump()


def test_train_lanes_do_not_run_one_by_one(monkeypatch: pytest.MonkeyPatch) -> None:
    """The lanes never reach the train's own integrator (they did, lane after lane)."""

    def refuse(*args: object) -> None:
        raise AssertionError("a train lane ran in the single-run kernel")

    trains = points()[:2]
    monkeypatch.setattr(TrainSystem, "integrate", refuse)
    got = run_lanes(trains, [(0, (0.01, 0.01)), (1, (0.01, 0.01))], SETTINGS)
    assert [p.start_index for p in got] == [0, 1]


def test_a_lane_that_diverges_stops_as_its_own_run() -> None:
    """With a divergence bound of 1.3 b some lanes stop early: each lane's intervals done, its
    strobes and LLE logs up to there are those of ``run_train`` with the same bound, and the
    other lanes run on unchanged."""
    trains = points()[:2]
    plans = step_plans(trains, SETTINGS.steps_per_period)
    t0, t1 = trains
    N = plans[0].steps
    lw = law(t0.params)
    starts = [t0.start_state(0.01, 0.01), t1.start_state(0.01, 0.01), t0.start_state(2.5, 1.0)]
    owner = np.array([0, 1, 0])
    tables = np.stack([forcing_table(t.kc, t.ec, t.tc, p.period, N)
                       for t, p in zip(trains, plans, strict=True)])  # fmt: skip
    x = np.array(starts)
    half = x.shape[1] // 2

    def stack(name: str) -> np.ndarray:
        return np.stack([getattr(t, name) for t in trains])

    bound = 1.3
    out = run_train_lanes(
        lw.code, lw.a, lw.c, lw.alpha, np.array([t.params.damping for t in trains]),
        stack("AK"), stack("AC"), stack("g"), stack("w"), stack("f"), stack("p"), tables, owner,
        np.array([p.period for p in plans]), np.ascontiguousarray(x[:, :half]),
        np.ascontiguousarray(x[:, half:]), N, 5, 10, 10 * N, bound,
    )  # fmt: skip
    xs, vs, logs, done, diverged = out[0], out[1], out[2], out[7], out[9]
    assert diverged.any() and not diverged.all()
    for lane, i in enumerate(owner.tolist()):
        t = trains[i]
        own = run_train(
            lw.code, lw.a, lw.c, lw.alpha, t.params.damping, t.AK, t.AC, t.g, t.w, t.f, t.p,
            t.kc, t.ec, t.tc, x[lane, :half].copy(), x[lane, half:].copy(), True,
            plans[i].period, N, 5, 10, 1, bound,
        )  # fmt: skip
        assert done[lane] == own[7]
        assert np.array_equal(xs[lane], own[0]) and np.array_equal(vs[lane], own[1])
        assert np.array_equal(logs[lane], own[2])
