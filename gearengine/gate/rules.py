"""The rules an operating point of the gate is judged by (``Rules``), for its own verdict and
for each of its attractors above ``min_basin``, and when a point is near a limit (where the
envelope gate refines, ``gate.envelope``).

Rules: ``fail_on`` classes (``chaotic`` fails chaotic and diverged points, ordered
periodic < quasi_periodic < chaotic < diverged as in ``signals.classify.SEVERITY``),
``melnikov`` (the criterion allows chaos), ``back_flank`` (back-flank impacts), ``separation``
(the teeth separate: drive-flank impacts, or impacts on both flanks) - the words of the
robustness probabilities P(separation), P(back_flank); the old word ``impacts``, which meant
back_flank here and separation in P(...), is refused (``IMPACTS_REFUSED``); and numeric limits,
which add to the classes instead of replacing them: ``max_lle`` (per unit tau), ``max_dte_um``
(dynamic transmission error peak to peak, µm), ``max_dynamic_factor`` (largest mesh force over
the static force F~_m). With basins (``settings.basins``) every attractor of a point whose
basin fraction is above ``min_basin`` is checked against the rules, and a failing window names
the attractors that broke it with their fractions; a point that diverged, or whose starts
reached no attractor, is judged by its own verdict too. A diverged verdict fails whatever the
rules: the gate cannot vouch for a response the model could not follow.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from gearengine.model.errors import InputError
from gearengine.model.units import IMPACTS_REFUSED, OUTPUTS
from gearengine.numerics.attractors import IMPACT_TEXT
from gearengine.numerics.results import Attractor
from gearengine.signals.classify import SEVERITY
from gearengine.studies.sweep.points import PhysicalValue, SweepPoint
from gearengine.studies.sweep.windows import SEPARATING

FailOn = Literal["chaotic", "quasi_periodic", "diverged", "melnikov", "back_flank", "separation"]


class Rules(BaseModel):
    """What fails the gate at a grid point; a limit is a finite number (nan, with which no
    comparison is true, passed every point)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    fail_on: list[FailOn] = Field(
        default_factory=lambda: ["chaotic"],
        description="Classes that fail (and anything worse), melnikov, back_flank (back-flank "
        "impacts), separation (the teeth separate: drive-flank or back-flank impacts), as the "
        "robustness probabilities name them. The old word impacts is refused: write back_flank "
        "or separation.",
    )
    max_lle: float | None = Field(
        None, allow_inf_nan=False, description="Largest LLE allowed, per unit tau."
    )
    max_dte_um: float | None = Field(
        None, gt=0.0, allow_inf_nan=False,
        description="Largest DTE peak to peak [µm], above 0 (a peak to peak is never below 0: "
        "a limit at or under 0 would fail every point).",
    )  # fmt: skip
    max_dynamic_factor: float | None = Field(
        None, gt=1.0, allow_inf_nan=False,
        description="Largest dynamic factor allowed: max mesh force / static force, above 1 (the "
        "largest force is at least the mean, the static force: a limit at or under 1 would fail "
        "every point).",
    )  # fmt: skip
    min_basin: float | None = Field(
        None,
        ge=0.0,
        lt=1.0,
        description="With basins: only attractors whose basin fraction is above this are "
        "checked; null checks every attractor found.",
    )

    @model_validator(mode="before")
    @classmethod
    def _refuse_impacts(cls, data: object) -> object:
        """The old word ``impacts`` meant two things (``IMPACTS_REFUSED``): refused, naming
        its place (``fail_on.1``), before the list of words would answer with the words alone."""
        words = data.get("fail_on") if isinstance(data, dict) else None
        if isinstance(words, list) and "impacts" in words:
            raise InputError(f"fail_on.{words.index('impacts')}", IMPACTS_REFUSED)
        return data


def point_failures(p: SweepPoint, rules: Rules) -> list[str]:
    """The rules one point of a sweep breaks (``verdict_failures`` of its verdict)."""
    physical = p.physical or {}
    dte, factor = physical.get("dte"), physical.get("dynamic_factor")
    return verdict_failures(
        rules,
        p.classification,
        p.lle,
        p.impact_regime,
        p.melnikov_chaos_possible,
        dte_um=None if dte is None else dte.value,
        dynamic_factor=None if factor is None else factor.value,
    )


def verdict_failures(
    rules: Rules,
    classification: str,
    lle: float | None,
    impact_regime: str | None,
    melnikov_chaos_possible: bool | None,
    dte_um: float | None = None,
    dynamic_factor: float | None = None,
) -> list[str]:
    """The rules one verdict breaks, as short labels ("chaotic", "DTE > 20 µm", ...): a sweep
    point's (``point_failures``) or one analysis's (``gearengine check``); a limit on a value
    that is missing (no design, diverged) fails, and a diverged verdict fails whatever
    ``fail_on`` says: the gate cannot vouch for a response the model could not follow."""
    out = []
    for name in rules.fail_on:
        if name in SEVERITY and SEVERITY[classification] >= SEVERITY[name]:
            out.append(classification.replace("_", "-"))
            break
    if classification == "diverged" and not out:  # whatever fail_on: nothing to vouch for
        out.append("diverged")
    if "melnikov" in rules.fail_on and melnikov_chaos_possible:
        out.append("Melnikov: chaos possible")
    if "back_flank" in rules.fail_on and impact_regime == "double_sided":
        out.append(IMPACT_TEXT["double_sided"])
    if "separation" in rules.fail_on and impact_regime in SEPARATING:
        out.append(IMPACT_TEXT["single_sided"])
    if rules.max_lle is not None and (lle is None or lle > rules.max_lle):
        out.append(f"LLE > {rules.max_lle:g} per unit tau")
    if rules.max_dte_um is not None and (dte_um is None or dte_um > rules.max_dte_um):
        out.append(f"DTE > {rules.max_dte_um:g} µm")
    if rules.max_dynamic_factor is not None and (
        dynamic_factor is None or dynamic_factor > rules.max_dynamic_factor
    ):
        out.append(f"dynamic factor > {rules.max_dynamic_factor:g}")
    return out


def attractor_failures(p: SweepPoint, rules: Rules) -> list[tuple[str, str]]:
    """(rule, who) of each rule a point breaks: with basins each attractor above
    ``rules.min_basin`` is checked as if it were the point ("chaotic, back-flank impacts
    from 41 % of starts" is who broke it), and the point's own verdict too where no attractor
    decides it (``judged_alone``: it diverged, or no start reached an attractor), named by its
    ``decided_by``; without basins, the point itself (who is empty)."""
    if p.attractors is None:
        return [(rule, "") for rule in point_failures(p, rules)]
    out = []
    if judged_alone(p):
        who = p.decided_by or "the settings' own start (no start reached an attractor)"
        out += [(rule, who) for rule in point_failures(p, rules)]
    for a in _checked(p, rules):
        physical = dict(p.physical or {})
        for key, value in (("dte", a.dte_um), ("dynamic_factor", a.dynamic_factor)):
            physical.pop(key, None)
            if value is not None:
                physical[key] = PhysicalValue(value=value, unit=OUTPUTS[key].unit)
        alone = p.model_copy(update={"classification": a.classification, "period": a.period,
                                     "lle": a.lle, "impact_regime": a.impact_regime,
                                     "physical": physical or None})  # fmt: skip
        who = f"{a.label} from {100 * a.fraction:.0f} % of starts"
        out += [(rule, who) for rule in point_failures(alone, rules)]
    return out


def _checked(p: SweepPoint, rules: Rules) -> list[Attractor]:
    """The attractors of ``p`` whose basin fraction is above ``rules.min_basin``."""
    least = -1.0 if rules.min_basin is None else rules.min_basin
    return [a for a in p.attractors or [] if a.fraction > least]


def judged_alone(p: SweepPoint) -> bool:
    """Whether a point with basins is judged by its own verdict beside its attractors': when
    it diverged (a divergence above the basin threshold decided it, or the settings' own start
    diverged) or no start reached an attractor (every one diverged or unsettled). A point whose
    attractors are all at or under ``min_basin`` is not: the rules leave them out by choice."""
    return p.attractors is not None and (p.classification == "diverged" or not p.attractors)


NEAR_LLE = 0.6
"""An attractor whose LLE is above -NEAR_LLE x mu is near the chaos limit: a periodic attractor
contracting at under 60 % of the linear rate is close to a bifurcation (the period-2 orbits
beside a chaotic window of the z = 23/67 pair have -0.011 at mu = 0.05)."""
NEAR_LIMIT = 0.1
"""A DTE or dynamic factor within this fraction of its limit is near it."""
ESTIMATE_Z = 2.0
"""Standard errors added to an LLE before comparing it with a limit."""


def near_limit(p: SweepPoint, rules: Rules) -> bool:
    """Whether point ``p`` is near a limit of ``rules``, for any attractor found, whatever its
    basin fraction: its LLE (plus ``ESTIMATE_Z`` standard errors) above -``NEAR_LLE`` x mu (mu
    the damping ratio: a linear response's LLE per unit tau) under a chaotic or quasi-periodic
    rule, or above ``max_lle`` - ``NEAR_LLE`` x mu; a rule broken from a basin at or under
    ``min_basin`` (not counted, but a neighbour's basin may be larger); its DTE or dynamic
    factor within ``NEAR_LIMIT`` of that limit."""
    mu = (p.dimensionless or {}).get("mu")
    margin = NEAR_LLE * mu if mu else 0.0
    chaos = any(r in ("chaotic", "quasi_periodic") for r in rules.fail_on)
    found = [(p.lle, p.lle_stderr, _physical(p, "dte"), _physical(p, "dynamic_factor"))]
    if p.attractors:
        found = [(a.lle, a.lle_stderr, a.dte_um, a.dynamic_factor) for a in p.attractors]
    max_lle, max_dte, max_factor = rules.max_lle, rules.max_dte_um, rules.max_dynamic_factor
    for lle, stderr, dte, factor in found:
        high = None if lle is None else lle + ESTIMATE_Z * (stderr or 0.0)
        if high is not None and chaos and high > -margin:
            return True
        if high is not None and max_lle is not None and high > max_lle - margin:
            return True
        if max_dte is not None and dte is not None and dte > (1 - NEAR_LIMIT) * max_dte:
            return True
        if max_factor is not None and factor is not None and factor > (1 - NEAR_LIMIT) * max_factor:
            return True
    if p.attractors and rules.min_basin is not None:
        ignored = rules.model_copy(update={"min_basin": None})
        return len(attractor_failures(p, ignored)) > len(attractor_failures(p, rules))
    return False


def attractor_set(p: SweepPoint, rules: Rules) -> frozenset[tuple[str, int | None]]:
    """The responses a point settles on (class and period of each attractor whose basin is
    above ``rules.min_basin``, or of the point without basins): two neighbours whose sets
    differ are on two sides of a bifurcation, where a window may hide between them."""
    own = {(p.classification, p.period)}
    if p.attractors is None:
        return frozenset(own)
    found = {(a.classification, a.period) for a in _checked(p, rules)}
    return frozenset(found | own if judged_alone(p) else found)


def _physical(p: SweepPoint, key: str) -> float | None:
    value = (p.physical or {}).get(key)
    return None if value is None else value.value
