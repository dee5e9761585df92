"""What a run-up asks for: a design, a driver-speed profile in time, and how to read it.

The profile is a linear ramp between ``from_speed`` and ``to_speed`` (``from_speed`` below
``to_speed``) at a ``rate`` or over a ``duration`` (each leg), run ``up`` (from -> to), ``down``
(to -> from) or ``up_down`` (up, then down from where the up leg ended); or a list of
``points`` [time, speed], linear between them. Speeds are strings with units ("500 rpm",
"52 rad/s") and rates too ("1000 rpm/s", "100 rad/s^2"): a bare number is refused there, since
the answer has no place for a note saying how it was read (a bare rate 2000 was 2000 rad/s^2,
a 0.26 s ramp where the CLI's --rate 2000, rpm/s, takes 2.5 s); times are "5 s" or seconds.
The torque may ramp linearly in time from the design's torque to ``to_torque`` over the whole
profile.

Refused before any compute (422 naming the field): a rate that is zero or negative, speeds
outside the plausible range of a shaft (``model.units``), a profile whose integration is over
the work budget (``MAX_RUNUP_STEPS``), a params-only request (a run-up needs the design's time
scale), the cubic-fit law (the run-up kernel is the kink-accurate piecewise one), a bin wider
than a quarter of the speed range (``widest_bin_rpm``: one 5000 rpm bin averaged away the chaotic
bins 50 rpm bins found).

A design with a ``train`` runs as its ``System`` (``systems.designs.design_model``) on the
scales of its equivalent pair: ``RunupRequest.model`` is the one door of the run-up room.
"""

from __future__ import annotations

import itertools
import math
from typing import Annotated, Literal

from pydantic import BaseModel, BeforeValidator, Field, PrivateAttr, WithJsonSchema, model_validator
from pydantic_core import InitErrorDetails

from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.model.errors import Problems
from gearengine.model.params import request_config
from gearengine.model.reduction import DesignConversion, ParamsOrDesign
from gearengine.model.units import (
    QUANTITIES,
    RPM,
    Duration,
    MeanTorque,
    Time,
    parse_quantity,
    quantity_type,
    registry,
)
from gearengine.numerics.settings import SimulationSettings
from gearengine.systems.base import System
from gearengine.systems.designs import design_model
from gearengine.systems.spur_pair.system import SpurPair

MAX_RUNUP_STEPS = 200_000_000
"""Cap on the RK4 steps of one run-up (every ensemble member, the quasi-static sweep aside)."""
MAX_PROFILE_POINTS = 1000
"""Most [time, speed] points of a profile."""
MAX_ENSEMBLE = 64
"""Most ensemble members (slightly perturbed starts) of the finite-time Lyapunov exponent."""


def _positive_rate(value: object) -> float:
    """A rate of change of speed with its unit: > 0 (the direction says up or down), then
    plausible."""
    kind = QUANTITIES["speed_rate"]
    try:
        return parse_quantity(value, kind, field="rate", unit_required=True)
    except ValueError:
        magnitude = value
        if isinstance(value, str):
            try:
                magnitude = registry().Quantity(value.strip()).magnitude
            except Exception:  # pint's own errors: parse_quantity's message says it all
                raise ValueError(f"cannot read {value!r}; write e.g. {kind.example!r}") from None
        number = isinstance(magnitude, (int, float)) and not isinstance(magnitude, bool)
        if number and magnitude <= 0:  # type: ignore[operator]
            raise ValueError(
                f"the rate must be positive, got {value!r}: the direction (up, down, up_down) "
                "says which way the speed goes"
            ) from None
        raise


SpeedRate = Annotated[
    float,
    BeforeValidator(_positive_rate),
    WithJsonSchema(
        {
            "type": "string",
            "examples": ["1000 rpm/s"],
            "description": "rate of change of the driver speed: a string with a unit (e.g. "
            "'1000 rpm/s', '100 rad/s^2'); positive (direction says up or down)",
        }
    ),
]
RunupSpeed = quantity_type("speed", unit_required=True)
"""A run-up's speed: a string with a unit ("500 rpm"), a bare number refused."""

RunupDirection = Literal["up", "down", "up_down"]


class Ensemble(BaseModel):
    """The slightly perturbed starts of the finite-time Lyapunov exponent."""

    model_config = request_config()

    size: int = Field(8, ge=1, le=MAX_ENSEMBLE, description="Members (the nominal start first).")
    perturbation: float = Field(
        1e-6, gt=0.0, le=1e-2, description="Standard deviation of the start perturbation of "
        "x and x' (units of b and b w_n)."
    )  # fmt: skip
    seed: int = Field(0, ge=0, description="Seed of numpy.random.default_rng.")


DEFAULT_BIN_RPM = 50.0
"""Width of a speed bin unless the request gives one [rpm]."""
MIN_BINS = 4
"""Fewest bins a profile's speed range is read in (unless they are no wider than the default)."""

QUASI_STATIC_SETTINGS = {"transient_periods": 60, "record_periods": 40, "steps_per_period": 128}
"""Settings of each point of the quasi-static continuation sweep unless the request gives them."""


class RunupRequest(ParamsOrDesign):
    """A run-up, run-down or both of a design through a range of driver speeds."""

    model_config = request_config(
        {
            "design": EXAMPLE_DESIGN,
            "from_speed": "500 rpm",
            "to_speed": "6000 rpm",
            "rate": "1000 rpm/s",
            "direction": "up_down",
            "bin_rpm": 50,
        }
    )

    from_speed: RunupSpeed | None = Field(None, description="Lower speed of a linear ramp.")
    to_speed: RunupSpeed | None = Field(None, description="Upper speed of a linear ramp.")
    rate: SpeedRate | None = Field(None, description="Ramp rate (give rate or duration).")
    duration: Duration | None = Field(None, description="Duration of each leg of the ramp.")
    direction: RunupDirection = Field("up", description="up, down, or up then down.")
    points: (
        Annotated[
            list[Annotated[tuple[Time, RunupSpeed], Field(strict=False)]],
            Field(min_length=2, max_length=MAX_PROFILE_POINTS),
        ]
        | None
    ) = Field(
        None,
        description="Instead of a ramp: [[time, speed], ...], times increasing from 0, speed "
        "linear in between; rising stretches are read as up, falling ones as down.",
        examples=[[["0 s", "500 rpm"], ["3 s", "6000 rpm"], ["5 s", "2000 rpm"]]],
    )
    to_torque: MeanTorque | None = Field(
        None, description="Torque at the end of the profile (linear in time from the design's)."
    )
    bin_rpm: float = Field(
        DEFAULT_BIN_RPM, gt=0.0, le=10_000.0, allow_inf_nan=False, description="Width of a "
        f"speed bin [rpm]; at most a quarter of the profile's speed range ({MIN_BINS} bins), or "
        f"{DEFAULT_BIN_RPM:g} rpm where that is wider."
    )  # fmt: skip
    steps_per_period: int = Field(
        64, ge=16, le=1000, description="RK4 steps per period of the fastest of the natural "
        "frequency and the excitations, at the segment's top speed."
    )  # fmt: skip
    settle_periods: int = Field(
        100, ge=0, le=100_000, description="Mesh periods at the start speed before the ramp."
    )
    ensemble: Ensemble = Field(default_factory=Ensemble)
    quasi_static: SimulationSettings = Field(
        default_factory=lambda: SimulationSettings(**QUASI_STATIC_SETTINGS),  # type: ignore[arg-type]
        description="Settings of each point of the quasi-static continuation sweep (bin "
        "centres); its starts are the loop's own (the members' start, then where the first line "
        "ended): initial_state, initial_states and random_initial_states are refused here.",
    )
    label: str | None = Field(None, max_length=200, description="The client's name for it.")

    TRAINS = True  # a train design runs as its System (model)

    _model: tuple[System, DesignConversion] | None = PrivateAttr(None)

    @model_validator(mode="after")
    def _carry_model(self) -> RunupRequest:
        """Build what the members integrate once, when the request is validated (as
        ``analysis.AnalysisRequest`` carries its system): the budget check, the plan of every
        chunk and the reading all read it from here (``model``)."""
        if self.design is None:
            return self
        if self.design.train is None:
            assert self.conversion is not None
            self._model = SpurPair(self.conversion.params), self.conversion
            return self
        model, conversion = design_model(self.design)
        assert isinstance(model, System)
        self._model = model, conversion
        return self

    def model(self) -> tuple[System, DesignConversion]:
        """(the system the members integrate, the conversion whose scales read them): the
        pair of Eq. (9) and the design's conversion, or a train's ``TrainSystem`` and its
        equivalent pair's (I_a = I_m + I_p, I_b = I_g + I_l), built once when the request
        was validated (the pair's conversion the one ``ParamsOrDesign.conversion`` made)."""
        assert self.design is not None and self._model is not None
        return self._model

    def leg_seconds(self) -> float:
        """Duration of one leg of a linear ramp [s]."""
        assert self.from_speed is not None and self.to_speed is not None
        if self.duration is not None:
            return self.duration
        assert self.rate is not None
        return (self.to_speed - self.from_speed) / self.rate

    def knots(self) -> list[tuple[float, float]]:
        """The profile as [(time s, speed rad/s)], linear in between."""
        if self.points is not None:
            return [(float(t), float(w)) for t, w in self.points]
        lo, hi, leg = self.from_speed, self.to_speed, self.leg_seconds()
        assert lo is not None and hi is not None
        return {
            "up": [(0.0, lo), (leg, hi)],
            "down": [(0.0, hi), (leg, lo)],
            "up_down": [(0.0, lo), (leg, hi), (2.0 * leg, lo)],
        }[self.direction]

    def speed_range(self) -> tuple[float, float]:
        """Lowest and highest speed of the profile [rad/s]."""
        speeds = [w for _, w in self.knots()]
        return min(speeds), max(speeds)

    def duration_s(self) -> float:
        """Length of the profile [s]."""
        return self.knots()[-1][0]


def request_errors(request: RunupRequest) -> list[InitErrorDetails]:
    """Checks across fields, as pydantic error details naming each field: a design with the
    piecewise law, one profile (points, or from/to with rate or duration), ordered speeds and
    times (the work budget is ``profile.checked_runup``'s), all before any compute."""
    problems = Problems("runup")
    add, errors = problems.add, problems.details

    design = request.design
    if design is None:
        add(("design",), "a run-up needs a design in physical units (its time scale)", None)
    elif design.backlash_law != "piecewise":
        add(("design", "backlash_law"), "run-ups integrate the piecewise law (Eq. 6)",
            design.backlash_law)  # fmt: skip
    ramp = {"from_speed": request.from_speed, "to_speed": request.to_speed,
            "rate": request.rate, "duration": request.duration}  # fmt: skip
    if request.points is not None:
        for name, value in ramp.items():
            if value is not None:
                add((name,), "give points or a ramp (from_speed, to_speed, rate), not both", value)
        if request.direction != "up":
            add(("direction",), "a points profile says its own direction", request.direction)
        times = [t for t, _ in request.points]
        if times[0] != 0.0 or any(b <= a for a, b in itertools.pairwise(times)):
            add(("points",), "times must start at 0 s and increase", times)
    else:
        for name in ("from_speed", "to_speed"):
            if ramp[name] is None:
                add((name,), "give from_speed and to_speed (or points)", None)
        lo, hi = request.from_speed, request.to_speed
        if lo is not None and hi is not None and not lo < hi:
            add(("to_speed",), "must be above from_speed (direction down runs down)", hi)
        if (request.rate is None) == (request.duration is None):
            add(("rate",), "give rate or duration (one of them)", request.rate)
    if not errors:  # a profile to read the speed range of
        lo, hi = (w / RPM for w in request.speed_range())
        widest = widest_bin_rpm(lo, hi)
        if request.bin_rpm > widest:
            add(("bin_rpm",), f"a bin of {request.bin_rpm:g} rpm is wider than a quarter of the "
                f"profile's {lo:g}-{hi:g} rpm range ({MIN_BINS} bins at least): a bin's FTLE and "
                "extremes are over its whole width, so chaos in part of it vanishes; give at "
                f"most {widest:g} rpm (the CLI's --bin)", request.bin_rpm)  # fmt: skip
    for name, value in ignored_starts(request.quasi_static).items():
        add(("quasi_static", name), "the quasi-static loop starts where the members start, its "
            "second line where the first ended: a start given here would not be used; remove "
            "it", value)  # fmt: skip
    return errors


def ignored_starts(settings: SimulationSettings) -> dict[str, object]:
    """The starts ``settings`` give other than the default ``initial_state``: the quasi-static
    loop replaces them with its own (``compute.quasi_static_loop``)."""
    default = SimulationSettings.model_fields["initial_state"].get_default(
        call_default_factory=True)  # fmt: skip
    given = {"initial_state": None if settings.initial_state == default else
             settings.initial_state, "initial_states": settings.initial_states,
             "random_initial_states": settings.random_initial_states}  # fmt: skip
    return {name: value for name, value in given.items() if value is not None}


def widest_bin_rpm(lo_rpm: float, hi_rpm: float) -> float:
    """The widest bin [rpm] a run-up over ``lo_rpm``..``hi_rpm`` [rpm] accepts: ``MIN_BINS``
    bins over the range, or the default bin where that is wider (a narrow profile)."""
    return max(DEFAULT_BIN_RPM, (hi_rpm - lo_rpm) / MIN_BINS)


def n_bins(lo_rpm: float, hi_rpm: float, width: float) -> int:
    """Bins of ``width`` rpm from ``lo_rpm`` covering ``hi_rpm`` (the last one may be short)."""
    return max(1, math.ceil((hi_rpm - lo_rpm) / width - 1e-9))
