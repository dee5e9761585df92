"""A remedies request: the envelope, the gate's rules, the levers and their ranges, with
every check across fields before any compute (``request_errors``)."""

from __future__ import annotations

import math

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)
from pydantic_core import InitErrorDetails

from gearengine.gate.envelope import (
    ENVELOPE_SETTINGS,
    GATE_STARTS,
    envelope_axis,
    envelope_sweep,
    gate_settings,
)
from gearengine.gate.resolution import GRID_POINTS, MAX_REFINE_DEPTH, REFINE_DEPTH
from gearengine.gate.rules import Rules
from gearengine.jsonio import message
from gearengine.model import params
from gearengine.model.design import EXAMPLE_DESIGN, Design
from gearengine.model.errors import Problems
from gearengine.model.fields import field_value, si_value
from gearengine.model.params import request_config
from gearengine.model.units import display_unit, in_display_unit
from gearengine.numerics.settings import SimulationSettings, over_light
from gearengine.studies.sweep.request import SweepRequest, validated

SAMPLES = 5
"""Bracket samples of a numerical search (t = 0, 1/4, ..., 1), the monotonicity check."""
MELNIKOV_SAMPLES = 17
"""Bracket samples of a Melnikov search (cheap: no integration)."""
MAX_BISECTIONS = 12
"""Envelope runs of a numerical bisection at most (after the samples)."""
MELNIKOV_RTOL = 1e-6
"""Width of the final Melnikov bracket relative to the change (and to the value)."""
DAMPING_RATIO_MAX = 0.2
"""Far end of the damping-ratio lever: the top of what a lubricated steel mesh shows."""
DAMPING_FACTOR = 4.0
"""Far end of a damping lever given as a coefficient c: this many times the design's c."""
BACKLASH_RANGE_UM = (5.0, 200.0)
"""Half backlash searched, µm (both directions from the design's value)."""
MAX_LEVERS = 20
COMBINATION_GRID = (1 / 3, 2 / 3, 1.0)
"""Fractions of each lever's range tried together in the combination grid."""
ENVELOPE_AXES = ("speed", "torque")
NOT_LEVERS = ("speed", "torque", "braking_torque", "speed_range")
"""Design fields that are the envelope (or its scan), not a lever."""


class Envelope(BaseModel):
    """The operating envelope: driver speeds x mean torques, as ``gearengine check`` takes it."""

    model_config = request_config()
    model_config["json_schema_extra"] = {"if": params.given("torque_points"),
                                         "then": params.given("torque")}  # fmt: skip

    speed: str = Field(description="Driver speeds LOW:HIGH (rpm unless a unit is given).",
                       examples=["500:6000"])  # fmt: skip
    torque: str | None = Field(None, description="Mean driver torques LOW:HIGH (N*m unless a "
                               "unit is given); absent: the design's torque.",
                               examples=["2:40"])  # fmt: skip
    speed_points: int = Field(GRID_POINTS["speed"], ge=1, le=200,
                              description="Grid speeds (as the gate).")  # fmt: skip
    torque_points: int | None = Field(None, ge=1, le=50,
                                      description="Grid torques (as the gate, default "
                                      f"{GRID_POINTS['torque']}); only with torque.")  # fmt: skip
    refine: int = Field(
        REFINE_DEPTH, ge=0, le=MAX_REFINE_DEPTH,
        description="Halvings of the grid spacing where neighbours differ (verdict or attractor "
        "set) or a point is near a limit (as the gate's --refine); a remedy's value is verified "
        "on a 2x finer grid, refined one halving more (as finely as a check of a grid 2x finer "
        "again).",
    )  # fmt: skip

    @field_validator("torque_points")
    @classmethod
    def _over_torques(cls, num: int | None, info: ValidationInfo) -> int | None:
        """A torque grid needs its range: without ``torque`` the design's one torque is
        checked, and the count was ignored unsaid. None (the default, filled in by ``sweep``)
        is dumped as null, so that a request read back from its JSON (a worker's, the
        service's store) passes: the count 5 of the default was refused there."""
        if num is not None and info.data.get("torque") is None:
            raise ValueError(
                "counts the points of a torque range, and none is given (torque LOW:HIGH)"
            )
        return num


class LeverRange(BaseModel):
    """A user's lever: a design field path and the values it may take."""

    model_config = request_config()

    lever: str = Field(description="Design field path, as a sweep axis.",
                       examples=["mesh.half_backlash"])  # fmt: skip
    bounds: list[str | float] = Field(
        min_length=2, max_length=2,
        description="[low, high]: unit strings or SI numbers; the design's value must lie "
        "inside, and the search goes from it toward each bound.",
        examples=[["5 um", "200 um"]],
    )  # fmt: skip


class RemediesRequest(Rules):
    """A failing design, its envelope and the gate's rules: what to change, by how much."""

    model_config = request_config(  # 7 x 3 points, one lever: within a default job budget
        {"design": EXAMPLE_DESIGN, "fail_on": ["chaotic"],
         "envelope": {"speed": "500:6000", "torque": "20:200", "speed_points": 7,
                      "torque_points": 3},
         "levers": [{"lever": "mesh.damping_ratio", "bounds": [0.05, 0.3]}]}
    )  # fmt: skip

    design: Design = Field(description="The pair in physical units.")
    envelope: Envelope
    settings: SimulationSettings = Field(
        default_factory=lambda: SimulationSettings.model_validate(ENVELOPE_SETTINGS),
        description="Integration settings of every envelope run, merged over the gate's light "
        "settings (as a design file's settings in gearengine check).",
    )
    levers: list[LeverRange] | None = Field(
        None, max_length=MAX_LEVERS,
        description="Levers to search instead of the default ones (damping, transmission error, "
        "half backlash down and up, stiffness variation, torque fluctuation).",
    )  # fmt: skip
    starts: int | None = Field(
        None, ge=1, le=1024,
        description="Basin starts per operating point, as the gate's --starts (default: the "
        f"gate's {GATE_STARTS}, or settings.basins; 1: the settings' own start only).",
    )  # fmt: skip
    tolerance: float = Field(
        0.02, gt=0.0, le=0.2,
        description="Numerical bisection stops when its bracket is narrower than this fraction "
        "of the change (and of the value).",
    )  # fmt: skip

    @field_validator("settings", mode="before")
    @classmethod
    def _over_the_gates(cls, given: object) -> object:
        return over_light(given)

    @model_validator(mode="after")
    def _checked(self) -> RemediesRequest:
        errors = request_errors(self)
        if errors:
            raise ValidationError.from_exception_data("RemediesRequest", errors)
        return self

    def rules(self) -> Rules:
        """The gate's rules of this request."""
        return Rules.model_validate(self.model_dump(include=set(Rules.model_fields)))

    def sweep(self, design: Design | None = None, finer: bool = False) -> SweepRequest:
        """The envelope's sweep of ``design`` (default: the request's); ``finer``: on the grid
        with half its spacing (2n - 1 points an axis), where a remedy is verified."""
        env = self.envelope

        def num(n: int) -> int:
            return 2 * n - 1 if finer else n

        axes = [envelope_axis("speed", env.speed, "rpm", num(env.speed_points))]
        if env.torque is not None:
            torques = GRID_POINTS["torque"] if env.torque_points is None else env.torque_points
            axes.append(envelope_axis("torque", env.torque, "N*m", num(torques)))
        settings = gate_settings(self.settings.model_dump(exclude_none=True), self.starts,
                                 self.min_basin)  # fmt: skip
        doc = envelope_sweep((design or self.design).model_dump(), settings, axes, "remedies")
        return SweepRequest.model_validate(doc)


class Lever(BaseModel):
    """One searched direction of a lever, SI values."""

    model_config = ConfigDict(frozen=True)

    path: str
    start: float
    end: float

    def at(self, t: float) -> float:
        """v(t) = v0 + t (v1 - v0)."""
        return self.start + t * (self.end - self.start)

    def shown(self, si: float) -> float:
        """``si`` in the lever's display unit (``model.units.display_unit``)."""
        return in_display_unit(self.path, si)

    @property
    def unit(self) -> str:
        return display_unit(self.path)[0]

    @property
    def suffix(self) -> str:
        """ " um" after a value, nothing for a dimensionless lever."""
        return "" if self.unit == "1" else f" {self.unit}"


def default_levers(design: Design) -> list[Lever]:
    """The levers every design has, in SI: damping up, each transmission-error, stiffness-
    variation and torque-fluctuation harmonic down to zero, half backlash down and up."""
    out: list[Lever] = []
    mesh = design.mesh
    if mesh.damping_ratio is not None and mesh.damping_ratio < DAMPING_RATIO_MAX:
        out.append(Lever(path="mesh.damping_ratio", start=mesh.damping_ratio,
                         end=DAMPING_RATIO_MAX))  # fmt: skip
    elif mesh.damping is not None and mesh.damping > 0:
        out.append(Lever(path="mesh.damping", start=mesh.damping,
                         end=DAMPING_FACTOR * mesh.damping))  # fmt: skip
    te, tf = design.transmission_error, design.torque_fluctuation
    out += _to_zero("transmission_error.harmonics", [] if te is None else te.harmonics)
    out += _to_zero("mesh.stiffness_harmonics", mesh.stiffness_harmonics or [])
    out += _to_zero("torque_fluctuation.harmonics", [] if tf is None else tf.harmonics)
    b = mesh.half_backlash
    for end in BACKLASH_RANGE_UM:
        if not math.isclose(b, end * 1e-6):
            out.append(Lever(path="mesh.half_backlash", start=b, end=end * 1e-6))
    return out


def _to_zero(prefix: str, harmonics: list) -> list[Lever]:
    return [Lever(path=f"{prefix}.{i}.amplitude", start=h.amplitude, end=0.0)
            for i, h in enumerate(harmonics) if h.amplitude > 0]  # fmt: skip


def request_levers(request: RemediesRequest) -> list[Lever]:
    """The request's levers (the user's, each split at the design's value), or the defaults."""
    if request.levers is None:
        return default_levers(request.design)
    out = []
    for given in request.levers:
        v0 = _current(request.design, given.lever)
        for bound in given.bounds:
            end = si_value(request.design, given.lever, bound)
            if not math.isclose(end, v0):
                out.append(Lever(path=given.lever, start=v0, end=end))
    return out


def _current(design: Design, path: str) -> float:
    """The design's number at ``path`` (SI); TypeError if the field is not a number."""
    value = field_value(design, path)
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        raise TypeError(f"{path} is not a number of the design")
    return float(value)


def request_errors(request: RemediesRequest) -> list[InitErrorDetails]:
    """The envelope and every user lever checked before any compute, as pydantic errors."""
    problems = Problems("remedies")
    add, errors = problems.add, problems.details

    env = request.envelope
    for name in ENVELOPE_AXES:
        text = getattr(env, name)
        if text is not None:
            try:
                envelope_axis(name, text, "rpm", 2)
            except ValueError as exc:
                add(("envelope", name), str(exc), text)
    if not errors:
        try:
            validated(request.sweep().model_dump())
        except ValidationError as exc:
            for e in exc.errors(include_url=False):
                loc = e["loc"]
                where = ENVELOPE_AXES[loc[1]] if loc[:1] == ("axes",) and len(loc) > 1 else None
                add(("envelope", where) if where else ("envelope",), e["msg"], e["input"])
    for i, given in enumerate(request.levers or []):
        problem = lever_problem(request.design, given)
        if problem is not None:
            where, text, value = problem
            add(("levers", i, *where), text, value)
    return errors


def lever_problem(design: Design, given: LeverRange) -> tuple[tuple, str, object] | None:
    """Why a user's lever cannot be searched, as (location in the lever, message, the value
    at fault), or None."""
    if given.lever.split(".")[0] in NOT_LEVERS:
        return ("lever",), f"{given.lever} is the envelope, not a lever", given.lever
    try:
        v0 = _current(design, given.lever)
    except (KeyError, IndexError, TypeError, ValueError):
        return ("lever",), f"the design has no numeric field {given.lever}", given.lever
    ends = []
    for k, bound in enumerate(given.bounds):
        try:
            ends.append(si_value(design, given.lever, bound))
        except ValidationError as exc:
            msg = "; ".join(message(e) for e in exc.errors(include_url=False))
            return ("bounds", k), msg, bound
    lo, hi = ends
    unit, factor = display_unit(given.lever)
    if not lo < hi:
        return ("bounds",), f"give [low, high] with low < high ({lo * factor:g} >= "\
            f"{hi * factor:g} {unit})", given.bounds  # fmt: skip
    if not lo <= v0 <= hi:
        return ("bounds",), f"the design's {given.lever} = {v0 * factor:g} {unit} lies "\
            f"outside [{lo * factor:g}, {hi * factor:g}] {unit}", given.bounds  # fmt: skip
    return None


# --- the two bounds ---------------------------------------------------------------------------
