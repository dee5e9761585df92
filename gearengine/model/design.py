"""A spur-gear pair as a designer describes it, in physical units, and its dimensionless form.

A ``Design`` holds gear data (teeth, base radius and inertia, or module, face width and
material), the running point (driver speed, mean driver torque), the mesh (stiffness, damping,
half backlash) and the excitations (transmission error, torque fluctuation). Quantities are
strings with units or SI numbers (``model.units``). ``convert_design`` derives what the data
leave implicit (``model.geometry``: base radii, inertias, contact ratio, ISO 6336-1 mesh
stiffness and its variation) and reduces the pair to the dimensionless parameters of Eq. (9)
through ``model.conversion`` (Eq. 7-8, with the r_a correction of the mean force); that
reduction lives in ``model.reduction``.

Frequencies: the mesh frequency is teeth x speed; the transmission error runs at the mesh
frequency unless an ``order`` (multiple of the driver speed) is given; the torque fluctuation at
``order`` x speed (default 1). The braking torque balances the driving one unless given.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import (
    ConfigDict,
    Field,
    ModelWrapValidatorHandler,
    PrivateAttr,
    model_validator,
)

from gearengine.model import geometry
from gearengine.model.errors import InputError
from gearengine.model.params import (
    MAX_HARMONICS,
    Phase,
    StrictModel,
    WholeNumber,
    given,
    request_config,
)
from gearengine.model.standards import backlash, iso1328
from gearengine.model.tolerances import Tolerances
from gearengine.model.train import Train
from gearengine.model.units import (
    QUANTITIES,
    SHARE,
    Angle,
    Backlash,
    Bore,
    Damping,
    ErrorAmplitude,
    HalfBacklash,
    Inertia,
    Length,
    MeanTorque,
    MeshStiffness,
    Module,
    Speed,
    StiffnessVariation,
    Torque,
    note,
    parse_quantity,
    plain_number,
    readings,
    si_numbers,
)


class Gear(StrictModel):
    """One gear: base radius and inertia directly, or its geometry (module, face width, ...)."""

    model_config = ConfigDict(
        **request_config(),
        json_schema_extra={  # what _enough checks, in the schema
            "allOf": [
                {"anyOf": [given(name), {"allOf": [given("module"), given("face_width")]}]}
                for name in ("base_radius", "inertia")
            ]
        },
    )

    teeth: WholeNumber = Field(ge=5, le=1000, description="Number of teeth z.", examples=[18])
    base_radius: Length | None = Field(None, description="Base-circle radius r_b.")
    inertia: Inertia | None = Field(None, description="Mass moment of inertia about the axis.")
    module: Module | None = Field(None, description="Normal module m (geometry form).")
    face_width: Length | None = Field(None, description="Face width b (geometry form).")
    pressure_angle: Angle = Field(math.radians(20.0), description="Pressure angle (20 deg).")
    profile_shift: float = Field(
        0.0, ge=-1.0, le=2.0, allow_inf_nan=False, description="Profile shift coefficient x."
    )
    bore: Bore = Field(0.0, description="Bore diameter (geometry form; 0: solid).")
    material: Literal["steel", "cast_iron", "bronze", "aluminium"] = Field(
        "steel", description="Density and Young's modulus (geometry form)."
    )

    @model_validator(mode="after")
    def _enough(self) -> Gear:
        geometric = self.module is not None and self.face_width is not None
        if self.base_radius is None and not geometric:  # geometry() derives it from both
            raise ValueError("give base_radius, or module and face_width for the geometry")
        if self.inertia is None and not geometric:
            raise ValueError("give inertia, or module and face_width to derive it")
        if self.module is not None and self.bore >= self.module * self.teeth:
            raise ValueError(
                f"bore: {self.bore * 1e3:.6g} mm leaves no gear body inside the reference "
                f"diameter m z = {self.module * self.teeth * 1e3:.6g} mm"
            )
        return self

    def geometry(self) -> dict[str, Any] | None:
        """The gear as ``model.geometry`` takes it, or None without module and face width."""
        if self.module is None or self.face_width is None:
            return None
        return {
            "teeth": self.teeth,
            "module": self.module,
            "face_width": self.face_width,
            "pressure_angle": self.pressure_angle,
            "profile_shift": self.profile_shift,
            "bore_diameter": self.bore,
            "material": self.material,
        }


class StiffnessVariationHarmonic(StrictModel):
    """Harmonic r of the mesh stiffness at r x the mesh frequency (Eq. 4)."""

    amplitude: StiffnessVariation = Field(description="k_r.", examples=["1e7 N/m"])
    phase: Phase = Field(0.0, description="Phase, rad.")


class ErrorHarmonic(StrictModel):
    """Harmonic r of the static transmission error (Eq. 5)."""

    amplitude: ErrorAmplitude = Field(description="e_r.", examples=["5 um"])
    phase: Phase = Field(0.0, description="Phase, rad.")


class TorqueFluctuationHarmonic(StrictModel):
    """Harmonic r of the driver-torque fluctuation (Eq. 3)."""

    amplitude: Torque = Field(
        description="T_pr; or a share of the mean torque, '3 %' (scales with the torque).",
        examples=["4 N*m"],
    )
    phase: Phase = Field(0.0, description="Phase, rad.")


class Mesh(StrictModel):
    """The tooth mesh: stiffness, damping and half backlash."""

    model_config = ConfigDict(
        **request_config(),
        json_schema_extra={"allOf": [
            {"oneOf": [given("damping_ratio"), given("damping")]},
            {"oneOf": [given("half_backlash"), given("backlash")]},
        ]},
    )  # fmt: skip

    stiffness: MeshStiffness = Field(
        description="Mean mesh stiffness k_m, or 'iso6336' to derive it from both gears' "
        "geometry (ISO 6336-1 method B: c_gamma_alpha times face width).",
        examples=["1e8 N/m", "iso6336"],
    )
    stiffness_harmonics: list[StiffnessVariationHarmonic] | None = Field(
        None,
        max_length=MAX_HARMONICS,
        description="Stiffness variation at r x mesh frequency. Default: none, or with "
        "'iso6336' the single/double tooth-contact wave of the contact ratio.",
    )
    damping_ratio: Annotated[float, plain_number("damping ratio")] | None = Field(
        None, ge=0.0, le=1.0, allow_inf_nan=False,
        description="Mesh damping ratio zeta, a plain number (0.05, not '5 %').",
    )  # fmt: skip
    damping: Damping | None = Field(None, description="Mesh damping c (instead of zeta).")
    half_backlash: HalfBacklash | None = Field(
        None,
        description="Half backlash b along the line of action (total clearance 2b); or give "
        "backlash.",
    )
    backlash: Backlash | None = Field(
        None,
        description="Nominal circumferential backlash j_t (a fit table's, DIN 3967, ISO/TR "
        "10064-2), instead of half_backlash: read as b = j_t cos(alpha_wt) / 2 with the "
        "operating transverse pressure angle alpha_wt, with a note (docs/units.md).",
        examples=["100 um"],
    )

    @model_validator(mode="after")
    def _one_damping(self) -> Mesh:
        if (self.damping_ratio is None) == (self.damping is None):
            raise ValueError("give exactly one of damping_ratio and damping")
        if (self.half_backlash is None) == (self.backlash is None):
            raise ValueError("give exactly one of half_backlash and backlash (circumferential)")
        return self


class TransmissionError(StrictModel):
    """Static transmission error e(t) = sum e_r cos(r w_e t + phi_r): its harmonics, or the
    bound of an ISO 1328 accuracy class (``accuracy_class``)."""

    model_config = ConfigDict(
        **request_config(),
        json_schema_extra={"oneOf": [given("harmonics"), given("accuracy_class")]},
    )

    order: float | None = Field(
        None, gt=0.0, le=1000.0, allow_inf_nan=False,
        description="Fundamental in multiples of the driver speed (default: teeth, the mesh "
        "frequency).",
    )  # fmt: skip
    harmonics: list[ErrorHarmonic] | None = Field(
        None, max_length=MAX_HARMONICS, description="The harmonics e_r; or give accuracy_class."
    )
    accuracy_class: iso1328.AccuracyClass | None = Field(
        None,
        ge=1,
        le=11,
        description="ISO 1328-1:2013 flank tolerance class of both gears (geometry form): one "
        "mesh-frequency harmonic whose amplitude is the class's bound sqrt(F_alpha,1^2 + "
        "F_alpha,2^2) / 2 (model.standards.iso1328.mesh_error_bound), with a note.",
        examples=[7],
    )

    @model_validator(mode="after")
    def _one_source(self) -> TransmissionError:
        if (self.harmonics is None) == (self.accuracy_class is None):
            raise ValueError("give exactly one of harmonics and accuracy_class")
        return self


class TorqueFluctuation(StrictModel):
    """Driver-torque fluctuation sum T_r cos(r w_p t + phi_r)."""

    order: float = Field(
        1.0, gt=0.0, le=1000.0, allow_inf_nan=False,
        description="Fundamental in multiples of the driver speed (default 1).",
    )  # fmt: skip
    harmonics: list[TorqueFluctuationHarmonic] = Field(max_length=MAX_HARMONICS)


EXAMPLE_DESIGN = {
    "driver": {"teeth": 18, "base_radius": "30 mm", "inertia": "2e-3 kg*m^2"},
    "driven": {"teeth": 30, "base_radius": "50 mm", "inertia": "8e-3 kg*m^2"},
    "speed": "1500 rpm",
    "torque": "40 N*m",
    "mesh": {
        "stiffness": "1e8 N/m",
        "stiffness_harmonics": [{"amplitude": "1e7 N/m", "phase": 0.0}],
        "damping_ratio": 0.05,
        "half_backlash": "50 um",
    },
    "transmission_error": {"harmonics": [{"amplitude": "5 um", "phase": 0.0}]},
    "torque_fluctuation": {"order": 1, "harmonics": [{"amplitude": "4 N*m", "phase": 0.0}]},
    "backlash_law": "piecewise",
}
"""The README's design (direct form)."""


GEOMETRY = {"allOf": [given("module"), given("face_width")]}
GEOMETRY_FORM = {"properties": {"driver": GEOMETRY, "driven": GEOMETRY}}
"""JSON schema: both gears in the geometry form (module and face width)."""


class Design(StrictModel):
    """A spur-gear pair in physical units; the driver (gear a) drives the driven gear (b)."""

    model_config = request_config(EXAMPLE_DESIGN)
    model_config["json_schema_extra"] |= {"allOf": [  # as _consistent, _derived_inputs check
        {"if": {"required": ["mesh"], "properties": {"mesh": {
            "required": ["stiffness"], "properties": {"stiffness": {"const": "iso6336"}}}}},
         "then": GEOMETRY_FORM},
        {"if": {"required": ["tolerances"], "properties": {"tolerances": given("accuracy")}},
         "then": {**GEOMETRY_FORM, "properties": {**GEOMETRY_FORM["properties"],
                  "transmission_error": {"anyOf": [{"type": "null"}, {"not": given("order")}]}}}},
        {"if": {"required": ["transmission_error"],
                "properties": {"transmission_error": given("accuracy_class")}},
         "then": GEOMETRY_FORM},
    ]}  # fmt: skip

    driver: Gear = Field(description="The driving gear a.")
    driven: Gear = Field(description="The driven gear b.")
    speed: Speed = Field(description="Driver shaft speed, e.g. '1500 rpm'.")
    torque: MeanTorque = Field(description="Mean driver torque, e.g. '40 N*m'.")
    braking_torque: MeanTorque | None = Field(
        None, description="Mean braking torque on the driven gear (default: balancing)."
    )
    mesh: Mesh
    transmission_error: TransmissionError | None = None
    torque_fluctuation: TorqueFluctuation | None = None
    backlash_law: Literal["piecewise", "cubic_fit"] = Field(
        "piecewise",
        description="piecewise: the exact law of Eq. (6); cubic_fit: the paper's "
        "-x/6 + x^3/6. The Melnikov criterion always uses the cubic fit.",
    )
    speed_range: Annotated[list[Speed], Field(min_length=2, max_length=2),
                           Field(json_schema_extra={"examples": [["500 rpm", "4500 rpm"]]})
                           ] | None = Field(
        None, description="Driver speeds scanned for Melnikov windows (default 10 rpm to 3x "
        "speed).",
    )  # fmt: skip
    tolerances: Tolerances | None = Field(
        None,
        description="Manufacturing tolerances (distributions of fields by path, ISO 1328 "
        "accuracy, backlash band): read by robustness jobs; the analyses use the nominal design.",
    )
    train: Train | None = Field(
        None,
        exclude_if=lambda train: train is None,  # a pair's JSON stays the pair's
        description="Motor, shafts, load and bearings around the mesh (docs/gear-trains.md); "
        "without it the pair of rigid discs of Eq. (2).",
    )

    _readings: list[str] = PrivateAttr(default_factory=list)

    _ripple_shares: dict[int, float] = PrivateAttr(default_factory=dict)

    @model_validator(mode="wrap")
    @classmethod
    def _with_readings(cls, data: Any, handler: ModelWrapValidatorHandler[Design]) -> Design:
        """Validate, keeping what was understood from unit spellings ("40 Nm"), bare numbers
        and ripple in % of the mean torque; a Design given again is itself (it lost them)."""
        if isinstance(data, Design):
            return data
        with readings() as found:
            data, shares = ripple_of_mean_torque(data, found)
            design = handler(data)._derived_inputs()
        design._readings = found
        design._ripple_shares = shares
        return design

    @property
    def ripple_shares(self) -> dict[int, float]:
        """Torque fluctuation harmonics given in % of the mean torque: {index: percent}, so
        that a design with another torque (a sweep's point) scales them."""
        return dict(self._ripple_shares)

    @property
    def readings(self) -> list[str]:
        """How unit spellings pint reads otherwise were understood ("torque '40 Nm' read as
        '40 N*m'"), for the notes."""
        return list(self._readings)

    def operating_pressure_angle(self) -> float:
        """alpha_wt [rad] of the pair: from the profile shifts (``model.geometry``), else the
        driver's pressure angle."""
        a, b = self.driver, self.driven
        if a.profile_shift == 0.0 and b.profile_shift == 0.0:
            return a.pressure_angle
        return geometry.operating_pressure_angle(
            a.teeth, b.teeth, a.profile_shift, b.profile_shift, a.pressure_angle
        )

    def _derived_inputs(self) -> Design:
        """A circumferential backlash j_t written as the half backlash b = j_t cos(alpha_wt) / 2
        (``model.standards.backlash``) and an accuracy class as its transmission-error bound
        (``model.standards.iso1328``), each with a note; the design then holds b and e_1 alone,
        so its dump reads back the same."""
        j_t = self.mesh.backlash
        if j_t is not None:
            alpha = self.operating_pressure_angle()
            b = backlash.half_backlash(j_t, alpha)
            mesh = self.mesh.model_copy(update={"half_backlash": b, "backlash": None})
            object.__setattr__(self, "mesh", mesh)  # frozen: the validator's own rewrite
            note(f"mesh.backlash j_t = {j_t * 1e6:.6g} um (circumferential) read as the half "
                 f"backlash b = j_t cos(alpha_wt) / 2 = {b * 1e6:.6g} um along the line of "
                 f"action (alpha_wt = {math.degrees(alpha):.4g} deg)")  # fmt: skip
        te = self.transmission_error
        if te is not None and te.accuracy_class is not None:
            grade = te.accuracy_class
            if self.driver.geometry() is None or self.driven.geometry() is None:
                raise InputError(
                    "transmission_error.accuracy_class",
                    "an ISO 1328 class needs the geometry form (module and face_width) on both "
                    "gears",
                )
            bound = iso1328.pair_te_bound(grade, self.driver, self.driven)
            with si_numbers():  # the engine's own SI value, not a user's bare number
                harmonic = ErrorHarmonic(amplitude=bound)
            te = te.model_copy(update={"harmonics": [harmonic], "accuracy_class": None})
            object.__setattr__(self, "transmission_error", te)
            note(f"transmission_error.accuracy_class {grade} read as one mesh-frequency harmonic "
                 f"e_1 = {bound * 1e6:.4g} um, the {iso1328.STANDARD} class-{grade} bound "
                 "sqrt(F_alpha,driver^2 + F_alpha,driven^2) / 2")  # fmt: skip
        return self

    @model_validator(mode="after")
    def _consistent(self) -> Design:
        if self.mesh.stiffness == "iso6336" and (
            self.driver.geometry() is None or self.driven.geometry() is None
        ):
            raise ValueError("mesh.stiffness 'iso6336' needs module and face_width on both gears")
        if self.speed_range is not None and not self.speed_range[0] < self.speed_range[1]:
            raise InputError("speed_range", "the first speed must be below the second")
        tol = self.tolerances
        if tol is not None and tol.accuracy is not None:
            if self.driver.geometry() is None or self.driven.geometry() is None:
                raise InputError(
                    "tolerances.accuracy",
                    "an ISO 1328 class needs the geometry form (module and face_width) on both "
                    "gears",
                )
            if self.transmission_error is not None and self.transmission_error.order is not None:
                raise InputError(
                    "tolerances.accuracy",
                    "the ISO 1328 class sets the transmission error at the mesh frequency; remove "
                    "transmission_error.order",
                )
            if ACCURACY_FIELD in tol.fields():
                raise InputError("tolerances.accuracy", f"already sets {ACCURACY_FIELD}")
        if tol is not None and tol.backlash is not None and BACKLASH_FIELD in tol.fields():
            raise InputError("tolerances.backlash", f"already sets {BACKLASH_FIELD}")
        return self


def ripple_of_mean_torque(data: Any, notes: list[str]) -> tuple[Any, dict[int, float]]:
    """``data`` with each torque fluctuation amplitude given in % ("3 %") written as that share
    of the mean torque in N*m (Eq. 3's T_pr = 0.03 T_m), with a note each, and the shares by
    harmonic index. Elsewhere a "%" is refused (``model.units.parse_quantity``); a torque
    that cannot be read is left to its own field's error."""
    harmonics = data.get("torque_fluctuation") if isinstance(data, dict) else None
    harmonics = harmonics.get("harmonics") if isinstance(harmonics, dict) else None
    if not isinstance(harmonics, list):
        return data, {}
    shares = {k: float(m.group(1)) for k, h in enumerate(harmonics)
              if isinstance(h, dict) and isinstance(h.get("amplitude"), str)
              and (m := SHARE.fullmatch(h["amplitude"]))}  # fmt: skip
    if not shares:
        return data, {}
    try:
        with readings():  # the torque's own reading is noted by its field
            mean = parse_quantity(data.get("torque"), QUANTITIES["mean_torque"], allow_zero=True)
    except ValueError:
        return data, {}
    written = [dict(h) if isinstance(h, dict) else h for h in harmonics]
    for k, share in shares.items():
        amplitude = share / 100.0 * abs(mean)
        written[k]["amplitude"] = f"{amplitude!r} N*m"
        notes.append(
            f"torque_fluctuation.harmonics.{k}.amplitude {share:g} % read as {amplitude:.6g} "
            f"N*m, {share:g} % of the mean torque {mean:.6g} N*m"
        )
    fluctuation = {**data["torque_fluctuation"], "harmonics": written}
    return {**data, "torque_fluctuation": fluctuation}, shares


ACCURACY_FIELD = "transmission_error.harmonics.0.amplitude"
"""The field an ISO 1328 accuracy class sets (``model.standards.iso1328.mesh_error_bound``)."""
BACKLASH_FIELD = "mesh.half_backlash"
"""The field a backlash band sets (``model.standards.backlash``)."""
