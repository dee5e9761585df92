"""An analysis request makes its RK4 step plan once, when it is validated: the budget reads its
work from it and ``analyze`` hands it to the attractors (no plan made again for the basins)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.numerics import attractors as attractors_module
from gearengine.numerics.runs import as_system, work
from gearengine.studies.basins import basins_work, with_basins
from tests.conftest import PAPER_PARAMS

ROOT = Path(__file__).resolve().parents[1]
SHORT = {"transient_periods": 20, "record_periods": 10, "steps_per_period": 64}


@pytest.mark.parametrize(
    "body",
    [
        {"params": PAPER_PARAMS, "settings": SHORT},
        {**json.loads((ROOT / "examples/design-train.json").read_text()), "settings": SHORT},
    ],
    ids=["pair", "train"],
)
def test_the_request_carries_the_plan_and_work_of_its_system(body: dict) -> None:
    """The plan is the system's own at the settings' steps per period; the work is
    ``numerics.settings.work`` of the system (a train's at its step cost), basins included."""
    request = AnalysisRequest.model_validate(body)
    assert request.plan == as_system(request.system).plan(SHORT["steps_per_period"])
    assert request.work == work(request.system, request.settings)
    full = with_basins(request)
    assert full.plan == request.plan
    assert basins_work(request) == work(full.system, full.settings) > request.work


def test_analyze_hands_the_carried_plan_to_the_attractors(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With basins the attractors run on the request's plan: no step plan is made for them."""
    settings = {**SHORT, "basins": {"starts": 4}}
    request = AnalysisRequest.model_validate({"params": PAPER_PARAMS, "settings": settings})

    def no_plans(*args: object) -> None:
        raise AssertionError("the attractors made a step plan again")

    monkeypatch.setattr(attractors_module, "step_plans", no_plans)
    result = analyze(request)
    assert result.numerics.basins is not None and result.numerics.basins.starts == 4


def test_every_start_runs_on_the_plan_in_hand(monkeypatch: pytest.MonkeyPatch) -> None:
    """A train's runs share one step plan: ``simulate`` makes it once for all its starts, and
    the attractors of a request make none (each start made its own in ``integrate``)."""
    from gearengine.numerics.attractors import planned_attractors
    from gearengine.numerics.simulation import simulate
    from gearengine.systems.gear_train.system import TrainSystem

    body = json.loads((ROOT / "examples/design-train.json").read_text())
    starts = {"initial_states": [[0.01, 0.01], [0.5, 0.0], [-0.5, 0.0]]}
    settings = {**SHORT, **starts, "basins": {"starts": 4}}
    request = AnalysisRequest.model_validate({**body, "settings": settings})
    made = []
    own_plan = TrainSystem.plan

    def counted(self: TrainSystem, steps_per_period: int) -> object:
        made.append(steps_per_period)
        return own_plan(self, steps_per_period)

    monkeypatch.setattr(TrainSystem, "plan", counted)
    plans = []
    for n in (1, 3):  # the starts add no plan (the Floquet flow makes its own)
        one = {"basins": None, "initial_states": starts["initial_states"][:n]}
        simulate(request.system, request.settings.model_copy(update=one))
        plans.append(len(made))
        made.clear()
    assert plans[0] == plans[1]
    _, counts = planned_attractors(request.system, request.settings, request.plan)
    assert made == [] and counts.starts == 4
