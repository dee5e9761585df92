"""Speed windows of a sweep over the driver speed: the intervals (rpm) of each response class,
of tooth contact (separation, back_flank) and of Melnikov chaos, at each level of the other
axis (a torque, say).

An interval joins consecutive grid speeds with the same verdict and reports the first and last
of them, so a window is known to the grid step: [500, 1100] rpm on a 100 rpm grid means the
verdict held at 500, 600, ..., 1100 rpm and differed at 400 and 1200 rpm (when on the grid).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from gearengine.model.units import display_unit
from gearengine.model.units import shown as rounded
from gearengine.studies.sweep.points import PhysicalValue, SpeedWindows, SweepPoint
from gearengine.studies.sweep.request import SweepAxis

SPEED = "speed"
SEPARATING = ("single_sided", "double_sided")
"""Impact regimes in which the teeth separate at some time: ``separation`` (the gate's
--fail-on separation, P(separation); ``double_sided`` is also ``back_flank``)."""


def response_label(p: SweepPoint) -> str:
    """A point's response in words: "periodic 2T", "chaotic", "quasi-periodic", "diverged"."""
    if p.classification == "periodic" and p.period is not None:
        return f"periodic {p.period}T"
    return p.classification.replace("_", "-")


def runs(speeds: Sequence[float], flags: Sequence[str | None]) -> dict[str, list[list[float]]]:
    """[first, last] speed of each run of equal, non-None ``flags`` (speeds ascending)."""
    out: dict[str, list[list[float]]] = {}
    start = 0
    for k in range(1, len(speeds) + 1):
        if k == len(speeds) or flags[k] != flags[start]:
            if flags[start] is not None:
                out.setdefault(flags[start], []).append([speeds[start], speeds[k - 1]])  # type: ignore[index]
            start = k
    return out


class _Axes(Protocol):
    """A sweep's request or result: what names its axes."""

    @property
    def axes(self) -> list[SweepAxis]: ...


def speed_windows(request: _Axes, points: Sequence[SweepPoint]) -> list[SpeedWindows] | None:
    """The windows of a sweep with a ``speed`` axis (None for other sweeps) over ``points``
    (its grid's, or with the gate's refined points between them); rows by the other axis'
    level, ascending; the down branch of a continuation sweep is left out."""
    names = [a.parameter for a in request.axes]
    if SPEED not in names:
        return None
    _, factor = display_unit(SPEED)  # rad/s to rpm
    other = next((n for n in names if n != SPEED), None)
    rows: dict[float | None, list[SweepPoint]] = {}
    for p in points:
        if p.branch != "down":
            rows.setdefault(None if other is None else p.values[other], []).append(p)
    out = []
    for level, row in sorted(rows.items(), key=lambda item: item[0] or 0.0):
        row.sort(key=lambda p: p.values[SPEED])
        speeds = [rounded(p.values[SPEED] * factor) for p in row]
        apart = ["separation" if p.impact_regime in SEPARATING else None for p in row]
        back = ["back_flank" if p.impact_regime == "double_sided" else None for p in row]
        melnikov = [
            "n/a" if p.melnikov_chaos_possible is None else
            "chaos" if p.melnikov_chaos_possible else None
            for p in row
        ]  # fmt: skip
        shown: dict[str, PhysicalValue] = {}
        if other is not None and level is not None:
            shown[other] = _level(row[0], other, level)
        out.append(
            SpeedWindows(
                level=shown,
                response=runs(speeds, [response_label(p) for p in row]),
                contact={**runs(speeds, apart), **runs(speeds, back)},
                melnikov=runs(speeds, melnikov).get("chaos", []),
                melnikov_not_applicable=runs(speeds, melnikov).get("n/a", []),
            )
        )
    return out


def _level(p: SweepPoint, name: str, si: float) -> PhysicalValue:
    if p.physical and name in p.physical:
        return p.physical[name]
    return PhysicalValue(value=si, unit="1")
