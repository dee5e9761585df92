"""``gearengine analyze FILE [--json]`` and the CI gate ``gearengine check FILE``.

``check`` exits 0 when the design passes, 1 when it fails a rule, 2 on invalid input;
``--fail-on X`` fails on X or anything worse (``numerics.classify.SEVERITY``).
"""

from __future__ import annotations

import argparse

from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
from gearengine.cli.documents import EXIT_FAIL, EXIT_OK, read_request
from gearengine.cli.melnikov import fmt_value, render_melnikov
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
        for note in result.numerics.notes:
            print(f"  note: {note}")
    return EXIT_OK


def failures(r: AnalysisResult, fail_on: list[str], max_lle: float | None) -> list[str]:
    """Reasons the design fails the gate (empty: pass)."""
    worst = r.numerics.worst_case.classification
    reasons = [
        f"--fail-on {f}" for f in fail_on if f != "melnikov" and SEVERITY[worst] >= SEVERITY[f]
    ]
    if "melnikov" in fail_on and r.melnikov.chaos_possible:
        reasons.append("--fail-on melnikov")
    lle = r.numerics.worst_case.lle
    if max_lle is not None and (lle is None or lle > max_lle):
        reasons.append(f"--max-lle {max_lle:g}")
    return reasons


def cmd_check(args: argparse.Namespace) -> int:
    """CI gate: exit 0 pass, 1 fail, 2 invalid input; one summary line."""
    result = analyze(read_request(args.file, AnalysisRequest))
    default = [] if args.max_lle is not None else ["chaotic"]  # a bare --max-lle stands alone
    reasons = failures(result, args.fail_on or default, args.max_lle)
    verdict = "FAIL" if reasons else "PASS"
    why = f" [{', '.join(reasons)}]" if reasons else ""
    print(f"{verdict}: {numerics_line(result)}{why}")
    return EXIT_FAIL if reasons else EXIT_OK
