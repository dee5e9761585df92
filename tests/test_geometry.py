"""Gear geometry (gearengine.model.geometry): hand-worked values, independent re-derivations and
cross-checks (ISO/TR 6336-30 worked example; ross-rotordynamics energy method when installed)."""

import importlib
import itertools
import math

import numpy as np
import pytest

from gearengine.model import geometry as g
from tests._ross import import_ross

DEG20 = math.radians(20.0)


def gear(z, **kw):
    base = dict(teeth=z, module=0.003, face_width=0.025, pressure_angle=DEG20, material="steel")
    return base | kw


def pair_18_30(**kw):
    return g.pair_from_geometry(gear(18, bore_diameter=0.02), gear(30, bore_diameter=0.03), **kw)


# ----------------------------------------------------------------------------- involute geometry


def test_base_radius_and_contact_ratio_worked_example():
    """z = 18/30, m = 3 mm, alpha = 20°, x = 0 (standard centre distance), by hand:

    r1 = 27 mm, r_b1 = 27 cos 20° = 25.37170 mm, r_a1 = 30 mm
    r2 = 45 mm, r_b2 = 45 cos 20° = 42.28617 mm, r_a2 = 48 mm
    a = 72 mm, alpha_w = 20°
    sqrt(30² - 25.37170²) = sqrt(256.2768) = 16.00865 mm
    sqrt(48² - 42.28617²) = sqrt(515.8800) = 22.71299 mm
    a sin(alpha_w) = 72 * 0.3420201 = 24.62545 mm
    path of contact g_alpha = 16.00865 + 22.71299 - 24.62545 = 14.09619 mm
    p_b = pi * 3 * cos 20° = 8.85639 mm  ->  eps_alpha = 14.09619 / 8.85639 = 1.59164
    """
    assert g.reference_radius(18, 3e-3) == pytest.approx(27e-3, rel=1e-12)
    assert g.base_radius(18, 3e-3, DEG20) == pytest.approx(25.37170e-3, rel=1e-6)
    assert g.base_radius(30, 3e-3, DEG20) == pytest.approx(42.28617e-3, rel=1e-6)
    assert g.tip_radius(18, 3e-3) == pytest.approx(30e-3, rel=1e-12)
    assert g.base_pitch(3e-3, DEG20) == pytest.approx(8.85639e-3, rel=1e-6)
    out = pair_18_30()
    assert out["contact_ratio"]["value"] == pytest.approx(1.59164, abs=1e-5)
    assert out["centre_distance"]["value"] == pytest.approx(0.072, rel=1e-12)
    assert out["operating_pressure_angle"]["value"] == pytest.approx(DEG20, abs=1e-12)
    assert out["base_radius_driver"]["value"] == pytest.approx(25.37170e-3, rel=1e-6)


def _contact_ratio_by_intersection(z1, z2, m, alpha, a_w, x1=0.0, x2=0.0):
    """Independent eps_alpha: intersect the line of action with both tip circles numerically.

    Gear 1 at the origin, gear 2 at (a_w, 0). The line of action passes through the pitch point
    P = (r_w1, 0) and is tangent to both base circles; its direction u is found from the
    tangency condition |P x u| = r_b1 (not from alpha_w). Points X(t) = P + t u.
    """
    rb1 = g.base_radius(z1, m, alpha)
    r_w1 = a_w * z1 / (z1 + z2)
    phi = math.asin(rb1 / r_w1)  # direction angle of u to the centre line
    u, p = np.array([math.cos(phi), math.sin(phi)]), np.array([r_w1, 0.0])
    t_t1, t_t2 = -p @ u, (np.array([a_w, 0.0]) - p) @ u  # tangency points T1 < 0 < T2
    ends = []
    for centre, r_a, keep in (
        ((0, 0), g.tip_radius(z1, m, x1), max),
        ((a_w, 0), g.tip_radius(z2, m, x2), min),
    ):
        d = p - np.array(centre, dtype=float)
        roots = np.roots([1.0, 2.0 * d @ u, d @ d - r_a**2]).real  # |d + t u|² = r_a²
        ends.append(keep(roots))
    t_end1, t_end2 = ends
    assert t_t1 < t_end2 < t_end1 < t_t2  # path of contact lies between T1 and T2
    return (t_end1 - t_end2) / (2.0 * math.pi * rb1 / z1)


@pytest.mark.parametrize(
    "z1, z2, x1, x2",
    [
        (18, 30, 0, 0),
        (17, 17, 0, 0),
        (20, 80, 0, 0),
        (40, 41, 0, 0),
        (18, 30, 0.3, 0.1),
        (13, 40, 0.5, -0.2),
        (25, 50, 0.2, 0.2),
    ],
)
def test_contact_ratio_matches_line_of_action_intersection(z1, z2, x1, x2):
    m = 0.004
    alpha_w = g.operating_pressure_angle(z1, z2, x1, x2, DEG20)
    a_w = g.centre_distance(z1, z2, m, DEG20, alpha_w)
    expected = _contact_ratio_by_intersection(z1, z2, m, DEG20, a_w, x1, x2)
    eps = g.transverse_contact_ratio(
        g.tip_radius(z1, m, x1),
        g.base_radius(z1, m, DEG20),
        g.tip_radius(z2, m, x2),
        g.base_radius(z2, m, DEG20),
        a_w,
        alpha_w,
        g.base_pitch(m, DEG20),
    )
    assert eps == pytest.approx(expected, rel=1e-10)
    assert 1.0 < eps < 2.0


@pytest.mark.parametrize(
    "z1, z2, x1, x2", [(18, 30, 0.3, 0.1), (13, 40, 0.5, -0.2), (20, 20, 0, 0)]
)
def test_operating_pressure_angle_gives_backlash_free_mesh(z1, z2, x1, x2):
    """On the operating pitch circles the two tooth thicknesses must fill one pitch exactly:
    s_wi = d_wi (s_i/d_i + inv(alpha) - inv(alpha_w)), s_i = m (pi/2 + 2 x_i tan(alpha))."""
    m = 0.002
    alpha_w = g.operating_pressure_angle(z1, z2, x1, x2, DEG20)
    a_w = g.centre_distance(z1, z2, m, DEG20, alpha_w)
    d_w = [2 * a_w * z / (z1 + z2) for z in (z1, z2)]
    s_w = [
        dw
        * (
            m * (math.pi / 2 + 2 * x * math.tan(DEG20)) / (m * z)
            + g.involute(DEG20)
            - g.involute(alpha_w)
        )
        for dw, z, x in zip(d_w, (z1, z2), (x1, x2), strict=True)
    ]
    assert s_w[0] + s_w[1] == pytest.approx(math.pi * d_w[0] / z1, rel=1e-12)
    assert a_w * math.cos(alpha_w) == pytest.approx(m * (z1 + z2) / 2 * math.cos(DEG20))
    assert (alpha_w > DEG20) == (x1 + x2 > 0)


def test_inverse_involute_round_trip_and_interference_refused():
    for a in np.radians([5, 14.5, 20, 25, 35, 60]):
        assert g.inverse_involute(g.involute(a)) == pytest.approx(a, abs=1e-13)
    with pytest.raises(ValueError, match="interference"):  # 8-tooth pinion, standard rack
        m = 0.001
        g.transverse_contact_ratio(
            g.tip_radius(60, m),
            g.base_radius(60, m, DEG20),
            g.tip_radius(8, m),
            g.base_radius(8, m, DEG20),
            m * 34,
            DEG20,
            g.base_pitch(m, DEG20),
        )


# ----------------------------------------------------------------------------------- inertia


def test_disc_inertia_hand_value():
    """Steel disc, r_o = 27 mm (reference radius of z = 18, m = 3 mm), bore 20 mm, b = 25 mm:
    J = 7850 * 0.025 * pi/2 * (0.027^4 - 0.010^4) = 308.2688 * (5.31441e-7 - 1.0e-8)
      = 308.2688 * 5.21441e-7 = 1.607440e-4 kg m²."""
    assert g.disc_inertia(7850, 0.025, 0.027, 0.010) == pytest.approx(1.607440e-4, rel=1e-6)
    assert pair_18_30()["inertia_driver"]["value"] == pytest.approx(1.607440e-4, rel=1e-6)
    mass = 7850 * 0.025 * math.pi * 0.027**2  # solid disc: J = m r²/2
    assert g.disc_inertia(7850, 0.025, 0.027) == pytest.approx(mass * 0.027**2 / 2)
    with pytest.raises(ValueError):
        g.disc_inertia(7850, 0.025, 0.01, 0.02)


# ----------------------------------------------------------------------------- ISO stiffness


def test_iso_single_stiffness_matches_iso_tr_6336_30_example():
    """ISO/TR 6336-30:2017 example (m_n = 8 mm, z = 17/103, x = 0.145/0, beta = 15.8°,
    basic rack profile D with h_fP = 1.4 m_n) as tabulated in the reference values of an
    open-source ISO 6336 implementation: z_n = 18.905/114.543, c'_th = 17.85584 and
    c' = 12.37047 N/(mm·µm). Checks C1..C9, C_M = 0.8, C_B and the cos(beta) term."""
    c_th = g.theoretical_single_stiffness(18.905, 114.543, 0.145, 0.0)
    assert c_th == pytest.approx(17.85584, rel=2e-5)
    c_b = g.basic_rack_factor(1.4, DEG20)
    assert c_b == pytest.approx(0.9)
    c1 = g.single_stiffness_per_width(18.905, 114.543, 0.145, 0.0, beta=math.radians(15.8), c_b=c_b)
    assert c1 == pytest.approx(12.37047, rel=2e-5)


def test_basic_rack_material_and_load_factors():
    assert g.basic_rack_factor(1.2, DEG20) == pytest.approx(1.0)
    assert g.basic_rack_factor(1.25, DEG20) == pytest.approx(0.975)
    assert g.basic_rack_factor(1.2, math.radians(25)) == pytest.approx(1.1)
    assert g.material_factor(206e9, 206e9) == pytest.approx(1.0)
    assert g.material_factor(206e9, 110e9) == pytest.approx(2 * 206 * 110 / 316 / 206)
    assert g.load_factor(None, 0.025) == 1.0
    assert g.load_factor(5000.0, 0.025) == 1.0  # 200 N/mm
    assert g.load_factor(1250.0, 0.025) == pytest.approx(0.5**0.25)  # 50 N/mm
    assert g.per_width_to_newton_per_metre(1.0, 0.010) == pytest.approx(1e7)


@pytest.mark.parametrize("z1, z2", [(17, 40), (18, 30), (25, 60), (30, 60), (40, 100)])
def test_standard_steel_pairs_near_iso_typical_values(z1, z2):
    """ISO 6336-1 quotes c' ~ 14 and c_gamma ~ 20 N/(mm·µm) as typical for standard steel
    gears; standard pairs (x = 0, ISO 53 profile A, solid blanks) must be in that region."""
    out = g.pair_from_geometry(gear(z1), gear(z2))
    c1, cg = out["single_stiffness_iso"]["value"], out["mesh_stiffness_iso"]["value"]
    assert 11.5 < c1 < 17.0
    assert 16.5 < cg < 24.5
    if (z1, z2) == (30, 60):
        assert c1 == pytest.approx(14.0, abs=0.5)
        assert cg == pytest.approx(20.0, abs=1.5)


def test_pair_from_geometry_example_values_and_units():
    """Steel 18/30, m = 3 mm, b = 25 mm, x = 0, ISO 53 profile A (h_fP = 1.25 m), by hand:
    q' = 0.04723 + 0.15551/18 + 0.25791/30 = 0.064466 mm·µm/N -> c'_th = 15.5121
    c' = 15.5121 * C_M 0.8 * C_R 1 * C_B 0.975 = 12.0993 N/(mm·µm)
    c_gamma_alpha = 12.0993 * (0.75 * 1.59164 + 0.25) = 17.4681 N/(mm·µm)
    k_mean = 17.4681 N/(mm·µm) * 25 mm = 436.70 N/µm = 4.3670e8 N/m"""
    out = pair_18_30()
    c_th = 1 / (0.04723 + 0.15551 / 18 + 0.25791 / 30)  # = 15.5121
    c1 = c_th * 0.8 * 0.975
    assert out["single_stiffness_iso"]["value"] == pytest.approx(c1, rel=1e-12)
    eps = out["contact_ratio"]["value"]
    assert out["mesh_stiffness_iso"]["value"] == pytest.approx(c1 * (0.75 * eps + 0.25))
    assert out["single_pair_stiffness"]["value"] == pytest.approx(c1 * 25 * 1e6)
    assert out["mesh_stiffness"]["value"] == pytest.approx(4.367e8, rel=1e-3)
    for key in (
        "base_radius_driver",
        "base_radius_driven",
        "inertia_driver",
        "inertia_driven",
        "contact_ratio",
        "single_pair_stiffness",
        "mesh_stiffness",
        "stiffness_harmonics",
        "centre_distance",
        "operating_pressure_angle",
    ):
        assert set(out[key]) == {"value", "unit", "source"} and out[key]["source"]
    assert out["mesh_stiffness"]["unit"] == "N/m"
    assert out["mesh_stiffness"]["source"].startswith("ISO 6336-1:2019")
    assert len(out["stiffness_harmonics"]["value"]) == 10


def test_pair_from_geometry_pinion_order_materials_and_load():
    base = pair_18_30()
    swapped = g.pair_from_geometry(gear(30, bore_diameter=0.03), gear(18, bore_diameter=0.02))
    assert swapped["mesh_stiffness"]["value"] == pytest.approx(base["mesh_stiffness"]["value"])
    assert swapped["inertia_driven"]["value"] == pytest.approx(base["inertia_driver"]["value"])
    bronze = g.pair_from_geometry(gear(18), gear(30, material="bronze"))
    ratio = bronze["mesh_stiffness"]["value"] / base["mesh_stiffness"]["value"]
    assert ratio == pytest.approx(g.material_factor(206e9, 110e9))
    light = pair_18_30(tangential_load=625.0)  # 25 N/mm -> factor 0.25^0.25
    ratio = light["single_pair_stiffness"]["value"] / base["single_pair_stiffness"]["value"]
    assert ratio == pytest.approx(0.25**0.25)
    custom = {"density": 1000.0, "youngs_modulus": 206e9, "poisson": 0.3}
    assert g.pair_from_geometry(gear(18, material=custom), gear(30))["inertia_driver"][
        "value"
    ] == pytest.approx(g.disc_inertia(1000.0, 0.025, 0.027))
    with pytest.raises(ValueError):
        g.pair_from_geometry(gear(18), gear(30, module=0.004))
    with pytest.raises(ValueError):
        g.pair_from_geometry(gear(18), gear(30), stiffness_method="fem")
    with pytest.raises(ValueError):
        g.pair_from_geometry(gear(18, material="unobtainium"), gear(30))


def test_profile_shift_raises_centre_distance_and_pressure_angle():
    out = g.pair_from_geometry(gear(18, profile_shift=0.3), gear(30, profile_shift=0.1))
    assert out["centre_distance"]["value"] > 0.072
    assert out["operating_pressure_angle"]["value"] > DEG20


# --------------------------------------------------------------------------- Fourier series


def _series(s, eps, k_mean, n, ratio=g.ISO_DOUBLE_TO_SINGLE):
    harm = g.stiffness_harmonics(eps, k_mean, n, ratio)
    return k_mean + sum(a * np.cos(2 * np.pi * r * s + p) for r, (a, p) in enumerate(harm, 1))


@pytest.mark.parametrize("ratio", [g.ISO_DOUBLE_TO_SINGLE, 2.0])
def test_wave_levels_and_mean(ratio):
    eps, k_mean = 1.59164, 4.367e8
    k_lo, k_hi = g.stiffness_levels(eps, k_mean, ratio)
    assert k_hi / k_lo == pytest.approx(ratio)
    s = (np.arange(200_000) + 0.5) / 200_000
    assert g.stiffness_wave(s, eps, k_mean, ratio).mean() == pytest.approx(k_mean, rel=1e-5)
    assert g.stiffness_wave(0.0, eps, k_mean, ratio) == k_hi  # new pair enters: double contact
    assert g.stiffness_wave(0.9, eps, k_mean, ratio) == k_lo


def test_iso_ratio_makes_single_level_equal_c_prime_b():
    out = pair_18_30()
    k_lo, _ = g.stiffness_levels(out["contact_ratio"]["value"], out["mesh_stiffness"]["value"])
    assert k_lo == pytest.approx(out["single_pair_stiffness"]["value"], rel=1e-12)


@pytest.mark.parametrize("eps", [1.25, 1.6, 1.9])
def test_harmonics_equal_fft_of_sampled_wave(eps):
    """Exact coefficients vs numpy FFT. For midpoint samples s_j = (j + 1/2)/N of a pulse of
    length d = eps - 1 with d N an integer, the DFT is exactly
    X_r/N = c_r * (pi r/N)/sin(pi r/N) * exp(+i pi r/N), c_r = continuous coefficient,
    so undoing that factor must give A_r/2 exp(i phi_r) to rounding error."""
    n_samples, k_mean, n = 1000, 3e8, 25
    s = (np.arange(n_samples) + 0.5) / n_samples
    spectrum = np.fft.rfft(g.stiffness_wave(s, eps, k_mean)) / n_samples
    r = np.arange(1, n + 1)
    correction = (
        np.sin(np.pi * r / n_samples)
        / (np.pi * r / n_samples)
        * np.exp(-1j * np.pi * r / n_samples)
    )
    continuous = spectrum[1 : n + 1] * correction  # c_r of the continuous wave
    harm = np.array(g.stiffness_harmonics(eps, k_mean, n))
    expected = harm[:, 0] / 2 * np.exp(1j * harm[:, 1])  # A cos(x + phi) = Re(A e^{i phi} e^{ix})
    assert spectrum[0].real == pytest.approx(k_mean, rel=1e-12)
    np.testing.assert_allclose(continuous, expected, rtol=0, atol=1e-9 * k_mean)


def test_series_reproduces_wave():
    eps, k_mean = 1.59164, 4.367e8
    k_lo, k_hi = g.stiffness_levels(eps, k_mean)
    s = (np.arange(20_000) + 0.5) / 20_000
    wave = g.stiffness_wave(s, eps, k_mean)
    l2 = [np.sqrt(np.mean((_series(s, eps, k_mean, n) - wave) ** 2)) for n in (1, 3, 10, 30, 100)]
    assert all(b < a for a, b in itertools.pairwise(l2))
    assert l2[-1] < 0.04 * (k_hi - k_lo)
    d = eps - 1  # Parseval: residual power = variance of the wave - sum A_r²/2
    amps = np.array([a for a, _ in g.stiffness_harmonics(eps, k_mean, 100)])
    residual = (k_hi - k_lo) ** 2 * d * (1 - d) - np.sum(amps**2) / 2
    assert l2[-1] ** 2 == pytest.approx(residual, rel=2e-2)
    far = np.minimum(np.abs(s - (eps - 1)), np.minimum(s, 1 - s)) > 0.03  # away from the jumps
    err = np.abs(_series(s, eps, k_mean, 300) - wave)[far].max()
    assert err < 0.02 * (k_hi - k_lo)
    assert _series(s, eps, k_mean, 50).mean() == pytest.approx(k_mean, rel=1e-9)


def test_harmonics_edge_cases():
    assert all(a == pytest.approx(0.0, abs=1e-6) for a, _ in g.stiffness_harmonics(1.0, 1e8, 5))
    for eps in (0.95, 2.0, 2.3):
        with pytest.raises(ValueError):
            g.stiffness_harmonics(eps, 1e8, 5)


# ------------------------------------------------------- cross-check with ross (optional venv)


def test_mean_mesh_stiffness_against_ross_energy_method():
    """Potential-energy TVMS of ross-rotordynamics (GearElementTVMS/Mesh) vs ISO k_mean.

    Skipped unless ross is importable (``tests._ross``; it is in the test extra)."""
    ross = import_ross()
    ross_gear = importlib.import_module("ross.gear_element")

    steel = ross.Material(name="steel_iso", rho=7850.0, E=206e9, Poisson=0.3)
    kw = dict(material=steel, width=0.025, module=0.003, pr_angle=DEG20)
    g1 = ross_gear.GearElementTVMS(n=0, bore_diameter=0.02, n_teeth=18, **kw)
    g2 = ross_gear.GearElementTVMS(n=1, bore_diameter=0.03, n_teeth=30, **kw)
    mesh = ross_gear.Mesh(g1, g2)
    k_ross = np.asarray(mesh.stiffness_range, dtype=float)
    ours = pair_18_30()
    ratio = k_ross.mean() / ours["mesh_stiffness"]["value"]
    print(
        f"ross mean {k_ross.mean():.4e} N/m, min {k_ross.min():.4e}, max {k_ross.max():.4e}; "
        f"ISO k_mean {ours['mesh_stiffness']['value']:.4e}; ratio {ratio:.3f}"
    )
    assert mesh.contact_ratio == pytest.approx(ours["contact_ratio"]["value"], rel=1e-9)
    assert g1.Ip == pytest.approx(ours["inertia_driver"]["value"], rel=1e-9)
    assert 0.7 < ratio < 1.4
