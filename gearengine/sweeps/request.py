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
from typing import Literal

import numpy as np
from pydantic import BaseModel, Field, ValidationError
from pydantic_core import InitErrorDetails, PydanticCustomError

from gearengine.model.aliases import Alias, with_aliases
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.params import Finite, GearParams, request_config
from gearengine.numerics.settings import SimulationSettings

MAX_AXIS_POINTS = 100_000
"""Upper cap of ``num`` of one axis (the service caps the product lower, max_sweep_points)."""

SweepBranch = Literal["up", "down"]
"""A line of a continuation sweep: up (run start -> stop) or down (stop -> start)."""
Direction = Literal["forward", "backward", "both"]


class SweepAxis(BaseModel):
    """One axis: ``num`` equally spaced values of a parameter alias from ``start`` to ``stop``."""

    model_config = request_config()

    parameter: Alias = Field(
        description="Parameter alias: mu, F_m, k_p1, F_e1, F_p1, Omega_k, Omega_e or Omega_p "
        "(first-harmonic amplitudes and excitation frequencies, dimensionless).",
        examples=["F_e1"],
    )
    start: Finite = Field(description="First value (dimensionless).", examples=[0.0])
    stop: Finite = Field(description="Last value (dimensionless).", examples=[0.3])
    num: int = Field(
        ge=1,
        le=MAX_AXIS_POINTS,
        description=f"Number of values, start and stop included (1..{MAX_AXIS_POINTS}).",
        examples=[301],
    )

    def values(self) -> list[float]:
        """The ``num`` values, start to stop (``numpy.linspace``)."""
        return [float(v) for v in np.linspace(self.start, self.stop, self.num)]


class SweepRequest(BaseModel):
    """A bifurcation diagram (one axis) or a chaos map (two axes) of the design ``params``."""

    model_config = request_config(
        {
            "params": PAPER_SECTION_41,
            "settings": {"transient_periods": 500, "record_periods": 500},
            "axes": [{"parameter": "F_e1", "start": 0.0, "stop": 0.3, "num": 301}],
            "continuation": False,
            "direction": "forward",
        }
    )

    params: GearParams = Field(description="The design; the axes' parameters are overwritten.")
    settings: SimulationSettings = Field(
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
        description="Carry the final state [x, v] from point to point along the first axis.",
    )
    direction: Direction = Field(
        "forward",
        description="With continuation: forward (start -> stop), backward, or both (exposes "
        "hysteresis; points carry branch up or down).",
    )

    def branches(self) -> list[SweepBranch]:
        """Branches run along the first axis: up (forward), down (backward) or both."""
        return {"forward": ["up"], "backward": ["down"], "both": ["up", "down"]}[self.direction]

    def n_points(self) -> int:
        """Number of computed points, every branch counted."""
        return math.prod(a.num for a in self.axes) * len(self.branches())


def request_errors(request: SweepRequest, max_points: int | None = None) -> list[InitErrorDetails]:
    """Checks across fields that pydantic cannot express, as pydantic error details.

    Distinct axis parameters, stop != start when num > 1, direction only with continuation,
    the point count under ``max_points``, and every corner of the grid a valid design (the
    admissible set of each alias is an interval, so the corners decide).
    """
    errors: list[InitErrorDetails] = []

    def add(loc: tuple[str | int, ...], message: str, value: object) -> None:
        errors.append({"type": PydanticCustomError("sweep", message), "loc": loc, "input": value})

    for i, axis in enumerate(request.axes):
        if axis.num > 1 and axis.stop == axis.start:
            add(("axes", i, "stop"), "stop must differ from start when num > 1", axis.stop)
        if i and axis.parameter in [a.parameter for a in request.axes[:i]]:
            add(("axes", i, "parameter"), f"{axis.parameter} is already swept", axis.parameter)
    if request.direction != "forward" and not request.continuation:
        add(("direction",), "backward and both need continuation: true", request.direction)
    if max_points is not None and request.n_points() > max_points:
        add(
            ("axes",),
            f"{request.n_points()} points, over the limit of {max_points} per sweep "
            "(max_sweep_points)",
            [a.num for a in request.axes],
        )
    if errors:
        return errors
    base = {a.parameter: a.start for a in request.axes}
    for i, axis in enumerate(request.axes):
        for end in ("start", "stop"):
            value = getattr(axis, end)
            try:
                with_aliases(request.params, {**base, axis.parameter: value})
            except ValidationError as exc:
                e = exc.errors(include_url=False)[0]
                where = ".".join(map(str, e["loc"]))
                add(("axes", i, end), f"gives an invalid design: {where}: {e['msg']}", value)
            except ValueError as exc:
                add(("axes", i, "parameter"), str(exc), axis.parameter)
                break
    return errors


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
