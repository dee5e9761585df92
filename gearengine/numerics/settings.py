"""How to integrate and analyse Eq. (9): periods, steps, initial states, and what a run costs.

Times are counted in sampling intervals T0 (the Poincare period of the forcing); the caps below
refuse absurd requests before any compute.
"""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    Field,
    ValidationInfo,
    field_validator,
    model_validator,
)

from gearengine.model.errors import InputError
from gearengine.model.params import Finite, GearParams, WholeNumber, not_both, request_config
from gearengine.model.units import QUANTITIES, parse_quantity
from gearengine.systems.base import StepPlan, System

MAX_PERIODS = 100_000
"""Upper cap of transient_periods and record_periods."""
MAX_STEPS_PER_PERIOD = 10_000
"""Upper cap of steps_per_period."""
MAX_STARTS = 64
"""Upper cap of the number of initial states."""
MAX_TOTAL_STEPS = 1_000_000_000
"""Cap on RK4 steps of one request: (transient + record) x steps per T0 x starts."""
MAX_BASIN_STARTS = 4096
"""Upper cap of ``basins.starts`` (a 64 x 64 grid)."""
DEFAULT_BASIN_BOX = [[-3.0, 3.0], [-3.0, 3.0]]
"""Default box of basin starts, dimensionless (see ``BasinSettings``)."""

State = Annotated[list[Finite], Field(min_length=2, max_length=2)]
"""A state [x, v] of Eq. (9): x in units of b, v = dx/dtau."""
MAX_BOX = 1000.0
"""Largest |end| of a dimensionless basin box (a thousand half backlashes)."""
BoxEnd = Annotated[
    Annotated[float, Field(ge=-MAX_BOX, le=MAX_BOX, allow_inf_nan=False)]
    | Annotated[str, Field(max_length=40)],
    Field(union_mode="left_to_right", examples=[-3.0, "-30 um", "-400 mm/s"]),
]
"""One end of a basin box range: a dimensionless number, or with a design a string with a
unit (µm, mm ... for x; mm/s, m/s ... for v)."""


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
                raise InputError("box", f"{name} range [{lo}, {hi}] is reversed")
        return self


SQUARE_STARTS = [k * k for k in range(1, math.isqrt(MAX_BASIN_STARTS) + 1)]
"""The counts of starts a grid takes (1, 4, 9, ..., 4096)."""


class BasinSettings(BaseModel):
    """Many starts of one design, to find every attractor and the fraction of starts reaching
    each (``numerics.attractors``).

    The default box, x in [-3, 3] half backlashes and v = dx/dtau in [-3, 3], covers the states
    a running gear pair can be thrown into: from 2 b onto the back flank, through the whole
    clearance (|x| <= 1), to 2 b of extra tooth deflection on the drive flank, and relative
    velocities at the mesh up to 3 b omega_n, the speed at which a free pair crosses the
    clearance in 2/3 of a time unit 1/omega_n (a shock or a load step of a few static
    forces gives that). With a design the ends may be given in µm and mm/s.
    """

    model_config = request_config()
    model_config["json_schema_extra"] = {  # as _square checks: a grid (the default) is square
        "if": {"not": {"required": ["grid"], "properties": {"grid": {"const": False}}}},
        "then": {"properties": {"starts": {"enum": SQUARE_STARTS}}},
    }

    starts: int = Field(
        16,
        ge=1,
        le=MAX_BASIN_STARTS,
        description=f"Number of initial states (1..{MAX_BASIN_STARTS}); with grid, a square "
        "(16, 64, 256, ...).",
        examples=[256],
    )
    box: Annotated[list[Annotated[list[BoxEnd], Field(min_length=2, max_length=2)]],
                   Field(min_length=2, max_length=2)] = Field(
        default_factory=lambda: [list(r) for r in DEFAULT_BASIN_BOX],
        description="[[xmin, xmax], [vmin, vmax]]: dimensionless (x in half backlashes b, "
        "v = dx/dtau), or with a design strings with units, e.g. [['-30 um', '30 um'], "
        "['-400 mm/s', '400 mm/s']]. Default [[-3, 3], [-3, 3]].",
        examples=[[[-3.0, 3.0], [-3.0, 3.0]]],
    )  # fmt: skip
    grid: bool = Field(
        True,
        description="true: the cell centres of a sqrt(starts) x sqrt(starts) grid over the box "
        "(x fastest); false: uniform random draws from seed.",
        examples=[True],
    )
    seed: int = Field(0, ge=0, description="Seed of numpy.random.default_rng (grid: false).")
    min_fraction: float = Field(
        0.0,
        ge=0.0,
        lt=1.0,
        description="The headline verdict is that of the worst attractor whose basin fraction "
        "is above this (0: any attractor found).",
        examples=[0.0],
    )

    @field_validator("box")
    @classmethod
    def _box(cls, box: list[list[float | str]]) -> list[list[float | str]]:
        for name, kind, (lo, hi) in zip("xv", ("displacement", "velocity"), box, strict=True):
            if isinstance(lo, str) != isinstance(hi, str):
                raise ValueError(f"give both ends of the {name} range with units or neither")
            ends = [box_end(e, kind) for e in (lo, hi)]
            if not ends[0] < ends[1]:
                raise ValueError(f"the {name} range [{lo}, {hi}] is empty or reversed")
        return box

    @model_validator(mode="after")
    def _square(self) -> BasinSettings:
        if self.grid and math.isqrt(self.starts) ** 2 != self.starts:
            raise ValueError(f"starts: {self.starts} is not a square; a grid needs 16, 64, 256...")
        return self

    def physical(self) -> bool:
        """True when the box is given in units (it needs a design's scales)."""
        return any(isinstance(e, str) for r in self.box for e in r)

    def dimensionless_box(self, x_scale: float = 1.0, v_scale: float = 1.0) -> list[list[float]]:
        """[[xmin, xmax], [vmin, vmax]] in units of b and b omega_n.

        Args:
            x_scale: metres per unit x (the half backlash b), for ends given in units.
            v_scale: m/s per unit v (b omega_n), for ends given in units.
        """
        return [
            [box_end(e, kind) / (scale if isinstance(e, str) else 1.0) for e in r]
            for r, kind, scale in zip(self.box, ("displacement", "velocity"),
                                      (x_scale, v_scale), strict=True)
        ]  # fmt: skip

    def states(self, x_scale: float = 1.0, v_scale: float = 1.0) -> list[tuple[float, float]]:
        """The initial states (x0, v0), dimensionless, in order (x fastest on a grid); the
        scales as in ``dimensionless_box``."""
        (x0, x1), (v0, v1) = self.dimensionless_box(x_scale, v_scale)
        if self.grid:
            n = math.isqrt(self.starts)
            xs = x0 + (x1 - x0) * (np.arange(n) + 0.5) / n
            vs = v0 + (v1 - v0) * (np.arange(n) + 0.5) / n
            return [(float(x), float(v)) for v in vs for x in xs]
        rng = np.random.default_rng(self.seed)
        xr = rng.uniform(x0, x1, self.starts)
        vr = rng.uniform(v0, v1, self.starts)
        return [(float(x), float(v)) for x, v in zip(xr, vr, strict=True)]


def box_end(end: float | str, kind: str) -> float:
    """A box end: the number itself, or a string with a unit in SI (m or m/s)."""
    if isinstance(end, str):
        return parse_quantity(end, QUANTITIES[kind], allow_zero=True)
    return end


ENVELOPE_SETTINGS = {"transient_periods": 60, "record_periods": 60, "steps_per_period": 128}
"""Light integration settings of studies that run many designs (an envelope check, a robustness
study, a remedies search): a request's or a design file's ``settings`` are merged over them
(``over_light``; adding ``random_initial_states`` keeps the 60 + 60 periods)."""


def over_light(given: object) -> object:
    """``given`` settings (an object, before validation) merged over ``ENVELOPE_SETTINGS``;
    anything else (a ``SimulationSettings``, a wrong type) as it is, for the model to judge."""
    return {**ENVELOPE_SETTINGS, **given} if isinstance(given, dict) else given


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
    model_config["json_schema_extra"] |= not_both("initial_states", "random_initial_states")

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
        description="Sweeps and batches: let a run stop early (the kernels' adaptive rule) once "
        "its strobes repeat with a period <= 12 over the last 120 intervals and its LLE has "
        "converged below zero, or, chaotic and quasi-periodic runs, once at least 200 intervals "
        "are recorded, the LLE's standard error over the 10 blocks of the record so far is "
        "below max(lle_stderr_abs, lle_stderr_rel |lle|) and the verdict is clear by 3 of them "
        "at three checks 10 intervals apart; "
        "false runs every point transient_periods + record_periods. Applies to the lanes of the "
        "lock-step kernels: commensurate forcing, both backlash laws; incommensurate points and "
        "simulate() run the full length. With physical_time (default) the lengths of every run, "
        "simulate() too, are decided in physical time instead; false: fixed lengths everywhere, "
        "the numbers of before.",
        examples=[True],
    )
    physical_time: bool = Field(
        True,
        description="With adaptive: the transient and the record in physical time "
        "(numerics.physical): the transient ends once the response has settled on a cycle of "
        "period <= 12 T0 to 1e-5 of its size (strobes at T0 repeating over >= 60 mesh periods, "
        "three cycles), after at least 10 damping time constants 1/(zeta omega_n); a response "
        "that does not settle (chaos, quasi-periodic) keeps the whole transient; the record is "
        "160 mesh periods (10 cycles at least) when periodic, else grows from 400 until the "
        "LLE's standard error meets lle_stderr_abs / lle_stderr_rel; transient_periods and "
        "record_periods are the upper bounds. Commensurate forcing only. false (or adaptive "
        "false): transient_periods + record_periods as counts of T0, as before.",
        examples=[True],
    )
    basins: BasinSettings | None = Field(
        None,
        description="Also run basins.starts initial states from a box and report every "
        "attractor found with its basin fraction (numerics.attractors, numerics.basins); the "
        "headline verdict becomes the worst attractor's. Null: the starts above only.",
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
        work *= self.lanes()
        if work > MAX_TOTAL_STEPS:
            raise ValueError(
                f"(transient_periods + record_periods) x steps_per_period x (starts + "
                f"basins.starts) = {work} RK4 "
                f"steps exceeds {MAX_TOTAL_STEPS}"
            )
        return self

    def lengths_text(self) -> str:
        """The transient and record lengths in words: "500 + 500 periods", or with physical
        time "<= 500 + 500 periods (ended when settled)" (they are upper bounds then)."""
        text = f"{self.transient_periods} + {self.record_periods} periods"
        return f"<= {text} (ended when settled)" if self.adaptive and self.physical_time else text

    def run_text(self) -> str:
        """The lengths (``lengths_text``) and steps a period of every run: "<= 60 + 60 periods
        (ended when settled), 128 steps a period"."""
        return f"{self.lengths_text()}, {self.steps_per_period} steps a period"

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

    def for_request(self, has_design: bool) -> SimulationSettings:
        """``self``, or ValueError when a basin box in units comes without a design."""
        if self.basins is not None and self.basins.physical() and not has_design:
            raise ValueError("basins.box: a box in units (µm, mm/s) needs a design; with "
                             "params give it dimensionless")  # fmt: skip
        return self

    def lanes(self) -> int:
        """Runs of one point: its starts and its basin starts."""
        return len(self.starts()) + (0 if self.basins is None else self.basins.starts)


def _for_request(settings: SimulationSettings, info: ValidationInfo) -> SimulationSettings:
    # a request's fields are validated in order: design (if any) comes before settings
    return settings.for_request(info.data.get("design") is not None)


RequestSettings = Annotated[SimulationSettings, AfterValidator(_for_request)]
"""The settings of a request that carries params or a design (``ParamsOrDesign``): a basin box
in units is refused without a design, naming ``settings``."""


def run_steps(settings: SimulationSettings, steps: int) -> int:
    """RK4 steps of a run: (transient + record) periods x ``steps`` per T0 x (starts + basin
    starts)."""
    return (settings.transient_periods + settings.record_periods) * steps * settings.lanes()


def plan_work(params: GearParams | System, settings: SimulationSettings, plan: StepPlan) -> int:
    """RK4 steps of ``simulate(params, settings)`` on ``plan``, its step plan made already; a
    ``System``'s steps count ``System.step_cost`` each (a train's, raised for stiff shafts, 3)."""
    cost = params.step_cost if isinstance(params, System) else 1
    return cost * run_steps(settings, plan.steps)


def check_work(settings: SimulationSettings, steps: int) -> None:
    """Refuse (``InputError`` naming ``steps_per_period``) a run over ``MAX_TOTAL_STEPS``."""
    total = run_steps(settings, steps)
    if total > MAX_TOTAL_STEPS:
        raise InputError(
            "steps_per_period",
            f"the excitation frequencies need {steps} RK4 steps per T0, {total} steps in all, "
            f"over the cap {MAX_TOTAL_STEPS}; lower steps_per_period or the periods",
        )
