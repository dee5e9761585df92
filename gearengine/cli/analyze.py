"""``gearengine analyze FILE [--json]`` and the CI gate ``gearengine check FILE``.

``check`` exits 0 when the design passes, 1 when it fails a rule, 2 on invalid input;
``--fail-on X`` fails on X or anything worse (``numerics.classify.SEVERITY``);
``--min-stability-margin X`` fails a periodic response whose Floquet stability margin
1 - max |lambda| is below X (or could not be computed).
"""

from __future__ import annotations

import argparse

from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
from gearengine.cli.documents import EXIT_FAIL, EXIT_OK, InvalidInputError, read_request
from gearengine.cli.envelope import cmd_envelope
from gearengine.cli.melnikov import fmt_value, render_engineering, render_melnikov
from gearengine.jsonio import dumps
from gearengine.numerics.classify import SEVERITY


def numerics_line(r: AnalysisResult) -> str:
    num = r.numerics
    kind = f"periodic {num.period}T" if num.period else num.classification
    lle = "LLE n/a" if num.lle is None else f"LLE {num.lle:+.4g} ± {num.lle_stderr or 0.0:.2g}"
    mel = {True: "possible", False: "not possible", None: "n/a"}[r.melnikov.chaos_possible]
    return f"{kind} ({lle} per unit tau, {num.impact_regime}), Melnikov: chaos {mel}"


def cmd_analyze(args: argparse.Namespace) -> int:
    result = analyze(read_request(args.file, AnalysisRequest))
    if args.json:
        print(dumps(result))
    else:
        print(render_melnikov(result.melnikov))
        print(f"Numerical verdict: {numerics_line(result)}")
        print(f"  {result.verdict.summary}")
        print(f"  forcing period T0 = {fmt_value(result.numerics.forcing_period)}")
        line = floquet_line(result)
        if line is not None:
            print(f"  {line}")
        for note in result.numerics.notes:
            print(f"  note: {note}")
        if result.engineering is not None:
            print(render_engineering(result.engineering))
    return EXIT_OK


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
    return (
        f"Floquet multipliers {lams}; stability margin {fl.stability_margin:.4g} "
        f"(nearest bifurcation: {fl.nearest_bifurcation})"
    )


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


def failures(
    r: AnalysisResult, fail_on: list[str], max_lle: float | None, min_margin: float | None = None
) -> list[str]:
    """Reasons the design fails the gate (empty: pass)."""
    worst = r.numerics.worst_case.classification
    reasons = [
        f"--fail-on {f}" for f in fail_on if f in SEVERITY and SEVERITY[worst] >= SEVERITY[f]
    ]
    if "impacts" in fail_on and r.numerics.impact_regime == "double_sided":
        reasons.append("--fail-on impacts")
    if "melnikov" in fail_on and r.melnikov.chaos_possible:
        reasons.append("--fail-on melnikov")
    lle = r.numerics.worst_case.lle
    if max_lle is not None and (lle is None or lle > max_lle):
        reasons.append(f"--max-lle {max_lle:g}")
    margin = None if min_margin is None else margin_failure(r, min_margin)
    if margin is not None:
        reasons.append(margin)
    return reasons


def cmd_check(args: argparse.Namespace) -> int:
    """CI gate: exit 0 pass, 1 fail, 2 invalid input; one summary line. With --speed or
    --torque, the gate over the operating envelope (``cli.envelope``)."""
    if args.speed or args.torque:
        return cmd_envelope(args)
    envelope_only = (args.max_dte, args.starts, args.min_basin)
    if any(v is not None for v in envelope_only) or args.json or args.junit or args.server:
        raise InvalidInputError(
            [
                "--max-dte, --starts, --min-basin, --json, --junit and --server check an "
                "envelope: give --speed LOW:HIGH (rpm) and/or --torque LOW:HIGH (N m)"
            ]
        )
    result = analyze(read_request(args.file, AnalysisRequest))
    fail_on = args.fail_on or ["chaotic"]  # the limits add to the classes, never replace them
    reasons = failures(result, fail_on, args.max_lle, args.min_stability_margin)
    verdict = "FAIL" if reasons else "PASS"
    why = f" [{', '.join(reasons)}]" if reasons else ""
    print(f"{verdict}: {numerics_line(result)}{why}")
    return EXIT_FAIL if reasons else EXIT_OK
