"""Quantity fields of the request models: ``quantity_type`` makes a pydantic type that reads a
string with a unit or an SI number through ``quantities.parse_quantity`` and stores SI, with the
JSON schema it states (``QuantitySchema``: the pattern of the usual units, bounded to the
plausible range); and the field types of every design field (``Length``, ``Speed``, ...).
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Any

from pydantic import BeforeValidator, ValidationInfo

from gearengine.model.units.quantities import (
    NUMBER,
    QUANTITIES,
    QuantityKind,
    parse_quantity,
    registry,
)


def quantity_pattern(kind: QuantityKind) -> str:
    """The schema's pattern of a quantity string: a magnitude and one of the usual units (the
    SI unit, the example's, a likely slip's), the magnitude's integer digits bounded so that it
    lies in the plausible range in that unit ("30 mm", not "30000000 mm"); a unit whose range
    no digit count fits takes any number ("20 deg"). What is read is wider (any unit of the
    right dimension, "0.5 mm"): the pattern states the common case, and the example, so that
    requests generated from the schema (schemathesis) are mostly valid."""
    ureg = registry()
    sign = "-?" if kind.signed else ""
    alternatives = [re.escape(kind.example)]
    for unit in dict.fromkeys([kind.unit, kind.example.split(maxsplit=1)[-1], *kind.slips]):
        per_si = float(ureg.Quantity(1.0, unit).to(kind.unit).magnitude)
        digits = _integer_digits(kind.low / per_si, kind.high / per_si)
        number = NUMBER
        if digits is not None:
            number = rf"{sign}[1-9]\d{{{digits[0] - 1},{digits[1] - 1}}}(\.\d{{1,3}})?"
        alternatives.append(rf"{number} *{re.escape(unit)}")
    return rf"^ *({'|'.join(alternatives)}) *$"


def _integer_digits(low: float, high: float) -> tuple[int, int] | None:
    """(fewest, most) integer digits of a number with a leading digit 1-9 that lies in
    [low, high]: k digits span [10^(k-1), 10^k); None if no k fits."""
    fewest = 1 if low <= 1.0 else math.ceil(math.log10(low)) + 1
    most = math.floor(math.log10(high))
    return (fewest, most) if fewest <= most else None


class QuantitySchema:
    """The JSON schema of a quantity field, made when a schema is asked for (the OpenAPI
    document), not at import: the pattern's unit factors need pint (``registry``)."""

    def __init__(
        self, kind: QuantityKind, allow_zero: bool, keyword: str | None, unit_required: bool
    ) -> None:
        self.kind, self.allow_zero, self.keyword = kind, allow_zero, keyword
        self.unit_required = unit_required

    def __get_pydantic_json_schema__(self, core: Any, handler: Any) -> dict[str, Any]:
        kind = self.kind
        low = -kind.high if kind.signed else kind.low  # the plausible range (_plausible)
        words = [] if self.keyword is None else [{"const": self.keyword}]
        zero = [{"const": 0}] if self.allow_zero and kind.low > 0.0 else []
        number = {"type": "number", "description": f"in {kind.unit}", "minimum": low,
                  "maximum": kind.high}  # fmt: skip
        text = {"type": "string", "pattern": quantity_pattern(kind), "examples": [kind.example]}
        if self.unit_required:
            return {**text, "description": f"{kind.name}: a string with a unit (e.g. "
                    f"{kind.example!r}); plausible range {kind.span()}"}  # fmt: skip
        return {
            "anyOf": [*words, text, number, *zero],
            "description": f"{kind.name}: a string with a unit (e.g. {kind.example!r}) or a "
            f"number in {kind.unit} (read with a note); plausible range {kind.span()}",
        }


def quantity_type(
    key: str, allow_zero: bool = False, keyword: str | None = None, unit_required: bool = False
) -> Any:
    """A pydantic field type: a string with a unit or an SI number (``unit_required``: a
    string with a unit only), stored in SI units; a ``keyword`` (such as "iso6336": derive it)
    passes through as the string itself."""
    kind = QUANTITIES[key]

    def parse(value: object, info: ValidationInfo) -> float | str:
        if keyword is not None and value == keyword:
            return keyword
        return parse_quantity(value, kind, allow_zero, info.field_name, unit_required)

    stored = float if keyword is None else float | str
    schema = QuantitySchema(kind, allow_zero, keyword, unit_required)
    return Annotated[stored, BeforeValidator(parse), schema]


Length = quantity_type("length")
Module = quantity_type("module")
Bore = quantity_type("length", allow_zero=True)
HalfBacklash = quantity_type("half_backlash")
Backlash = quantity_type("backlash")
"""The circumferential backlash j_t of a fit table (DIN 3967, ISO/TR 10064-2)."""
ErrorAmplitude = quantity_type("error", allow_zero=True)
Speed = quantity_type("speed")
Torque = quantity_type("torque", allow_zero=True)
MeanTorque = quantity_type("mean_torque", allow_zero=True)
"""A mean (driving or braking) torque: a magnitude, a negative one refused."""
Stiffness = quantity_type("stiffness")
MeshStiffness = quantity_type("stiffness", keyword="iso6336")
StiffnessVariation = quantity_type("stiffness_variation", allow_zero=True)
Inertia = quantity_type("inertia")
Damping = quantity_type("damping", allow_zero=True)
Angle = quantity_type("angle")
Duration = quantity_type("duration")
Time = quantity_type("duration", allow_zero=True)
TorsionalStiffness = quantity_type("torsional_stiffness")
BearingStiffness = quantity_type("bearing_stiffness")
Mass = quantity_type("mass")
ShearModulus = quantity_type("shear_modulus")
SampleRate = quantity_type("sample_rate")
