"""``gearengine melnikov FILE [--json] [--method ...] [--mean-load ...]``: the Melnikov
verdict as a readable table, or the API's JSON."""

from __future__ import annotations

import argparse

from gearengine.analysis import MelnikovAnswer, answer_melnikov
from gearengine.cli.documents import EXIT_OK, read_request
from gearengine.engineering.block import Engineering
from gearengine.homoclinic.schemas import MelnikovRequest, MelnikovResult, ParameterThreshold
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


def render_engineering(eng: Engineering) -> str:
    """The engineering block of a design as readable lines (gear units)."""
    windows = ", ".join(f"{a:,.0f}-{b:,.0f}" for a, b in eng.speed_windows_rpm) or "none"
    if eng.speed_windows_note:
        windows += f" ({eng.speed_windows_note})"
    lo, hi = eng.speed_range_rpm
    natural = f"f_n = {eng.natural_frequency_hz:.6g} Hz"
    if eng.modes is not None:  # a train: its mesh mode; f_n is its stiff limit's
        mesh = eng.modes.modes[eng.modes.mesh_mode]
        share = f"{mesh.mesh_energy_share:.0%}"
        natural = (f"the train's mesh mode {mesh.frequency_hz:.6g} Hz, {share} of its strain "
                   f"energy in the mesh; {natural} of its stiff limit")  # fmt: skip
    lines = [
        f"In gear units ({natural}, mesh {eng.mesh_frequency_hz:.6g} Hz at "
        f"{eng.speed_rpm:,.0f} rpm):",
        f"  Melnikov speed windows [rpm] (scanned {lo:,.0f}-{hi:,.0f}): {windows}",
    ]
    if eng.critical:
        lines.append(f"  {'parameter':<36} {'value':>12} {'nearest critical':>17} "
                     f"{'margin to chaos':>16}")  # fmt: skip
    if eng.critical_torque_nm is not None:
        lines.insert(
            2, f"  critical torque T_crit = {eng.critical_torque_nm:,.4g} N*m (the criterion "
            "applies below it)"
        )  # fmt: skip
    for name, c in eng.critical.items():
        lines.append(
            f"  {name + ' [' + c.unit + ']':<36} {fmt_value(c.value):>12} "
            f"{fmt_value(c.nearest):>17} {fmt_value(c.margin_to_chaos):>16}"
        )
    if any(not c.critical_values for c in eng.critical.values()):
        lines.append("  -: no value of that parameter alone flips the verdict (the other "
                     "excitations keep it where it is)")  # fmt: skip
    lines.append(f"  {eng.summary}")
    return "\n".join(lines)


def cmd_melnikov(args: argparse.Namespace) -> int:
    """Print the Melnikov verdict of a request file (with a design, in gear units too)."""
    req = read_request(args.file, MelnikovRequest)
    if args.method:
        req = req.model_copy(update={"method": args.method})
    if getattr(args, "mean_load", None):
        req = req.model_copy(update={"mean_load": args.mean_load})
    result = answer_melnikov(req)
    if args.json:
        print(dumps(result))
        return EXIT_OK
    print(render_melnikov(result))
    if isinstance(result, MelnikovAnswer) and result.engineering is not None:
        print(render_engineering(result.engineering))
    return EXIT_OK
