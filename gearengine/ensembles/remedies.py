"""Remedies: the smallest change of one design lever that makes a whole operating envelope pass.

A lever is a design field path, as in sweeps (``mesh.damping_ratio``,
``transmission_error.harmonics.0.amplitude``, ``mesh.half_backlash``, ...), searched from the
design's value v0 toward a far end v1 along v(t) = v0 + t (v1 - v0), t in [0, 1]. Two bounds per
lever:

* **Melnikov bound**: the smallest t after which the Melnikov criterion (paper Eqs. 20-24,
  ``homoclinic.thresholds.chaos_possible``) rules out a transverse homoclinic tangle at every
  envelope point. A guarantee for that mechanism only; a point where the criterion does not apply
  (``chaos_possible`` None: no saddle of the cubic fit, e.g. a load above the critical torque)
  counts as "not judged", never as a failure, and the summary says how many there were.
  Bisection to ``MELNIKOV_RTOL`` (microseconds a point).
* **Numerical bound**: the smallest t after which the gate (``sweeps.gate``: the same rules,
  settings and grid as ``gearengine check --speed --torque``) passes, by bisection with full
  envelope runs; the value returned is one that was run, and its report is attached.

Each search first samples the bracket (``SAMPLES`` values, v0 and v1 included). The lever is
called monotone when the samples switch from fail to pass exactly once; then bisection between
the last failing and the first passing sample is valid. Otherwise bisection still returns a
switch (the first one from v0), but other values may pass too: the remedy says the value found
is not unique. A lever whose samples never pass is ``unreachable`` (with the range searched and
the failures at its far end). When no single lever clears the envelope, ``combination``
suggests two levers together, from a 3 x 3 grid of the two levers that left the fewest failing
points at their far ends.

A job of kind ``remedies`` (``gearengine.jobs``): one chunk per lever, and a last chunk for the
combination; a chunk depends only on (request, index).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)
from pydantic_core import InitErrorDetails, PydanticCustomError

from gearengine import jobs
from gearengine.homoclinic.thresholds import chaos_possible
from gearengine.jsonio import message
from gearengine.model.design import ACCURACY_FIELD, EXAMPLE_DESIGN, Design
from gearengine.model.params import request_config
from gearengine.model.reduction import convert_design
from gearengine.model.standards import iso1328
from gearengine.model.units import display_unit, in_display_unit
from gearengine.numerics.batch import threads_may_share_kernels
from gearengine.numerics.settings import SimulationSettings
from gearengine.sweeps.axes import design_with, field_value, si_value
from gearengine.sweeps.gate import (
    ENVELOPE_SETTINGS,
    EnvelopeReport,
    Rules,
    check_envelope,
    envelope_axis,
    envelope_sweep,
)
from gearengine.sweeps.plan import sweep_work
from gearengine.sweeps.request import SweepRequest, validated

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

    speed: str = Field(description="Driver speeds LOW:HIGH (rpm unless a unit is given).",
                       examples=["500:6000"])  # fmt: skip
    torque: str | None = Field(None, description="Mean driver torques LOW:HIGH (N*m unless a "
                               "unit is given); absent: the design's torque.",
                               examples=["2:40"])  # fmt: skip
    speed_points: int = Field(23, ge=1, le=200, description="Grid speeds (as the gate).")
    torque_points: int = Field(5, ge=1, le=50, description="Grid torques (as the gate).")


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

    model_config = request_config(
        {"design": EXAMPLE_DESIGN, "envelope": {"speed": "500:6000", "torque": "20:200"},
         "fail_on": ["chaotic"]}
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
    tolerance: float = Field(
        0.02, gt=0.0, le=0.2,
        description="Numerical bisection stops when its bracket is narrower than this fraction "
        "of the change (and of the value).",
    )  # fmt: skip

    @field_validator("settings", mode="before")
    @classmethod
    def _over_the_gates(cls, given: object) -> object:
        return {**ENVELOPE_SETTINGS, **given} if isinstance(given, dict) else given

    @model_validator(mode="after")
    def _checked(self) -> RemediesRequest:
        errors = request_errors(self)
        if errors:
            raise ValidationError.from_exception_data("RemediesRequest", errors)
        return self

    def rules(self) -> Rules:
        """The gate's rules of this request."""
        return Rules.model_validate(self.model_dump(include=set(Rules.model_fields)))

    def sweep(self, design: Design | None = None) -> SweepRequest:
        """The envelope's sweep of ``design`` (default: the request's)."""
        env = self.envelope
        axes = [envelope_axis("speed", env.speed, "rpm", env.speed_points)]
        if env.torque is not None:
            axes.append(envelope_axis("torque", env.torque, "N*m", env.torque_points))
        doc = envelope_sweep((design or self.design).model_dump(), self.settings.model_dump(),
                             axes, "remedies")  # fmt: skip
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
        """``si`` in the lever's display unit (``sweeps.axes.display_unit``)."""
        return in_display_unit(self.path, si)

    @property
    def unit(self) -> str:
        return display_unit(self.path)[0]

    @property
    def suffix(self) -> str:
        """ " um" after a value, nothing for a dimensionless lever."""
        return "" if self.unit == "1" else f" {self.unit}"


class Sample(BaseModel):
    """One value tried: whether the envelope passed (numerical) or chaos was ruled out."""

    model_config = ConfigDict(frozen=True)

    value: float = Field(description="In the remedy's unit.")
    passed: bool
    failing_points: int = Field(description="Points failing (numerical) or where the criterion "
                                "allows chaos (Melnikov).")  # fmt: skip


class Remedy(BaseModel):
    """The smallest change of one lever found to make the envelope pass."""

    model_config = ConfigDict(frozen=True, serialize_by_alias=True, validate_by_name=True)

    lever: str = Field(description="Design field path.")
    from_: float = Field(alias="from", description="The design's value, in unit.")
    to: float = Field(description="The remedy's value, in unit.")
    unit: str
    bound: Literal["numerical", "melnikov"]
    monotone: bool = Field(description="The bracket samples switch from fail to pass once; "
                           "else the value found is one switch, not unique.")  # fmt: skip
    bracket: list[float] = Field(description="[last failing value tried, to], in unit.")
    samples: list[Sample] = Field(description="The bracket samples, from the design's value.")
    not_applicable_points: int | None = Field(
        None, description="Melnikov: envelope points at ``to`` where the criterion does not "
        "apply (not judged; not failures).",
    )  # fmt: skip
    contact_ratio: float | None = Field(
        None, description="With gear geometry: the transverse contact ratio at ``to`` (a "
        "profile-shift lever moves it, and with it the stiffness variation)."
    )  # fmt: skip
    iso1328_class: list[int | None] | None = Field(
        None, description="A transmission-error lever of a design with gear geometry: [class at "
        "from, class at to], the coarsest ISO 1328-1:2013 flank tolerance class whose profile "
        "tolerances bound the mesh harmonic below the amplitude (null: none of 1-11 does)."
    )  # fmt: skip
    summary: str
    check: EnvelopeReport = Field(description="The envelope report of a run at ``to``.")


class Unreachable(BaseModel):
    """A lever with no value in its range that clears the envelope (by one bound)."""

    model_config = ConfigDict(frozen=True)

    lever: str
    bound: Literal["numerical", "melnikov"]
    searched: list[str] = Field(description="[from, far end] with units.")
    samples: list[Sample]
    why: str


class LeverSetting(BaseModel):
    """One lever's value in a combination."""

    model_config = ConfigDict(frozen=True, serialize_by_alias=True, validate_by_name=True)

    lever: str
    from_: float = Field(alias="from")
    to: float
    unit: str


class Combination(BaseModel):
    """Two levers changed together, when no single lever clears the envelope."""

    model_config = ConfigDict(frozen=True)

    levers: list[LeverSetting]
    how: str = Field(description="How it was found.")
    summary: str
    check: EnvelopeReport


class ChunkOutcome(BaseModel):
    """A chunk's result: a lever's remedies and unreachable bounds, or the combination."""

    model_config = ConfigDict(frozen=True)

    baseline: EnvelopeReport | None = Field(description="The design's own report (chunk 0).")
    passed_already: bool
    remedies: list[Remedy] = []
    unreachable: list[Unreachable] = []
    combination: Combination | None = None


class RemediesResult(BaseModel):
    """What to change, by how much, and the runs that prove it."""

    model_config = ConfigDict(frozen=True)

    passed_already: bool = Field(description="The design passes its envelope as it is.")
    answer: str = Field(description="The ranked answer in words.")
    remedies: list[Remedy] = Field(description="Ranked: smallest relative change first.")
    unreachable: list[Unreachable]
    combination: Combination | None = Field(
        description="Two levers together, only when no single lever clears the envelope."
    )
    check: EnvelopeReport | None = Field(
        description="The design's own envelope report (null only in a partial result without "
        "the first chunk)."
    )


# --- levers ---------------------------------------------------------------------------------


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
    errors: list[InitErrorDetails] = []

    def add(loc: tuple[str | int, ...], message: str, value: object) -> None:
        errors.append({"type": PydanticCustomError("remedies", message), "loc": loc,
                       "input": value})  # fmt: skip

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
        problem = _lever_problem(request.design, given)
        if problem is not None:
            add(("levers", i, problem[0]), problem[1], getattr(given, problem[0]))
    return errors


def contact_ratio(design: Design) -> float | None:
    """The transverse contact ratio of a design with gear geometry (None without)."""
    derived = convert_design(design).derived.get("contact_ratio")
    return None if derived is None else float(derived.value)


def iso1328_class(design: Design, amplitude: float) -> int | None:
    """The coarsest ISO 1328-1:2013 flank tolerance class (1-11) whose total profile tolerances
    of both gears bound the mesh-frequency transmission-error harmonic at or below ``amplitude``
    [m] (``iso1328.mesh_error_bound``); None when no class does or the standard does not apply
    (no geometry, or outside its range)."""
    gears = (design.driver, design.driven)
    if any(g.module is None or g.face_width is None for g in gears):
        return None
    for grade in range(11, 0, -1):
        try:
            profile = [iso1328.tolerances(grade, g.teeth, g.module * 1e3, g.face_width * 1e3)
                       .F_alpha for g in gears]  # type: ignore[operator]  # fmt: skip
        except ValueError:
            return None
        if iso1328.mesh_error_bound(*profile) * 1e-6 <= amplitude:
            return grade
    return None


def accuracy_classes(design: Design, lever: Lever, to: float) -> list[int | None] | None:
    """[class at from, class at to] of the transmission-error lever an accuracy class sets."""
    if lever.path != ACCURACY_FIELD or iso1328_class(design, float("inf")) is None:
        return None
    return [iso1328_class(design, lever.start), iso1328_class(design, to)]


def _lever_problem(design: Design, given: LeverRange) -> tuple[str, str] | None:
    """Why a user's lever cannot be searched, as (field, message), or None."""
    if given.lever.split(".")[0] in NOT_LEVERS:
        return "lever", f"{given.lever} is the envelope, not a lever"
    try:
        v0 = _current(design, given.lever)
    except (KeyError, IndexError, TypeError, ValueError):
        return "lever", f"the design has no numeric field {given.lever}"
    ends = []
    for k, bound in enumerate(given.bounds):
        try:
            ends.append(si_value(design, given.lever, bound))
        except ValidationError as exc:
            msg = "; ".join(message(e) for e in exc.errors(include_url=False))
            return "bounds", f"bounds[{k}]: {msg}"
    lo, hi = ends
    unit, factor = display_unit(given.lever)
    if not lo < hi:
        return "bounds", f"give [low, high] with low < high ({lo * factor:g} >= {hi * factor:g} "\
            f"{unit})"  # fmt: skip
    if not lo <= v0 <= hi:
        return "bounds", f"the design's {given.lever} = {v0 * factor:g} {unit} lies outside "\
            f"[{lo * factor:g}, {hi * factor:g}] {unit}"  # fmt: skip
    return None


# --- the two bounds ---------------------------------------------------------------------------


def envelope_points(request: RemediesRequest) -> list[dict[str, float]]:
    """The envelope's grid points as sweep values (SI), speed fastest as in the sweep."""
    sweep = request.sweep()
    names = [a.parameter for a in sweep.axes]
    grids = sweep.grids()
    rows = [[]] if len(grids) == 1 else [[(names[1], t)] for t in grids[1]]
    return [dict([(names[0], v), *row]) for row in rows for v in grids[0]]


def melnikov_failures(design: Design, points: list[dict[str, float]],
                      values: dict[str, float]) -> tuple[int, int]:  # fmt: skip
    """(points where the criterion allows chaos, points where it does not apply) over the
    envelope ``points`` of ``design`` with the fields ``values`` set (SI): each point's
    ``chaos_possible``, as the sweep's ``melnikov_chaos_possible``."""
    verdicts = [chaos_possible(convert_design(design_with(design, {**values, **p})).params)
                for p in points]  # fmt: skip
    return sum(v is True for v in verdicts), sum(v is None for v in verdicts)


def _search(test: Callable[[float], tuple[bool, int]], lever: Lever, samples: int,
            width: Callable[[float, float], bool], max_steps: int
            ) -> tuple[list[Sample], bool, tuple[float, float] | None]:  # fmt: skip
    """Bracket samples of v(t), monotone on them?, and [last failing, first passing] value (SI)
    after bisection (None when no sample passes). ``test(v) -> (passed, failing points)``."""
    ts = [k / (samples - 1) for k in range(samples)]
    results = [test(lever.at(t)) for t in ts]
    shown = [Sample(value=lever.shown(lever.at(t)), passed=r[0], failing_points=r[1])
             for t, r in zip(ts, results, strict=True)]  # fmt: skip
    passes = [r[0] for r in results]
    if not any(passes):
        return shown, False, None
    j = passes.index(True)
    monotone = j > 0 and all(passes[j:])
    if j == 0:
        return shown, monotone, (lever.at(0.0), lever.at(0.0))
    fail, good = lever.at(ts[j - 1]), lever.at(ts[j])
    for _ in range(max_steps):
        if width(fail, good):
            break
        mid = 0.5 * (fail + good)
        if test(mid)[0]:
            good = mid
        else:
            fail = mid
    return shown, monotone, (fail, good)


def _narrow(rtol: float, lever: Lever) -> Callable[[float, float], bool]:
    """Bracket [a, b] narrow enough: |b - a| <= rtol x min(|change|, |value|) (the change alone
    when the value is 0)."""

    def done(a: float, b: float) -> bool:
        change = abs(b - lever.start)
        scale = min(change, abs(b)) if b != 0 else change
        return abs(b - a) <= rtol * scale

    return done


def _words(path: str) -> str:
    """A lever's name in words: "damping ratio", "transmission error (harmonic 2)"."""
    names = {"damping_ratio": "damping ratio", "damping": "damping",
             "half_backlash": "half backlash", "profile_shift": "profile shift"}  # fmt: skip
    parts = path.split(".")
    if parts[-1] in names:
        gear = f"{parts[0]}'s " if parts[0] in ("driver", "driven") else ""
        return gear + names[parts[-1]]
    kind = {"transmission_error": "transmission error", "stiffness_harmonics":
            "stiffness variation", "torque_fluctuation": "torque fluctuation"}  # fmt: skip
    for part in parts:
        if part in kind:
            index = next((p for p in parts if p.isdigit()), "0")
            return kind[part] + ("" if index == "0" else f" (harmonic {int(index) + 1})")
    return path


def _change(lever: Lever, to: float) -> str:
    """ "raise the damping ratio from 0.05 to 0.071" """
    verb = "raise" if lever.end > lever.start else "lower"
    unit = lever.suffix
    return (f"{verb} the {_words(lever.path)} from {lever.shown(lever.start):.4g} to "
            f"{lever.shown(to):.4g}{unit}")  # fmt: skip


def _uniqueness(monotone: bool) -> str:
    return ("" if monotone else "; the response is not monotone on the bracket samples, so "
            "this is one switch from the design's value, not a unique bound")  # fmt: skip


def lever_outcome(request: RemediesRequest, lever: Lever, baseline: EnvelopeReport
                  ) -> tuple[list[Remedy], list[Unreachable]]:  # fmt: skip
    """Both bounds of one lever."""
    rules = request.rules()
    reports: dict[float, EnvelopeReport] = {lever.start: baseline}

    def run(value: float) -> EnvelopeReport:
        if value not in reports:
            design = design_with(request.design, {lever.path: value})
            reports[value] = check_envelope(request.sweep(design), rules)
        return reports[value]

    def numerical(value: float) -> tuple[bool, int]:
        report = run(value)
        return report.passed, report.failing_points

    points = envelope_points(request)

    def melnikov(value: float) -> tuple[bool, int]:
        possible, _ = melnikov_failures(request.design, points, {lever.path: value})
        return possible == 0, possible

    searched = [f"{lever.shown(v):g}{lever.suffix}" for v in (lever.start, lever.end)]
    remedies: list[Remedy] = []
    unreachable: list[Unreachable] = []
    for bound, test, samples, rtol, steps in (
        ("numerical", numerical, SAMPLES, request.tolerance, MAX_BISECTIONS),
        ("melnikov", melnikov, MELNIKOV_SAMPLES, MELNIKOV_RTOL, 60),
    ):
        shown, monotone, bracket = _search(test, lever, samples, _narrow(rtol, lever), steps)
        if bracket is None:
            unreachable.append(Unreachable(
                lever=lever.path, bound=bound, searched=searched, samples=shown,
                why=_why(bound, lever, shown, run(lever.end) if bound == "numerical" else None),
            ))  # fmt: skip
            continue
        fail, to = bracket
        if bound == "melnikov" and to == lever.start:
            continue  # the criterion rules chaos out already: no change needed for it
        report = run(to)
        blind = None
        if bound == "melnikov":
            blind = melnikov_failures(request.design, points, {lever.path: to})[1]
        remedies.append(Remedy(
            lever=lever.path, from_=lever.shown(lever.start), to=lever.shown(to),
            unit=lever.unit, bound=bound, monotone=monotone,
            bracket=[lever.shown(fail), lever.shown(to)], samples=shown,
            not_applicable_points=blind, check=report,
            contact_ratio=contact_ratio(design_with(request.design, {lever.path: to})),
            iso1328_class=accuracy_classes(request.design, lever, to),
            summary=_summary(bound, lever, to, monotone, report, blind),
        ))  # fmt: skip
    return remedies, unreachable


def _summary(bound: str, lever: Lever, to: float, monotone: bool, report: EnvelopeReport,
             blind: int | None) -> str:  # fmt: skip
    run = (f"the envelope check passes there ({report.points} points run)" if report.passed
           else f"the envelope check still fails there at {report.failing_points} of "
           f"{report.points} points")  # fmt: skip
    if bound == "numerical":
        return f"{_change(lever, to)}: {run}{_uniqueness(monotone)}"
    na = (f"; the criterion does not apply at {blind} of {report.points} points (no saddle "
          "under that load: not judged there)" if blind else "")  # fmt: skip
    return (f"{_change(lever, to)}: the Melnikov criterion rules out homoclinic chaos at every "
            f"envelope point{na}; {run}{_uniqueness(monotone)}")  # fmt: skip


def _why(bound: str, lever: Lever, samples: list[Sample], far: EnvelopeReport | None) -> str:
    values = ", ".join(f"{s.value:g}" for s in samples)
    if bound == "melnikov":
        return (f"the Melnikov criterion allows chaos somewhere in the envelope at every sampled "
                f"{_words(lever.path)} ({values}{lever.suffix})")  # fmt: skip
    assert far is not None
    return (f"no sampled {_words(lever.path)} ({values}{lever.suffix}) clears the envelope; at "
            f"{lever.shown(lever.end):g}{lever.suffix} {far.failing_points} of {far.points} points "
            "still fail")  # fmt: skip


# --- the job ----------------------------------------------------------------------------------


def _chunk(request: RemediesRequest, index: int, chunk_points: int = 1) -> str:
    """Chunk ``index``: lever ``index`` (both bounds), or the combination (the last chunk);
    chunk 0 also carries the design's own report."""
    levers = request_levers(request)
    baseline = check_envelope(request.sweep(), request.rules())
    out = ChunkOutcome(baseline=baseline if index == 0 else None, passed_already=baseline.passed)
    if baseline.passed:
        return out.model_dump_json()
    if index == len(levers):
        update = {"combination": combination(request, levers)}
    else:
        remedies, unreachable = lever_outcome(request, levers[index], baseline)
        update = {"remedies": remedies, "unreachable": unreachable}
    return out.model_copy(update=update).model_dump_json()


def combination(request: RemediesRequest, levers: list[Lever]) -> Combination | None:
    """Two levers together, when none clears the envelope alone at its far end: the two with
    the fewest failing points there (distinct fields), tried on a 3 x 3 grid of fractions of
    their ranges in order of total fraction; the first grid point that passes (None if none)."""
    rules = request.rules()
    far: list[tuple[int, Lever]] = []
    for lever in levers:
        report = check_envelope(request.sweep(design_with(request.design,
                                {lever.path: lever.end})), rules)  # fmt: skip
        if report.passed:
            return None
        far.append((report.failing_points, lever))
    ranked = [lev for _, lev in sorted(far, key=lambda f: f[0])]
    pair = [ranked[0], *(lev for lev in ranked[1:] if lev.path != ranked[0].path)][:2]
    if len(pair) < 2:
        return None
    grid = sorted(((s, t) for s in COMBINATION_GRID for t in COMBINATION_GRID),
                  key=lambda st: (st[0] + st[1], st[0]))  # fmt: skip
    for s, t in grid:
        values = {pair[0].path: pair[0].at(s), pair[1].path: pair[1].at(t)}
        report = check_envelope(request.sweep(design_with(request.design, values)), rules)
        if report.passed:
            settings = [LeverSetting(lever=lev.path, from_=lev.shown(lev.start),
                                     to=lev.shown(values[lev.path]), unit=lev.unit)
                        for lev in pair]  # fmt: skip
            return Combination(
                levers=settings,
                how="no single lever cleared the envelope at its far end; the two levers that "
                "left the fewest failing points there, on a 3 x 3 grid of 1/3, 2/3 and all of "
                "each range, the first passing in order of total change",
                summary=f"{_change(pair[0], values[pair[0].path])} and "
                f"{_change(pair[1], values[pair[1].path])}: the envelope check passes there",
                check=report,
            )
    return None


def assemble(request: RemediesRequest, chunks: list[str]) -> RemediesResult:
    """The ranked answer from the chunks' outcomes (any subset of them, for a partial result)."""
    outcomes = [ChunkOutcome.model_validate_json(text) for text in chunks]
    baseline = next((o.baseline for o in outcomes if o.baseline is not None), None)
    passed = any(o.passed_already for o in outcomes)
    remedies = sorted((r for o in outcomes for r in o.remedies), key=_cost)
    unreachable = [u for o in outcomes for u in o.unreachable]
    combo = next((o.combination for o in outcomes if o.combination is not None), None)
    if any(r.bound == "numerical" for r in remedies):
        combo = None  # a single lever clears it (past a far end that did not)
    if passed:
        words = "the design passes its envelope as it is"
    else:
        words = answer(remedies, unreachable, combo)
        points = envelope_points(request)
        possible, blind = melnikov_failures(request.design, points, {})
        if blind == len(points):
            words += ("; the Melnikov criterion does not apply at any envelope point (the load "
                      "is above its critical torque throughout), so it sets no bound")  # fmt: skip
        elif possible == 0:
            na = f" (it does not apply at {blind} of them)" if blind else ""
            words += (f"; the Melnikov criterion rules out homoclinic chaos at every envelope "
                      f"point already{na}, so it sets no bound")  # fmt: skip
    return RemediesResult(passed_already=passed, answer=words, remedies=remedies,
                          unreachable=unreachable, combination=combo,
                          check=baseline)  # fmt: skip


def _cost(r: Remedy) -> tuple[int, float]:
    """Numerical remedies first, then by relative change |to - from| / |from|."""
    return (r.bound != "numerical", abs(r.to - r.from_) / (abs(r.from_) or 1.0))


def answer(remedies: list[Remedy], unreachable: list[Unreachable],
           combo: Combination | None) -> str:  # fmt: skip
    """The ranked answer in words: each lever's numerical value, its Melnikov guarantee beside
    it, then what no value in range clears."""
    by_lever: dict[tuple[str, bool], dict[str, Remedy]] = {}
    for r in remedies:
        by_lever.setdefault((r.lever, r.to > r.from_), {})[r.bound] = r
    parts = []
    for found in by_lever.values():
        num, mel = found.get("numerical"), found.get("melnikov")
        first = num or mel
        assert first is not None
        unit = "" if first.unit == "1" else f" {first.unit}"
        words = _words(first.lever)
        verb = "raise" if first.to > first.from_ else "lower"
        text = f"{verb} the {words} from {first.from_:.4g}"
        if num is not None:
            text += f" to {num.to:.4g}{unit} (numerically"
            if num.iso1328_class is not None:
                grades = [str(c) if c else "finer than 1" for c in num.iso1328_class]
                text += f"; ISO 1328 class {grades[0]} -> {grades[1]}"
            text += ")" if num.monotone else "; not unique: the response is not monotone)"
        if mel is not None:
            outcome = "passes" if mel.check.passed else "still fails"
            text += (f"{' or' if num else ' to'} {mel.to:.4g}{unit} (Melnikov guarantee against "
                     f"homoclinic chaos; the envelope check {outcome} there)")  # fmt: skip
        parts.append(text)
    words = "; or ".join(parts) if parts else "no single lever clears the envelope"
    for u in unreachable:
        if u.bound == "numerical":
            words += f"; {_words(u.lever)} has no value in {u.searched[0]} to {u.searched[1]} "\
                "that clears the envelope"  # fmt: skip
    if combo is not None:
        words += f"; together: {combo.summary}"
    return words


def _work(request: RemediesRequest) -> int:
    """RK4 steps at most: per lever its samples, bisections and the Melnikov bound's run; the
    combination's far ends and grid; one baseline per chunk."""
    n = len(request_levers(request))
    runs = n * (1 + SAMPLES + MAX_BISECTIONS + 1) + 1 + n + len(COMBINATION_GRID) ** 2
    return runs * sweep_work(request.sweep())


REMEDIES_JOB = jobs.JobKind(
    name="remedies",
    request=RemediesRequest,
    chunk_points=1,
    chunk_counts=lambda request, size: [1] * (len(request_levers(request)) + 1),
    work=_work,
    compute_chunk=_chunk,
    assemble=assemble,
)
"""Remedies as a kind of job (``gearengine.jobs.KINDS``): one chunk per lever, then the
combination."""


def remedies(request: RemediesRequest, progress_callback: Callable[[int, int], None] | None = None,
             workers: int = 1) -> RemediesResult:  # fmt: skip
    """Every lever of ``request`` in this process (``jobs.run_local``)."""
    if not threads_may_share_kernels():
        workers = 1  # numba's workqueue layer: one kernel call at a time, or it aborts
    result = jobs.run_local("remedies", request, progress_callback, workers=workers)
    assert isinstance(result, RemediesResult)
    return result
