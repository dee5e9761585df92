"""Which attractor decides an ensemble's verdict, and the words that name it: the worst
attractor (or divergence) above a basin-fraction threshold (``headline``), an attractor with
its fraction ("chaotic from 31 % of starts", ``of_starts``) and the coexistence of several
(``coexistence``). Read by every ensemble: analyses, sweeps, gates, robustness."""

from __future__ import annotations

from dataclasses import dataclass

from gearengine.numerics.results import Attractor, BasinCounts


@dataclass(frozen=True)
class Headline:
    """The verdict an ensemble of starts decides: its worst member above the threshold."""

    classification: str
    period: int | None
    decided_by: str
    """Which member decided it: 'chaotic, back-flank impacts from 41 % of starts'."""
    fraction: float
    """Its basin fraction (of diverged starts for 'diverged')."""
    attractor: Attractor | None = None
    """The deciding attractor (None for divergence): its LLE and impact regime."""

    @property
    def kind(self) -> str:
        """'periodic (1T)', 'chaotic', 'quasi-periodic', 'diverged'."""
        if self.period:
            return f"{self.classification} ({self.period}T)"
        return self.classification.replace("_", "-")


def percent(fraction: float) -> str:
    """0.40625 -> '41 %', 0.004 -> '0.4 %'."""
    return f"{100 * fraction:.0f} %" if fraction >= 0.01 else f"{100 * fraction:.1g} %"


def headline(found: list[Attractor], counts: BasinCounts, min_fraction: float) -> Headline | None:
    """The worst attractor (or divergence) whose basin fraction is above ``min_fraction``;
    None when no start qualifies (every basin at or below it)."""
    diverged = counts.diverged / counts.starts
    if counts.diverged and diverged > min_fraction:
        return Headline("diverged", None, f"diverged from {percent(diverged)} of starts", diverged)
    for a in found:  # worst first
        if a.fraction > min_fraction:
            return Headline(a.classification, a.period, of_starts(a.label, a.fraction), a.fraction,
                            a)  # fmt: skip
    return None


def of_starts(label: str, fraction: float) -> str:
    """An attractor named with its basin fraction: 'chaotic, ... from 31 % of starts'."""
    return f"{label} from {percent(fraction)} of starts"


def coexistence(found: list[Attractor], counts: BasinCounts) -> str:
    """'periodic 1T, teeth always in contact from 83 % of starts; chaotic from 17 %' (largest
    basin first), with the diverged and unsettled starts."""
    parts = [(a.fraction, a.label) for a in sorted(found, key=lambda a: -a.count)]
    for n, what in ((counts.diverged, "diverged"), (counts.unsettled, "unsettled")):
        if n:
            parts.append((n / counts.starts, what))
    texts = [f"{label} from {percent(f)}" for f, label in parts]
    if texts:
        texts[0] += f" of {counts.starts} starts"
    return "; ".join(texts)
