"""``gearengine melnikov FILE [--json] [--method closed_form|quadrature]``: the Melnikov
verdict as a readable table, or the API's JSON."""

from __future__ import annotations

import argparse

from gearengine.cli.documents import EXIT_OK, read_request
from gearengine.homoclinic.schemas import MelnikovRequest, MelnikovResult, ParameterThreshold
from gearengine.homoclinic.verdict import melnikov
from gearengine.jsonio import dumps


def fmt_value(v: float | None) -> str:
    """A number in 6 significant digits, ``-`` for none."""
    return "-" if v is None else f"{v:.6g}"


def _threshold_row(name: str, t: ParameterThreshold) -> str:
    crit = ", ".join(fmt_value(v) for v in t.critical_values) or (t.note or "none")
    margin = "-"
    if t.margin is not None:
        margin = f"{t.margin:+.4g}"
        if t.relative_margin is not None:
            margin += f" ({100 * t.relative_margin:+.1f}%)"
    return f"  {name:<8} {fmt_value(t.value):>10}  {crit:<36} {fmt_value(t.nearest):>10}  {margin}"


def render_melnikov(r: MelnikovResult) -> str:
    """Readable verdict table of a Melnikov result."""
    if not r.applicable:
        return "Melnikov criterion not applicable\n" + "\n".join(f"  note: {n}" for n in r.notes)
    verdict = "POSSIBLE" if r.chaos_possible else "not possible"
    lines = [
        f"Melnikov verdict: chaos {verdict} "
        f"({'transverse' if r.chaos_possible else 'no transverse'} homoclinic intersection)",
        f"  cubic law f_h = -{r.a:g} x + {r.c:g} x^3, "
        f"forcing period T0 = {fmt_value(r.forcing_period)}",
        "  branch  sign change       min M         max M   extrema",
    ]
    for name, b in (r.branches or {}).items():
        change = "yes" if b.sign_change else "no"
        lines.append(f"  {name:<7} {change:<11} {b.min:>13.6g} {b.max:>13.6g}   {b.extrema}")
    lines.append(f"  {'param':<8} {'value':>10}  {'critical values':<36} {'nearest':>10}  margin")
    lines += [_threshold_row(name, t) for name, t in r.thresholds.items()]
    lines += [f"  note: {n}" for n in r.notes]
    return "\n".join(lines)


def cmd_melnikov(args: argparse.Namespace) -> int:
    req = read_request(args.file, MelnikovRequest)
    result = melnikov(req.params, method=args.method or req.method)
    print(dumps(result) if args.json else render_melnikov(result))
    return EXIT_OK
