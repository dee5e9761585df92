"""The optional ``train`` block of a design: motor, shafts, load and bearings around the mesh.

Without it a design is the paper's pair of rigid discs on rigid, perfectly supported shafts
(Eq. 2a-2b). With it the driver gear (pinion) hangs on a torsionally soft input shaft behind a
motor inertia, the driven gear on an output shaft in front of a load inertia, and, with
``bearings``, each gear centre moves along the line of action on a bearing spring. The equations
of the train are in ``docs/gear-trains.md``; its matrices in ``systems.gear_train.model``.

A shaft is given by its torsional stiffness, or by its length, diameter and shear modulus
(solid round shaft: k = G pi d^4 / (32 L); default steel, G = 79.3 GPa). Shaft damping is a
damping ratio of the two-inertia shaft mode, c = 2 zeta sqrt(k J_eq) with J_eq = J_1 J_2 /
(J_1 + J_2); bearing damping c = 2 zeta sqrt(k m) with the mass carried on that bearing.
"""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import Field, model_validator

from gearengine.model.errors import InputError
from gearengine.model.params import StrictModel, given
from gearengine.model.units import (
    BearingStiffness,
    Inertia,
    Length,
    Mass,
    ShearModulus,
    TorsionalStiffness,
)

STEEL_SHEAR_MODULUS = 79.3e9
"""Shear modulus G of steel [Pa], the default of a shaft given by its geometry."""

DampingRatio = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]
"""A damping ratio zeta, 0 to 1."""


class Inertial(StrictModel):
    """A rigid rotor on the train: the motor or the load."""

    inertia: Inertia = Field(description="Mass moment of inertia about the shaft axis.")


class Shaft(StrictModel):
    """A shaft as a torsional spring and damper between two inertias."""

    model_config = StrictModel.model_config | {  # as _one_form checks: one form of the two
        "json_schema_extra": {
            "oneOf": [
                {**given("torsional_stiffness"), "not": {"anyOf": [
                    given("length"), given("diameter"), given("shear_modulus")]}},
                {"allOf": [given("length"), given("diameter")],
                 "not": given("torsional_stiffness")},
            ]
        }
    }  # fmt: skip

    torsional_stiffness: TorsionalStiffness | None = Field(
        None, description="Torsional stiffness k (or give length and diameter).",
        examples=["3e4 N*m/rad"],
    )  # fmt: skip
    length: Length | None = Field(None, description="Length L of a solid round shaft.")
    diameter: Length | None = Field(None, description="Diameter d of a solid round shaft.")
    shear_modulus: ShearModulus | None = Field(
        None, description="Shear modulus G (default steel, 79.3 GPa); with length and diameter."
    )
    damping_ratio: DampingRatio = Field(
        0.0, description="Damping ratio zeta of the shaft mode: c = 2 zeta sqrt(k J_eq)."
    )

    @model_validator(mode="after")
    def _one_form(self) -> Shaft:
        geometric = self.length is not None or self.diameter is not None
        if self.torsional_stiffness is not None:
            if geometric or self.shear_modulus is not None:
                name = next(n for n in ("length", "diameter", "shear_modulus") if getattr(self, n))
                raise InputError(name, "give torsional_stiffness, or length and diameter, "
                                       "not both")  # fmt: skip
            return self
        for name in ("length", "diameter"):
            if getattr(self, name) is None:
                raise InputError(
                    name, "give torsional_stiffness, or both length and diameter of the shaft"
                )
        stiffness = self.stiffness
        if not 10.0 <= stiffness <= 1e9:
            raise InputError(
                "diameter",
                f"the shaft's torsional stiffness G pi d^4 / (32 L) = {stiffness:.6g} N m/rad "
                "is outside the plausible range 10 to 1e9 N m/rad",
            )
        return self

    @property
    def stiffness(self) -> float:
        """Torsional stiffness k [N m/rad]: given, or G pi d^4 / (32 L) of a solid shaft."""
        if self.torsional_stiffness is not None:
            return self.torsional_stiffness
        assert self.length is not None and self.diameter is not None
        g = STEEL_SHEAR_MODULUS if self.shear_modulus is None else self.shear_modulus
        return g * math.pi * self.diameter**4 / (32.0 * self.length)


class Bearing(StrictModel):
    """The bearing support of one gear centre along the line of action."""

    stiffness: BearingStiffness = Field(description="Support stiffness along the line of action.")
    damping_ratio: DampingRatio = Field(
        0.0, description="Damping ratio zeta of the support: c = 2 zeta sqrt(k m)."
    )
    mass: Mass = Field(
        description="Mass m moving on the support (the gear and its share of shaft)."
    )


class Bearings(StrictModel):
    """The supports of both gear centres."""

    driver: Bearing = Field(description="Support of the driver gear (pinion) centre.")
    driven: Bearing = Field(description="Support of the driven gear centre.")


EXAMPLE_TRAIN = {
    "motor": {"inertia": "4e-3 kg*m^2"},
    "input_shaft": {"torsional_stiffness": "3e4 N*m/rad", "damping_ratio": 0.02},
    "output_shaft": {"torsional_stiffness": "8e4 N*m/rad", "damping_ratio": 0.02},
    "load": {"inertia": "3e-2 kg*m^2"},
    "bearings": {
        "driver": {"stiffness": "2e8 N/m", "damping_ratio": 0.03, "mass": "1.2 kg"},
        "driven": {"stiffness": "3e8 N/m", "damping_ratio": 0.03, "mass": "3 kg"},
    },
}
"""The train of issue 32's worked example (around ``examples/design-direct.json``)."""


class Train(StrictModel):
    """Motor, input shaft, output shaft, load and (optionally) bearings around the mesh.

    The mean driver torque and its fluctuation act on the motor, the braking torque on the load.
    """

    model_config = StrictModel.model_config | {"json_schema_extra": {"examples": [EXAMPLE_TRAIN]}}

    motor: Inertial = Field(description="Motor (driving) inertia behind the input shaft.")
    input_shaft: Shaft = Field(description="Shaft between the motor and the driver gear.")
    output_shaft: Shaft = Field(description="Shaft between the driven gear and the load.")
    load: Inertial = Field(description="Load (driven machine) inertia behind the output shaft.")
    bearings: Bearings | None = Field(
        None, description="Gear-centre supports along the line of action (none: rigid)."
    )
