"""``gearengine analyze FILE [--json]`` and the CI gate ``gearengine check FILE``.

``check`` exits 0 when the design passes, 1 when it fails a rule, 2 on invalid input;
``--fail-on X`` fails on X or anything worse (``signals.classify.SEVERITY``);
``--min-stability-margin X`` fails a periodic response whose Floquet stability margin
1 - max |lambda| is below X (or could not be computed).
"""

from __future__ import annotations

import argparse
import sys

from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze, decision
from gearengine.cli.documents import (
    EXIT_FAIL,
    EXIT_OK,
    InvalidInputError,
    read_document,
    read_request,
    validated_input,
)
from gearengine.cli.envelope import cmd_envelope, rules_of, settings_text
from gearengine.cli.melnikov import fmt_value, render_engineering, render_melnikov
from gearengine.gate.rules import Rules, verdict_failures
from gearengine.jsonio import dumps


def cmd_analyze(args: argparse.Namespace) -> int:
    request = read_request(args.file, AnalysisRequest)
    result = analyze(request)
    if args.json:
        print(dumps(result))
    else:
        print(render_melnikov(result.melnikov))
        print(f"Numerical verdict: {result.summary()}")
        print(f"  {result.verdict.summary}")
        if request.settings.basins is None:  # say what one or a few starts cannot see
            n = len(request.settings.starts())
            print(f"  from {n} start{'s' if n > 1 else ''} of the settings: other attractors "
                  f"of this design are not searched (gearengine basins {args.file})")  # fmt: skip
        print(f"  forcing period T0 = {fmt_value(result.numerics.forcing_period)}")
        print(f"  {lengths_line(result)}")
        line = floquet_line(result)
        if line is not None:
            who = "" if result.verdict.decided_by is None else "of the settings' start: "
            print(f"  {who}{line}")
        for note in [*result.numerics.notes, *design_readings(request)]:
            print(f"  note: {note}")
        if result.engineering is not None:
            print(render_engineering(result.engineering))
    return EXIT_OK


def lengths_line(r: AnalysisResult) -> str:
    """How long the worst start ran: transient and record, in mesh periods (and seconds with a
    design), and why each stopped (``numerics.physical``)."""
    parts = []
    for name, part in (("transient", r.numerics.transient), ("record", r.numerics.record)):
        if part is None:
            continue
        sec = "" if part.seconds is None else f", {part.seconds:.3g} s"
        parts.append(f"{name} {part.periods} T0 = {part.mesh_periods:g} mesh periods{sec} "
                     f"({part.reason})")  # fmt: skip
    return "ran: " + "; ".join(parts)


def floquet_line(r: AnalysisResult) -> str | None:
    """The multipliers and stability margin of a periodic response, or why there are none."""
    fl = r.numerics.floquet
    if fl is None:
        return (
            None
            if r.numerics.floquet_note is None
            else f"no Floquet multipliers: {r.numerics.floquet_note}"
        )
    lams = ", ".join(f"{re:.6g}{im:+.6g}i" if im else f"{re:.6g}" for re, im in fl.multipliers)
    pair = any(note.startswith("complex pair") for note in fl.notes)  # JSON: the generic label
    near = "no bifurcation while they are a complex pair" if pair else (
        f"nearest bifurcation: {fl.nearest_bifurcation}")  # fmt: skip
    notes = "".join(f"; {note}" for note in fl.notes)  # as the JSON says them
    return f"Floquet multipliers {lams}; stability margin {fl.stability_margin:.4g} ({near}){notes}"


def margin_failure(r: AnalysisResult, min_margin: float) -> str | None:
    """Why a periodic response fails ``--min-stability-margin`` (None: passes or not periodic).
    A periodic response whose margin could not be computed fails: the gate cannot vouch."""
    if r.numerics.worst_case.classification != "periodic":
        return None
    fl = r.numerics.floquet
    if fl is None:
        return f"--min-stability-margin {min_margin:g}: margin unavailable"
    if fl.stability_margin < min_margin:
        return f"--min-stability-margin {min_margin:g}: margin {fl.stability_margin:.4g}"
    return None


def failures(r: AnalysisResult, rules: Rules, min_margin: float | None = None) -> list[str]:
    """Reasons the design fails the gate (empty: pass): the envelope's rules judging its one
    verdict (``gate.rules.verdict_failures``: its worst start's, with basins its worst
    attractor's; its DTE and dynamic factor in µm and 1, with basins the largest over the
    attractors, as the summary line gives them), and the Floquet stability margin."""
    run = r.numerics.worst_case
    decided = decision(r.numerics, r.settings)
    who = run if decided is None else decided.attractor  # None: diverged
    classification = run.classification if decided is None else decided.classification
    eng = r.engineering
    resp = None if eng is None else eng.response
    dte, factor = (None, None) if resp is None else (resp.dte_peak_to_peak_um, resp.dynamic_factor)
    if eng is not None and eng.most_adverse is not None:
        dte, factor = (None if (w := eng.most_adverse.get(key)) is None else w.value
                       for key in ("dte", "dynamic_factor"))  # fmt: skip
    impact = r.numerics.impact_regime if who is run else getattr(who, "impact_regime", None)
    reasons = verdict_failures(rules, classification, None if who is None else who.lle, impact,
                               r.melnikov.chaos_possible, dte, factor)  # fmt: skip
    margin = None if min_margin is None else margin_failure(r, min_margin)
    if margin is not None:
        reasons.append(margin)
    return reasons


ENVELOPE_ONLY = {"fail_on": "--fail-on", "max_lle": "--max-lle", "max_dte": "--max-dte",
                 "max_dynamic_factor": "--max-dynamic-factor", "min_basin": "--min-basin",
                 "min_stability_margin": "--min-stability-margin", "refine": "--refine",
                 "runup": "--runup", "server": "--server"}  # fmt: skip
"""The options of ``check`` that the probability gate (``--max-probability``) does not read."""


def envelope_only(args: argparse.Namespace) -> list[str]:
    """The options given that the probability gate would ignore (``ENVELOPE_ONLY``)."""
    return [option for name, option in ENVELOPE_ONLY.items() if getattr(args, name) is not None]


ONE_DESIGN_SETTINGS = (
    "as analyze runs the file; an envelope check runs the light settings where the file sets "
    "none, so its DTE and forces at this point can differ in their last digits"
)
"""Why a one-design check and an envelope check may give one point two DTEs (5.02 and
5.0096 µm: 500 + 500 periods at 200 steps against 60 + 60 at 128, a new-user review)."""


def cmd_check(args: argparse.Namespace) -> int:
    """CI gate: exit 0 pass, 1 fail, 2 invalid input; one summary line. With --speed or
    --torque, the gate over the operating envelope (``cli.envelope``); with --max-probability,
    over the design's tolerances (``cli.robustness``), refused with the envelope's rules and
    options, which it would ignore (``envelope_only``). The document is read once, here, and
    the rules once for the envelope and the one design."""
    if not args.max_probability and (args.samples is not None or args.seed is not None):
        raise InvalidInputError(["--samples and --seed sample a design's tolerances: give "
                                 "--max-probability NAME=P with them"])  # fmt: skip
    if args.max_probability:
        ignored = envelope_only(args)
        if ignored:
            verb = "judges" if len(ignored) == 1 else "judge"
            raise InvalidInputError([
                f"{', '.join(ignored)} {verb} the envelope check (the nominal design), which "
                "--max-probability does not run: run it as a second check without "
                "--max-probability"
            ])  # fmt: skip
    doc = read_document(args.file)
    if args.max_probability:
        from gearengine.cli.robustness import cmd_probability_gate

        return cmd_probability_gate(args, doc)
    rules = rules_of(args)  # one read of the rules, for the envelope and the one design
    if args.speed or args.torque:
        return cmd_envelope(args, doc, rules)
    given = [option for option, value in (
        ("--starts", args.starts), ("--min-basin", args.min_basin), ("--json", args.json),
        ("--junit", args.junit), ("--server", args.server), ("--refine", args.refine),
        ("--runup", args.runup), ("--speed-points", args.speed_points),
        ("--torque-points", args.torque_points),
    ) if value is not None and value is not False]  # fmt: skip
    if given:
        verb, them = ("checks", "it") if len(given) == 1 else ("check", "them")
        raise InvalidInputError([f"{', '.join(given)} {verb} an envelope (one design's check "
                                 f"would ignore {them}): give --speed LOW:HIGH (rpm) and/or "
                                 "--torque LOW:HIGH (N m)"])  # fmt: skip
    request = validated_input(AnalysisRequest.model_validate, doc, args.file)
    limits = physical_limits(rules)
    if request.design is None and limits:
        raise InvalidInputError(
            [
                f"{args.file}: {', '.join(limits)} need a design in physical "
                'units ({"design": {...}}); dimensionless params have no µm or static force'
            ]
        )
    result = analyze(request)
    reasons = failures(result, rules, args.min_stability_margin)
    verdict = "FAIL" if reasons else "PASS"
    why = f" [{', '.join(reasons)}]" if reasons else ""
    print(f"{verdict}: {result.summary()}{why}")
    for note in design_readings(request):  # stdout keeps its one summary line
        print(f"note: {note}", file=sys.stderr)
    print(f"{settings_text(request.settings)} ({ONE_DESIGN_SETTINGS})", file=sys.stderr)
    return EXIT_FAIL if reasons else EXIT_OK


def physical_limits(rules: Rules) -> list[str]:
    """The limits of ``rules`` that need a design in physical units (µm, static force)."""
    names = {"--max-dte": rules.max_dte_um, "--max-dynamic-factor": rules.max_dynamic_factor}
    return [name for name, limit in names.items() if limit is not None]


def design_readings(request: AnalysisRequest) -> list[str]:
    """What was read from the design's own spellings and bare numbers (``Design.readings``:
    "speed: the bare number 300 read as 300 rad/s = 2,864.79 rpm ..."), said in the text as
    the JSON's ``engineering.notes`` says it."""
    return [] if request.design is None else request.design.readings
