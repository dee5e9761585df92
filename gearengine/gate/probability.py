"""The probability gate's report (``gearengine check ... --max-probability chaotic=0.01``): per
operating point its verdict (pass, fail or undecided), the reasons, and for each limit the
Clopper-Pearson interval the verdict read at the confidence it decided at (95 % for a fixed
``--samples N``, one look; 1 - 0.05 / looks for ``--samples auto``, ``sequential``), with the
robustness result it was read from, as the envelope gate's report carries its sweep.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from gearengine.model.units import display_unit
from gearengine.studies.robustness.results import Probability, RobustnessPoint, RobustnessResult
from gearengine.studies.robustness.sequential import (
    ERROR,
    Verdict,
    combined,
    decision_interval,
)
from gearengine.studies.robustness.tolerances import probability
from gearengine.studies.sweep.points import PhysicalValue

ONE_LOOK = 1.0 - ERROR
"""The confidence of one look (a fixed sample count): the results' 95 % intervals."""
FOLLOWED_ONLY = ("periodic", "quasi_periodic", "chaotic", "separation", "back_flank",
                 "dynamic_factor_above_limit")  # fmt: skip
"""Outcomes a diverged sample leaves unknown (no class, contact or force: the model could not
follow it); P(diverged) and P(melnikov_chaos_possible) are known for every sample."""


class LimitVerdict(BaseModel):
    """One probability limit at one operating point, as the verdict read it."""

    model_config = ConfigDict(frozen=True)

    limit: float = Field(description="The largest probability allowed.")
    verdict: Verdict = Field(
        description="pass: the upper bound is at or below the limit, diverged samples counted "
        "as the outcome; fail: the lower bound is above it; undecided: the interval holds the "
        "limit (or no samples), or the diverged samples could break it."
    )
    count: int = Field(description="Samples k with the outcome.")
    samples: int = Field(description="Samples n counted.")
    interval: list[float] | None = Field(
        description="The Clopper-Pearson interval [low, high] the verdict read, at confidence "
        "(null without samples)."
    )
    confidence: float = Field(
        description="The confidence of interval: 0.95 for a fixed sample count, 0.993 for a "
        "look of --samples auto (the 5 % error shared over its looks)."
    )


class PointVerdict(BaseModel):
    """The gate's verdict at one operating point."""

    model_config = ConfigDict(frozen=True)

    point: dict[str, PhysicalValue] = Field(description="The operating point in gear units.")
    verdict: Verdict = Field(
        description="fail: a limit's lower bound is above it; pass: every upper bound is at or "
        "below its limit; else undecided (fails the gate: it proves nothing)."
    )
    reasons: list[str] = Field(description="The limits not proved, in words (as the text).")
    limits: dict[str, LimitVerdict] = Field(description="Per limited probability.")
    samples: int = Field(description="Samples counted at this point.")
    starts_per_sample: int = Field(description="Initial states each sample ran.")


class ProbabilityReport(BaseModel):
    """The verdict of the probability gate (``gearengine check --max-probability``)."""

    model_config = ConfigDict(frozen=True)

    passed: bool = Field(description="True when every point passes (none fails or is undecided).")
    limits: dict[str, float] = Field(description="The largest probability allowed, per event.")
    confidence: float = Field(description="The confidence every verdict decided at.")
    points: int = Field(description="Operating points checked.")
    failing_points: int = Field(description="Points over a limit.")
    undecided_points: int = Field(description="Points whose intervals hold a limit.")
    verdicts: list[PointVerdict] = Field(description="Per operating point, as result.points.")
    notes: list[str] = Field([], description="How the samples were taken, where it needs saying.")
    result: RobustnessResult = Field(description="The robustness result (95 % intervals).")


ONE_START = (
    "each sample is judged from the settings' own start, not as the worst attractor of the 16 "
    "starts the envelope check runs a point: another attractor of a sample may be chaotic; "
    "--starts 16 judges each sample by its worst of 16 starts, at 17x the work"
)
"""The probability gate's words for one start a sample (its default, chosen for its cost)."""


def sampling_notes(result: RobustnessResult, limits: dict[str, float]) -> list[str]:
    """What the gate says of how its samples were judged: from one start each (``ONE_START``),
    and what the event dynamic_factor_above_limit counts, with the study's limit, where it is
    limited (the name alone never said 1.5)."""
    told = [ONE_START] if result.starts_per_sample == 1 else []
    if "dynamic_factor_above_limit" in limits:
        told.append(f"dynamic_factor_above_limit: the largest dynamic mesh force above "
                    f"{result.dynamic_factor_limit:g} times the static force (the study's "
                    "dynamic_factor_limit)")  # fmt: skip
    return told


def at_confidence(confidence: float) -> str:
    """ " at 95 %", " at 99.3 %": the confidence a bound was read at, in the reasons."""
    return f" at {100 * confidence:.3g} %"


def proofs(point: RobustnessPoint, verdict: PointVerdict) -> list[str]:
    """The upper bounds that prove a passing point's limits, in words: "P(chaotic) upper
    bound at 95 % 0.0457 <= 0.05 (0/64 samples)" (a pass said nothing of its bound)."""
    out = []
    for name, read in verdict.limits.items():
        if read.verdict == "pass" and read.interval is not None:
            prob = point.probabilities[name]
            out.append(f"P({name}) upper bound{at_confidence(read.confidence)} "
                       f"{read.interval[1]:.3g} <= {read.limit:g} ({prob.count}/{prob.samples} "
                       "samples)")  # fmt: skip
    return out


def unfollowed(point: RobustnessPoint, name: str, limit: float,
               confidence: float = ONE_LOOK) -> str | None:  # fmt: skip
    """Why a limit the followed samples prove is not proved: its diverged samples, counted as
    the outcome (``FOLLOWED_ONLY``: whatever they did, unseen), put the upper bound above the
    limit; None when no sample diverged, the outcome is known for them, the limit is not
    proved anyway, or proved even were every diverged sample the outcome. A diverged sample
    never turns a fail into a pass: the lower bound counts the followed events alone."""
    d, prob = point.probabilities["diverged"].count, point.probabilities[name]
    ci = decision_interval(prob, confidence)
    if not d or name not in FOLLOWED_ONLY or ci is None or ci[1] > limit:
        return None
    worst = Probability.model_validate(probability(prob.count + d, prob.samples))
    high = decision_interval(worst, confidence)[1]  # type: ignore[index]
    if high <= limit:
        return None
    return (f"P({name}) undecided: {d} of {prob.samples} samples diverged (the model could not "
            f"follow them); counted as {name}, the upper bound{at_confidence(confidence)} is "
            f"{high:.3g} > {limit:g}")  # fmt: skip


def read_limit(point: RobustnessPoint, name: str, limit: float,
               confidence: float = ONE_LOOK) -> tuple[LimitVerdict, str | None]:  # fmt: skip
    """One limit at a point, read once: its verdict and, where the limit is not proved, why in
    words: over (the lower bound above the limit), undecided (the interval holds the limit, or
    no samples) or undecided by the diverged samples (``unfollowed``: a pass proved on the
    followed samples alone). The interval is the one the verdict read, at ``confidence``
    (``sequential.decision_interval``), and the words name it (a fixed count's 95 % too): the
    verdict and its words come from one reading and cannot disagree."""
    prob = point.probabilities[name]
    ci = decision_interval(prob, confidence)
    at, counted = at_confidence(confidence), f"({prob.count}/{prob.samples} samples)"
    said: Verdict = "undecided"
    if ci is None:
        why: str | None = f"P({name}) undecided: no samples"
    elif ci[0] > limit:
        said, why = "fail", f"P({name}) lower bound{at} {ci[0]:.3g} > {limit:g} {counted}"
    elif ci[1] > limit:
        why = f"P({name}) undecided: upper bound{at} {ci[1]:.3g} > {limit:g} {counted}"
    else:
        why = unfollowed(point, name, limit, confidence)
        said = "pass" if why is None else "undecided"
    read = LimitVerdict(limit=limit, verdict=said, count=prob.count, samples=prob.samples,
                        interval=ci, confidence=confidence)  # fmt: skip
    return read, why


def point_verdict(point: RobustnessPoint, limits: dict[str, float], confidence: float,
                  starts: int, units: dict[str, str] | None,
                  own: dict[str, PhysicalValue] | None = None) -> PointVerdict:  # fmt: skip
    """One point's verdict under ``limits`` at ``confidence``: each limit's (``read_limit``),
    combined once (``sequential.combined``: a pass proved on the followed samples alone, not
    on the diverged ones, is undecided), its values in ``units`` (the result's
    ``shown_units``, else ``display_unit``); a study without axes named by ``own`` (the
    design's speed and torque) instead of an empty point."""
    read, reasons = {}, []
    for name, limit in limits.items():
        read[name], why = read_limit(point, name, limit, confidence)
        if why is not None:
            reasons.append(why)
    shown = {k: PhysicalValue(value=v, unit=(units or {}).get(k) or display_unit(k)[0])
             for k, v in point.shown.items()} or dict(own or {})  # fmt: skip
    overall = combined(r.verdict for r in read.values())
    return PointVerdict(point=shown, verdict=overall, reasons=reasons, limits=read,
                        samples=point.samples, starts_per_sample=starts)  # fmt: skip


def probability_report(result: RobustnessResult, limits: dict[str, float],
                       confidence: float = ONE_LOOK, notes: list[str] | None = None,
                       own: dict[str, PhysicalValue] | None = None
                       ) -> ProbabilityReport:  # fmt: skip
    """The gate's report of ``result`` under ``limits``, each verdict read at ``confidence``;
    ``own`` names the point of a study without axes (``point_verdict``)."""
    verdicts = [point_verdict(p, limits, confidence, result.starts_per_sample,
                              result.shown_units, own) for p in result.points]  # fmt: skip
    said = [v.verdict for v in verdicts]
    return ProbabilityReport(
        passed=all(v == "pass" for v in said), limits=limits, confidence=confidence,
        points=len(said), failing_points=said.count("fail"),
        undecided_points=said.count("undecided"), verdicts=verdicts, notes=notes or [],
        result=result,
    )  # fmt: skip
