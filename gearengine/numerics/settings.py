"""How to integrate and analyse Eq. (9): periods, steps, initial states, and what a run costs.

Times are counted in sampling intervals T0 (the Poincare period of the forcing); the caps below
refuse absurd requests before any compute.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import BaseModel, Field, model_validator

from gearengine.model.params import Finite, GearParams, WholeNumber, request_config
from gearengine.numerics.forcing import step_plan

MAX_PERIODS = 100_000
"""Upper cap of transient_periods and record_periods."""
MAX_STEPS_PER_PERIOD = 10_000
"""Upper cap of steps_per_period."""
MAX_STARTS = 64
"""Upper cap of the number of initial states."""
MAX_TOTAL_STEPS = 1_000_000_000
"""Cap on RK4 steps of one request: (transient + record) x steps per T0 x starts."""

State = Annotated[list[Finite], Field(min_length=2, max_length=2)]
"""A state [x, v] of Eq. (9): x in units of b, v = dx/dtau."""


class RandomStarts(BaseModel):
    """Initial states drawn uniformly from a box [xmin, xmax] x [vmin, vmax]."""

    model_config = request_config()

    count: WholeNumber = Field(
        ge=1, le=MAX_STARTS, description="Number of initial states.", examples=[8]
    )
    box: Annotated[list[State], Field(min_length=2, max_length=2)] = Field(
        description="[[xmin, xmax], [vmin, vmax]] of the uniform draw.",
        examples=[[[-1.5, 1.5], [-0.5, 0.5]]],
    )
    seed: WholeNumber = Field(
        0, ge=0, description="Seed of numpy.random.default_rng.", examples=[0]
    )

    @model_validator(mode="after")
    def _ordered(self) -> RandomStarts:
        for name, (lo, hi) in zip(("x", "v"), self.box, strict=True):
            if lo > hi:
                raise ValueError(f"box: {name} range [{lo}, {hi}] is reversed")
        return self


class SimulationSettings(BaseModel):
    """How to integrate and analyse Eq. (9). Times are in sampling intervals T0."""

    model_config = request_config(
        {
            "transient_periods": 500,
            "record_periods": 500,
            "steps_per_period": 200,
            "initial_state": [0.01, 0.01],
        }
    )

    transient_periods: WholeNumber = Field(
        500,
        ge=0,
        le=MAX_PERIODS,
        description="Intervals T0 integrated and discarded before recording.",
        examples=[500],
    )
    record_periods: WholeNumber = Field(
        500,
        ge=1,
        le=MAX_PERIODS,
        description="Intervals T0 recorded (strobes, Lyapunov sums, spectrum).",
        examples=[500],
    )
    steps_per_period: WholeNumber = Field(
        200,
        ge=4,
        le=MAX_STEPS_PER_PERIOD,
        description="RK4 steps per period of the fastest active excitation.",
        examples=[200],
    )
    initial_state: State = Field(
        default_factory=lambda: [0.01, 0.01],
        description="Initial state [x, v] at tau = 0 (used when no other starts are given).",
        examples=[[0.01, 0.01]],
    )
    initial_states: Annotated[list[State], Field(min_length=1, max_length=MAX_STARTS)] | None = (
        Field(
            None,
            description=f"Several initial states [[x, v], ...], at most {MAX_STARTS}.",
            examples=[[[0.01, 0.01], [1.5, 0.0]]],
        )
    )
    random_initial_states: RandomStarts | None = Field(
        None, description="Initial states drawn at random from a box."
    )
    adaptive: bool = Field(
        True,
        description="Sweeps and batches: let a run stop early (numerics.kernels.adaptive) once "
        "its strobes repeat with a period <= 12 over the last 120 intervals and its LLE has "
        "converged below zero, or, chaotic and quasi-periodic runs, once at least 100 intervals "
        "are recorded, the LLE's standard error over the 10 blocks of the record so far is "
        "below max(lle_stderr_abs, lle_stderr_rel |lle|) and the verdict is clear by 3 of them "
        "at three checks 10 intervals apart; "
        "false runs every point transient_periods + record_periods. Applies to the lanes of the "
        "lock-step kernels: commensurate forcing, both backlash laws; incommensurate points and "
        "simulate() run the full length.",
        examples=[True],
    )
    lle_stderr_rel: float = Field(
        0.1,
        ge=0.0,
        le=1.0 / 3.0,
        description="adaptive: tolerance on the LLE's standard error relative to |lle| at which "
        "a chaotic or quasi-periodic run stops (0: the relative test off).",
        examples=[0.1],
    )
    lle_stderr_abs: float = Field(
        1e-3,
        ge=0.0,
        le=0.1,
        description="adaptive: absolute tolerance on the LLE's standard error (per unit "
        "dimensionless time tau) at which a chaotic or quasi-periodic run stops (0: off; both "
        "0: such runs run the full length).",
        examples=[1e-3],
    )
    lyapunov_nolds: bool = Field(
        False,
        description="Also estimate the LLE from x(t) with nolds.lyap_r (slow).",
        examples=[False],
    )

    @model_validator(mode="after")
    def _work(self) -> SimulationSettings:
        if self.initial_states is not None and self.random_initial_states is not None:
            raise ValueError("give initial_states or random_initial_states, not both")
        work = (self.transient_periods + self.record_periods) * self.steps_per_period
        work *= len(self.starts())
        if work > MAX_TOTAL_STEPS:
            raise ValueError(
                f"(transient_periods + record_periods) x steps_per_period x starts = {work} RK4 "
                f"steps exceeds {MAX_TOTAL_STEPS}"
            )
        return self

    def starts(self) -> list[tuple[float, float]]:
        """Initial states (x0, v0) in order: initial_states, random ones, or initial_state."""
        if self.initial_states is not None:
            return [(s[0], s[1]) for s in self.initial_states]
        r = self.random_initial_states
        if r is not None:
            rng = np.random.default_rng(r.seed)
            xs = rng.uniform(r.box[0][0], r.box[0][1], r.count)
            vs = rng.uniform(r.box[1][0], r.box[1][1], r.count)
            return [(float(x), float(v)) for x, v in zip(xs, vs, strict=True)]
        return [(self.initial_state[0], self.initial_state[1])]


def run_steps(settings: SimulationSettings, steps: int) -> int:
    """RK4 steps of a run: (transient + record) periods x ``steps`` per T0 x starts."""
    return (settings.transient_periods + settings.record_periods) * steps * len(settings.starts())


def work(params: GearParams, settings: SimulationSettings) -> int:
    """RK4 steps ``simulate(params, settings)`` takes (for compute budgets)."""
    return run_steps(settings, step_plan(params, settings.steps_per_period).steps)


def check_work(settings: SimulationSettings, steps: int) -> None:
    """Refuse (ValueError naming ``steps_per_period``) a run over ``MAX_TOTAL_STEPS``."""
    total = run_steps(settings, steps)
    if total > MAX_TOTAL_STEPS:
        raise ValueError(
            f"steps_per_period: the excitation frequencies need {steps} RK4 steps per T0, "
            f"{total} steps in all, over the cap {MAX_TOTAL_STEPS}; lower steps_per_period or "
            "the periods"
        )
