"""What a lever's value means for a gear maker: the contact ratio and the ISO 1328-1 accuracy
class that delivers a transmission-error amplitude."""

from __future__ import annotations

from gearengine.gate.remedies.request import Lever
from gearengine.model.design import ACCURACY_FIELD, Design
from gearengine.model.reduction import convert_design
from gearengine.model.standards import iso1328

ISO_ROUNDING = 0.005
"""Relative tolerance with which a transmission-error amplitude meets a class bound: ISO 1328-1
rounds its tolerances (to 0.1, 0.5 or 1 µm by size), and a designer writes the class-7 bound
11.31 µm as 11.3 µm, so a value within 0.5 % below a bound is that bound's class."""


def contact_ratio(design: Design) -> float | None:
    """The transverse contact ratio of a design with gear geometry (None without)."""
    derived = convert_design(design).derived.get("contact_ratio")
    return None if derived is None else float(derived.value)


def iso1328_class(design: Design, amplitude: float) -> int | None:
    """The coarsest ISO 1328-1:2013 flank tolerance class (1-11) whose total profile tolerances
    of both gears bound the mesh-frequency transmission-error harmonic at or below ``amplitude``
    [m] (``iso1328.mesh_error_bound``), within ``ISO_ROUNDING``: bound <= amplitude x (1 +
    ISO_ROUNDING); None when no class does or the standard does not apply (no geometry, or
    outside its range)."""
    for grade in range(11, 0, -1):
        try:
            bound = iso1328.pair_te_bound(grade, design.driver, design.driven)
        except ValueError:
            return None
        if bound <= amplitude * (1.0 + ISO_ROUNDING):
            return grade
    return None


def accuracy_classes(design: Design, lever: Lever, to: float) -> list[int | None] | None:
    """[class at from, class at to] of the transmission-error lever an accuracy class sets."""
    if lever.path != ACCURACY_FIELD or iso1328_class(design, float("inf")) is None:
        return None
    return [iso1328_class(design, lever.start), iso1328_class(design, to)]
