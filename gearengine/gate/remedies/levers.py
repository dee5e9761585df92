"""What a lever's value means for a gear maker: the contact ratio and the ISO 1328-1 accuracy
class that delivers a transmission-error amplitude."""

from __future__ import annotations

from gearengine.gate.remedies.request import Lever
from gearengine.model.design import ACCURACY_FIELD, Design
from gearengine.model.reduction import convert_design
from gearengine.model.standards import iso1328


def contact_ratio(design: Design) -> float | None:
    """The transverse contact ratio of a design with gear geometry (None without)."""
    derived = convert_design(design).derived.get("contact_ratio")
    return None if derived is None else float(derived.value)


def iso1328_class(design: Design, amplitude: float) -> int | None:
    """The coarsest ISO 1328-1:2013 flank tolerance class (1-11) whose total profile tolerances
    of both gears bound the mesh-frequency transmission-error harmonic at or below ``amplitude``
    [m] (``iso1328.mesh_error_bound``); None when no class does or the standard does not apply
    (no geometry, or outside its range)."""
    gears = (design.driver, design.driven)
    if any(g.module is None or g.face_width is None for g in gears):
        return None
    for grade in range(11, 0, -1):
        try:
            profile = [iso1328.tolerances(grade, g.teeth, g.module * 1e3, g.face_width * 1e3)
                       .F_alpha for g in gears]  # type: ignore[operator]  # fmt: skip
        except ValueError:
            return None
        if iso1328.mesh_error_bound(*profile) * 1e-6 <= amplitude:
            return grade
    return None


def accuracy_classes(design: Design, lever: Lever, to: float) -> list[int | None] | None:
    """[class at from, class at to] of the transmission-error lever an accuracy class sets."""
    if lever.path != ACCURACY_FIELD or iso1328_class(design, float("inf")) is None:
        return None
    return [iso1328_class(design, lever.start), iso1328_class(design, to)]
