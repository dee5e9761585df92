"""Physical quantities as engineers type them: "1500 rpm", "50 um", "40 N*m", parsed with pint.

A field of a physical design takes a string with a unit, or a bare number in SI units. Each
kind of quantity (``QUANTITIES``) names its pint dimension, its SI unit and the range an actual
spur-gear pair can have; a value outside that range is refused, and when reading the number in
a neighbouring unit would put it inside ("100 m" for a backlash), the refusal says what was
probably meant ("did you mean 100 µm?"). Errors are ``ValueError`` whose message pydantic puts
after the field's path, so a 422 names the field, the unit given and the dimension expected.

Reference: H. E. Grecco et al., pint (https://pint.readthedocs.io), the registry used here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING, Annotated, Any

from pydantic import BeforeValidator, WithJsonSchema

if TYPE_CHECKING:
    import pint


@cache
def registry() -> pint.UnitRegistry:
    """The one pint registry of the engine (rpm = revolution per minute, µm and um alike),
    made when a quantity is first read: importing pint costs ~0.15 s, which every command and
    the service's start-up would otherwise pay for designs given as plain numbers."""
    import pint

    return pint.UnitRegistry()


@dataclass(frozen=True)
class QuantityKind:
    """A kind of physical quantity: its dimension, SI unit, plausible range and the units a
    slip of the keyboard most likely meant (tried, in order, when a value is out of range)."""

    name: str
    unit: str
    low: float
    high: float
    slips: tuple[str, ...]
    example: str

    @property
    def dimensionality(self) -> Any:
        return registry().Quantity(1.0, self.unit).dimensionality

    def describe(self, si: float) -> str:
        """``si`` in the kind's unit, 6 significant digits."""
        return f"{si:.6g} {self.unit}"


QUANTITIES: dict[str, QuantityKind] = {
    "length": QuantityKind("length", "m", 1e-9, 10.0, ("um", "mm"), "30 mm"),
    "half_backlash": QuantityKind("half backlash", "m", 1e-7, 5e-3, ("um", "mm"), "50 um"),
    "error": QuantityKind("transmission error", "m", 0.0, 1e-3, ("um", "mm"), "5 um"),
    "speed": QuantityKind(
        "shaft speed", "rad/s", 2 * math.pi / 60, 2e5 * 2 * math.pi / 60, ("rpm",), "1500 rpm"
    ),
    "torque": QuantityKind("torque", "N*m", 0.0, 1e6, (), "40 N*m"),
    "stiffness": QuantityKind("mesh stiffness", "N/m", 1e6, 1e11, ("N/um", "N/mm"), "1e8 N/m"),
    "stiffness_variation": QuantityKind(
        "stiffness variation", "N/m", 0.0, 1e11, ("N/um", "N/mm"), "1e7 N/m"
    ),
    "inertia": QuantityKind("inertia", "kg*m^2", 1e-9, 1e4, ("kg*cm^2", "kg*mm^2"), "2e-3 kg*m^2"),
    "damping": QuantityKind("damping", "N*s/m", 0.0, 1e7, (), "1100 N*s/m"),
    "angle": QuantityKind("angle", "rad", math.radians(10), math.radians(35), ("deg",), "20 deg"),
    "displacement": QuantityKind("displacement", "m", 0.0, 1e-2, ("um", "mm"), "-30 um"),
    "velocity": QuantityKind("velocity", "m/s", 0.0, 100.0, ("mm/s",), "200 mm/s"),
}
"""Kinds of quantity by key; ``low``/``high`` bound plausible magnitudes in SI units."""

# Lengths of gear bodies (radius, module, face width, bore) may be zero only for a bore.
POSITIVE_KINDS = frozenset({"length", "half_backlash", "speed", "stiffness", "inertia", "angle"})


def parse_quantity(value: object, kind: QuantityKind, allow_zero: bool = False) -> float:
    """``value`` (a string with a unit, or a number in SI units) in the kind's SI unit.

    Raises ValueError naming the unit given and the dimension expected, or the plausible range
    with a guess at the intended unit.
    """
    ureg = registry()
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise ValueError(f"give a number in {kind.unit} or a string with a unit, e.g. "
                         f"{kind.example!r}")  # fmt: skip
    if isinstance(value, str):
        try:
            quantity = ureg.Quantity(value.strip())
        except Exception as exc:
            raise ValueError(f"cannot read {value!r} as a quantity ({exc}); write e.g. "
                             f"{kind.example!r}") from None  # fmt: skip
        if not isinstance(quantity, ureg.Quantity):
            quantity = ureg.Quantity(float(quantity), kind.unit)
        elif quantity.dimensionless and kind.unit not in ("rad",):
            quantity = ureg.Quantity(quantity.magnitude, kind.unit)
        if quantity.dimensionality != kind.dimensionality:
            raise ValueError(
                f"{value!r} has the unit {quantity.units:~} ({quantity.dimensionality}); "
                f"a {kind.name} needs a unit of dimension {kind.dimensionality}, e.g. "
                f"{kind.example!r}"
            )
        si = float(quantity.to(kind.unit).magnitude)
    else:
        si = float(value)
    return _plausible(si, value, kind, allow_zero)


def _plausible(si: float, given: object, kind: QuantityKind, allow_zero: bool) -> float:
    """``si`` if finite and in the kind's range; else a refusal with the likely slip."""
    if not math.isfinite(si):
        raise ValueError(f"{given!r} is not a finite {kind.name}")
    if si == 0.0 and allow_zero:
        return si
    if kind.low <= abs(si) <= kind.high and (si > 0.0 or kind.low == 0.0):
        return si
    ureg = registry()
    shown = given if isinstance(given, str) else kind.describe(si)
    message = (
        f"{shown} is outside the plausible range of a {kind.name}, "
        f"{kind.describe(kind.low)} to {kind.describe(kind.high)}"
    )
    magnitude = ureg.Quantity(given).magnitude if isinstance(given, str) else si
    for slip in kind.slips:
        meant = float(ureg.Quantity(abs(float(magnitude)), slip).to(kind.unit).magnitude)
        if kind.low <= meant <= kind.high and meant > 0.0:
            message += f": did you mean {magnitude:g} {ureg.Unit(slip):~P}?"
            break
    raise ValueError(message)


def quantity_type(key: str, allow_zero: bool = False, keyword: str | None = None) -> Any:
    """A pydantic field type: a string with a unit or an SI number, stored in SI units; a
    ``keyword`` (such as "iso6336": derive it) passes through as the string itself."""
    kind = QUANTITIES[key]

    def parse(value: object) -> float | str:
        if keyword is not None and value == keyword:
            return keyword
        return parse_quantity(value, kind, allow_zero)

    words = [] if keyword is None else [{"const": keyword}]
    schema = {
        "anyOf": [
            *words,
            {"type": "string", "examples": [kind.example]},
            {"type": "number", "description": f"in {kind.unit}"},
        ],
        "description": f"{kind.name}: a string with a unit (e.g. {kind.example!r}) or a number "
        f"in {kind.unit}; plausible range {kind.describe(kind.low)} to "
        f"{kind.describe(kind.high)}",
    }
    stored = float if keyword is None else float | str
    return Annotated[stored, BeforeValidator(parse), WithJsonSchema(schema)]


Length = quantity_type("length")
Bore = quantity_type("length", allow_zero=True)
HalfBacklash = quantity_type("half_backlash")
ErrorAmplitude = quantity_type("error", allow_zero=True)
Speed = quantity_type("speed")
Torque = quantity_type("torque", allow_zero=True)
Stiffness = quantity_type("stiffness")
MeshStiffness = quantity_type("stiffness", keyword="iso6336")
StiffnessVariation = quantity_type("stiffness_variation", allow_zero=True)
Inertia = quantity_type("inertia")
Damping = quantity_type("damping", allow_zero=True)
Angle = quantity_type("angle")

RPM = 2.0 * math.pi / 60.0
"""One revolution per minute in rad/s."""
