"""The CI gate over an operating envelope: which grid points of a speed x torque sweep break
which rule (``gate.rules``), refined between grid points where neighbours differ or a point is
near a limit, gathered into failing speed windows per torque level (in words:
``gate.envelope_text``; the JUnit XML that GitHub, GitLab and Jenkins show: ``gate.junit``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Hashable, Sequence

from pydantic import BaseModel, ConfigDict, Field

from gearengine.gate.resolution import REFINE_DEPTH, Resolution, resolution
from gearengine.gate.resolution import refine as refine_points
from gearengine.gate.rules import Rules, attractor_failures, attractor_set, near_limit
from gearengine.model.units import POINT_OUTPUTS, with_unit
from gearengine.numerics.settings import ENVELOPE_SETTINGS
from gearengine.studies import jobs
from gearengine.studies.sweep.compute import points_at, run_local
from gearengine.studies.sweep.export import points_of_chunk
from gearengine.studies.sweep.plan import SweepPlan, balanced_chunk_points
from gearengine.studies.sweep.points import PhysicalValue, SpeedWindows, SweepPoint
from gearengine.studies.sweep.request import SweepRequest
from gearengine.studies.sweep.results import SweepResult
from gearengine.studies.sweep.windows import SPEED, runs, speed_windows

GATE_STARTS = 16
"""Basin starts per operating point of the gate unless ``--starts`` or the file's
``settings.basins`` say otherwise: a 4 x 4 grid over the default box (benchmarks/README.md has
its cost); ``--starts 1`` checks the settings' own start alone, as before basins."""


def gate_settings(settings: dict, starts: int | None, min_basin: float | None = None) -> dict:
    """The gate's settings with its basin starts: ``starts`` (a grid when it is a square, else
    random draws), else the file's basins, else ``GATE_STARTS``; ``starts`` 1 leaves basins
    out. ``min_basin`` (the rules'), when given, is the basins' ``min_fraction`` too: a point's
    verdict and the magnitudes it shows come from the attractors the gate checks (with the
    file's 0 a 10 % attractor's DTE was shown where --min-basin 0.2 passed the point)."""
    if starts is None:
        starts = None if settings.get("basins") is not None else GATE_STARTS
    if starts == 1:
        return {k: v for k, v in settings.items() if k != "basins"}
    basins = dict(settings.get("basins") or {})
    if starts is not None:
        basins.update(starts=starts, grid=math.isqrt(max(starts, 0)) ** 2 == starts)
    if min_basin is not None and basins:
        basins["min_fraction"] = min_basin
    return {**settings, "basins": basins} if basins else settings


def envelope_axis(name: str, text: str, unit: str, num: int) -> dict[str, object]:
    """A sweep axis from "A:B" (bare numbers in ``unit``) or "52rad/s:628rad/s".

    Raises ValueError for text that is not a range.
    """
    ends = text.split(":")
    if len(ends) != 2 or not all(e.strip() for e in ends):
        raise ValueError("give a range as LOW:HIGH (two values and a colon, e.g. 500:6000)")
    lo, hi = (with_unit(e, unit) for e in ends)
    return {"parameter": name, "start": lo, "stop": hi, "num": num}


def envelope_sweep(design: object, settings: dict[str, object] | None,
                   axes: list[dict[str, object]], label: str) -> dict[str, object]:  # fmt: skip
    """The sweep document of an envelope check: ``axes`` (``envelope_axis``) of ``design``
    under ``settings`` merged over ``ENVELOPE_SETTINGS``."""
    return {"design": design, "settings": {**ENVELOPE_SETTINGS, **(settings or {})},
            "axes": axes, "label": label}  # fmt: skip


def check_envelope(
    request: SweepRequest,
    rules: Rules,
    progress_callback: Callable[[int, int], None] | None = None,
    workers: int = 1,
    refine: int = REFINE_DEPTH,
    refine_failing: bool = True,
) -> EnvelopeReport:
    """The gate's report of one envelope sweep, computed in this process (``sweep_here``),
    refined ``refine`` times between grid points where neighbours differ or a point is near a
    limit (``gate.resolution.refine``); ``refine_failing`` False skips the refinement when the
    grid fails already (only pass or fail needed: refining cannot make it pass)."""
    result = sweep_here(request, progress_callback, workers)
    return refined_report(request, result, rules, refine, refine_failing, workers)


def sweep_here(request: SweepRequest, progress_callback: Callable[[int, int], None] | None = None,
               workers: int = 1) -> SweepResult:  # fmt: skip
    """The envelope sweep computed in this process: ``workers`` threads,
    ``balanced_chunk_points`` down to one point per chunk, as the CLI gate runs it."""
    chunk = balanced_chunk_points(request.n_points(), workers, smallest=1)
    return run_local(request, progress_callback, chunk_points=chunk, workers=workers)


def check_or_failures(request: SweepRequest, rules: Rules, refine: int = REFINE_DEPTH,
                      first: Sequence[dict[str, float]] = ()
                      ) -> EnvelopeReport | list[SweepPoint]:  # fmt: skip
    """Pass or fail of an envelope sweep with the least work, where only that is needed (a
    bisection step): the chunks of ``check_envelope`` (one worker) one by one, those holding a
    grid point of ``first`` (values expected to fail) before the others, stopping at the first
    chunk with a failing point: its failing points are returned. A grid that passes is
    refined batch by batch, the points of ``first`` first, to the first batch with a failing
    point (``gate.resolution.refine``'s ``stop``): the refined points that failed are returned.
    A check that passes gives ``check_envelope``'s report (refined), the same bits: the same
    chunks and refined points, assembled alike."""
    job = jobs.kind("sweep")
    size = balanced_chunk_points(request.n_points(), 1, smallest=1)
    plan = SweepPlan(request, size)
    grids = request.grids()
    wanted = {tuple(v[a.parameter] for a in request.axes) for v in first}

    def expected(i: int) -> bool:
        return any(tuple(g[k] for g, k in zip(grids, ix, strict=True)) in wanted
                   for ix in plan.chunk(i).points)  # fmt: skip

    fails, near, kind = _judges(rules)
    text = request.model_dump_json()
    outputs = [""] * plan.n_chunks()
    for i in sorted(range(plan.n_chunks()), key=lambda i: not expected(i)):
        outputs[i] = jobs.compute_chunk_json("sweep", text, i, size)
        points = [SweepPoint.model_validate(p) for p in points_of_chunk(outputs[i])]
        failing = [p for p in points if fails(p)]
        if failing:
            return failing
    result = job.assemble(request, outputs)
    assert isinstance(result, SweepResult)
    grid = [p for p in result.points if p.branch != "down"]
    added = refine_points(request, grid, fails, near, refine, kind=kind, stop=fails, first=first)
    failing = [p for p in added if fails(p)]
    return failing or envelope_report(result, rules, added, resolution(request, refine, len(added)))


def fails_toward(request: SweepRequest, rules: Rules, refine: int,
                 at: Sequence[dict[str, float]]) -> bool:  # fmt: skip
    """Does the check of ``request`` (refined ``refine`` times) fail, as found from the grid
    cells holding the values ``at`` alone (points between grid points where a refinement
    failed before)? Their corners, then the way down toward each through the cells holding
    it while each is split (``gate.resolution.refine``'s ``first``). A failure so found fails
    the whole check: a failing corner fails the grid, and a refined point reached through
    split cells is one the check's refinement reaches when its grid passes (a cell is split
    on its own corners alone). False says nothing of the rest of the check."""
    names, grids = [a.parameter for a in request.axes], request.grids()

    def span(g: list[float], v: float) -> list[float]:  # the grid values either side of v
        return (
            g
            if len(g) == 1
            else next(
                g[k : k + 2]
                for k in range(len(g) - 1)
                if min(g[k], g[k + 1]) <= v <= max(g[k], g[k + 1])
            )
        )

    corners: list[dict[str, float]] = []
    for v in at:
        spans = [span(g, v[n]) for n, g in zip(names, grids, strict=True)]
        cell = [dict(zip(names, x, strict=True)) for x in itertools.product(*spans)]
        corners += [c for c in cell if c not in corners]
    points = points_at(request, corners)
    fails, near, kind = _judges(rules)
    if any(fails(p) for p in points):
        return True
    found = refine_points(request, points, fails, near, refine, kind=kind, stop=fails, first=at,
                          levels=False)  # fmt: skip
    return any(fails(p) for p in found)


def refined_report(request: SweepRequest, result: SweepResult, rules: Rules,
                   refine: int = REFINE_DEPTH, refine_failing: bool = True, workers: int = 1
                   ) -> EnvelopeReport:  # fmt: skip
    """The report of an envelope sweep's ``result`` (computed here or on a server), refined
    between its grid points in this process as ``check_envelope`` says, built once: the grid
    fails when one of its points does (``refine_failing`` False then leaves it unrefined)."""
    grid = [p for p in result.points if p.branch != "down"]
    fails, near, kind = _judges(rules)
    depth = 0 if not refine_failing and any(fails(p) for p in grid) else max(refine, 0)
    added = refine_points(request, grid, fails, near, depth, workers, kind)
    return envelope_report(result, rules, added, resolution(request, depth, len(added)))


def _judges(rules: Rules) -> tuple[Callable[[SweepPoint], bool], Callable[[SweepPoint], bool],
                                   Callable[[SweepPoint], Hashable]]:  # fmt: skip
    """What the refinement (``gate.resolution.refine``) reads of a point under ``rules``: does
    it fail (``attractor_failures``), is it near a limit (``near_limit``), and its attractor
    set (``attractor_set``), for the report, a bisection step and ``fails_toward`` alike."""
    return (lambda p: bool(attractor_failures(p, rules)), lambda p: near_limit(p, rules),
            lambda p: attractor_set(p, rules))  # fmt: skip


class FailingWindow(BaseModel):
    """A run of grid speeds at one torque level that breaks one rule."""

    model_config = ConfigDict(frozen=True)

    level: dict[str, PhysicalValue] = Field(description="The torque level (other axis).")
    rule: str = Field(description="The rule broken, e.g. 'chaotic', 'DTE > 20 µm'.")
    speeds_rpm: list[float] = Field(description="[first, last] failing grid speed [rpm].")
    attractors: list[str] | None = Field(
        None,
        description="With basins: per failing speed, the attractors that broke the rule and "
        "their basin fractions ('5750 rpm: chaotic, ... from 41 % of starts'); else null.",
    )


class RunupCheck(BaseModel):
    """What ``check --runup`` ran (``gate.runup.gate_envelope``): a run-up and run-down at one
    rate through the envelope's speed range at each of its levels, and what they found."""

    model_config = ConfigDict(frozen=True)

    rate_rpm_s: float = Field(description="Ramp rate [rpm/s].")
    speeds_rpm: list[float] = Field(description="[lowest, highest] speed [rpm] of each ramp.")
    directions: list[str] = Field(description="The legs run at each level, in order.")
    bin_rpm: float = Field(description="Width of a speed bin [rpm]: the grid's speed step, "
                           "at most a quarter of the range and half the time a chaotic run may "
                           "last (gate.runup.CHAOS_SECONDS).")  # fmt: skip
    ensemble: int = Field(description="Perturbed starts of each bin's FTLE.")
    levels: list[dict[str, PhysicalValue]] = Field(
        description="The levels of the other axis run (one empty level: the design's torque)."
    )
    failing_windows: int = Field(description="Failing windows the run-ups found (in failures).")

    def text(self) -> str:
        """ "run-up and run-down at 2000 rpm/s through 1000-6000 rpm (50 rpm bins, 4 starts) at
        each of the 5 levels, torque 5 N*m to torque 60 N*m: no failing window"."""
        lo, hi = self.speeds_rpm
        legs = " and ".join(f"run-{d}" for d in self.directions)
        n = len(self.levels)
        where = "at the design's torque" if n == 1 and not self.levels[0] else (
            f"at the level {level_text(self.levels[0])}" if n == 1 else
            f"at each of the {n} levels, {level_text(self.levels[0])} to "
            f"{level_text(self.levels[-1])}")  # fmt: skip
        k = self.failing_windows
        found = "no failing window" if k == 0 else f"{k} failing window{'s' if k != 1 else ''}"
        ramp = f"{legs} at {self.rate_rpm_s:g} rpm/s through {lo:g}-{hi:g} rpm"
        return f"{ramp} ({self.bin_rpm:.4g} rpm bins, {self.ensemble} starts) {where}: {found}"


class EnvelopeReport(BaseModel):
    """The verdict of the gate over an envelope (``gearengine check --speed --torque``)."""

    model_config = ConfigDict(frozen=True)

    passed: bool
    rules: Rules
    points: int = Field(description="Points checked: the grid's and the refined ones between.")
    failing_points: int
    melnikov_not_judged: int = Field(
        0,
        description="Grid points where the Melnikov criterion does not apply (above the critical "
        "torque, or no saddle): --fail-on melnikov never fails them.",
    )
    failures: list[FailingWindow]
    windows: list[SpeedWindows] = Field(
        description="All response windows, failing or not, over the grid points and the refined "
        "points between them (the points failures come from; sweep.windows has the grid's "
        "alone), by torque level ascending."
    )
    resolution: Resolution | None = Field(
        None, description="What was checked: grid spacing, starts, and the points inserted "
        "between grid points (null: a report read back without it).",
    )  # fmt: skip
    sweep: SweepResult = Field(description="The sweep result (the API's document).")
    refined: list[SweepPoint] = Field(
        [], description="The points inserted between the grid points (gate.resolution), "
        "checked by the same rules; their failures are in failures.",
    )  # fmt: skip
    notes: list[str] = Field([], description="How the rules were read, where it needs saying.")
    runup: RunupCheck | None = Field(
        None, description="What check --runup ran and found (null: no run-ups ran)."
    )


def _level_key(p: SweepPoint) -> tuple:
    return tuple(sorted((k, v.value) for k, v in (p.physical or {}).items() if k not in
                        (SPEED, *POINT_OUTPUTS)))  # fmt: skip


def envelope_report(result: SweepResult, rules: Rules, refined: Sequence[SweepPoint] = (),
                    resolution: Resolution | None = None) -> EnvelopeReport:  # fmt: skip
    """Failing windows of a sweep over the driver speed (and another axis) under ``rules``,
    with the points ``refined`` between its grid points beside them."""
    rows: dict[tuple, list[SweepPoint]] = {}
    for p in [*result.points, *refined]:
        if p.branch != "down":
            rows.setdefault(_level_key(p), []).append(p)
    checked = [p for row in rows.values() for p in row]
    notes = unjudged_chaos(checked, rules) + unsettled_starts(checked)  # before what fails
    failures: list[FailingWindow] = []
    failing = 0
    for _, row in sorted(rows.items()):
        row.sort(key=lambda p: p.values[SPEED])
        level = {k: v for k, v in (row[0].physical or {}).items()
                 if k not in (SPEED, *POINT_OUTPUTS)}  # fmt: skip
        speeds = [p.physical[SPEED].value for p in row]  # type: ignore[index]
        found = [attractor_failures(p, rules) for p in row]
        broken = [[rule for rule, _ in f] for f in found]
        failing += sum(1 for b in broken if b)
        for rule in dict.fromkeys(r for b in broken for r in b):
            for span in runs(speeds, [rule if rule in b else None for b in broken]).get(rule, []):
                who = [f"{v:g} rpm: {w}" for v, f in zip(speeds, found, strict=True)
                       if span[0] <= v <= span[1] for r, w in f if r == rule and w]  # fmt: skip
                named = list(dict.fromkeys(who)) or None
                failures.append(FailingWindow(level=level, rule=rule, speeds_rpm=span,
                                              attractors=named))  # fmt: skip
    return EnvelopeReport(
        notes=notes,
        passed=not failures,
        rules=rules,
        points=len(checked),
        failing_points=failing,
        melnikov_not_judged=sum(1 for p in checked if p.melnikov_chaos_possible is None),
        failures=failures,
        windows=speed_windows(result, [*result.points, *refined]) or [],
        resolution=resolution,
        sweep=result,
        refined=list(refined),
    )


def unjudged_chaos(points: Sequence[SweepPoint], rules: Rules) -> list[str]:
    """A note when ``rules.fail_on`` leaves chaos out (``--fail-on melnikov`` replaces the
    default ``chaotic``) and some ``points`` are chaotic: a PASS that never says "chaotic"
    read as a design free of chaos (second new-user review)."""
    if any(w in ("quasi_periodic", "chaotic") for w in rules.fail_on):
        return []
    chaotic = sum(1 for p in points if p.classification == "chaotic")
    if not chaotic:
        return []
    given = ", ".join(rules.fail_on) or "none"
    return [f"{chaotic} of {len(points)} points are chaotic, which these rules do not judge "
            f"(fail_on: {given}; a class given replaces the default chaotic: add chaotic to "
            "fail on it)"]  # fmt: skip


def unsettled_starts(points: Sequence[SweepPoint]) -> list[str]:
    """A note when points left basin starts unsettled: a point is judged by the starts that
    reached an attractor, and a pass at 8 of 16 starts unsettled (the fractions summing to
    0.5) said nothing of the other half (fourth new-user review)."""
    hit = [(p, p.basins) for p in points if p.basins is not None and p.basins.unsettled]
    if not hit:
        return []
    worst, counts = max(hit, key=lambda pc: pc[1].unsettled / pc[1].starts)
    where = level_text({k: v for k, v in (worst.physical or {}).items()
                        if k not in POINT_OUTPUTS})  # fmt: skip
    return [f"{len(hit)} of {len(points)} points left basin starts unsettled (no period up to "
            "64 and no positive LLE within the run: an unfinished transient or a longer "
            f"period), up to {counts.unsettled} of {counts.starts} at {where}; such a point is "
            "judged by the starts that settled, or by the settings' own start when none did "
            "(more transient_periods in the file's settings decide them)"]  # fmt: skip


def level_text(level: dict[str, PhysicalValue]) -> str:
    """ "torque 40 N*m", or "the design's torque" for a sweep over the speed alone (it read
    "all", which a user did not take for a torque level: fourth new-user review)."""
    return ", ".join(f"{k} {v.value:g} {v.unit}" for k, v in level.items()) or "the design's torque"


def window_text(w: FailingWindow) -> str:
    """One failing window in words: "torque 20 N*m: chaotic at 3000-3500 rpm"."""
    lo, hi = w.speeds_rpm
    span = f"{lo:g} rpm" if lo == hi else f"{lo:g}-{hi:g} rpm"
    who = "" if not w.attractors else f" ({'; '.join(w.attractors)})"
    return f"{level_text(w.level)}: {w.rule} at {span}{who}"
