"""The envelope gate's report in words, as ``gearengine check --speed/--torque`` prints it: the
verdict with the rules as options, why the Melnikov criterion judges no point where it does not,
the failing windows, and per level of the other axis the impact and Melnikov windows in rpm
(``level_text`` and ``window_text`` name a level and a window, as the report's own notes do).
"""

from __future__ import annotations

from gearengine.gate.envelope import EnvelopeReport, level_text, window_text
from gearengine.gate.rules import Rules
from gearengine.homoclinic.train_reduction import ABOVE_T_CRIT
from gearengine.model.units import POINT_OUTPUTS
from gearengine.numerics.attractors import IMPACT_TEXT
from gearengine.studies.sweep.points import SpeedWindows
from gearengine.studies.sweep.windows import SPEED


def report_lines(report: EnvelopeReport, why: tuple[str, str] = ABOVE_T_CRIT) -> list[str]:
    """PASS or FAIL, then the notes, what was checked, one line per failing window (rpm and
    N m) and each level's windows; ``why`` says why Melnikov judges no point where it does not
    (``homoclinic.train_reduction.not_judged_reason`` of the design: short, whole)."""
    verdict = "PASS" if report.passed else "FAIL"
    short, reason = why
    lines = [f"{verdict}: {report.failing_points} of {report.points} operating points break "
             f"the rules ({rules_text(report.rules)})"]  # fmt: skip
    if "melnikov" in report.rules.fail_on and report.melnikov_not_judged:
        lines.append(f"  Melnikov could not judge {report.melnikov_not_judged} of "
                     f"{report.points} points ({reason})")  # fmt: skip
    lines += [f"  note: {note}" for note in report.notes]
    if report.resolution is not None:
        lines.append(f"  resolution: {report.resolution.text()}")
    if report.runup is not None:
        lines.append(f"  run-ups: {report.runup.text()}")
    lines += [f"  {window_text(w)}" for w in report.failures]
    return lines + [f"  {line}" for line in windows_summary(report.windows, short, report)]


def rules_text(rules: Rules) -> str:
    """The rules as options: "--fail-on chaotic, --max-dte 20 µm"."""
    parts = [f"--fail-on {f}" for f in rules.fail_on]
    if rules.max_lle is not None:
        parts.append(f"--max-lle {rules.max_lle:g} per unit tau")
    if rules.max_dte_um is not None:
        parts.append(f"--max-dte {rules.max_dte_um:g} µm")
    if rules.max_dynamic_factor is not None:
        parts.append(f"--max-dynamic-factor {rules.max_dynamic_factor:g}")
    if rules.min_basin is not None:
        parts.append(f"--min-basin {rules.min_basin:g}")
    return ", ".join(parts)


def refined_levels(report: EnvelopeReport) -> dict[str, str]:
    """The speeds checked at each torque level refined between the grid's (by its
    ``level_text``): "refined level, checked at 3 speeds in 4636-4864 rpm" (the grid's levels
    are checked over the whole range)."""
    grid = {level_text(w.level) for w in report.sweep.windows or []}
    speeds: dict[str, list[float]] = {}
    for w in report.windows:
        if level_text(w.level) not in grid:
            speeds[level_text(w.level)] = []
    for p in report.refined:
        level = level_text({k: v for k, v in (p.physical or {}).items()
                            if k not in (SPEED, *POINT_OUTPUTS)})  # fmt: skip
        if level in speeds and p.physical is not None:
            speeds[level].append(p.physical[SPEED].value)
    return {level: f"refined level, checked at {len(v)} speed{'s' if len(v) != 1 else ''} "
            f"in {spans_text([[min(v), max(v)]])}" for level, v in speeds.items() if v}  # fmt: skip


def windows_summary(windows: list[SpeedWindows], reason: str = "above T_crit",
                    report: EnvelopeReport | None = None) -> list[str]:  # fmt: skip
    """Per level of the other axis, the impact and Melnikov windows in rpm, pass or fail:
    "windows at torque 40 N*m: tooth separation 500-1100 rpm; Melnikov:
    chaos possible nowhere" ("teeth always in contact" only where no point diverged: a
    diverged point has no contact verdict); ``reason`` says why Melnikov does not apply where
    it does not (``not_judged_reason``); ``report`` (whose windows these are) says over which
    speeds a level refined between the grid's was checked (``refined_levels``): "windows at
    torque 8.44 N*m (refined level, checked at 3 speeds in 4636-4864 rpm): ..."."""
    refined = {} if report is None else refined_levels(report)
    out = []
    for w in windows:
        parts = [f"{CONTACT_LABELS[k]} {spans_text(v)}" for k, v in w.contact.items()]
        if "diverged" in w.response:  # no contact verdict there: never "always in contact"
            parts.append(f"diverged (contact unknown) {spans_text(w.response['diverged'])}")
        contact = "; ".join(parts)
        melnikov = f"chaos possible {spans_text(w.melnikov) if w.melnikov else 'nowhere'}"
        if w.melnikov_not_applicable:
            na = f"not applicable at {spans_text(w.melnikov_not_applicable)} ({reason})"
            melnikov = f"{melnikov}, {na}" if w.melnikov else na
        level = level_text(w.level)
        where = f" at {level}" if w.level else ""
        if level in refined:
            where += f" ({refined[level]})"
        out.append(f"windows{where}: {contact or 'teeth always in contact'}; "
                   f"Melnikov: {melnikov}")  # fmt: skip
    return out


CONTACT_LABELS = {
    "separation": IMPACT_TEXT["single_sided"],
    "back_flank": IMPACT_TEXT["double_sided"],
}
"""The contact of a speed window (``SpeedWindows.contact``) in the gate's words."""


def spans_text(spans: list[list[float]]) -> str:
    """ "500-1100, 3000 rpm": speed runs [first, last] in rpm."""
    return ", ".join(f"{a:g}" if a == b else f"{a:g}-{b:g}" for a, b in spans) + " rpm"
