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
* **Numerical bound**: the smallest t after which the gate (``gate.envelope``: the same rules,
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

A job of kind ``remedies`` (``gearengine.studies.jobs``): one chunk per lever, and a last chunk
for the combination; a chunk depends only on (request, index).
"""

from __future__ import annotations

import itertools
import math
import threading
from collections.abc import Callable

from gearengine.gate.envelope import EnvelopeReport, check_envelope, check_or_failures, fails_toward
from gearengine.gate.remedies.levers import accuracy_classes, contact_ratio
from gearengine.gate.remedies.request import (
    MAX_BISECTIONS,
    MELNIKOV_RTOL,
    MELNIKOV_SAMPLES,
    SAMPLES,
    Lever,
    RemediesRequest,
)
from gearengine.gate.remedies.results import Remedy, Sample, Unreachable
from gearengine.gate.resolution import MAX_REFINE_DEPTH
from gearengine.gate.rules import attractor_failures
from gearengine.homoclinic.thresholds import chaos_possible
from gearengine.homoclinic.train_reduction import melnikov_point
from gearengine.model.design import Design
from gearengine.model.fields import design_with, si_value
from gearengine.studies.sweep.compute import points_at
from gearengine.studies.sweep.points import SweepPoint
from gearengine.studies.sweep.request import SweepRequest
from gearengine.systems.designs import design_model


def envelope_points(request: RemediesRequest, finer: bool = False) -> list[dict[str, float]]:
    """The envelope's grid points as sweep values (SI), speed fastest as in the sweep; ``finer``:
    those of the 2x finer grid a remedy is verified on."""
    sweep = request.sweep(finer=finer)
    names = [a.parameter for a in sweep.axes]
    grids = sweep.grids()
    rows = [[]] if len(grids) == 1 else [[(names[1], t)] for t in grids[1]]
    return [dict([(names[0], v), *row]) for row in rows for v in grids[0]]


def melnikov_failures(design: Design, points: list[dict[str, float]],
                      values: dict[str, float]) -> tuple[int, int]:  # fmt: skip
    """(points where the criterion allows chaos, points where it does not apply) over the
    envelope ``points`` of ``design`` with the fields ``values`` set (SI): each point's
    ``chaos_possible``, as the sweep's ``melnikov_chaos_possible`` (of a train, its mesh-mode
    reduction's: ``melnikov_point``)."""
    verdicts = [melnikov_allows(design, {**values, **p}) for p in points]
    return sum(v is True for v in verdicts), sum(v is None for v in verdicts)


def melnikov_first_allowing(design: Design, points: list[dict[str, float]],
                            values: dict[str, float], first: int = 0) -> int | None:  # fmt: skip
    """The index of an envelope point where the Melnikov criterion allows chaos for ``design``
    with the fields ``values`` set (``points[first]`` tried first, then the others in order,
    up to the first that allows it), None where it allows it at none: ``melnikov_failures``'s
    pass or fail alone, for a bisection step."""
    for k in [first, *(k for k in range(len(points)) if k != first)]:
        if melnikov_allows(design, {**values, **points[k]}) is True:
            return k
    return None


def melnikov_allows(design: Design, values: dict[str, float]) -> bool | None:
    """``chaos_possible`` of ``design`` with the fields ``values`` set (SI): True where the
    Melnikov criterion allows chaos, None where it does not apply."""
    judged = melnikov_point(design_model(design_with(design, values))[0])
    return None if judged is None else chaos_possible(judged)


def _search(test: Callable[[float], tuple[bool, int, int]], lever: Lever, samples: int,
            width: Callable[[float, float], bool], max_steps: int,
            passes_at: Callable[[float], bool] | None = None,
            verify: Callable[[float], bool] | None = None,
            narrow: Callable[..., tuple[float, float] | None] | None = None,
            ) -> tuple[list[Sample], bool, tuple[float, float] | None]:  # fmt: skip
    """Bracket samples of v(t), monotone on them?, and [last failing, first passing] value (SI)
    after bisection (None when no sample passes, or none passes ``verify``).
    ``test(v) -> (passed, failing points, points)`` runs the samples; ``passes_at(v)`` (default: the
    test's pass) each bisection step, where only pass or fail is needed. With ``verify`` the
    value found must pass it too (a finer grid): if not, the search goes on from it toward the
    far end with ``verify`` as its test, and the bracket returned is ``verify``'s. ``narrow``
    narrows the samples' bracket: ``_bisect`` (default), or ``_gallop`` for a test whose
    failure is cheaper than its pass; ``verify``'s is ``_gallop``."""
    ts = [k / (samples - 1) for k in range(samples)]
    results = [test(lever.at(t)) for t in ts]
    shown = [Sample(value=lever.shown(lever.at(t)), passed=r[0], failing_points=r[1],
                    points=r[2]) for t, r in zip(ts, results, strict=True)]  # fmt: skip
    passes = [r[0] for r in results]
    if not any(passes):
        return shown, False, None
    j = passes.index(True)
    monotone = j > 0 and all(passes[j:])
    narrow = narrow or _bisect
    if j == 0:
        fail, good = lever.at(0.0), lever.at(0.0)
    else:
        step = passes_at or (lambda v: test(v)[0])
        fail, good = narrow(step, lever.at(ts[j - 1]), lever.at(ts[j]), width, max_steps)
    if verify is None or verify(good):
        return shown, monotone, (fail, good)
    fail = good  # it fails ``verify``: on from it toward the next samples that passed
    for end in (lever.at(t) for t, ok in zip(ts[j:], passes[j:], strict=True) if ok):
        if end != fail:
            bracket = _gallop(verify, fail, end, width, max_steps, known=False)
            if bracket is not None:
                return shown, monotone, bracket
            fail = end
    return shown, monotone, None


def _bisect(passes: Callable[[float], bool], fail: float, good: float,
            width: Callable[[float, float], bool], max_steps: int
            ) -> tuple[float, float]:  # fmt: skip
    """[fail, good] narrowed by bisection with ``passes`` until ``width`` says it is narrow."""
    for _ in range(max_steps):
        if width(fail, good):
            break
        mid = 0.5 * (fail + good)
        if passes(mid):
            good = mid
        else:
            fail = mid
    return fail, good


def _gallop(passes: Callable[[float], bool], fail: float, good: float,
            width: Callable[[float, float], bool], max_steps: int, known: bool = True,
            ) -> tuple[float, float] | None:  # fmt: skip
    """``_bisect``'s bracket, its probes taken from the failing end, for a test whose failure is
    cheap and whose pass is not (a failing envelope check stops at its first failing point, a
    passing one runs every point). Bisection's halvings toward ``fail`` while every step passes
    are m_1 = (fail + good) / 2, m_2 = (fail + m_1) / 2, ... down to the first m_K that ``width``
    accepts with ``fail``; they are probed upward from m_K (galloping search; Bentley & Yao,
    Inf. Proc. Lett. 5, 1976) to the first that passes, m_i, and bisection goes on from
    [m_i+1, m_i], the bracket it reaches itself when the test switches once between them. So
    a lever that switches once gets bisection's bracket, bit for bit, and a switch near the
    failing end (the usual case: the value found on the coarser grid, or the last failing
    sample) costs one passing check instead of one per halving. ``known`` False: ``good`` is
    not known to pass and is tried last (None when it fails too)."""
    halvings = [good]
    while not width(fail, halvings[-1]) and len(halvings) <= max_steps:
        halvings.append(0.5 * (fail + halvings[-1]))
    last = len(halvings) - 1
    for k in range(last, 0, -1):
        if passes(halvings[k]):  # bisection's steps 1..k passed, step k + 1 (if any) failed
            return _bisect(passes, fail, halvings[k], width, max_steps - k - (k < last))
        fail = halvings[k]
    if not known and not passes(good):
        return None
    return _bisect(passes, fail, good, width, max_steps - (last >= 1))


def _narrow(rtol: float, lever: Lever) -> Callable[[float, float], bool]:
    """Bracket [a, b] narrow enough: |b - a| <= rtol x min(|change|, |value|) (the change alone
    when the value is 0)."""

    def done(a: float, b: float) -> bool:
        change = abs(b - lever.start)
        scale = min(change, abs(b)) if b != 0 else change
        return abs(b - a) <= rtol * scale

    return done


def lever_words(path: str) -> str:
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


def change_words(lever: Lever, to: float) -> str:
    """ "raise the damping ratio from 0.05 to 0.071" """
    verb = "raise" if lever.end > lever.start else "lower"
    unit = lever.suffix
    return (f"{verb} the {lever_words(lever.path)} from {lever.shown(lever.start):.4g} to "
            f"{lever.shown(to):.4g}{unit}")  # fmt: skip


def _uniqueness(monotone: bool) -> str:
    return ("" if monotone else "; the response is not monotone on the bracket samples, so "
            "this is one switch from the design's value, not a unique bound")  # fmt: skip


MEMO_SIZE = 32
"""Envelope reports kept in this process (``shared_check``)."""
_memo: dict[str, EnvelopeReport] = {}
_memo_locks: dict[str, threading.Lock] = {}
_memo_lock = threading.Lock()


def verify_depth(request: RemediesRequest) -> int:
    """The refinement of a remedy's verification on the 2x finer grid: one halving more than
    the search's (none if the search refines none), so that its finest spacing is that of a
    check of a grid 2x finer again at the search's refinement. At the search's depth, the TE
    remedy of the z = 23/67 pair over 4,500-5,700 rpm x 5-12 N*m passed its 7 x 3 grid and
    failed ``check`` on 13 x 5 (chaotic at 4,825 rpm / 5 N*m from 38 % of starts, a point only
    that check's refinement reached)."""
    depth = request.envelope.refine
    return min(MAX_REFINE_DEPTH, depth + 1) if depth > 0 else 0


def shared_check(request: RemediesRequest, sweep: SweepRequest, finish: bool = False,
                 depth: int | None = None) -> EnvelopeReport:  # fmt: skip
    """``check_envelope`` of ``sweep`` under the request's rules and refinement (``depth``
    halvings, default the request's), computed once
    per process: the design's own check that every chunk needs, and a lever's far end that the
    combination checks again, are run once however many chunks ask (threads asking for the same
    sweep wait for the first). ``finish``: refine a grid that fails too (the design's own report,
    shown to the user); else a failing grid is not refined (only pass or fail is needed)."""
    rules = request.rules()
    depth = request.envelope.refine if depth is None else depth
    key = "\n".join((sweep.model_dump_json(), rules.model_dump_json(), str(depth),
                      str(finish)))  # fmt: skip
    with _memo_lock:
        lock = _memo_locks.setdefault(key, threading.Lock())
    with lock:
        if key not in _memo:
            report = check_envelope(sweep, rules, refine=depth, refine_failing=finish)
            with _memo_lock:
                while len(_memo) >= MEMO_SIZE:
                    _memo_locks.pop(next(iter(_memo)), None)
                    _memo.pop(next(iter(_memo)))
                _memo[key] = report
        return _memo[key]


SHOWN_DIGITS = 4
"""Significant digits of a numerical remedy's value, as the answer prints it (``.4g``)."""
HINTS = 4
"""Points that failed at the last failing value, run first at the next bisection value: one of
them failing there decides the step (the envelope fails) without the rest of the grid."""


def lever_outcome(request: RemediesRequest, lever: Lever, baseline: EnvelopeReport,
                  check: Callable[[SweepRequest, int], EnvelopeReport] | None = None,
                  ) -> tuple[list[Remedy], list[Unreachable]]:  # fmt: skip
    """Both bounds of one lever; ``check(sweep, depth)`` runs an envelope sweep refined
    ``depth`` times (default ``shared_check``); the finer grid's at ``verify_depth``."""
    rules = request.rules()
    check = check or (lambda sweep, depth: shared_check(request, sweep, depth=depth))
    depths = {False: request.envelope.refine, True: verify_depth(request)}
    reports: dict[tuple[float, bool], EnvelopeReport] = {(lever.start, False): baseline}
    failed: dict[bool, list[SweepPoint]] = {  # per grid (finer or not): its failing points
        False: [p for p in baseline.sweep.points if attractor_failures(p, rules)],
        True: [],
    }

    def run(value: float, finer: bool = False) -> EnvelopeReport:
        if (value, finer) not in reports:
            design = design_with(request.design, {lever.path: value})
            reports[(value, finer)] = report = check(request.sweep(design, finer), depths[finer])
            if not report.passed:  # its grid points: a failure there is the grid's
                failed[finer] = [p for p in report.sweep.points if attractor_failures(p, rules)]
        return reports[(value, finer)]

    def numerical(value: float) -> tuple[bool, int, int]:
        report = run(value)
        return report.passed, report.failing_points, report.points

    def passes_at(value: float, finer: bool = False) -> bool:
        """Pass or fail at ``value``: the grid points that failed last run first (``HINTS``),
        then the grid chunk by chunk, theirs first, to the first chunk with a failing point,
        then the refinement batch by batch, the refined points that failed last first, to
        the first failing one (``check_or_failures``); one failing fails the check, the answer
        the full check would give. A grid that passes leaves its full report, refined. Only
        grid points are tried ahead of the check: a refined point fails it only where the
        refinement at ``value`` reaches."""
        if (value, finer) in reports:
            return reports[(value, finer)].passed
        sweep = request.sweep(design_with(request.design, {lever.path: value}), finer)
        names = [a.parameter for a in sweep.axes]
        grid = set(itertools.product(*sweep.grids()))
        last = [{n: p.values[n] for n in names} for p in failed[finer]]
        hints = [h for h in last if tuple(h[n] for n in names) in grid][:HINTS]
        if hints and any(attractor_failures(p, rules) for p in points_at(sweep, hints)):
            return False
        between = [h for h in last if tuple(h[n] for n in names) not in grid][:HINTS]
        if between and fails_toward(sweep, rules, depths[finer], between):
            return False
        got = check_or_failures(sweep, rules, depths[finer], last)
        if isinstance(got, list):
            failed[finer] = got
            return False
        reports[(value, finer)] = got
        return True

    def snapped(value: float) -> float:
        """``value`` as the answer prints it (``SHOWN_DIGITS``, rounded toward the far end),
        read back as a design file reads it: the value verified is the one a user types."""
        shown = lever.shown(value)
        digits = SHOWN_DIGITS - 1 - math.floor(math.log10(abs(shown))) if shown else 0
        toward = math.ceil if lever.end > lever.start else math.floor
        near = toward(round(shown * 10**digits, 6)) / 10**digits
        if (near - lever.shown(lever.end)) * (lever.end - lever.start) > 0:
            return lever.end
        return si_value(request.design, lever.path, near if lever.unit == "1"
                        else f"{near!r} {lever.unit}")  # fmt: skip

    points = envelope_points(request)

    def melnikov(value: float) -> tuple[bool, int, int]:
        possible, _ = melnikov_failures(request.design, points, {lever.path: value})
        return possible == 0, possible, len(points)

    allowed_at = [0]  # the envelope point where the criterion allowed chaos last

    def melnikov_rules_out(value: float) -> bool:
        """``melnikov``'s pass or fail alone (a bisection step), the point that allowed chaos
        at the last failing value tried first."""
        k = melnikov_first_allowing(request.design, points, {lever.path: value}, allowed_at[0])
        allowed_at[0] = allowed_at[0] if k is None else k
        return k is None

    searched = [f"{lever.shown(v):g}{lever.suffix}" for v in (lever.start, lever.end)]
    remedies: list[Remedy] = []
    unreachable: list[Unreachable] = []
    for bound, test, samples, rtol, steps in (
        ("numerical", numerical, SAMPLES, request.tolerance, MAX_BISECTIONS),
        ("melnikov", melnikov, MELNIKOV_SAMPLES, MELNIKOV_RTOL, 60),
    ):
        shown, monotone, bracket = _search(
            test, lever, samples, _narrow(rtol, lever), steps,
            passes_at=passes_at if bound == "numerical" else melnikov_rules_out,
            verify=(lambda v: passes_at(snapped(v), finer=True)) if bound == "numerical"
            else None,
            narrow=_gallop if bound == "numerical" else _bisect,
        )  # fmt: skip
        if bracket is None:
            far = run(lever.end) if bound == "numerical" else None
            unreachable.append(Unreachable(
                lever=lever.path, bound=bound, searched=searched, samples=shown,
                why=_why(bound, lever, shown, far, run(lever.end, finer=True) if far is not None
                         and far.passed else None),
            ))  # fmt: skip
            continue
        fail, to = bracket
        to = snapped(to) if bound == "numerical" else to
        if bound == "melnikov" and to == lever.start:
            continue  # the criterion rules chaos out already: no change needed for it
        report = run(to, finer=bound == "numerical")
        blind, between = None, None
        if bound == "melnikov":
            blind = melnikov_failures(request.design, points, {lever.path: to})[1]
            finer = envelope_points(request, finer=True)  # between the search's points
            between = [melnikov_failures(request.design, finer, {lever.path: to})[0], len(finer)]
        remedies.append(Remedy(
            lever=lever.path, from_=lever.shown(lever.start), to=lever.shown(to),
            unit=lever.unit, bound=bound, monotone=monotone,
            bracket=[lever.shown(fail), lever.shown(to)], samples=shown,
            not_applicable_points=blind, melnikov_between=between, check=report,
            melnikov_points=len(points) if bound == "melnikov" else None,
            contact_ratio=contact_ratio(design_with(request.design, {lever.path: to})),
            iso1328_class=accuracy_classes(request.design, lever, to),
            summary=_summary(bound, lever, to, monotone, report, blind, len(points)),
        ))  # fmt: skip
    return remedies, unreachable


def melnikov_words(applies: int, points: int) -> str:
    """What the Melnikov criterion guarantees at a value where it allows chaos nowhere:
    ``applies`` of ``points`` envelope grid points are judged (the rest have no saddle under
    their load), and the guarantee is stated only where it applies."""
    if applies == 0:
        return (f"the Melnikov criterion applies at none of the {points} envelope points (no "
                "saddle under their load), so it guarantees nothing there")  # fmt: skip
    where = ("every envelope point" if applies == points else
             f"the {applies} of {points} envelope points where it applies (no saddle under the "
             "load at the others: not judged)")  # fmt: skip
    return f"the Melnikov criterion rules out homoclinic chaos at {where}"


def _summary(bound: str, lever: Lever, to: float, monotone: bool, report: EnvelopeReport,
             blind: int | None, points: int) -> str:  # fmt: skip
    grid = f"; {report.resolution.text()}" if report.resolution is not None else ""
    finer = " on the 2x finer grid" if bound == "numerical" else ""
    run = (f"the envelope check passes there{finer} ({report.points} points run{grid})"
           if report.passed else f"the envelope check still fails there at "
           f"{report.failing_points} of {report.points} points{grid}")  # fmt: skip
    if bound == "numerical":
        return f"{change_words(lever, to)}: {run}{_uniqueness(monotone)}"
    words = melnikov_words(points - (blind or 0), points)
    return f"{change_words(lever, to)}: {words}; {run}{_uniqueness(monotone)}"


def _why(bound: str, lever: Lever, samples: list[Sample], far: EnvelopeReport | None,
         finer: EnvelopeReport | None = None) -> str:  # fmt: skip
    values = ", ".join(f"{s.value:g}" for s in samples)
    if bound == "melnikov":
        return (f"the Melnikov criterion allows chaos somewhere in the envelope at every sampled "
                f"{lever_words(lever.path)} ({values}{lever.suffix})")  # fmt: skip
    assert far is not None
    if finer is not None:
        return (f"sampled {lever_words(lever.path)} values pass the envelope's grid but none "
                f"passes its 2x finer grid; at {lever.shown(lever.end):g}{lever.suffix} "
                f"{finer.failing_points} of {finer.points} points fail there")  # fmt: skip
    return (f"no sampled {lever_words(lever.path)} ({values}{lever.suffix}) clears the envelope; "
            f"at {lever.shown(lever.end):g}{lever.suffix} {far.failing_points} of {far.points} "
            "points still fail")  # fmt: skip


# --- the job ----------------------------------------------------------------------------------
