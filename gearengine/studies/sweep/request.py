"""Parameter sweeps of Eq. (9): bifurcation diagrams (one axis) and 2-D chaos maps (two axes).

A sweep is a grid of parameter points, each a copy of ``params`` with the axes' aliases set
(``F_e1``, ``mu``, ``Omega_e``, ...). Points are enumerated with the first axis fastest and split
into chunks, the unit of work of the job queue. Chunk i depends only on (request, i, chunk size),
so a chunk computed twice gives the same bytes and an interrupted sweep resumes exactly.

With ``continuation`` a chunk is a whole line along the first axis, integrated point by point,
each point starting from the previous point's final state; ``direction`` runs each line forward
(start -> stop, branch "up"), backward (stop -> start, branch "down") or both, each branch from
the settings' initial state at its own end. Without continuation every point starts from the
settings' initial states and points of a chunk run together in ``simulate_batch``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from typing import Annotated, Literal

import numpy as np
from pydantic import BaseModel, Field, PlainValidator, ValidationError, WithJsonSchema
from pydantic_core import InitErrorDetails

from gearengine.model.design import Design
from gearengine.model.errors import Problems
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.fields import is_integer_field, si_value
from gearengine.model.params import GearParams, WholeNumber, request_config
from gearengine.model.reduction import ParamsOrDesign
from gearengine.model.units import Scales
from gearengine.model.units.quantities import NUMBER
from gearengine.numerics.settings import RequestSettings, SimulationSettings
from gearengine.studies.sweep.axes import (
    axis_problem,
    changes_nothing,
    is_dimensionless,
    point_model,
    scaled_point,
)
from gearengine.systems.base import System

MAX_AXIS_POINTS = 100_000
"""Upper cap of ``num`` of one axis (the service caps the product lower, max_job_points)."""


def _axis_value(value: object) -> float | str:
    """A finite number, or a string (a quantity with a unit, parsed against the design)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ValueError("give a number, or a string with a unit such as '500 rpm'")
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError("Input should be a finite number")
    return value if isinstance(value, str) else float(value)


AxisValue = Annotated[
    float | str,
    PlainValidator(_axis_value),
    WithJsonSchema({"anyOf": [{"type": "number"}, {"type": "string", "examples": ["500 rpm"]}]}),
]
"""An axis end: a number (dimensionless, or SI for a physical field) or a string with a unit."""

SweepOutput = Literal[
    "classification", "period", "lle", "lle_stderr", "impact_regime", "melnikov_chaos_possible",
    "poincare_x", "x_peak_to_peak", "periods_run", "force_max", "force_min", "physical",
    "dimensionless", "attractors", "basins", "coexisting",
]  # fmt: skip
"""A field of ``SweepPoint`` a sweep may keep (``SweepRequest.outputs``)."""

SweepBranch = Literal["up", "down"]
"""A line of a continuation sweep: up (run start -> stop) or down (stop -> start)."""
Direction = Literal["forward", "backward", "both"]


class SweepAxis(BaseModel):
    """One axis: ``num`` equally spaced values of a parameter from ``start`` to ``stop``."""

    model_config = request_config()

    parameter: str = Field(
        min_length=1,
        max_length=100,
        pattern=r"^[A-Za-z_][A-Za-z0-9_.]*$",
        description="A dimensionless alias of Eq. (9) (mu, F_m, k_p1, F_e1, F_p1, Omega_k, "
        "Omega_e, Omega_p), Omega (every excitation frequency scaled together), or with a "
        "design a physical field: speed, torque, mesh.half_backlash, mesh.damping_ratio, "
        "transmission_error.harmonics.0.amplitude, ... (see gearengine.studies.sweep.axes).",
        examples=["F_e1", "speed"],
    )
    start: AxisValue = Field(
        description="First value: a number (dimensionless, or SI for a physical field) or a "
        "string with a unit ('500 rpm').",
        examples=[0.0, "500 rpm"],
    )
    stop: AxisValue = Field(description="Last value, as start.", examples=[0.3, "6000 rpm"])
    num: WholeNumber = Field(
        ge=1,
        le=MAX_AXIS_POINTS,
        description=f"Number of values, start and stop included (1..{MAX_AXIS_POINTS}).",
        examples=[301],
    )

    def count_problem(self) -> tuple[str, str] | None:
        """(field, why) when the points do not span the range: stop equal to start with
        ``num`` > 1, or one point over a range, which is its start alone (``check --speed
        1000:6000 --speed-points 1`` passed on 1,000 rpm, 6,000 unsaid); else None."""
        if self.num > 1 and self.stop == self.start:
            return "stop", ("stop equals start, which is one value: give 1 point (num 1; "
                            "--speed-points 1 or --torque-points 1 on the command line), or a "
                            "stop that differs for several")  # fmt: skip
        if self.num == 1 and self.stop != self.start:
            return "num", (f"1 point over {self.start}:{self.stop} is its start alone: give at "
                           "least 2 points, or stop equal to start for one point")  # fmt: skip
        return None

    def values(self, design: Design | None = None) -> list[float]:
        """The ``num`` values, start to stop (``numpy.linspace``), in SI units for a physical
        field of ``design``. A physical axis whose ends are written in one unit is spaced in
        that unit ("1000 rpm" to "6000 rpm": in rpm), each inner value taken as the decimal it
        shows (15 significant digits) and converted as that value alone would be: a point is
        the same float on every grid it is on (4750 rpm of 1000:6000 in 5 points was one ulp
        from a one-point axis at 4750 rpm, and its robustness counts could differ)."""
        lo, hi = self.start, self.stop
        if is_dimensionless(self.parameter):
            return [float(v) for v in np.linspace(float(lo), float(hi), self.num)]
        assert design is not None
        (a, unit), (b, same) = _written(lo), _written(hi)
        if unit and unit == same:
            shown = _shown(np.linspace(a, b, self.num))
            return [si_value(design, self.parameter, f"{v!r} {unit}") for v in shown]
        lo, hi = (si_value(design, self.parameter, v) for v in (lo, hi))
        spaced = np.linspace(lo, hi, self.num)  # bare numbers (SI already), or two units
        return _shown(spaced) if unit == same == "" else [float(v) for v in spaced]


def _shown(spaced: np.ndarray) -> list[float]:
    """Evenly spaced values, each inner one as the decimal it shows (15 significant digits:
    3999.9999999999995 is 4000), the ends as given."""
    last = len(spaced) - 1
    return [float(v) if i in (0, last) else float(f"{v:.15g}") for i, v in enumerate(spaced)]


_WRITTEN = re.compile(rf"\s*({NUMBER})\s*(.*?)\s*")


def _written(value: float | str) -> tuple[float, str | None]:
    """An axis end as (number, unit as written): a bare number's unit is SI (""), a string's
    the text after its number; None for a string that does not start with a number."""
    if not isinstance(value, str):
        return float(value), ""
    found = _WRITTEN.fullmatch(value)
    return (0.0, None) if found is None else (float(found.group(1)), found.group(4))


class SweepRequest(ParamsOrDesign):
    """A bifurcation diagram (one axis) or a chaos map (two axes) of the design ``params``."""

    TRAINS = True  # a train design runs as its System at every point (studies.sweep.axes)

    model_config = request_config(
        {
            "params": PAPER_SECTION_41,
            "settings": {"transient_periods": 500, "record_periods": 500},
            "axes": [{"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 301}],
            "continuation": False,
            "direction": "forward",
        }
    )
    model_config["json_schema_extra"] |= {  # as request_errors checks: backward needs continuation
        "if": {"required": ["direction"],
               "properties": {"direction": {"enum": ["backward", "both"]}}},
        "then": {"required": ["continuation"], "properties": {"continuation": {"const": True}}},
    }  # fmt: skip

    settings: RequestSettings = Field(
        default_factory=SimulationSettings,
        description="Integration settings of every point (periods, steps, initial states).",
    )
    axes: list[SweepAxis] = Field(
        min_length=1,
        max_length=2,
        description="One axis: bifurcation diagram; two axes: chaos map (first axis fastest).",
    )
    continuation: bool = Field(
        False,
        description="Carry the final state [x, v] from point to point along the first axis; "
        "on a one-axis sweep also locate the bifurcation points (result: bifurcations).",
    )
    direction: Direction = Field(
        "forward",
        description="With continuation: forward (start -> stop), backward, or both (exposes "
        "hysteresis; points carry branch up or down).",
    )
    label: str | None = Field(
        None,
        max_length=200,
        description="The client's name for the sweep, shown in job listings; not computed on.",
        examples=["stage 1: F_e1 at 1500 rpm"],
    )
    outputs: Annotated[list[SweepOutput], Field(min_length=1)] | None = Field(
        None,
        description="The point fields to keep (values and branch are always kept); null keeps "
        "every field. Leaving out poincare_x makes a map's result about 30 times smaller.",
        examples=[["classification", "period", "lle"]],
    )

    def branches(self) -> list[SweepBranch]:
        """Branches run along the first axis: up (forward), down (backward) or both."""
        return {"forward": ["up"], "backward": ["down"], "both": ["up", "down"]}[self.direction]

    def n_points(self) -> int:
        """Number of computed points, every branch counted."""
        return math.prod(a.num for a in self.axes) * len(self.branches())

    def grids(self) -> list[list[float]]:
        """Each axis' values (SI units for physical fields)."""
        return [a.values(self.design) for a in self.axes]

    def point(self, values: dict[str, float]) -> GearParams | System:
        """What the numerics run at one grid point (``studies.sweep.axes.point_model``): its
        parameters of Eq. (9), or for a design with a train its ``System``."""
        assert self.params is not None
        return point_model(self.params, self.design, values)

    def scaled_point(self, values: dict[str, float]) -> tuple[GearParams | System, Scales | None]:
        """What runs at one grid point and, for a design, its scales
        (``studies.sweep.axes.scaled_point``)."""
        assert self.params is not None
        scales = None if self.conversion is None else self.conversion.scales
        return scaled_point(self.params, self.design, scales, values)


def request_errors(request: SweepRequest, max_points: int | None = None) -> list[InitErrorDetails]:
    """Checks across fields that pydantic cannot express, as pydantic error details.

    Distinct axis parameters, points that span their range (``SweepAxis.count_problem``),
    direction only with continuation,
    the point count under ``max_points``, and every corner of the grid a valid design (the
    admissible set of each alias is an interval, so the corners decide).
    """
    problems = Problems("sweep")
    add, errors = problems.add, problems.details

    for i, axis in enumerate(request.axes):
        if (problem := axis.count_problem()) is not None:
            add(("axes", i, problem[0]), problem[1], getattr(axis, problem[0]))
        if i and axis.parameter in [a.parameter for a in request.axes[:i]]:
            add(("axes", i, "parameter"), f"{axis.parameter} is already swept", axis.parameter)
    if request.direction != "forward" and not request.continuation:
        add(("direction",), "backward and both need continuation: true", request.direction)
    if max_points is not None and request.n_points() > max_points:
        add(
            ("axes",),
            f"{request.n_points()} points, over the limit of {max_points} per sweep "
            "(max_job_points)",
            [a.num for a in request.axes],
        )
    if errors:
        return errors
    for i, axis in enumerate(request.axes):
        problem = axis_problem(request.params, request.design, axis.parameter, axis.start,
                               axis.stop, {})  # fmt: skip
        if problem is not None:
            add(("axes", i, problem[0]), problem[1], getattr(axis, problem[0]))
    if errors:
        return errors
    grids = request.grids()
    for i, (axis, grid) in enumerate(zip(request.axes, grids, strict=True)):
        integer = request.design is not None and is_integer_field(request.design, axis.parameter)
        if integer and not all(float(v).is_integer() for v in grid):
            add(("axes", i, "num"), f"{axis.parameter} is an integer: choose num so that "
                "(stop - start) / (num - 1) is a whole number", axis.num)  # fmt: skip
    if errors:
        return errors
    for own in (True, False):  # each axis on the design alone first: no other axis blamed
        base = {} if own else {a.parameter: g[0] for a, g in zip(request.axes, grids, strict=True)}
        for i, (axis, grid) in enumerate(zip(request.axes, grids, strict=True)):
            model = _corner_problems(request, i, axis, grid, base, add)
        if errors:
            return errors
    for i, axis in enumerate(request.axes):
        if not errors and request.continuation and isinstance(model, System) and model.n > 2:
            add(("continuation",), f"continuation carries the final state [x, v] from point to "
                f"point; the {model.name.replace('_', ' ')} has {model.n} coordinates, whose full "
                "state it does not carry yet: set continuation false", True)  # fmt: skip
            return errors
        if axis.num > 1 and not errors and _changes_nothing(request, i, grids):
            add(("axes", i, "parameter"), f"{axis.parameter} changes nothing in Eq. (9) for this "
                "design (its excitation has no nonzero harmonic?)", axis.parameter)  # fmt: skip
    return errors


def _corner_problems(
    request: SweepRequest,
    i: int,
    axis: SweepAxis,
    grid: list[float],
    base: dict[str, float],
    add: Callable,
) -> GearParams | System | None:
    """Check axis ``i`` at both ends of its ``grid`` (and at 0 when a physical range passes
    through it: a load's admissible set may exclude 0 alone) with the other axes at ``base``,
    adding each problem; the model at its last end checked."""
    ends = [("start", grid[0]), ("stop", grid[-1])]
    if request.design is not None and grid[0] * grid[-1] < 0.0:
        ends.append(("through 0", 0.0))
    model = None
    for end, value in ends:
        try:
            model = request.point({**base, axis.parameter: value})
        except ValidationError as exc:
            e = exc.errors(include_url=False)[0]
            where = ".".join(map(str, e["loc"]))
            add(("axes", i, "start" if end == "through 0" else end),
                f"gives an invalid design: {where}: {e['msg']}", value)  # fmt: skip
        except ValueError as exc:
            if end == "through 0":
                add(("axes", i, "start"), f"the range from {axis.start} to {axis.stop} passes "
                    f"through 0, where the design is invalid ({exc}): sweep each side of 0 on "
                    "its own", axis.start)  # fmt: skip
            elif is_dimensionless(axis.parameter):  # an alias this model has not at all
                add(("axes", i, "parameter"), str(exc), axis.parameter)
            else:  # a field of the design that cannot take this value
                add(("axes", i, end), f"gives an invalid design: {exc}", value)
            break
    return model


def _changes_nothing(request: SweepRequest, i: int, grids: list[list[float]]) -> bool:
    """Axis ``i`` leaves Eq. (9) unchanged at both ends of the other axis (if any)."""
    others = [(a.parameter, g) for k, (a, g) in enumerate(zip(request.axes, grids, strict=True))
              if k != i]  # fmt: skip
    ends = [{}] if not others else [{others[0][0]: v} for v in (others[0][1][0], others[0][1][-1])]
    name, grid = request.axes[i].parameter, grids[i]
    assert request.params is not None
    return all(
        changes_nothing(request.params, request.design, name, grid[0], grid[-1], base)
        for base in ends
    )


def checked(request: SweepRequest, max_points: int | None = None) -> SweepRequest:
    """``request`` if ``request_errors`` finds nothing; else ``ValidationError`` naming each
    field (the checks the API and the CLI share)."""
    errors = request_errors(request, max_points)
    if errors:
        raise ValidationError.from_exception_data("SweepRequest", errors)
    return request


def validated(data: object, max_points: int | None = None) -> SweepRequest:
    """Parse and check a sweep request document; raises ``ValidationError`` naming each field."""
    return checked(SweepRequest.model_validate(data), max_points)
