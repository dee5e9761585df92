"""A gear train's ensembles in the lock-step kernel (issue 32: "the lanes run in the lock-step
kernels"): ``run_lanes`` advances every lane of trains with one state dimension, law and N
together (``systems.gear_train.lanes``), with each lane's numbers those of its own run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gearengine.model.design import Design
from gearengine.numerics.batch import run_lanes, run_verdict, step_plans
from gearengine.numerics.runs import integrate
from gearengine.numerics.settings import SimulationSettings
from gearengine.systems.designs import design_model
from gearengine.systems.gear_train.system import TrainSystem

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
