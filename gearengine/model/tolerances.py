"""Manufacturing tolerances of a design: what the gears that are built may be.

``design.tolerances`` maps a physical field of the design, by its path (``mesh.half_backlash``,
``mesh.damping_ratio``, ``transmission_error.harmonics.0.amplitude``, ...), to a distribution of
its value (units as everywhere: strings read by pint, or SI numbers):

* ``{"uniform": [low, high]}``;
* ``{"normal": {"mean": m, "sd": s}}``, truncated at the field's physical bounds;
* ``{"triangular": [low, mode, high]}``;

and offers two standards as shortcuts: ``"accuracy": {"standard": "ISO 1328-1:2013", "class":
7}`` (both gears; needs their geometry form; the mesh-frequency transmission-error amplitude,
``model.standards.iso1328.mesh_error_bound``) and ``"backlash": {"min": "80 um", "max": "120
um"}`` (a circumferential backlash band, ``model.standards.backlash``). Correlated inputs are not
modelled: every field varies independently.
``gearengine.studies.robustness.tolerances`` samples them.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from gearengine.model.params import request_config
from gearengine.model.standards.iso1328 import AccuracyClass
from gearengine.model.units import Length

Value = Annotated[float, Field(allow_inf_nan=False)] | str
"""A field's value: an SI number or a string with a unit ("50 um")."""


class _Strict(BaseModel):
    model_config = request_config()


class Uniform(_Strict):
    """Every value between low and high equally likely."""

    uniform: Annotated[list[Value], Field(min_length=2, max_length=2)] = Field(
        description="[low, high].", examples=[["40 um", "60 um"]]
    )


class NormalSpec(_Strict):
    mean: Value = Field(description="Mean.", examples=["50 um"])
    sd: Value = Field(description="Standard deviation (> 0).", examples=["4 um"])


class Normal(_Strict):
    """A normal distribution truncated at the field's physical bounds (a half backlash > 0, a
    damping ratio in [0, 1], ...)."""

    normal: NormalSpec


class Triangular(_Strict):
    """The triangular distribution with its mode between low and high."""

    triangular: Annotated[list[Value], Field(min_length=3, max_length=3)] = Field(
        description="[low, mode, high].", examples=[["40 um", "50 um", "60 um"]]
    )


Distribution = Uniform | Normal | Triangular


class Accuracy(BaseModel):
    """An ISO 1328-1:2013 flank tolerance class for both gears."""

    model_config = ConfigDict(
        **request_config(), validate_by_name=True, validate_by_alias=True, serialize_by_alias=True
    )

    standard: Literal["ISO 1328-1:2013"] = Field(description="The standard.")
    tolerance_class: AccuracyClass = Field(
        alias="class", ge=1, le=11, description="Flank tolerance class A, 1 (finest) to 11."
    )


class BacklashBand(_Strict):
    """A circumferential backlash band, as the fit tables (DIN 3967, ISO/TR 10064-2) give it."""

    min: Length = Field(description="Least circumferential backlash j_t,min.", examples=["80 um"])
    max: Length = Field(description="Most circumferential backlash j_t,max.", examples=["120 um"])

    @model_validator(mode="after")
    def _ordered(self) -> BacklashBand:
        if not self.min < self.max:
            raise ValueError("the band's min must be below its max")
        return self


class Tolerances(BaseModel):
    """Distributions of the design's fields by path, and the standards' shortcuts."""

    model_config = ConfigDict(
        extra="allow",
        frozen=True,
        strict=True,
        json_schema_extra={
            "examples": [
                {
                    "accuracy": {"standard": "ISO 1328-1:2013", "class": 7},
                    "backlash": {"min": "80 um", "max": "120 um"},
                    "mesh.damping_ratio": {"uniform": [0.04, 0.06]},
                }
            ]
        },
    )
    __pydantic_extra__: dict[str, Distribution] = Field(init=False)  # type: ignore[assignment]

    accuracy: Accuracy | None = Field(None, description="ISO 1328-1:2013 class of both gears.")
    backlash: BacklashBand | None = Field(None, description="Circumferential backlash band.")

    def fields(self) -> dict[str, Distribution]:
        """The distributions given by field path."""
        return dict(self.__pydantic_extra__ or {})
