"""Physical gear data -> dimensionless Eq. (8): unit checks, a direct check against the
two-degree-of-freedom equations (2a)-(2b) in SI units, the F^_m erratum and input validation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError
from scipy.integrate import solve_ivp

from gearengine.model.conversion import (
    Conversion,
    PhysicalGearData,
    equivalent_mass,
    mean_force,
    to_dimensionless,
)
from gearengine.model.params import (
    MAX_HARMONICS,
    Backlash,
    CubicBacklash,
    Excitation,
    GearParams,
    PiecewiseBacklash,
)

# A realistic pair: 18/30 teeth, module ~3.5 mm base radii, 1500 rpm input, 40 N m.
R_A, R_B = 0.03, 0.05
T_MA = 40.0
GEAR = {
    "inertia_a": 2.0e-3,
    "inertia_b": 8.0e-3,
    "base_radius_a": R_A,
    "base_radius_b": R_B,
    "teeth_a": 18,
    "teeth_b": 30,
    "shaft_speed_a": 1500.0 * 2.0 * math.pi / 60.0,
    "mesh_stiffness": 1.0e8,
    "stiffness_harmonics": [
        {"amplitude": 1.0e7, "phase": 0.3},
        {"amplitude": 3.0e6, "phase": 1.0},
    ],
    "mesh_damping": 1.1e3,
    "half_backlash": 1.0e-4,
    "torque_a_mean": T_MA,
    "torque_b_mean": T_MA * R_B / R_A,
    "torque_harmonics": [
        {"amplitude": 10.0, "phase": 0.0},
        {"amplitude": 4.0, "phase": -0.5},
    ],
    "transmission_error_harmonics": [
        {"amplitude": 1.0e-5, "phase": 0.2},
        {"amplitude": 3.0e-6, "phase": 0.4},
    ],
}


def gear(**changes: object) -> PhysicalGearData:
    return PhysicalGearData.model_validate({**GEAR, **changes})


# --- (a) the dimensionless groups, one by one -----------------------------------------------


def test_equivalent_mass_and_natural_frequency() -> None:
    conv = to_dimensionless(gear())
    # 1/m = r_a^2/I_a + r_b^2/I_b = 0.45 + 0.3125 = 0.7625 kg^-1
    assert conv.equivalent_mass == pytest.approx(1.0 / 0.7625, rel=1e-14)
    assert conv.natural_frequency == pytest.approx(math.sqrt(1.0e8 * 0.7625), rel=1e-14)
    assert conv.time_scale * conv.natural_frequency == pytest.approx(1.0, rel=1e-15)
    # identical gears: m = I / (2 r^2)
    same = gear(inertia_b=2.0e-3, base_radius_b=R_A, teeth_b=18)
    assert equivalent_mass(same) == pytest.approx(2.0e-3 / (2.0 * R_A**2), rel=1e-14)


def test_frequencies_default_orders() -> None:
    data = gear()
    conv = to_dimensionless(data)
    w_n, w_a = conv.natural_frequency, data.shaft_speed_a
    p = conv.params
    assert conv.mesh_frequency == pytest.approx(18 * w_a, rel=1e-15)
    assert p.stiffness is not None and p.transmission_error is not None and p.torque is not None
    assert p.stiffness.frequency == pytest.approx(18 * w_a / w_n, rel=1e-14)
    assert p.transmission_error.frequency == pytest.approx(18 * w_a / w_n, rel=1e-14)
    assert p.torque.frequency == pytest.approx(w_a / w_n, rel=1e-14)


def test_frequencies_explicit_orders() -> None:
    data = gear(torque_order=2.0, transmission_error_order=36.0)
    conv = to_dimensionless(data)
    w_n, w_a = conv.natural_frequency, data.shaft_speed_a
    assert conv.params.torque is not None and conv.params.transmission_error is not None
    assert conv.params.torque.frequency == pytest.approx(2.0 * w_a / w_n, rel=1e-14)
    assert conv.params.transmission_error.frequency == pytest.approx(36.0 * w_a / w_n, rel=1e-14)
    assert conv.mesh_frequency == pytest.approx(18 * w_a, rel=1e-15)


def test_damping_and_amplitudes() -> None:
    data = gear()
    conv = to_dimensionless(data)
    m, w_n, p = conv.equivalent_mass, conv.natural_frequency, conv.params
    b_km = 1.0e-4 * 1.0e8
    assert p.damping == pytest.approx(1.1e3 / (2.0 * m * w_n), rel=1e-14)
    assert p.stiffness is not None and p.transmission_error is not None and p.torque is not None
    # k~_pr = k_r / (2 m w_n^2) = k_r / (2 k_m)
    assert [h.amplitude for h in p.stiffness.harmonics] == pytest.approx([0.05, 0.015], rel=1e-14)
    assert [h.amplitude for h in p.stiffness.harmonics] == pytest.approx(
        [1.0e7 / (2.0 * m * w_n**2), 3.0e6 / (2.0 * m * w_n**2)], rel=1e-12
    )
    # F~_er = e_r / b
    assert [h.amplitude for h in p.transmission_error.harmonics] == pytest.approx(
        [0.1, 0.03], rel=1e-14
    )
    # F~_pr = m r_a T_pr / (I_a b k_m)
    gain = m * R_A / 2.0e-3 / b_km
    assert [h.amplitude for h in p.torque.harmonics] == pytest.approx(
        [10.0 * gain, 4.0 * gain], rel=1e-14
    )
    # phases pass through unchanged, harmonic order is kept
    assert [h.phase for h in p.stiffness.harmonics] == [0.3, 1.0]
    assert [h.phase for h in p.torque.harmonics] == [0.0, -0.5]
    assert [h.phase for h in p.transmission_error.harmonics] == [0.2, 0.4]


def test_mean_force_is_the_tooth_force_for_balanced_torques() -> None:
    # T_mb = T_ma r_b / r_a  =>  F^_m = m T_ma / r_a (r_a^2 / I_a + r_b^2 / I_b) = T_ma / r_a
    data = gear()
    assert mean_force(data) == pytest.approx(T_MA / R_A, rel=1e-14)
    assert to_dimensionless(data).params.mean_force == pytest.approx(T_MA / R_A / 1.0e4, rel=1e-14)
    assert not any("unbalanced" in n for n in to_dimensionless(data).notes)


def test_unbalanced_torques_are_noted() -> None:
    conv = to_dimensionless(gear(torque_b_mean=50.0))
    assert any("unbalanced" in n for n in conv.notes)


def test_backlash_law_passes_through() -> None:
    assert to_dimensionless(gear()).params.backlash == PiecewiseBacklash(alpha=0.0)
    cubic = {"model": "cubic", "a": 0.2, "c": 0.1}
    assert to_dimensionless(gear(backlash=cubic)).params.backlash == CubicBacklash(a=0.2, c=0.1)


def test_empty_harmonics_keep_frequencies() -> None:
    conv = to_dimensionless(
        gear(stiffness_harmonics=[], torque_harmonics=[], transmission_error_harmonics=[])
    )
    assert conv.params.active_frequencies() == []
    assert conv.params.stiffness is not None
    assert conv.params.stiffness.frequency * conv.natural_frequency == pytest.approx(
        conv.mesh_frequency, rel=1e-14
    )


SCALES = [(1.0e3, 1.0, 1.0), (1.0, 7.0, 1.0), (1.0, 1.0, 1.0e-3), (0.01, 3.0, 60.0)]


def _rescaled(length: float, mass: float, time: float) -> dict[str, object]:
    """GEAR expressed in units [length m, mass kg, time s]: each value divided by its unit."""

    def harmonics(key: str, unit: float) -> list[dict[str, float]]:
        return [{"amplitude": h["amplitude"] / unit, "phase": h["phase"]} for h in GEAR[key]]

    torque = mass * length**2 / time**2
    return {
        **GEAR,
        "inertia_a": GEAR["inertia_a"] / (mass * length**2),
        "inertia_b": GEAR["inertia_b"] / (mass * length**2),
        "base_radius_a": R_A / length,
        "base_radius_b": R_B / length,
        "shaft_speed_a": GEAR["shaft_speed_a"] * time,
        "mesh_stiffness": GEAR["mesh_stiffness"] / (mass / time**2),
        "stiffness_harmonics": harmonics("stiffness_harmonics", mass / time**2),
        "mesh_damping": GEAR["mesh_damping"] / (mass / time),
        "half_backlash": GEAR["half_backlash"] / length,
        "torque_a_mean": T_MA / torque,
        "torque_b_mean": GEAR["torque_b_mean"] / torque,
        "torque_harmonics": harmonics("torque_harmonics", torque),
        "transmission_error_harmonics": harmonics("transmission_error_harmonics", length),
    }


@pytest.mark.parametrize(("length", "mass", "time"), SCALES)
def test_groups_do_not_depend_on_units(length: float, mass: float, time: float) -> None:
    """Every group is dimensionless: expressing the data in other units leaves it unchanged."""
    ref = to_dimensionless(gear()).params.model_dump()
    other = to_dimensionless(PhysicalGearData.model_validate(_rescaled(length, mass, time)))
    assert _flat(other.params.model_dump()) == pytest.approx(_flat(ref), rel=1e-12)


def test_printed_mean_force_is_not_dimensionless() -> None:
    """The paper's F^_m = m (T_ma / I_a + T_mb r_b / I_b) changes with the length unit."""
    ratios = []
    for length in (1.0, 1.0e3):
        data = PhysicalGearData.model_validate(_rescaled(length, 1.0, 1.0))
        ratios.append(_printed_mean_force(data) / (data.half_backlash * data.mesh_stiffness))
    assert abs(ratios[1] / ratios[0] - 1.0) > 0.5


def _flat(tree: object) -> list[float]:
    if isinstance(tree, dict):
        return [v for key in sorted(tree) for v in _flat(tree[key])]
    if isinstance(tree, list):
        return [v for item in tree for v in _flat(item)]
    return [tree] if isinstance(tree, float) else []


# --- (b) Eq. (2a)-(2b) in SI units against Eq. (8) from to_dimensionless -------------------


def _fh(backlash: Backlash, x: float) -> float:
    """f_h in units of b, written independently of gearengine.backlash."""
    if isinstance(backlash, PiecewiseBacklash):
        return x - (1.0 - backlash.alpha) * min(max(x, -1.0), 1.0)
    return -backlash.a * x + backlash.c * x**3


def _fourier(harmonics: list, omega: float, t: float) -> tuple[float, float]:
    """sum_r A_r cos(r omega t + phi_r) and its time derivative."""
    value = deriv = 0.0
    for r, h in enumerate(harmonics, start=1):
        arg = r * omega * t + h.phase
        value += h.amplitude * math.cos(arg)
        deriv -= r * omega * h.amplitude * math.sin(arg)
    return value, deriv


def _physical_rhs(data: PhysicalGearData):
    """Eq. (2a)-(2b): state (theta_a, theta_b, theta_a', theta_b') in rad, rad/s; t in s."""
    w_a = data.shaft_speed_a
    w_k = data.teeth_a * w_a
    w_e = (data.transmission_error_order or data.teeth_a) * w_a
    w_p = data.torque_order * w_a
    ra, rb, b = data.base_radius_a, data.base_radius_b, data.half_backlash

    def rhs(t: float, y: np.ndarray) -> list[float]:
        e, de = _fourier(data.transmission_error_harmonics, w_e, t)
        x_rel = ra * y[0] - rb * y[1] - e
        v_rel = ra * y[2] - rb * y[3] - de
        k = data.mesh_stiffness + _fourier(data.stiffness_harmonics, w_k, t)[0]
        force = data.mesh_damping * v_rel + k * b * _fh(data.backlash, x_rel / b)
        t_a = data.torque_a_mean + _fourier(data.torque_harmonics, w_p, t)[0]
        return [
            y[2],
            y[3],
            (t_a - ra * force) / data.inertia_a,
            (-data.torque_b_mean + rb * force) / data.inertia_b,
        ]

    return rhs


def _excitation_sum(exc: Excitation | None, tau: float, power: int = 0) -> float:
    """sum_r (r Omega)^power A_r cos(r Omega tau + phi_r)."""
    if exc is None:
        return 0.0
    return sum(
        (r * exc.frequency) ** power * h.amplitude * math.cos(r * exc.frequency * tau + h.phase)
        for r, h in enumerate(exc.harmonics, start=1)
    )


def _dimensionless_rhs(p: GearParams):
    """Eq. (8): state (x, dx/dtau)."""

    def rhs(tau: float, y: np.ndarray) -> list[float]:
        stiffness = 1.0 + 2.0 * _excitation_sum(p.stiffness, tau)
        forcing = (
            p.mean_force
            + _excitation_sum(p.torque, tau)
            + _excitation_sum(p.transmission_error, tau, power=2)
        )
        return [y[1], -2.0 * p.damping * y[1] - stiffness * _fh(p.backlash, y[0]) + forcing]

    return rhs


MESH_PERIODS = 6
N_SAMPLES = 1500
X0, V0 = 0.0, -1.0  # x~(0) / b and dx~/dt(0) / (b w_n): start inside the clearance


def physical_response(data: PhysicalGearData, w_n: float) -> tuple[np.ndarray, np.ndarray]:
    """x~(t) / b from Eq. (2a)-(2b), sampled at t; returns (t, x~ / b)."""
    b, ra = data.half_backlash, data.base_radius_a
    w_e = data.teeth_a * data.shaft_speed_a
    e0, de0 = _fourier(data.transmission_error_harmonics, w_e, 0.0)
    # theta_b(0) = 0 and theta_b'(0) = 0: the rest fixes x~(0) and x~'(0)
    y0 = [(X0 * b + e0) / ra, 0.0, (V0 * b * w_n + de0) / ra, 0.0]
    t_end = MESH_PERIODS * 2.0 * math.pi / (data.teeth_a * data.shaft_speed_a)
    t = np.linspace(0.0, t_end, N_SAMPLES)
    sol = solve_ivp(
        _physical_rhs(data), (0.0, t_end), y0, method="DOP853", t_eval=t, rtol=1e-11, atol=1e-16
    )
    assert sol.success, sol.message
    e = np.array([_fourier(data.transmission_error_harmonics, w_e, ti)[0] for ti in t])
    return t, (ra * sol.y[0] - data.base_radius_b * sol.y[1] - e) / b


def dimensionless_response(p: GearParams, tau: np.ndarray) -> np.ndarray:
    sol = solve_ivp(
        _dimensionless_rhs(p),
        (0.0, tau[-1]),
        [X0, V0],
        method="DOP853",
        t_eval=tau,
        rtol=1e-11,
        atol=1e-14,
    )
    assert sol.success, sol.message
    return sol.y[0]


BACKLASH_LAWS = [
    {"model": "piecewise", "alpha": 0.0},
    {"model": "piecewise", "alpha": 0.25},
    {"model": "cubic", "a": 0.1667, "c": 0.1667},
]


@pytest.mark.parametrize("backlash", BACKLASH_LAWS, ids=["piecewise0", "piecewise025", "cubic"])
def test_dimensionless_equation_reproduces_two_dof_model(backlash: dict[str, object]) -> None:
    data = gear(backlash=backlash)
    conv = to_dimensionless(data)
    t, x_phys = physical_response(data, conv.natural_frequency)
    x_dim = dimensionless_response(conv.params, conv.natural_frequency * t)
    scale = np.max(np.abs(x_phys))
    assert np.max(np.abs(x_dim - x_phys)) / scale < 1e-6
    if backlash["model"] == "piecewise":
        # the response crosses both clearance edges: all three branches of f_h are exercised
        assert x_phys.min() < -1.0 and x_phys.max() > 1.0


def _printed_mean_force(data: PhysicalGearData) -> float:
    """The paper's printed F^_m = m (T_ma / I_a + T_mb r_b / I_b), without r_a."""
    return equivalent_mass(data) * (
        data.torque_a_mean / data.inertia_a
        + data.torque_b_mean * data.base_radius_b / data.inertia_b
    )


def test_printed_mean_force_does_not_reproduce_two_dof_model() -> None:
    data = gear()
    conv = to_dimensionless(data)
    printed = _printed_mean_force(data) / (data.half_backlash * data.mesh_stiffness)
    assert abs(printed / conv.params.mean_force - 1.0) > 1.0
    wrong = conv.params.model_copy(update={"mean_force": printed})
    t, x_phys = physical_response(data, conv.natural_frequency)
    x_wrong = dimensionless_response(wrong, conv.natural_frequency * t)
    assert np.max(np.abs(x_wrong - x_phys)) / np.max(np.abs(x_phys)) > 0.1


# --- (c) validation ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("inertia_a", -1.0e-3),
        ("inertia_b", 0.0),
        ("base_radius_a", float("nan")),
        ("mesh_stiffness", float("inf")),
        ("mesh_damping", -1.0),
        ("half_backlash", 0.0),
        ("teeth_a", 0),
        ("shaft_speed_a", -10.0),
        ("torque_a_mean", float("nan")),
        ("torque_order", 0.0),
        ("transmission_error_order", -1.0),
    ],
)
def test_bad_scalar_raises_naming_field(field: str, value: float) -> None:
    with pytest.raises(ValidationError) as info:
        gear(**{field: value})
    assert field in {str(err["loc"][0]) for err in info.value.errors()}


def test_bad_harmonic_raises_naming_field() -> None:
    bad = [{"amplitude": float("nan"), "phase": 0.0}]
    with pytest.raises(ValidationError) as info:
        gear(transmission_error_harmonics=bad)
    assert info.value.errors()[0]["loc"] == ("transmission_error_harmonics", 0, "amplitude")


def test_too_many_harmonics_and_unknown_field_rejected() -> None:
    with pytest.raises(ValidationError, match="stiffness_harmonics"):
        gear(stiffness_harmonics=[{"amplitude": 1.0}] * (MAX_HARMONICS + 1))
    with pytest.raises(ValidationError, match="rpm"):
        gear(rpm=1500.0)


def test_every_field_documents_units_and_example() -> None:
    for name, field in PhysicalGearData.model_fields.items():
        assert field.description and "[" in field.description, name
        assert field.examples, name
    for name, field in Conversion.model_fields.items():
        assert field.description, name


def test_the_physical_conversion_gives_its_units() -> None:
    """natural_frequency and mesh_frequency are rad/s (named in ``units``), also given in Hz."""
    conv = to_dimensionless(gear())
    assert conv.units["natural_frequency"] == conv.units["mesh_frequency"] == "rad/s"
    assert conv.natural_frequency_hz == pytest.approx(conv.natural_frequency / (2 * math.pi))
    assert conv.mesh_frequency_hz == pytest.approx(conv.mesh_frequency / (2 * math.pi))
    assert set(conv.units) == set(conv.model_dump()) - {"params", "notes", "units"}
