"""Designs in physical units: parsing with pint, plausibility, conversion to Eq. (9) checked
against the two-degree-of-freedom Eqs. (2a)-(2b), and the engineering block."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearengine.analysis import AnalysisRequest, analyze, answer_melnikov, convert
from gearengine.engineering.response import response
from gearengine.homoclinic import melnikov
from gearengine.homoclinic.boundary import speed_windows
from gearengine.homoclinic.schemas import MelnikovRequest
from gearengine.model.aliases import with_speed_factor
from gearengine.model.conversion import to_dimensionless
from gearengine.model.design import EXAMPLE_DESIGN, Design
from gearengine.model.params import GearParams
from gearengine.model.reduction import convert_design, physical_data
from gearengine.numerics.results import NumericsResult
from gearengine.systems.spur_pair.forcing import packed_forcing
from gearengine.systems.spur_pair.laws import LAWS
from tests.test_conversion import dimensionless_response, physical_response


def design(**changes: object) -> dict:
    """The README's design with top-level or dotted-path changes ("mesh.half_backlash")."""
    d = copy.deepcopy(EXAMPLE_DESIGN)
    for path, value in changes.items():
        *head, last = path.split(".")
        node = d
        for key in head:
            node = node[int(key)] if key.isdigit() else node[key]
        node[last] = value
    return d


LIGHT = design(torque="3 N*m", **{"torque_fluctuation.harmonics.0.amplitude": "1 N*m"})
"""The README's pair lightly loaded (3 N m, below its critical torque 9.62 N m): rattle-prone,
where the Melnikov criterion applies (examples/design-light-load.json)."""


# --- parsing and plausibility ------------------------------------------------------------------


def test_units_are_read_with_pint() -> None:
    d = Design.model_validate(
        design(speed="157.07963267948966 rad/s", torque="40 N*m", **{
            "mesh.half_backlash": "0.05 mm", "driver.inertia": "20 kg*cm^2",
            "transmission_error.harmonics.0.amplitude": "5 µm",
        })
    )  # fmt: skip
    assert d.speed == pytest.approx(1500 * 2 * math.pi / 60)
    assert d.mesh.half_backlash == pytest.approx(50e-6)
    assert d.driver.inertia == pytest.approx(2e-3)
    assert d.transmission_error.harmonics[0].amplitude == pytest.approx(5e-6)
    assert Design.model_validate(design(speed=157.07963267948966)).speed == d.speed  # SI number


@pytest.mark.parametrize(
    ("path", "value", "words"),
    [
        ("speed", "30 mm", ["design.speed", "mm", "[length]", "1 / [time]"]),
        ("torque", "3 m/s", ["design.torque", "m / s", "[length] / [time]"]),
        ("mesh.half_backlash", "100 m", ["did you mean 100 µm?", "1e-07 m to 0.005 m"]),
        ("mesh.half_backlash", 100, ["did you mean 100 µm?"]),
        ("speed", "0.5 rpm", ["plausible range of a shaft speed"]),
        ("speed", 30000, ["did you mean 30000 rpm?", "30000 rad/s"]),
        ("mesh.stiffness", "1e3 N/m", ["plausible range of a mesh stiffness"]),
        ("mesh.damping_ratio", 1.5, ["less than or equal to 1"]),
        ("driver.inertia", "-2e-3 kg*m^2", ["design.driver.inertia"]),
        ("driver.base_radius", "0 mm", ["design.driver.base_radius"]),
        ("speed", "fast", ["cannot read 'fast'"]),
    ],
)
def test_bad_physical_input_is_refused_clearly(
    client: TestClient, path: str, value: object, words: list[str]
) -> None:
    r = client.post("/v1/melnikov", json={"design": design(**{path: value})})
    assert r.status_code == 422, r.text
    text = json.dumps(r.json(), ensure_ascii=False)
    for word in words:
        assert word in text, (word, text)


def test_radii_inconsistent_with_teeth_are_refused(client: TestClient) -> None:
    r = client.post("/v1/melnikov", json={"design": design(**{"driven.base_radius": "52 mm"})})
    assert r.status_code == 422
    assert "teeth ratio" in r.text and "design.driven.base_radius" in r.text
    ok = design(**{"driven.base_radius": "50.4 mm"})  # 0.8 %: within 1 %
    assert client.post("/v1/melnikov", json={"design": ok}).status_code == 200


def test_rounded_braking_torque_raises_no_note() -> None:
    assert (
        convert_design(Design.model_validate(design(braking_torque="66.667 N*m"))).notes[1:] == []
    )
    noted = convert_design(Design.model_validate(design(braking_torque="80 N*m")))
    assert any("balancing" in n for n in noted.notes)


@pytest.mark.parametrize(
    ("typed", "understood"),
    [("40 Nm", "40 N*m"), ("0.04 kNm", "0.04 kN*m"), ("40000 Nmm", "40000 N*mm"),
     ("40 N.m", None), ("40 N m", None)],
)  # fmt: skip
def test_torque_spellings_engineers_type(
    client: TestClient, typed: str, understood: str | None
) -> None:
    """pint alone reads "Nm" as a number-metre (N: Avogadro's number) and refuses it as a
    torque; the design reads it as newton metres and says so in its notes."""
    d = Design.model_validate(design(torque=typed))
    assert d.torque == pytest.approx(40.0)
    said = [n for n in convert_design(d).notes if "read as" in n]
    assert said == ([] if understood is None else [f"torque {typed!r} read as {understood!r}"])
    r = client.post("/v1/melnikov", json={"design": design(torque=typed)})
    assert r.status_code == 200, r.text
    assert r.json()["engineering"]["notes"][: len(said)] == said


def test_params_xor_design(client: TestClient) -> None:
    both = {"design": EXAMPLE_DESIGN, "params": {"damping": 0.1}}
    assert client.post("/v1/melnikov", json=both).status_code == 422
    assert client.post("/v1/melnikov", json={}).status_code == 422


UNITS = ["rpm", "rad/s", "mm", "um", "µm", "m", "N*m", "N/m", "kg*m^2", "kg*cm^2", "deg", "Hz",
         "s", "", "furlong", "N/um", "kg", "%", "1/s", "m^2"]  # fmt: skip
FIELDS = [
    "speed",
    "torque",
    "mesh.half_backlash",
    "mesh.stiffness",
    "driver.inertia",
    "driven.base_radius",
    "transmission_error.harmonics.0.amplitude",
    "torque_fluctuation.harmonics.0.amplitude",
    "mesh.stiffness_harmonics.0.amplitude",
]


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    st.sampled_from(FIELDS),
    st.one_of(
        st.floats(allow_nan=True, allow_infinity=True),
        st.tuples(st.floats(-1e12, 1e12), st.sampled_from(UNITS)).map(lambda t: f"{t[0]} {t[1]}"),
        st.text(max_size=12),
    ),
)
def test_random_units_and_magnitudes_give_200_or_422(
    client: TestClient, path: str, value: object
) -> None:
    body = json.dumps({"design": design(**{path: value})})  # NaN and Infinity as JSON5 literals
    r = client.post("/v1/melnikov", content=body, headers={"content-type": "application/json"})
    assert r.status_code in (200, 422), r.text


# --- conversion against Eqs. (2a)-(2b) ------------------------------------------------------------


def test_design_params_reproduce_the_two_dof_model() -> None:
    """The params of a design (direct form, rpm, µm, N m strings) make Eq. (9) follow a DOP853
    integration of Eqs. (2a)-(2b) in physical units."""
    d = Design.model_validate(design())
    data, _, _ = physical_data(d)
    conv = convert_design(d)
    assert conv.params == to_dimensionless(data).params
    w_n = 2 * math.pi * conv.natural_frequency_hz
    t, x_phys = physical_response(data, w_n)
    x_dim = dimensionless_response(conv.params, w_n * t)
    assert np.max(np.abs(x_dim - x_phys)) / np.max(np.abs(x_phys)) < 1e-6
    assert conv.params.damping == pytest.approx(0.05)  # mu~ = zeta
    assert conv.params.transmission_error.harmonics[0].amplitude == pytest.approx(0.1)  # 5/50 um


def test_geometry_form_derives_radii_inertia_and_iso_stiffness() -> None:
    gear = {"module": "3 mm", "face_width": "25 mm", "pressure_angle": "20 deg"}
    d = design(
        driver={"teeth": 18, **gear, "bore": "20 mm"},
        driven={"teeth": 30, **gear, "bore": "30 mm"},
        mesh={"stiffness": "iso6336", "damping_ratio": 0.05, "half_backlash": "50 um"},
    )
    conv = convert_design(Design.model_validate(d))
    der = conv.derived
    assert der["contact_ratio"].value == pytest.approx(1.59164, abs=1e-5)
    assert der["base_radius_driver"].value == pytest.approx(0.027 * math.cos(math.radians(20)))
    assert 3e8 < conv.mesh_stiffness_n_per_m < 6e8 and "ISO 6336" in der["mesh_stiffness"].source
    assert len(conv.params.stiffness.harmonics) == 5


# --- the engineering block ------------------------------------------------------------------------


def test_speed_windows_agree_with_melnikov_at_every_edge() -> None:
    req = MelnikovRequest.model_validate({"design": LIGHT})
    answer = answer_melnikov(req)
    windows = answer.engineering.speed_windows_rpm
    assert windows, "the lightly loaded design has a Melnikov window"
    lo, hi = answer.engineering.speed_range_rpm
    for a, b in windows:
        for edge, inside in ((a, +1), (b, -1)):
            if edge in (lo, hi):
                continue
            for step, expect in ((inside, True), (-inside, False)):
                rpm = edge + step * 1e-4 * edge
                scaled = with_speed_factor(req.params, rpm / 1500.0)
                assert melnikov(scaled).chaos_possible is expect, (rpm, expect)


def test_margin_to_chaos_sign_follows_the_verdict() -> None:
    safe = answer_melnikov(MelnikovRequest.model_validate({"design": LIGHT}))
    assert safe.chaos_possible is False
    te = safe.engineering.critical["transmission_error_amplitude"]
    assert te.unit == "um" and te.value == pytest.approx(5.0) and te.margin_to_chaos > 0
    assert te.nearest == pytest.approx(te.value + te.margin_to_chaos)
    big = copy.deepcopy(LIGHT)
    big["transmission_error"]["harmonics"][0]["amplitude"] = f"{te.nearest * 1.1} um"
    unsafe = answer_melnikov(MelnikovRequest.model_validate({"design": big}))
    assert unsafe.chaos_possible is True
    assert unsafe.engineering.critical["transmission_error_amplitude"].margin_to_chaos < 0


def mesh_force(params: GearParams, t: np.ndarray, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Dimensionless mesh force K(tau) f_h(x) + 2 mu~ x' at the samples (Eq. 9's left side)."""
    kc, _, _ = packed_forcing(params)
    stiffness = 1.0 + np.cos(np.multiply.outer(t, kc[1]) + kc[2]) @ kc[0]
    return stiffness * LAWS[params.backlash.model].f_h(params.backlash, x) + 2 * params.damping * v


def _synthetic(params: GearParams, x: np.ndarray, t: np.ndarray, v: np.ndarray) -> NumericsResult:
    """A numerical result whose record is the path (t, x, v), its extremes those of the path."""
    base = analyze(AnalysisRequest.model_validate({"design": EXAMPLE_DESIGN})).numerics
    hist = {"t": t.tolist(), "x": x.tolist(), "v": v.tolist()}
    force = mesh_force(params, t, x, v)
    return base.model_copy(
        update={"time_history": base.time_history.model_copy(update=hist),
                "x_peak_to_peak": float(x.max() - x.min()),
                "force_max": float(force.max()), "force_min": float(force.min())}
    )  # fmt: skip


def test_engineering_numbers_of_a_hand_computed_response() -> None:
    """x(tau) = 1.5 cos(tau) with no stiffness variation and the piecewise law (alpha = 0):

    - DTE = 3 b = 150 µm peak to peak;
    - teeth apart while |cos| <= 2/3: fraction (2/pi) asin(2/3) = 0.46453;
    - back flank while cos < -2/3: fraction acos(2/3)/pi = 0.26772... wait, cos < -2/3 on an arc
      of 2 (pi - acos(-2/3))... = 2 acos(2/3) per 2 pi: acos(2/3)/pi = 0.26772;
    - the force b k_m f_h(x): f_h(1.5) = 0.5 at tau = 0 where x' = 0, so the largest mesh force
      is 0.5 b k_m = 0.5 * 50e-6 * 1e8 = 2500 N; dynamic factor 2500 / F_m with F_m = 1333.3 N
      (40 N m / 30 mm): 1.875; the smallest is -2500 N (back flank).
    """
    d = design(mesh={"stiffness": "1e8 N/m", "damping_ratio": 0.0, "half_backlash": "50 um"})
    conv = convert_design(Design.model_validate(d))
    t = np.linspace(0.0, 2 * math.pi, 200_001)
    x, v = 1.5 * np.cos(t), -1.5 * np.sin(t)
    resp = response(conv.params, _synthetic(conv.params, x, t, v), conv)
    assert resp.dte_peak_to_peak_um == pytest.approx(150.0)
    assert resp.contact.separation_fraction == pytest.approx(
        2 / math.pi * math.asin(2 / 3), abs=1e-4
    )
    assert resp.contact.back_flank_fraction == pytest.approx(math.acos(2 / 3) / math.pi, abs=1e-4)
    assert resp.dynamic_mesh_force_max_n == pytest.approx(2500.0, rel=1e-6)
    assert resp.dynamic_mesh_force_min_n == pytest.approx(-2500.0, rel=1e-6)
    assert resp.static_force_n == pytest.approx(4000 / 3)
    assert resp.dynamic_factor == pytest.approx(1.875, rel=1e-6)


def test_single_sided_hand_computed_fractions() -> None:
    """x = 0.5 + cos(tau): apart while x <= 1, i.e. cos <= 1/2: fraction 1 - 1/3 = 2/3; never
    below -1 (min -0.5), so no back-flank contact: single-sided impacts."""
    conv = convert_design(Design.model_validate(design()))
    t = np.linspace(0.0, 2 * math.pi, 200_001)
    resp = response(conv.params, _synthetic(conv.params, 0.5 + np.cos(t), t, -np.sin(t)), conv)
    assert resp.contact.separation_fraction == pytest.approx(2 / 3, abs=1e-4)
    assert resp.contact.back_flank_fraction == 0.0


@pytest.mark.parametrize(
    ("backlash", "torque", "error", "regime"),
    [
        ("50 um", "40 N*m", "5 um", "no_impact"),
        ("80 um", "5 N*m", "10 um", "single_sided"),
        ("5 um", "2 N*m", "20 um", "double_sided"),
    ],
)
def test_simulated_contact_regimes(backlash: str, torque: str, error: str, regime: str) -> None:
    d = design(**{"mesh.half_backlash": backlash, "torque": torque,
                  "transmission_error.harmonics.0.amplitude": error})  # fmt: skip
    request = {"design": d, "settings": {"record_periods": 200}}
    result = analyze(AnalysisRequest.model_validate(request))
    contact = result.engineering.response.contact
    assert contact.regime == result.numerics.impact_regime == regime
    assert (contact.separation_fraction > 0) == (regime != "no_impact")
    assert (contact.back_flank_fraction > 0) == (regime == "double_sided")
    assert 0.0 <= contact.back_flank_fraction <= 1.0 - contact.separation_fraction


def test_every_endpoint_answers_a_design(client: TestClient) -> None:
    body = {"design": EXAMPLE_DESIGN}
    mel = client.post("/v1/melnikov", json=body).json()
    assert mel["params"]["damping"] == pytest.approx(0.05) and mel["engineering"]["summary"]
    ana = client.post("/v1/analyses", json={**body, "settings": {"record_periods": 100}}).json()
    assert ana["engineering"]["response"]["dte_peak_to_peak_um"] > 0
    assert ana["params"] == mel["params"]
    plot = client.post("/v1/analyses/plot", json={**body, "settings": {"record_periods": 50}})
    assert plot.headers["content-type"] == "image/png"
    curve = client.post("/v1/thresholds", json={"design": LIGHT, "parameter": "mu", "num": 5})
    assert curve.status_code == 200 and len(curve.json()["frequencies"]) == 5
    loaded = client.post("/v1/thresholds", json={**body, "parameter": "mu", "num": 5})
    assert loaded.status_code == 422 and "mean_force" in loaded.text  # above T_crit
    conv = client.post("/v1/conversions/design", json=body).json()
    assert conv["conversion"]["params"] == mel["params"]
    sweep = {**body, "settings": {"transient_periods": 10, "record_periods": 10},
             "axes": [{"parameter": "mu", "start": 0.04, "stop": 0.06, "num": 2}]}  # fmt: skip
    assert client.post("/v1/sweeps", json=sweep).status_code == 202


def test_speed_windows_of_a_scan_without_flips() -> None:
    p = convert_design(Design.model_validate(design())).params
    assert speed_windows(p, 1500.0, 100.0, 200.0) == []
    assert convert(
        __import__("gearengine.analysis", fromlist=["DesignRequest"]).DesignRequest.model_validate(
            {"design": LIGHT}
        )
    ).engineering.speed_windows_rpm


def test_an_analysis_and_a_one_point_sweep_give_the_same_response() -> None:
    """One definition of the DTE and the dynamic factor (``model.units.response_values``, from
    the kernel's per-step extremes): /v1/analyses and a one-point speed sweep at the design's
    speed give the same numbers (before: dynamic factor 1.093296 against 1.093390)."""
    from gearengine.studies.sweep import run_local, validated

    light = {"transient_periods": 60, "record_periods": 60}
    analysis = analyze(AnalysisRequest.model_validate({"design": EXAMPLE_DESIGN,
                                                       "settings": light}))  # fmt: skip
    axes = [{"parameter": "speed", "start": "1500 rpm", "stop": "1500 rpm", "num": 1}]
    (point,) = run_local(
        validated({"design": EXAMPLE_DESIGN, "settings": light, "axes": axes})
    ).points
    resp = analysis.engineering.response
    assert point.values["speed"] == Design.model_validate(EXAMPLE_DESIGN).speed
    assert point.physical["dte"].value == resp.dte_peak_to_peak_um
    assert point.physical["dynamic_factor"].value == resp.dynamic_factor
    assert point.force_max == analysis.numerics.force_max
    assert point.x_peak_to_peak == analysis.numerics.x_peak_to_peak
