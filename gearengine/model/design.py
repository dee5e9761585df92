"""A spur-gear pair as a designer describes it, in physical units, and its dimensionless form.

A ``Design`` holds gear data (teeth, base radius and inertia, or module, face width and
material), the running point (driver speed, mean driver torque), the mesh (stiffness, damping,
half backlash) and the excitations (transmission error, torque fluctuation). Quantities are
strings with units or SI numbers (``model.units``). ``convert_design`` derives what the data
leave implicit (``model.geometry``: base radii, inertias, contact ratio, ISO 6336-1 mesh
stiffness and its variation) and reduces the pair to the dimensionless parameters of Eq. (9)
through ``model.conversion`` (Eq. 7-8, with the r_a correction of the mean force).

Frequencies: the mesh frequency is teeth x speed; the transmission error runs at the mesh
frequency unless an ``order`` (multiple of the driver speed) is given; the torque fluctuation at
``order`` x speed (default 1). The braking torque balances the driving one unless given.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    GetJsonSchemaHandler,
    PrivateAttr,
    ValidationInfo,
    field_validator,
    model_validator,
)
from pydantic.json_schema import JsonSchemaValue
from pydantic_core import CoreSchema

from gearengine.model import geometry
from gearengine.model.backlash import collocation_fit
from gearengine.model.conversion import (
    PhysicalGearData,
    StiffnessHarmonic,
    TorqueHarmonic,
    TransmissionErrorHarmonic,
    to_dimensionless,
)
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.params import (
    MAX_HARMONICS,
    CubicBacklash,
    GearParams,
    Phase,
    PiecewiseBacklash,
    request_config,
)
from gearengine.model.units import (
    RPM,
    Angle,
    Bore,
    Damping,
    ErrorAmplitude,
    HalfBacklash,
    Inertia,
    Length,
    MeshStiffness,
    Speed,
    StiffnessVariation,
    Torque,
)

RATIO_TOLERANCE = 0.01
"""Largest relative mismatch of base-radius ratio and teeth ratio accepted."""
BALANCE_TOLERANCE = 1e-3
"""Relative mismatch of a given braking torque with the balancing one that raises a note
(rounding such as 66.667 for 200/3 N m stays below it)."""
ISO_HARMONICS = 5
"""Harmonics of the mesh-stiffness wave kept when the variation comes from the contact ratio."""


class _Strict(BaseModel):
    model_config = request_config()


class Gear(_Strict):
    """One gear: base radius and inertia directly, or its geometry (module, face width, ...)."""

    teeth: int = Field(ge=5, le=1000, description="Number of teeth z.", examples=[18])
    base_radius: Length | None = Field(None, description="Base-circle radius r_b.")
    inertia: Inertia | None = Field(None, description="Mass moment of inertia about the axis.")
    module: Length | None = Field(None, description="Normal module m (geometry form).")
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
        if self.base_radius is None and self.module is None:
            raise ValueError("give base_radius, or module (and face_width) for the geometry")
        if self.inertia is None and not geometric:
            raise ValueError("give inertia, or module and face_width to derive it")
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


class StiffnessVariationHarmonic(_Strict):
    """Harmonic r of the mesh stiffness at r x the mesh frequency (Eq. 4)."""

    amplitude: StiffnessVariation = Field(description="k_r.", examples=["1e7 N/m"])
    phase: Phase = Field(0.0, description="Phase, rad.")


class ErrorHarmonic(_Strict):
    """Harmonic r of the static transmission error (Eq. 5)."""

    amplitude: ErrorAmplitude = Field(description="e_r.", examples=["5 um"])
    phase: Phase = Field(0.0, description="Phase, rad.")


class TorqueFluctuationHarmonic(_Strict):
    """Harmonic r of the driver-torque fluctuation (Eq. 3)."""

    amplitude: Torque = Field(description="T_pr.", examples=["4 N*m"])
    phase: Phase = Field(0.0, description="Phase, rad.")


class Mesh(_Strict):
    """The tooth mesh: stiffness, damping and half backlash."""

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
    damping_ratio: float | None = Field(
        None, ge=0.0, le=1.0, allow_inf_nan=False, description="Mesh damping ratio zeta."
    )
    damping: Damping | None = Field(None, description="Mesh damping c (instead of zeta).")
    half_backlash: HalfBacklash = Field(description="Half backlash b (total 2b).")

    @model_validator(mode="after")
    def _one_damping(self) -> Mesh:
        if (self.damping_ratio is None) == (self.damping is None):
            raise ValueError("give exactly one of damping_ratio and damping")
        return self


class TransmissionError(_Strict):
    """Static transmission error e(t) = sum e_r cos(r w_e t + phi_r)."""

    order: float | None = Field(
        None, gt=0.0, le=1000.0, allow_inf_nan=False,
        description="Fundamental in multiples of the driver speed (default: teeth, the mesh "
        "frequency).",
    )  # fmt: skip
    harmonics: list[ErrorHarmonic] = Field(max_length=MAX_HARMONICS)


class TorqueFluctuation(_Strict):
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


class Design(_Strict):
    """A spur-gear pair in physical units; the driver (gear a) drives the driven gear (b)."""

    model_config = request_config(EXAMPLE_DESIGN)

    driver: Gear = Field(description="The driving gear a.")
    driven: Gear = Field(description="The driven gear b.")
    speed: Speed = Field(description="Driver shaft speed, e.g. '1500 rpm'.")
    torque: Torque = Field(description="Mean driver torque, e.g. '40 N*m'.")
    braking_torque: Torque | None = Field(
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
    speed_range: Annotated[list[Speed], Field(min_length=2, max_length=2)] | None = Field(
        None, description="Driver speeds scanned for Melnikov windows (default 10 rpm to 3x "
        "speed).",
    )  # fmt: skip

    @model_validator(mode="after")
    def _consistent(self) -> Design:
        if self.mesh.stiffness == "iso6336" and (
            self.driver.geometry() is None or self.driven.geometry() is None
        ):
            raise ValueError("mesh.stiffness 'iso6336' needs module and face_width on both gears")
        if self.speed_range is not None and not self.speed_range[0] < self.speed_range[1]:
            raise ValueError("speed_range: the first speed must be below the second")
        return self


class Derived(BaseModel):
    """A quantity derived from the design, with its unit and where it comes from."""

    model_config = ConfigDict(frozen=True)

    value: float | list[dict[str, float]] = Field(description="The value (SI units).")
    unit: str = Field(description="Its unit.")
    source: str = Field(description="The formula or standard it comes from.")


class DesignConversion(BaseModel):
    """The design reduced to Eq. (9), with the scales that map answers back to gear data."""

    model_config = ConfigDict(frozen=True)

    params: GearParams = Field(description="Dimensionless parameters of Eq. (9) used.")
    derived: dict[str, Derived] = Field(description="Quantities derived from the design.")
    natural_frequency_hz: float = Field(description="f_n = sqrt(k_m / m) / (2 pi) [Hz].")
    time_scale_s: float = Field(description="Time unit 1 / omega_n [s]: t = tau / omega_n.")
    mesh_frequency_hz: float = Field(description="Mesh frequency teeth x speed [Hz].")
    speed_rpm: float = Field(description="Driver speed [rpm].")
    equivalent_mass_kg: float = Field(description="m = I_a I_b / (I_b r_a^2 + I_a r_b^2).")
    half_backlash_m: float = Field(description="b [m]: x = 1 is one half backlash.")
    mesh_stiffness_n_per_m: float = Field(description="k_m [N/m]: forces scale with b k_m.")
    static_force_n: float = Field(description="Mean mesh force F^_m [N] (Eq. 7).")
    torque_gain: float = Field(description="F~_p per N m of driver torque fluctuation [1/(N m)].")
    notes: list[str] = Field(description="Assumptions and remarks, in plain words.")


def _gear_values(design: Design, derived: dict[str, Derived]) -> dict[str, float]:
    """Base radii and inertias: given ones win over those derived from geometry."""
    out = {}
    for role, gear in (("driver", design.driver), ("driven", design.driven)):
        for name in ("base_radius", "inertia"):
            given = getattr(gear, name)
            key = f"{name}_{role}"
            if given is None:
                given = float(derived[key].value)  # type: ignore[arg-type]
            out[key] = given
    return out


def _geometry(design: Design) -> dict[str, Derived]:
    """Quantities of ``model.geometry`` for the gears given in geometry form."""
    g1, g2 = design.driver.geometry(), design.driven.geometry()
    if g1 is not None and g2 is not None:
        radius = g1["module"] * g1["teeth"] / 2.0
        pair = geometry.pair_from_geometry(
            g1, g2, tangential_load=abs(design.torque) / radius, n_harmonics=ISO_HARMONICS
        )
        return {k: Derived(**v) for k, v in pair.items()}
    derived = {}
    for role, g in (("driver", g1), ("driven", g2)):
        if g is None:
            continue
        derived[f"base_radius_{role}"] = Derived(
            value=geometry.base_radius(g["teeth"], g["module"], g["pressure_angle"]),
            unit="m",
            source="involute geometry: r_b = (m z/2) cos(alpha)",
        )
        density = geometry.MATERIALS[g["material"]]["density"]
        r = geometry.reference_radius(g["teeth"], g["module"])
        derived[f"inertia_{role}"] = Derived(
            value=geometry.disc_inertia(density, g["face_width"], r, g["bore_diameter"] / 2.0),
            unit="kg*m^2",
            source="solid disc with bore at the reference diameter: J = rho b pi/2 (r^4 - r_i^4)",
        )
    return derived


def _stiffness(design: Design, derived: dict[str, Derived]) -> tuple[float, list]:
    """(k_m, harmonics as (amplitude N/m, phase)) from the mesh data or ISO 6336-1."""
    mesh = design.mesh
    if mesh.stiffness == "iso6336":
        k_m = float(derived["mesh_stiffness"].value)  # type: ignore[arg-type]
        wave = derived["stiffness_harmonics"].value
        harmonics = [(h["amplitude"], h["phase"]) for h in wave]  # type: ignore[union-attr]
    else:
        k_m, harmonics = float(mesh.stiffness), []  # type: ignore[arg-type]
    if mesh.stiffness_harmonics is not None:
        harmonics = [(h.amplitude, h.phase) for h in mesh.stiffness_harmonics]
    return k_m, harmonics


def physical_data(design: Design) -> tuple[PhysicalGearData, dict[str, Derived], list[str]]:
    """The design as the SI record of ``model.conversion``, the derived quantities and notes.

    Raises ValueError (message starting with the field) for inconsistent radii and teeth.
    """
    derived = _geometry(design)
    gears = _gear_values(design, derived)
    ra, rb = gears["base_radius_driver"], gears["base_radius_driven"]
    teeth = design.driver.teeth / design.driven.teeth
    if abs(ra / rb - teeth) > RATIO_TOLERANCE * teeth:
        raise ValueError(
            f"design.driven.base_radius: base radii ratio r_a / r_b = {ra / rb:.4f} differs "
            f"from the teeth ratio {design.driver.teeth}/{design.driven.teeth} = {teeth:.4f} "
            "by more than 1 %"
        )
    k_m, harmonics = _stiffness(design, derived)
    if sum(abs(a) for a, _ in harmonics) >= k_m:
        raise ValueError(
            "design.mesh.stiffness_harmonics: the amplitudes add up to the mean mesh stiffness "
            f"{k_m:.6g} N/m or more, so the stiffness would become negative"
        )
    balancing = design.torque * rb / ra
    braking = balancing if design.braking_torque is None else design.braking_torque
    notes = []
    if abs(braking - balancing) > BALANCE_TOLERANCE * max(abs(balancing), 1e-12):
        notes.append(f"braking torque {braking:.6g} N m differs from the balancing "
                     f"{balancing:.6g} N m: the pair would speed up or slow down")  # fmt: skip
    mesh, te, tf = design.mesh, design.transmission_error, design.torque_fluctuation
    ia, ib = gears["inertia_driver"], gears["inertia_driven"]
    m = ia * ib / (ib * ra**2 + ia * rb**2)  # equivalent mass (Eq. 7)
    zeta = mesh.damping_ratio
    damping = mesh.damping if zeta is None else 2.0 * zeta * math.sqrt(k_m * m)  # mu~ = zeta
    data = PhysicalGearData(
        inertia_a=ia, inertia_b=ib,
        base_radius_a=ra, base_radius_b=rb,
        teeth_a=design.driver.teeth, teeth_b=design.driven.teeth,
        shaft_speed_a=design.speed, mesh_stiffness=k_m,
        stiffness_harmonics=[StiffnessHarmonic(amplitude=a, phase=p) for a, p in harmonics],
        mesh_damping=damping, half_backlash=mesh.half_backlash,
        torque_a_mean=design.torque, torque_b_mean=braking,
        torque_harmonics=[] if tf is None else [
            TorqueHarmonic(amplitude=h.amplitude, phase=h.phase) for h in tf.harmonics],
        transmission_error_harmonics=[] if te is None else [
            TransmissionErrorHarmonic(amplitude=h.amplitude, phase=h.phase) for h in te.harmonics],
        backlash=PiecewiseBacklash() if design.backlash_law == "piecewise" else _paper_cubic(),
        torque_order=1.0 if tf is None else tf.order,
        transmission_error_order=None if te is None else te.order,
    )  # fmt: skip
    return data, derived, notes


def _paper_cubic() -> CubicBacklash:
    fit = collocation_fit(0.0)
    return CubicBacklash(a=fit.a, c=fit.c)


def convert_design(design: Design) -> DesignConversion:
    """The dimensionless parameters of ``design`` (Eq. 7-9) with the scales and derivations."""
    data, derived, notes = physical_data(design)
    conv = to_dimensionless(data)
    notes += [n for n in conv.notes if n.startswith(("base-radius", "sum of |k_r|"))]
    m = conv.equivalent_mass
    for role, r, inertia in (
        ("driver", data.base_radius_a, data.inertia_a),
        ("driven", data.base_radius_b, data.inertia_b),
    ):
        derived.setdefault(f"base_radius_{role}", Derived(value=r, unit="m", source="given"))
        derived.setdefault(f"inertia_{role}", Derived(value=inertia, unit="kg*m^2", source="given"))
    derived["equivalent_mass"] = Derived(
        value=m, unit="kg", source="m = I_a I_b / (I_b r_a^2 + I_a r_b^2) (Eq. 7)"
    )
    if design.mesh.damping_ratio is None:
        notes.append(f"damping {data.mesh_damping:.6g} N s/m is a damping ratio of "
                     f"{conv.params.damping:.4g}")  # fmt: skip
    if design.backlash_law == "piecewise":
        notes.append(
            "the numerical verdict uses the exact piecewise backlash law; the Melnikov "
            "criterion needs a smooth law and uses its cubic fit -x/6 + x^3/6 (the paper's)"
        )
    force_scale = data.half_backlash * data.mesh_stiffness
    return DesignConversion(
        params=conv.params,
        derived=derived,
        natural_frequency_hz=conv.natural_frequency / (2.0 * math.pi),
        time_scale_s=conv.time_scale,
        mesh_frequency_hz=conv.mesh_frequency / (2.0 * math.pi),
        speed_rpm=design.speed / RPM,
        equivalent_mass_kg=m,
        half_backlash_m=data.half_backlash,
        mesh_stiffness_n_per_m=data.mesh_stiffness,
        static_force_n=conv.params.mean_force * force_scale,
        torque_gain=m * data.base_radius_a / data.inertia_a / force_scale,
        notes=notes,
    )


class ParamsOrDesign(BaseModel):
    """A request that carries exactly one of ``params`` (dimensionless) or ``design``.

    With a design, ``params`` is filled with its conversion after validation, so every engine
    function reads ``params`` (never None once validated); ``conversion`` keeps the scales for
    answers in physical units.
    """

    design: Design | None = Field(
        None,
        description="The pair in physical units (see docs/units.md). Give this or params.",
        examples=[EXAMPLE_DESIGN],
    )
    params: GearParams | None = Field(
        None,
        validate_default=True,
        description="Dimensionless parameters of Eq. (9). Give this or design.",
        examples=[PAPER_SECTION_41],
    )
    _conversion: DesignConversion | None = PrivateAttr(None)

    @field_validator("params")
    @classmethod
    def _given(cls, params: GearParams | None, info: ValidationInfo) -> GearParams | None:
        # design is validated first: absent from info.data when it failed (its errors suffice)
        if params is None and "design" in info.data and info.data["design"] is None:
            raise ValueError("Field required: give params (dimensionless) or design (physical)")
        return params

    @model_validator(mode="after")
    def _convert(self) -> ParamsOrDesign:
        if self.design is None:
            return self
        conversion = convert_design(self.design)
        # a stored request (a sweep job) carries both: params must be the design's conversion
        if self.params is not None and self.params != conversion.params:
            raise ValueError("give params or design, not both")
        object.__setattr__(self, "params", conversion.params)
        self._conversion = conversion
        return self

    @classmethod
    def __get_pydantic_json_schema__(
        cls, core_schema: CoreSchema, handler: GetJsonSchemaHandler
    ) -> JsonSchemaValue:
        """The schema says what validation does: exactly one of params and design."""
        schema = handler.resolve_ref_schema(handler(core_schema))
        schema["oneOf"] = [{"required": ["params"]}, {"required": ["design"]}]
        return schema

    @property
    def conversion(self) -> DesignConversion | None:
        """The design's conversion, or None for a dimensionless request."""
        return self._conversion

    def speed_rpm_range(self) -> tuple[float, float]:
        """Driver speeds [rpm] scanned for Melnikov windows (design's range or the default)."""
        assert self.design is not None
        if self.design.speed_range is not None:
            lo, hi = self.design.speed_range
            return lo / RPM, hi / RPM
        return 10.0, 3.0 * self.design.speed / RPM
