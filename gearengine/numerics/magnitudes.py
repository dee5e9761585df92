"""The magnitudes of an ensemble's answer: the verdict is the worst attractor's by class
(``headline.headline``); each magnitude shown or gated (DTE, dynamic factor, mesh forces) is
the most adverse over the attractors above the basin threshold, naming the attractor it comes
from, which need not be the one that decided the verdict (issue 30; docs/basins.md).
"""

from __future__ import annotations

from collections.abc import Callable

from gearengine.model.params import GearParams
from gearengine.numerics.headline import Headline, of_starts
from gearengine.numerics.results import Attractor, NumericsResult, WorstValue
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import simulate
from gearengine.systems.base import System

ADVERSE = {
    "dte": ("dte_um", "um", max),
    "dynamic_factor": ("dynamic_factor", "1", max),
    "force_max": ("force_max_n", "N", max),
    "force_min": ("force_min_n", "N", min),
}
"""The magnitudes of a design's response shown and gated (``model.units.POINT_OUTPUTS``): the
``Attractor`` field holding each, its unit, and which end is the most adverse (the smallest
force_min: the hardest back-flank contact)."""


def most_adverse(found: list[Attractor], head: Headline | None,
                 min_fraction: float) -> dict[str, WorstValue]:  # fmt: skip
    """Each magnitude of ``ADVERSE`` at its most adverse over the attractors whose basin
    fraction is above ``min_fraction`` (those the verdict ``head`` was chosen from), naming the
    attractor it comes from: the verdict is the worst attractor by class, a DTE, a dynamic
    factor or a force is the largest (force_min the smallest) over them, which need not be that
    attractor's (a chaotic 31 % with DTE 20 µm beside a periodic 69 % with 62 µm: 62 µm).
    Empty when no attractor decides (``head`` None) or the starts diverged (no finite
    magnitude)."""
    if head is None or head.attractor is None:
        return {}
    counted = {k: a for k, a in enumerate(found) if a.fraction > min_fraction}
    return adverse_over(found, counted, ADVERSE)


def adverse_over(found: list[Attractor], sources: dict[int, object],
                 table: dict[str, tuple[str, str, Callable]]) -> dict[str, WorstValue]:  # fmt: skip
    """Per magnitude of ``table`` (name: field, unit, ``max`` or ``min``) its most adverse value
    over ``sources`` (attractor index: what holds the field, the attractor itself or a response
    of its own), named by the attractor in ``found``; on a tie the worse attractor (earlier in
    ``found``) names it."""
    out = {}
    for name, (field, unit, pick) in table.items():
        have = [(getattr(src, field), k) for k, src in sources.items()
                if getattr(src, field) is not None]  # fmt: skip
        if have:
            value, k = pick(have, key=lambda vk: vk[0])
            a = found[k]
            out[name] = WorstValue(value=value, unit=unit, attractor=k, label=a.label,
                                   classification=a.classification,
                                   fraction=a.fraction)  # fmt: skip
    return out


def attractor_runs(
    system: GearParams | System,
    settings: SimulationSettings,
    found: list[Attractor],
    min_fraction: float,
) -> dict[int, NumericsResult]:
    """Each attractor of ``found`` above ``min_fraction`` run again from the start that reached
    it (the settings' lengths, one start, ~0.02-0.1 s), by its index: the basin runs keep
    extremes, not histories, and the magnitudes read from a time history (the TE with the
    static TE, the contact force: ``engineering.response.HISTORY_MAGNITUDES``) need one."""
    runs = {}
    for k, a in enumerate(found):
        if a.fraction > min_fraction:
            one = settings.model_copy(update={
                "initial_state": a.start, "initial_states": None, "random_initial_states": None,
                "basins": None})  # fmt: skip
            runs[k] = simulate(system, one)
    return runs


def worst_words(worst: dict[str, WorstValue]) -> str:
    """' Over the attractors: the largest dynamic transmission error 62 µm peak to peak
    (periodic 1T, ... from 69 % of starts), the largest dynamic factor 9.92 (the same).'; ''
    without basins."""
    parts, last = [], None
    for key, words, unit in (("dte", "dynamic transmission error", " µm peak to peak"),
                             ("dynamic_factor", "dynamic factor", "")):  # fmt: skip
        w = worst.get(key)
        if w is None:
            continue
        who = "the same attractor" if w.label == last else of_starts(w.label, w.fraction)
        parts.append(f"the largest {words} {w.value:.3g}{unit} ({who})")
        last = w.label
    return f" Over the attractors: {', '.join(parts)}." if parts else ""
