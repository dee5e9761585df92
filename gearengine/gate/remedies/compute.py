"""The remedies job: one chunk per lever (``search.lever_outcome``) and a last chunk for the
combination, assembled into the ranked answer; ``remedies()`` runs it in process."""

from __future__ import annotations

import math
from collections.abc import Callable

from gearengine.gate.remedies.request import (
    COMBINATION_GRID,
    MAX_BISECTIONS,
    SAMPLES,
    Lever,
    RemediesRequest,
    request_levers,
)
from gearengine.gate.remedies.results import (
    ChunkOutcome,
    Combination,
    LeverSetting,
    RemediesResult,
    Remedy,
    Unreachable,
)
from gearengine.gate.remedies.search import (
    change_words,
    envelope_points,
    lever_outcome,
    lever_words,
    melnikov_failures,
    shared_check,
    verify_depth,
)
from gearengine.model.fields import design_with
from gearengine.numerics.batch import threads_may_share_kernels
from gearengine.studies import jobs
from gearengine.studies.sweep.plan import sweep_work
from gearengine.studies.sweep.request import SweepRequest


def _chunk(request: RemediesRequest, index: int, chunk_points: int = 1) -> str:
    """Chunk ``index``: lever ``index`` (both bounds), or the combination (the last chunk);
    chunk 0 also carries the design's own report."""
    levers = request_levers(request)
    baseline = shared_check(request, request.sweep(), finish=True)
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
    far: list[tuple[int, Lever]] = []
    for lever in levers:
        report = shared_check(request, request.sweep(design_with(request.design,
                              {lever.path: lever.end})))  # fmt: skip
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
        report = shared_check(request, request.sweep(design_with(request.design, values)))
        if report.passed:
            settings = [LeverSetting(lever=lev.path, from_=lev.shown(lev.start),
                                     to=lev.shown(values[lev.path]), unit=lev.unit)
                        for lev in pair]  # fmt: skip
            return Combination(
                levers=settings,
                how="no single lever cleared the envelope at its far end; the two levers that "
                "left the fewest failing points there, on a 3 x 3 grid of 1/3, 2/3 and all of "
                "each range, the first passing in order of total change",
                summary=f"{change_words(pair[0], values[pair[0].path])} and "
                f"{change_words(pair[1], values[pair[1].path])}: the envelope check passes there",
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
    it where the criterion judges envelope points and the envelope check passes there (with
    what was checked: the resolution), then what no value in range clears, and the Melnikov
    values that guarantee nothing (judging no point, or where the check still fails)."""
    by_lever: dict[tuple[str, bool], dict[str, Remedy]] = {}
    for r in remedies:
        by_lever.setdefault((r.lever, r.to > r.from_), {})[r.bound] = r
    parts, blind = [], []
    for found in by_lever.values():
        num, mel = found.get("numerical"), found.get("melnikov")
        first = num or mel
        assert first is not None
        unit = "" if first.unit == "1" else f" {first.unit}"
        if mel is not None and not _guarantees(mel):
            blind.append(f"{lever_words(mel.lever)} at {mel.to:.4g}{unit}: {_no_guarantee(mel)}")
            mel = None
            if num is None:  # not a remedy to offer
                continue
        words = lever_words(first.lever)
        verb = "raise" if first.to > first.from_ else "lower"
        text = f"{verb} the {words} from {first.from_:.4g}"
        if num is not None:
            text += f" to {num.to:.4g}{unit} (numerically"
            if num.iso1328_class is not None:
                grades = [str(c) if c else "finer than 1" for c in num.iso1328_class]
                text += f"; ISO 1328 class {grades[0]} -> {grades[1]}"
            text += ")" if num.monotone else "; not unique: the response is not monotone)"
        if mel is not None:
            points, applies = mel.melnikov_points or 0, _judged(mel)
            what = "Melnikov guarantee against homoclinic chaos"
            if applies < points:
                what += f" at the {applies} of {points} points where the criterion applies"
            text += (f"{' or' if num else ' to'} {mel.to:.4g}{unit} ({what}; the envelope check "
                     f"passes there{_checked(mel)})")  # fmt: skip
        parts.append(text)
    words = "; or ".join(parts) if parts else "no single lever clears the envelope"
    for u in unreachable:
        if u.bound == "numerical":
            words += (f"; {lever_words(u.lever)} has no value in {u.searched[0]} to "
                      f"{u.searched[1]} that clears the envelope")  # fmt: skip
    for b in blind:
        words += f"; {b}"
    if combo is not None:
        words += f"; together: {combo.summary}"
    return words


def _guarantees(mel: Remedy) -> bool:
    """A Melnikov value is offered with its guarantee only where its criterion judges some
    envelope point, allows chaos at none of the 2x finer grid's points between them, and the
    envelope check passes there."""
    return _judged(mel) > 0 and _between(mel) == 0 and mel.check.passed


def _between(mel: Remedy) -> int:
    """Points of the 2x finer grid where the criterion still allows chaos at a Melnikov value."""
    return 0 if mel.melnikov_between is None else mel.melnikov_between[0]


def _no_guarantee(mel: Remedy) -> str:
    """Why a Melnikov value guarantees nothing, with what was checked."""
    points = mel.melnikov_points or 0
    if _judged(mel) == 0:
        return (f"the Melnikov criterion allows chaos nowhere but applies at none of the "
                f"{points} points, so it guarantees nothing")  # fmt: skip
    if _between(mel):
        chaos, finer = mel.melnikov_between  # type: ignore[misc]
        return (f"the Melnikov criterion allows homoclinic chaos at none of the {points} grid "
                f"points but still at {chaos} of the {finer} points of the 2x finer grid between "
                "them, so it guarantees nothing between grid points")  # fmt: skip
    return (f"the Melnikov criterion allows homoclinic chaos at none of the {_judged(mel)} of "
            f"{points} points it judges, but the envelope check still fails there at "
            f"{mel.check.failing_points} of {mel.check.points} points{_checked(mel)}, so it "
            "guarantees no pass")  # fmt: skip


def _checked(mel: Remedy) -> str:
    """The resolution the envelope check at a Melnikov value ran at (empty without one)."""
    resolution = mel.check.resolution
    return "" if resolution is None else f" (checked on {resolution.text()})"


def _judged(mel: Remedy) -> int:
    """Envelope points where a Melnikov value's criterion applies (has a saddle to judge)."""
    return (mel.melnikov_points or 0) - (mel.not_applicable_points or 0)


FINER_RUNS = 2
"""Runs on the 2x finer grid (about 4x the points) a numerical remedy's verification takes in
the budget: its value, and one more when it fails there."""
BOUNDARY_POINTS = 3
"""Points a check's refinement adds, in the budget, per grid cell a boundary across the
envelope crosses (n - 1 + m - 1 cells of an n x m grid) and per cell of each deeper halving
(2, 4, ... cells): a split cell adds up to 5, shared with its neighbours. On the z = 23/67 pair
over 1,000-6,000 rpm x 5-60 N*m (23 x 5, 16 starts) this is 234 points at two halvings (the
design's own check added 82, its Melnikov value's 275) and 1,092 on the 45 x 9 verification
at three (a failing one added 378 on average)."""


def checked_work(sweep: SweepRequest, depth: int) -> int:
    """RK4 steps, about, of an envelope check of ``sweep`` refined ``depth`` times: its grid's,
    and its refinement's (``BOUNDARY_POINTS``; at most every point of the grid ``2**depth``
    times finer) at the grid's mean steps a point."""
    cells = [len(g) - 1 for g in sweep.grids()]
    every = math.prod(c * 2**depth + 1 for c in cells) - sweep.n_points()
    refined = min(every, BOUNDARY_POINTS * sum(cells) * (2**depth - 1))
    return sweep_work(sweep) * (sweep.n_points() + refined) // sweep.n_points()


def _work(request: RemediesRequest) -> int:
    """RK4 steps, about: per lever its samples, bisections and the Melnikov bound's run, each
    refined as the check is, and the verification on the finer grid refined one halving deeper
    (``verify_depth``); the combination's far ends and grid; the baseline."""
    n = len(request_levers(request))
    runs = n * (1 + SAMPLES + MAX_BISECTIONS + 1) + 1 + n + len(COMBINATION_GRID) ** 2
    coarse = checked_work(request.sweep(), request.envelope.refine)
    return runs * coarse + n * FINER_RUNS * checked_work(request.sweep(finer=True),
                                                         verify_depth(request))  # fmt: skip


REMEDIES_JOB = jobs.JobKind(
    name="remedies",
    request=RemediesRequest,
    chunk_points=1,
    chunk_counts=lambda request, size: [1] * (len(request_levers(request)) + 1),
    work=_work,
    compute_chunk=_chunk,
    assemble=assemble,
)
"""Remedies as a kind of job (``gearengine.studies.jobs.KINDS``): one chunk per lever, then the
combination."""


def remedies(request: RemediesRequest, progress_callback: Callable[[int, int], None] | None = None,
             workers: int = 1) -> RemediesResult:  # fmt: skip
    """Every lever of ``request`` in this process (``jobs.run_local``)."""
    if not threads_may_share_kernels():
        workers = 1  # numba's workqueue layer: one kernel call at a time, or it aborts
    result = jobs.run_local("remedies", request, progress_callback, workers=workers)
    assert isinstance(result, RemediesResult)
    return result
