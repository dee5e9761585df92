"""Physical gear data (SI units) to the dimensionless parameters of Eq. (8)-(9).

The two torsional equations of motion (Eq. 2a-2b) reduce to one equation for the relative
displacement along the line of action, x~ = r_a theta_a - r_b theta_b - e(t) (Eq. 7):

    m x~'' + c x~' + k(t) f_h(x~) = F^_m + F^_p(t) + F^_e(t)

    m      = I_a I_b / (I_b r_a^2 + I_a r_b^2)                 equivalent mass [kg]
    F^_m   = m (r_a T_ma / I_a + r_b T_mb / I_b)               mean force [N]
    F^_p   = m (r_a / I_a) sum_r T_pr cos(r w_p t + phi_pr)     torque fluctuation [N]
    F^_e   = -m e''(t) = m sum_r (r w_e)^2 e_r cos(r w_e t + phi_er)                  [N]

Erratum: the paper prints F^_m = m (T_ma / I_a + T_mb r_b / I_b), without r_a in the first term.
That expression is not even a force (its first term has units N/m); multiplying (2a) by r_a / I_a
and (2b) by r_b / I_b and subtracting gives the form above. With balanced mean torques,
T_mb = T_ma r_b / r_a, it reduces to the tooth force F^_m = T_ma / r_a. ``docs/conversion.md``
has the derivation; ``tests/test_conversion.py`` checks it against a direct integration of (2a-2b).

Dividing Eq. (7) by b k_m with x = x~ / b and tau = w_n t gives Eq. (8) with

    w_n = sqrt(k_m / m),  Omega_{k,e,p} = w_{k,e,p} / w_n,  mu~ = c / (2 m w_n),
    k~_pr = k_r / (2 m w_n^2) = k_r / (2 k_m),  F~_m = F^_m / (b k_m),
    F~_pr = F^_pr / (b k_m) with F^_pr = m r_a T_pr / I_a,  F~_er = e_r / b.

Frequencies: mesh w_k = n_a w_a; transmission error w_e = (transmission_error_order) w_a,
default n_a w_a = w_k; torque fluctuation w_p = (torque_order) w_a, default w_a.
"""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import Field

from gearengine.model.params import (
    MAX_HARMONICS,
    Backlash,
    Excitation,
    GearParams,
    Harmonic,
    PiecewiseBacklash,
    StrictModel,
)
from gearengine.model.units import RADIUS_RATIO_TOLERANCE, TORQUE_BALANCE_TOLERANCE

Positive = Annotated[float, Field(ge=1.0e-12, le=1.0e12, allow_inf_nan=False)]
"""A physical quantity that must be positive, in [1e-12, 1e12] SI units (no subnormals)."""
SIValue = Annotated[float, Field(ge=-1.0e12, le=1.0e12, allow_inf_nan=False)]
"""A signed physical quantity in SI units, |value| <= 1e12."""


class _Phase(StrictModel):
    phase: SIValue = Field(
        0.0, description="Phase angle phi_r of this harmonic [rad].", examples=[0.0]
    )


class StiffnessHarmonic(_Phase):
    """Harmonic r of the mesh stiffness: k_r cos(r w_k t + phi_kr) (Eq. 4)."""

    amplitude: SIValue = Field(description="Stiffness amplitude k_r [N/m].", examples=[1.0e7])


class TorqueHarmonic(_Phase):
    """Harmonic r of the driver torque: T_pr cos(r w_p t + phi_pr) (Eq. 3)."""

    amplitude: SIValue = Field(description="Torque amplitude T_pr [N m].", examples=[10.0])


class TransmissionErrorHarmonic(_Phase):
    """Harmonic r of the static transmission error: e_r cos(r w_e t + phi_er) (Eq. 5)."""

    amplitude: SIValue = Field(
        description="Transmission-error amplitude e_r [m].", examples=[1.0e-5]
    )


class PhysicalGearData(StrictModel):
    """A spur gear pair in SI units, the model of Eq. (1)-(6); gear a drives gear b."""

    inertia_a: Positive = Field(
        description="Mass moment of inertia I_a of the driver gear a [kg m^2].", examples=[2.0e-3]
    )
    inertia_b: Positive = Field(
        description="Mass moment of inertia I_b of the driven gear b [kg m^2].", examples=[8.0e-3]
    )
    base_radius_a: Positive = Field(
        description="Base-circle radius r_a of gear a [m].", examples=[0.03]
    )
    base_radius_b: Positive = Field(
        description="Base-circle radius r_b of gear b [m].", examples=[0.05]
    )
    teeth_a: int = Field(ge=1, description="Number of teeth n_a of gear a [-].", examples=[18])
    teeth_b: int = Field(ge=1, description="Number of teeth n_b of gear b [-].", examples=[30])
    shaft_speed_a: Positive = Field(
        description="Mean angular speed w_a of the driver shaft [rad/s] (not rpm).",
        examples=[157.08],
    )
    mesh_stiffness: Positive = Field(
        description="Mean mesh stiffness k_m along the line of action [N/m].", examples=[1.0e8]
    )
    stiffness_harmonics: list[StiffnessHarmonic] = Field(
        default_factory=list,
        max_length=MAX_HARMONICS,
        description=(
            "Mesh-stiffness harmonics r = 1, 2, ...: entry r-1 is k_r [N/m] times "
            f"cos(r w_k t + phi_kr), w_k the mesh frequency. At most {MAX_HARMONICS}."
        ),
        examples=[[{"amplitude": 1.0e7, "phase": 0.0}]],
    )
    mesh_damping: Annotated[float, Field(ge=0.0, le=1.0e12, allow_inf_nan=False)] = Field(
        description="Mesh damping coefficient c along the line of action [N s/m].",
        examples=[1.1e3],
    )
    half_backlash: Positive = Field(
        description="Half backlash b; the total backlash is 2b [m].", examples=[1.0e-4]
    )
    torque_a_mean: SIValue = Field(
        description="Mean input torque T_ma on the driver gear a [N m].", examples=[40.0]
    )
    torque_b_mean: SIValue = Field(
        description=(
            "Mean braking torque T_mb on the driven gear b [N m], positive opposing the drive "
            "(Eq. 2b has -T_b on the right). Steady running needs T_mb = T_ma r_b / r_a."
        ),
        examples=[66.667],
    )
    torque_harmonics: list[TorqueHarmonic] = Field(
        default_factory=list,
        max_length=MAX_HARMONICS,
        description=(
            "Driver-torque harmonics r = 1, 2, ...: entry r-1 is T_pr [N m] times "
            f"cos(r w_p t + phi_pr), w_p = torque_order * w_a. At most {MAX_HARMONICS}."
        ),
        examples=[[{"amplitude": 10.0, "phase": 0.0}]],
    )
    transmission_error_harmonics: list[TransmissionErrorHarmonic] = Field(
        default_factory=list,
        max_length=MAX_HARMONICS,
        description=(
            "Static transmission-error harmonics r = 1, 2, ...: entry r-1 is e_r [m] times "
            "cos(r w_e t + phi_er), w_e = transmission_error_order * w_a. "
            f"At most {MAX_HARMONICS}."
        ),
        examples=[[{"amplitude": 1.0e-5, "phase": 0.0}]],
    )
    backlash: Backlash = Field(
        default_factory=PiecewiseBacklash,
        description=(
            "Backlash law f_h [-] (x and f_h in units of b), passed through unchanged: "
            "piecewise (Eq. 6/8, default alpha = 0) or cubic -a x + c x^3 (Eq. 9, paper "
            "a = c = 0.1667)."
        ),
        examples=[{"model": "piecewise", "alpha": 0.0}],
    )
    torque_order: Positive = Field(
        1.0,
        description=(
            "Fundamental of the torque fluctuation in multiples of the shaft speed, "
            "w_p = torque_order * w_a [-] (default 1: the input shaft frequency)."
        ),
        examples=[1.0],
    )
    transmission_error_order: Positive | None = Field(
        None,
        description=(
            "Fundamental of the transmission error in multiples of the shaft speed, "
            "w_e = transmission_error_order * w_a [-] (default n_a: the mesh frequency)."
        ),
        examples=[18.0],
    )


CONVERSION_UNITS = {
    "equivalent_mass": "kg",
    "natural_frequency": "rad/s",
    "time_scale": "s",
    "mesh_frequency": "rad/s",
    "natural_frequency_hz": "Hz",
    "mesh_frequency_hz": "Hz",
}
"""Units of the numbers of a ``Conversion`` (/v1/conversions/physical)."""


class Conversion(StrictModel):
    """Result of ``to_dimensionless``: the parameters of Eq. (8) and the scales used."""

    params: GearParams = Field(description="Dimensionless parameters of Eq. (8)-(9).")
    equivalent_mass: float = Field(
        description="Equivalent mass m = I_a I_b / (I_b r_a^2 + I_a r_b^2) [kg]."
    )
    natural_frequency: float = Field(
        description="Natural frequency w_n = sqrt(k_m / m) [rad/s]; tau = w_n t."
    )
    time_scale: float = Field(description="Time unit 1 / w_n [s]: physical time t = tau / w_n.")
    mesh_frequency: float = Field(description="Mesh frequency w_k = n_a w_a [rad/s].")
    notes: list[str] = Field(
        default_factory=list, description="Derived values and warnings about the input."
    )
    natural_frequency_hz: float = Field(description="f_n = w_n / (2 pi) [Hz].")
    mesh_frequency_hz: float = Field(description="Mesh frequency w_k / (2 pi) [Hz].")
    units: dict[str, str] = Field(
        default_factory=lambda: dict(CONVERSION_UNITS),
        description="The unit of each number above.",
        examples=[{"natural_frequency": "rad/s", "mesh_frequency": "rad/s"}],
    )


def pair_mass(ia: float, ib: float, ra: float, rb: float) -> float:
    """Equivalent mass m = I_a I_b / (I_b r_a^2 + I_a r_b^2) [kg] of inertias I [kg m^2] on
    base radii r [m] (Eq. 7)."""
    return ia * ib / (ib * ra**2 + ia * rb**2)


def equivalent_mass(data: PhysicalGearData) -> float:
    """m = I_a I_b / (I_b r_a^2 + I_a r_b^2) [kg] of the record (Eq. 7, ``pair_mass``)."""
    return pair_mass(data.inertia_a, data.inertia_b, data.base_radius_a, data.base_radius_b)


def torque_gain(data: PhysicalGearData) -> float:
    """F~_p per N m of driver-torque fluctuation, m r_a / (I_a b k_m) [1/(N m)] (Eq. 7-8)."""
    force_scale = data.half_backlash * data.mesh_stiffness
    return equivalent_mass(data) * data.base_radius_a / data.inertia_a / force_scale


def mean_force(data: PhysicalGearData) -> float:
    """Corrected mean mesh force F^_m = m (r_a T_ma / I_a + r_b T_mb / I_b) [N] (Eq. 7).

    The paper prints m (T_ma / I_a + T_mb r_b / I_b); the r_a in the first term is missing there.
    """
    return equivalent_mass(data) * (
        data.base_radius_a * data.torque_a_mean / data.inertia_a
        + data.base_radius_b * data.torque_b_mean / data.inertia_b
    )


def to_dimensionless(data: PhysicalGearData) -> Conversion:
    """Dimensionless groups of Eq. (8) for a physical gear pair (Eq. 7 divided by b k_m).

    Raises ``pydantic.ValidationError`` when a group falls outside ``GearParams``' bounds (for
    example a frequency ratio above 1e3).
    """
    m = equivalent_mass(data)
    k_m, b = data.mesh_stiffness, data.half_backlash
    omega_n = math.sqrt(k_m / m)
    omega_k = data.teeth_a * data.shaft_speed_a
    te_order = (
        data.teeth_a if data.transmission_error_order is None else data.transmission_error_order
    )
    force_scale = b * k_m
    f_m = mean_force(data)

    def excitation(omega: float, harmonics: list[tuple[float, float]]) -> Excitation:
        return Excitation(
            frequency=omega / omega_n,
            harmonics=[Harmonic(amplitude=amp, phase=phase) for amp, phase in harmonics],
        )

    gain = torque_gain(data)
    params = GearParams(
        damping=data.mesh_damping / (2.0 * m * omega_n),
        mean_force=f_m / force_scale,
        backlash=data.backlash,
        stiffness=excitation(
            omega_k, [(h.amplitude / (2.0 * k_m), h.phase) for h in data.stiffness_harmonics]
        ),
        transmission_error=excitation(
            te_order * data.shaft_speed_a,
            [(h.amplitude / b, h.phase) for h in data.transmission_error_harmonics],
        ),
        torque=excitation(
            data.torque_order * data.shaft_speed_a,
            [(h.amplitude * gain, h.phase) for h in data.torque_harmonics],
        ),
    )
    orders = {"stiffness": data.teeth_a, "transmission_error": te_order,
              "torque": data.torque_order}  # fmt: skip
    return Conversion(
        params=params.with_shaft_orders(orders),
        equivalent_mass=m,
        natural_frequency=omega_n,
        time_scale=1.0 / omega_n,
        mesh_frequency=omega_k,
        notes=_notes(data, f_m),
        natural_frequency_hz=omega_n / (2.0 * math.pi),
        mesh_frequency_hz=omega_k / (2.0 * math.pi),
    )


def _notes(data: PhysicalGearData, f_m: float) -> list[str]:
    ra, rb = data.base_radius_a, data.base_radius_b
    notes = [
        f"mean force F^_m = m (r_a T_ma / I_a + r_b T_mb / I_b) = {f_m:.6g} N (the paper's "
        "printed Eq. 7 omits r_a in the first term; corrected here)"
    ]
    imbalance = data.torque_a_mean / ra - data.torque_b_mean / rb
    if abs(imbalance) > TORQUE_BALANCE_TOLERANCE * max(abs(data.torque_a_mean / ra), abs(f_m)):
        notes.append(
            f"mean torques are unbalanced: T_ma / r_a - T_mb / r_b = {imbalance:.6g} N, so the "
            "pair speeds up or slows down (Eq. 1 assumes constant speeds); Eq. 7 for x~ still "
            "holds"
        )
    ratio, teeth_ratio = ra / rb, data.teeth_a / data.teeth_b
    if abs(ratio - teeth_ratio) > RADIUS_RATIO_TOLERANCE * teeth_ratio:
        notes.append(
            f"base-radius ratio r_a / r_b = {ratio:.6g} differs from the teeth ratio "
            f"n_a / n_b = {teeth_ratio:.6g}"
        )
    k_var = sum(abs(h.amplitude) for h in data.stiffness_harmonics)
    if k_var >= data.mesh_stiffness:
        notes.append(
            f"sum of |k_r| = {k_var:.6g} N/m reaches k_m: the mesh stiffness can become negative"
        )
    if isinstance(data.backlash, PiecewiseBacklash):
        notes.append(
            "piecewise backlash law kept for the numerics; the Melnikov analysis replaces it by "
            "its cubic fit through x = 0, 1, 2 (the paper's a = c = 1/6 for alpha = 0)"
        )
    return notes
