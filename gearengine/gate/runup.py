"""The run-up in the CI gate (``gearengine check ... --runup 1000``): a run-up and run-down
through the envelope's speed range at each torque level, failing on the envelope's rules.

Rules on the bins of each branch (``gate.rules.Rules``): ``chaotic`` in ``fail_on`` fails a
run of chaotic bins (ensemble FTLE clearly positive, or above ``max_lle`` when given) that lasts
longer than ``chaos_seconds``: a ramp crossing a chaotic window quickly may pass, one lingering
in it fails. ``back_flank`` (or ``impacts``) fails back-flank impacts, ``separation`` any loss
of contact, ``max_dte_um`` and ``max_dynamic_factor`` their limits, each bin by itself.
Failures name the branch and the speeds.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from gearengine.gate.envelope import EnvelopeReport, FailingWindow, RunupCheck
from gearengine.gate.rules import Rules
from gearengine.model.units import RPM, display_unit, in_display_unit, shown
from gearengine.numerics.attractors import IMPACT_TEXT
from gearengine.studies.runup.compute import run_local
from gearengine.studies.runup.profile import validated_runup
from gearengine.studies.runup.reading import transient_chaos
from gearengine.studies.runup.request import RunupRequest, widest_bin_rpm
from gearengine.studies.runup.results import RunupBin, RunupResult
from gearengine.studies.sweep.points import PhysicalValue
from gearengine.studies.sweep.request import SweepRequest
from gearengine.studies.sweep.windows import SPEED, runs

CHAOS_SECONDS = 0.05
"""Longest time a run-up may spend in chaotic bins before the gate fails it [s]."""
GATE_ENSEMBLE = 4
"""Ensemble members of a gate's run-up (the FTLE's standard error over 4 starts)."""


def bin_failures(b: RunupBin, rules: Rules) -> list[str]:
    """The per-bin rules a bin breaks (chaos is judged over runs, see ``runup_failures``); a
    bin where a member diverged (no LLE, or no contact verdict) fails whatever ``fail_on``
    says: the gate cannot vouch for a response the model could not follow."""
    out = ["diverged"] if b.lle is None or b.contact is None else []
    if "back_flank" in rules.fail_on and (b.back_flank_impacts or 0) > 0:
        out.append(IMPACT_TEXT["double_sided"])
    if "separation" in rules.fail_on and (b.separation_fraction or 0) > 0:
        out.append(IMPACT_TEXT["single_sided"])
    if rules.max_dte_um is not None and (
        b.dte_peak_to_peak_um is None or b.dte_peak_to_peak_um > rules.max_dte_um
    ):
        out.append(f"DTE > {rules.max_dte_um:g} µm")
    if rules.max_dynamic_factor is not None and (
        b.dynamic_factor is None or b.dynamic_factor > rules.max_dynamic_factor
    ):
        out.append(f"dynamic factor > {rules.max_dynamic_factor:g}")
    return out


def _chaotic(b: RunupBin, rules: Rules) -> bool:
    if b.lle is None:
        return True  # a diverged member: worse than chaos
    return b.lle > rules.max_lle if rules.max_lle is not None else bool(b.chaotic)


def runup_failures(
    result: RunupResult, rules: Rules, level: dict[str, PhysicalValue],
    chaos_seconds: float = CHAOS_SECONDS,
) -> list[FailingWindow]:  # fmt: skip
    """The failing windows of one run-up at one torque ``level``."""
    out: list[FailingWindow] = []
    for name in ("up", "down"):
        branch = getattr(result, name)
        if branch is None:
            continue
        bins = sorted(branch.bins, key=lambda b: b.speed_rpm[0])
        starts = [b.speed_rpm[0] for b in bins]
        broken = [bin_failures(b, rules) for b in bins]
        for rule in dict.fromkeys(r for f in broken for r in f):
            for lo, hi in runs(starts, [rule if rule in f else None for f in broken]).get(rule, []):
                top = next(b.speed_rpm[1] for b in bins if b.speed_rpm[0] == hi)
                out.append(FailingWindow(level=level, rule=f"run-{name}: {rule}",
                                         speeds_rpm=[lo, top]))  # fmt: skip
        if "chaotic" not in rules.fail_on and rules.max_lle is None:
            continue
        flags = ["chaos" if _chaotic(b, rules) else None for b in bins]
        transient = transient_chaos(branch, getattr(result.quasi_static, name))
        for lo, hi in runs(starts, flags).get("chaos", []):
            inside = [b for b in bins if lo <= b.speed_rpm[0] <= hi]
            seconds = sum(b.time_s[1] - b.time_s[0] for b in inside)
            if seconds > chaos_seconds:
                what = "FTLE clearly positive" if rules.max_lle is None else (
                    f"FTLE > {rules.max_lle:g} per unit tau")  # fmt: skip
                rule = f"run-{name}: chaotic ({what}) for {seconds:.3g} s"
                if all(any(a <= b.speed_rpm[0] < z for a, z in transient) for b in inside):
                    rule += (
                        " where the quasi-static continuation (one start followed from "
                        "speed to speed) is not chaotic: the ramp's transient, or an "
                        "attractor it does not follow"
                    )
                out.append(FailingWindow(level=level, rule=rule,
                                         speeds_rpm=[lo, inside[-1].speed_rpm[1]]))  # fmt: skip
    return out


@dataclass(frozen=True)
class GateRunups:
    """The run-ups of ``check --runup``, validated before the envelope is computed: the ramp's
    rate [rpm/s], [lowest, highest] speed [rpm] and bin width [rpm] as shown, and one run-up and
    run-down (``requests``) a level of ``levels``."""

    rate_rpm_s: float
    speeds_rpm: list[float]
    bin_rpm: float
    levels: list[dict[str, PhysicalValue]]
    requests: list[RunupRequest]


def gate_runups(sweep: SweepRequest, rate_rpm_s: float) -> GateRunups:
    """A run-up and run-down at ``rate_rpm_s`` [rpm/s] through the envelope sweep's speed range
    at each torque level of its grid (the levels of the sweep's speed windows), each validated
    (``validated_runup``) so that a bad ramp is refused before any compute: ``ValidationError``
    naming the field, ``ValueError`` for an envelope without a speed range.

    Bins are the grid step, at most a quarter of the range (``widest_bin_rpm``) and at most
    half ``CHAOS_SECONDS`` of ramp each, so that the chaos rule is resolved: the grid's 227 rpm
    bins (0.114 s at 2000 rpm/s) hid a run-down chaotic over 4900-5650 rpm that 50 rpm bins
    show, and the verdict changed with --speed-points. The sweep's design is validated already
    (every corner of its grid, ``request_errors``): each level's run-up carries it, at the
    level's torque, as the validated ``Design`` it is, not as a document to read again."""
    design = sweep.design
    assert design is not None
    levels = torque_levels(sweep)
    axis = next((a for a in sweep.axes if a.parameter == SPEED), None)
    grid = [] if axis is None else axis.values(design)
    if axis is None or axis.num < 2 or not grid[0] < grid[-1]:
        raise ValueError("give the envelope a speed range, --speed LOW:HIGH")
    lo, hi = grid[0] / RPM, grid[-1] / RPM
    ramp = {
        "from_speed": f"{lo!r} rpm", "to_speed": f"{hi!r} rpm",
        "rate": f"{rate_rpm_s!r} rpm/s", "direction": "up_down",
        "bin_rpm": min((hi - lo) / (axis.num - 1), widest_bin_rpm(lo, hi),
                       rate_rpm_s * CHAOS_SECONDS / 2),
        "ensemble": {"size": GATE_ENSEMBLE},
    }  # fmt: skip
    requests = [validated_runup({"design": design if not level else design.model_copy(
                    update={"torque": level["torque"].value}), **ramp})
                for level in levels]  # fmt: skip
    return GateRunups(rate_rpm_s=rate_rpm_s, speeds_rpm=[shown(lo), shown(hi)],
                      bin_rpm=shown(ramp["bin_rpm"]), levels=levels,
                      requests=requests)  # fmt: skip


def torque_levels(sweep: SweepRequest) -> list[dict[str, PhysicalValue]]:
    """The torque levels of the envelope grid, ascending, as its speed windows name them
    (``studies.sweep.windows``: the torque in its display unit); one empty level when the
    envelope has no torque axis (the design's torque)."""
    axis = next((a for a in sweep.axes if a.parameter == "torque"), None)
    if axis is None or sweep.design is None:
        return [{}]
    unit = display_unit("torque")[0]
    return [{"torque": PhysicalValue(value=in_display_unit("torque", t), unit=unit)}
            for t in sorted(set(axis.values(sweep.design)))]  # fmt: skip


def gate_envelope(
    report: EnvelopeReport, runups: GateRunups,
    progress: Callable[[int, int], None] | None = None, workers: int = 1,
) -> EnvelopeReport:  # fmt: skip
    """``report`` with the failing windows of ``runups`` (``gate_runups``), and what ran
    (``runup``)."""
    found: list[FailingWindow] = []
    levels = runups.levels
    for k, (level, request) in enumerate(zip(levels, runups.requests, strict=True)):
        found += runup_failures(run_local(request, workers=workers), report.rules, level)
        if progress is not None:
            progress(k + 1, len(levels))
    ran = RunupCheck(rate_rpm_s=runups.rate_rpm_s, speeds_rpm=runups.speeds_rpm,
                     directions=["up", "down"], bin_rpm=runups.bin_rpm,
                     ensemble=GATE_ENSEMBLE, levels=levels,
                     failing_windows=len(found))  # fmt: skip
    failures = [*report.failures, *found]
    return report.model_copy(update={"failures": failures, "passed": not failures, "runup": ran})
