"""A design reduced to Eq. (9): what the data leave implicit is derived (``model.geometry``),
the pair becomes the SI record of ``model.conversion`` and then the dimensionless parameters,
with the scales that map answers back to gear data (``DesignConversion``). ``ParamsOrDesign``
is the part of every request that carries ``params`` or a ``design``.
"""

from __future__ import annotations

import math
from typing import ClassVar

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
from gearengine.model.backlash import paper_cubic
from gearengine.model.conversion import (
    PhysicalGearData,
    StiffnessHarmonic,
    TorqueHarmonic,
    TransmissionErrorHarmonic,
    pair_mass,
    to_dimensionless,
    torque_gain,
)
from gearengine.model.design import EXAMPLE_DESIGN, Design
from gearengine.model.errors import InputError
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.params import CubicBacklash, GearParams, PiecewiseBacklash, given
from gearengine.model.standards import backlash, iso1328
from gearengine.model.units import (
    RADIUS_RATIO_TOLERANCE,
    RPM,
    TORQUE_BALANCE_TOLERANCE,
    Scales,
)

ISO_HARMONICS = 5
"""Harmonics of the mesh-stiffness wave kept when the variation comes from the contact ratio."""


class Derived(BaseModel):
    """A quantity derived from the design, with its unit and where it comes from."""

    model_config = ConfigDict(frozen=True)

    value: float | list[dict[str, float]] = Field(
        description="The value in its unit (SI, except the ISO 1328 tolerances: um)."
    )
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

    @property
    def scales(self) -> Scales:
        """What maps this design's dimensionless answers back to gear data (``model.units``:
        ``to_physical``, ``OUTPUTS``)."""
        return Scales(
            half_backlash=self.half_backlash_m,
            mesh_stiffness=self.mesh_stiffness_n_per_m,
            natural_frequency=1.0 / self.time_scale_s,
            static_force=self.static_force_n,
            mesh_frequency=2.0 * math.pi * self.mesh_frequency_hz,
            speed=self.speed_rpm * RPM,
            torque_gain=self.torque_gain,
        )


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


def _geometry(design: Design, torque: float | None = None) -> dict[str, Derived]:
    """Quantities of ``model.geometry`` for the gears given in geometry form, the ISO 6336
    stiffness at the mean driver torque ``torque`` [N m] (default: the design's)."""
    g1, g2 = design.driver.geometry(), design.driven.geometry()
    if g1 is not None and g2 is not None:
        radius = g1["module"] * g1["teeth"] / 2.0
        load = abs(design.torque if torque is None else torque) / radius
        pair = geometry.pair_from_geometry(g1, g2, tangential_load=load, n_harmonics=ISO_HARMONICS)
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


def iso_mesh_stiffness(design: Design, torque: float) -> float:
    """k_m [N/m] of a design with ``mesh.stiffness = "iso6336"`` at the mean driver torque
    ``torque`` [N m] (the load factor of ISO 6336-1 S5 grows with it below 100 N/mm): the
    ``mesh_stiffness_n_per_m`` that ``convert_design`` gives at that torque, without the rest
    of the conversion."""
    return float(_geometry(design, torque)["mesh_stiffness"].value)  # type: ignore[arg-type]


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
    if abs(ra / rb - teeth) > RADIUS_RATIO_TOLERANCE * teeth:
        raise InputError(
            "design.driven.base_radius",
            f"base radii ratio r_a / r_b = {ra / rb:.4f} differs from the teeth ratio "
            f"{design.driver.teeth}/{design.driven.teeth} = {teeth:.4f} by more than "
            f"{RADIUS_RATIO_TOLERANCE:.0%}",
        )
    k_m, harmonics = _stiffness(design, derived)
    if sum(abs(a) for a, _ in harmonics) >= k_m:
        raise InputError(
            "design.mesh.stiffness_harmonics",
            f"the amplitudes add up to the mean mesh stiffness {k_m:.6g} N/m or more, so the "
            "stiffness would become negative",
        )
    balancing = design.torque * rb / ra
    braking = balancing if design.braking_torque is None else design.braking_torque
    notes = design.readings
    if abs(braking - balancing) > TORQUE_BALANCE_TOLERANCE * max(abs(balancing), 1e-12):
        notes.append(f"braking torque {braking:.6g} N m differs from the balancing "
                     f"{balancing:.6g} N m: the pair would speed up or slow down")  # fmt: skip
    mesh, te, tf = design.mesh, design.transmission_error, design.torque_fluctuation
    ia, ib = gears["inertia_driver"], gears["inertia_driven"]
    m = pair_mass(ia, ib, ra, rb)
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
    """The paper's cubic law (``backlash.paper_cubic``) as a backlash of Eq. (9)."""
    fit = paper_cubic()
    return CubicBacklash(a=fit.a, c=fit.c)


def tolerance_derived(design: Design) -> dict[str, Derived]:
    """With ``tolerances.accuracy``: each gear's ISO 1328-1:2013 flank tolerances [µm]
    (``f_pT_driver``, ``F_alpha_driven``, ...) and the bound of the mesh-frequency transmission
    error they allow (``transmission_error_bound``, ``iso1328.mesh_error_bound``); with
    ``tolerances.backlash``: the half-backlash band (``half_backlash_min``/``_max``)."""
    tol, out = design.tolerances, {}
    if tol is None:
        return out
    if tol.accuracy is not None:
        grade = tol.accuracy.tolerance_class
        pair = iso1328.pair_tolerances(grade, design.driver, design.driven)
        for role, values in zip(("driver", "driven"), pair, strict=True):
            for name, formula in iso1328.FORMULAS.items():
                out[f"{name}_{role}"] = Derived(
                    value=getattr(values, name),
                    unit="um",
                    source=f"{iso1328.STANDARD} class {grade}, 5.3 Eq. {formula}, rounded (5.2.3)",
                )
        out["transmission_error_bound"] = Derived(
            value=iso1328.pair_te_bound(grade, design.driver, design.driven),
            unit="m",
            source="mesh-harmonic TE amplitude bound sqrt(F_alpha_driver^2 + F_alpha_driven^2)/2 "
            "(profile deviations drive the mesh harmonic; amplitude drawn uniformly below it)",
        )
    if tol.backlash is not None:
        band = half_backlash_band(design, tol.backlash.min, tol.backlash.max)
        for end, value in zip(("min", "max"), band, strict=True):
            out[f"half_backlash_{end}"] = Derived(
                value=value,
                unit="m",
                source="b = j_t cos(alpha_wt) / 2 of the circumferential band (ISO/TR 10064-2)",
            )
    return out


def half_backlash_band(design: Design, j_min: float, j_max: float) -> tuple[float, float]:
    """(b_min, b_max) [m] of a circumferential backlash band [m] of this pair."""
    return backlash.half_backlash_band(j_min, j_max, design.operating_pressure_angle())


def convert_design(design: Design) -> DesignConversion:
    """The dimensionless parameters of ``design`` (Eq. 7-9) with the scales and derivations."""
    data, derived, notes = physical_data(design)
    conv, gain = to_dimensionless(data), torque_gain(data)
    notes += [n for n in conv.notes if n.startswith(("base-radius", "sum of |k_r|"))]
    m = conv.equivalent_mass
    for role, r, inertia in (
        ("driver", data.base_radius_a, data.inertia_a),
        ("driven", data.base_radius_b, data.inertia_b),
    ):
        gear = getattr(design, role)
        for name, value, unit in (("base_radius", r, "m"), ("inertia", inertia, "kg*m^2")):
            key = f"{name}_{role}"
            if key in derived and getattr(gear, name) is not None:  # given beside the geometry
                notes.append(f"{role}.{name}: the given {value:.6g} {unit} is used, not the "
                             f"{float(derived[key].value):.6g} {unit} the geometry gives "  # type: ignore[arg-type]
                             f"({derived[key].source})")  # fmt: skip
                derived[key] = Derived(value=value, unit=unit, source="given")
            derived.setdefault(key, Derived(value=value, unit=unit, source="given"))
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
    derived |= tolerance_derived(design)
    force_scale = data.half_backlash * data.mesh_stiffness
    return DesignConversion(
        params=conv.params,
        derived=derived,
        natural_frequency_hz=conv.natural_frequency_hz,
        time_scale_s=conv.time_scale,
        mesh_frequency_hz=conv.mesh_frequency_hz,
        speed_rpm=design.speed / RPM,
        equivalent_mass_kg=m,
        half_backlash_m=data.half_backlash,
        mesh_stiffness_n_per_m=data.mesh_stiffness,
        static_force_n=conv.params.mean_force * force_scale,
        torque_gain=gain,
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
        if self.design.train is not None and not self.TRAINS:
            raise InputError(
                "design.train",
                "this request does not model a gear train yet: analyse it with /v1/analyses "
                "(gearengine analyze), sweep or gate it with /v1/sweeps (gearengine sweep, "
                "check), its modes with /v1/analyses/campbell, or remove train",
            )
        conversion = convert_design(self.design)
        # a stored request (a sweep job) carries both: params must be the design's conversion
        if self.params is not None and not self.params.same_parameters(conversion.params):
            raise ValueError("give params or design, not both")
        object.__setattr__(self, "params", conversion.params)
        self._conversion = conversion
        return self

    @classmethod
    def __get_pydantic_json_schema__(
        cls, core_schema: CoreSchema, handler: GetJsonSchemaHandler
    ) -> JsonSchemaValue:
        """The schema says what validation does: exactly one of params and design, given (a
        null one counts as absent), neither field outside ``ONE_OF`` given, and no
        ``design.train`` unless the request answers for trains (``TRAINS``)."""
        schema = handler.resolve_ref_schema(handler(core_schema))
        schema["oneOf"] = [given(name) for name in cls.ONE_OF]
        rules = [{"not": given(name)} for name in ("params", "design") if name not in cls.ONE_OF]
        if not cls.TRAINS:
            rules.append(
                {
                    "not": {
                        "required": ["design"],
                        "properties": {"design": {"type": "object", **given("train")}},
                    }
                }
            )
        if rules:
            schema["allOf"] = [*schema.get("allOf", []), *rules]
        return schema

    TRAINS: ClassVar[bool] = False
    """Whether this request answers for a design's ``train`` (``systems.gear_train``); the
    others refuse one, naming ``design.train``, rather than answer for the pair alone."""

    ONE_OF: ClassVar[tuple[str, ...]] = ("params", "design")
    """The fields of which a request gives exactly one (in its schema's ``oneOf``)."""

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
