"""Physical quantities of an external spur-gear pair derived from its geometry.

Pure functions (``math``/``numpy`` only). SI units in and out unless a name says otherwise;
the ISO stiffness values keep the standard's unit N/(mm·µm) (``*_per_width`` functions).

Equations used (numbers refer to the short comments in the code):

(G1) r = m z / 2                           reference radius           [ISO 21771]
(G2) r_b = r cos(alpha)                    base radius                [ISO 21771]
(G3) r_a = m (z/2 + h_a* + x), h_a* = 1    tip radius, no tip shortening (assumption)
(G4) inv(alpha_w) = inv(alpha) + 2 tan(alpha) (x1 + x2)/(z1 + z2), inv(a) = tan(a) - a
(G5) a_w = m (z1 + z2)/2 * cos(alpha)/cos(alpha_w)          operating centre distance
(G6) eps_alpha = [sqrt(r_a1² - r_b1²) + sqrt(r_a2² - r_b2²) - a_w sin(alpha_w)] / p_b,
     p_b = pi m cos(alpha)                 transverse contact ratio (path of contact / base pitch)
(I1) J = rho b pi/2 (r_o⁴ - r_i⁴)          polar inertia of a solid disc with a bore
(S1) q' = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1² + C9 x2²
     [mm·µm/N], c'_th = 1/q'               ISO 6336-1:2019 cl. 9, Method B (index 1 = pinion)
(S2) c' = c'_th C_M C_R C_B cos(beta)      single stiffness, C_M = 0.8, C_R = 1 (solid blank)
(S3) C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20° - alpha_Pn)]   basic-rack factor
(S4) c' *= E/E_st, E = 2 E1 E2/(E1 + E2), E_st = 206 GPa            non-steel pairs
(S5) c' *= (F_t K_A / b / 100 N/mm)^0.25   only if F_t K_A / b < 100 N/mm
(S6) c_gamma_alpha = c' (0.75 eps_alpha + 0.25)                   mean mesh stiffness
(S7) k [N/m] = c [N/(mm·µm)] * b [mm] * 1e6
(F1) k(s) = k_lo + (k_hi - k_lo) [0 <= s mod 1 < eps_alpha - 1],  k_hi = ratio * k_lo
(F2) k(s) = k_mean + sum_r A_r cos(2 pi r s + phi_r),  s = f_mesh t

The coefficients of (S1)-(S6) were checked against independent open-source implementations
and against the ISO/TR 6336-30:2017 worked example (c'_th = 17.856, c' = 12.370 N/(mm·µm));
see NOTES.md for the sources and for the equation numbering of the standard itself.
"""

import math

import numpy as np

E_STEEL = 206e9  # Pa, E_st of ISO 6336-1 (S4)

#: name -> density rho [kg/m³], Young's modulus E [Pa], Poisson's ratio nu [-].
#: steel: ISO 6336 reference values; the others are handbook values, see NOTES.md.
MATERIALS: dict[str, dict[str, float]] = {
    "steel": {"density": 7850.0, "youngs_modulus": 206e9, "poisson": 0.30},
    "cast_iron": {"density": 7200.0, "youngs_modulus": 110e9, "poisson": 0.26},  # grey, GJL-250
    "bronze": {"density": 8700.0, "youngs_modulus": 110e9, "poisson": 0.34},  # CuSn12Ni2-C
    "aluminium": {"density": 2810.0, "youngs_modulus": 71.7e9, "poisson": 0.33},  # 7075-T6
}

#: C1..C9 of (S1), ISO 6336-1 Method B, basic rack alpha = 20°, h_aP = m, h_fP = 1.2 m.
ISO_Q_COEFFICIENTS = (
    0.04723,
    0.15551,
    0.25791,
    -0.00635,
    -0.11654,
    -0.00193,
    -0.24188,
    0.00529,
    0.00182,
)

#: double-contact / single-contact level ratio of the stiffness wave that reproduces
#: c_gamma_alpha of (S6) exactly when the single-contact level equals c' (see stiffness_levels).
ISO_DOUBLE_TO_SINGLE = 1.75


def involute(alpha: float) -> float:
    """Involute function inv(alpha) = tan(alpha) - alpha [rad]."""
    return math.tan(alpha) - alpha


def inverse_involute(value: float) -> float:
    """Angle alpha in (0, pi/2) [rad] with inv(alpha) = value (Newton iteration)."""
    if value <= 0.0:
        raise ValueError("inverse involute needs a positive value")
    alpha = min((3.0 * value) ** (1.0 / 3.0), 1.5)  # inv(a) ~ a³/3 for small a
    for _ in range(100):
        step = (involute(alpha) - value) / math.tan(alpha) ** 2  # d inv/d alpha = tan²
        alpha = min(max(alpha - step, 1e-9), 1.5707)
        if abs(step) < 1e-15:
            break
    return alpha


def reference_radius(z: int, m: float) -> float:
    """Reference (pitch) radius r = m z / 2 [m] (G1); module m [m], teeth z."""
    return m * z / 2.0


def base_radius(z: int, m: float, alpha: float) -> float:
    """Base radius r_b = (m z / 2) cos(alpha) [m] (G2); pressure angle alpha [rad]."""
    return reference_radius(z, m) * math.cos(alpha)


def tip_radius(z: int, m: float, x: float = 0.0, addendum_coefficient: float = 1.0) -> float:
    """Tip radius r_a = m (z/2 + h_a* + x) [m] (G3).

    Standard addendum h_a* = 1 and no tip shortening: for x1 + x2 > 0 the bottom clearance
    of the pair is therefore slightly smaller than the nominal 0.25 m (ISO 21771 would cut
    the tips by k m to restore it); this slightly overestimates eps_alpha.
    """
    return m * (z / 2.0 + addendum_coefficient + x)


def base_pitch(m: float, alpha: float) -> float:
    """Transverse base pitch p_b = pi m cos(alpha) [m] (= 2 pi r_b / z)."""
    return math.pi * m * math.cos(alpha)


def operating_pressure_angle(z1: int, z2: int, x1: float, x2: float, alpha: float) -> float:
    """Operating (working) pressure angle alpha_w [rad] of a backlash-free external pair (G4)."""
    return inverse_involute(involute(alpha) + 2.0 * math.tan(alpha) * (x1 + x2) / (z1 + z2))


def centre_distance(z1: int, z2: int, m: float, alpha: float, alpha_w: float | None = None):
    """Operating centre distance a_w = m (z1 + z2)/2 * cos(alpha)/cos(alpha_w) [m] (G5).

    Without alpha_w (x1 + x2 = 0) this is the standard centre distance m (z1 + z2)/2.
    """
    alpha_w = alpha if alpha_w is None else alpha_w
    return m * (z1 + z2) / 2.0 * math.cos(alpha) / math.cos(alpha_w)


def transverse_contact_ratio(r_a1, r_b1, r_a2, r_b2, a_w, alpha_w, p_b) -> float:
    """Transverse contact ratio eps_alpha [-] of an external spur pair (G6).

    r_a*, r_b*: tip and base radii [m]; a_w: operating centre distance [m]; alpha_w:
    operating pressure angle [rad]; p_b: base pitch [m]. Undercut is not checked; a path of
    contact reaching beyond a base-circle tangency point (involute interference) is refused.
    """
    g1 = math.sqrt(r_a1**2 - r_b1**2)  # tangency point T1 -> end of contact on gear 1 tip
    g2 = math.sqrt(r_a2**2 - r_b2**2)
    t1t2 = a_w * math.sin(alpha_w)  # length of the line of action between the base circles
    if g1 > t1t2 or g2 > t1t2:
        raise ValueError("tip circle reaches past the interference point: involute interference")
    return (g1 + g2 - t1t2) / p_b


def disc_inertia(density: float, face_width: float, r_outer: float, r_inner: float = 0.0):
    """Polar mass moment of inertia J = rho b pi/2 (r_o⁴ - r_i⁴) [kg·m²] (I1).

    density rho [kg/m³], face width b [m], outer/bore radius [m]. For gears the module passes
    r_o = reference radius: the tooth ring between root and tip holds about the material of a
    full ring up to the reference circle (ISO 6336-1 uses the similar d_m = (d_a + d_f)/2 for
    its reduced mass); a tip-radius disc would overestimate J by roughly (r_a/r)^4.
    """
    if not 0.0 <= r_inner < r_outer:
        raise ValueError("need 0 <= r_inner < r_outer")
    return density * face_width * math.pi / 2.0 * (r_outer**4 - r_inner**4)


def theoretical_single_stiffness(z_n1: float, z_n2: float, x1: float = 0.0, x2: float = 0.0):
    """Theoretical single stiffness c'_th = 1/q' [N/(mm·µm)] (S1), ISO 6336-1:2019 cl. 9.

    z_n1, x1: pinion (gear with fewer teeth); z_n2, x2: wheel. Virtual teeth z_n = z for spur
    gears. ISO's regression holds for x1 >= x2 and -0.5 <= x1 + x2 <= 2.
    """
    c1, c2, c3, c4, c5, c6, c7, c8, c9 = ISO_Q_COEFFICIENTS
    q = (
        c1
        + c2 / z_n1
        + c3 / z_n2
        + c4 * x1
        + c5 * x1 / z_n1
        + c6 * x2
        + c7 * x2 / z_n2
        + c8 * x1**2
        + c9 * x2**2
    )
    return 1.0 / q


def basic_rack_factor(dedendum_coefficient: float = 1.25, alpha_n: float = math.radians(20)):
    """Basic-rack factor C_B [-] (S3); h_fP/m_n and alpha_Pn [rad]. ISO 53 A: 0.975."""
    return (1.0 + 0.5 * (1.2 - dedendum_coefficient)) * (
        1.0 - 0.02 * (20.0 - math.degrees(alpha_n))
    )


def material_factor(e1: float, e2: float) -> float:
    """E/E_st with E = 2 E1 E2/(E1 + E2) [-] (S4); Young's moduli in Pa."""
    return 2.0 * e1 * e2 / (e1 + e2) / E_STEEL


def load_factor(tangential_load: float | None, face_width: float) -> float:
    """Low-load correction (F_t K_A / b / 100 N/mm)^0.25 if below 100 N/mm, else 1 (S5).

    tangential_load: F_t K_A [N] (None = at least 100 N/mm assumed); face_width b [m].
    """
    if tangential_load is None:
        return 1.0
    if tangential_load <= 0.0:
        raise ValueError(
            f"the ISO 6336 mesh stiffness needs a positive tangential load (F_t K_A = "
            f"{tangential_load:.4g} N): at a mean torque of 0 give mesh.stiffness in N/m"
        )
    specific_load = tangential_load / (face_width * 1e3)  # N/mm
    return min(1.0, (specific_load / 100.0) ** 0.25)


def single_stiffness_per_width(
    z_n1, z_n2, x1=0.0, x2=0.0, *, beta=0.0, c_m=0.8, c_r=1.0, c_b=1.0, e_factor=1.0, l_factor=1.0
) -> float:
    """Single stiffness c' [N/(mm·µm)] (S2) with the factors of (S3)-(S5) passed in.

    beta: helix angle [rad] (0 for spur); c_m: theoretical-vs-measured correction C_M;
    c_r: gear-blank factor C_R; c_b: basic_rack_factor(); e_factor: material_factor();
    l_factor: load_factor().
    """
    c_th = theoretical_single_stiffness(z_n1, z_n2, x1, x2)
    return c_th * c_m * c_r * c_b * math.cos(beta) * e_factor * l_factor


def mesh_stiffness_per_width(c_single: float, eps_alpha: float) -> float:
    """Mean mesh stiffness c_gamma_alpha = c' (0.75 eps_alpha + 0.25) [N/(mm·µm)] (S6)."""
    return c_single * (0.75 * eps_alpha + 0.25)


def per_width_to_newton_per_metre(c: float, face_width: float) -> float:
    """Convert c [N/(mm·µm)] over face width b [m] to a stiffness [N/m] (S7)."""
    return c * (face_width * 1e3) * 1e6


def stiffness_levels(eps_alpha: float, k_mean: float, ratio: float = ISO_DOUBLE_TO_SINGLE):
    """Single- and double-contact levels (k_lo, k_hi) [N/m] of the wave (F1) with mean k_mean.

    The mean k_lo [1 + (ratio - 1)(eps_alpha - 1)] equals k_mean. With ratio = 1.75 and
    k_mean = c_gamma_alpha b this gives k_lo = c' b exactly, because (S6) is
    c' [1 (2 - eps_alpha) + 1.75 (eps_alpha - 1)]; ratio = 2 is the textbook "two pairs are
    twice as stiff" wave (k_lo = k_mean / eps_alpha).
    """
    if not 1.0 <= eps_alpha < 2.0:
        raise ValueError("rectangular mesh-stiffness wave needs 1 <= eps_alpha < 2")
    k_lo = k_mean / (1.0 + (ratio - 1.0) * (eps_alpha - 1.0))
    return k_lo, ratio * k_lo


def stiffness_wave(s, eps_alpha: float, k_mean: float, ratio: float = ISO_DOUBLE_TO_SINGLE):
    """Mesh stiffness k(s) [N/m] at normalised mesh time s = f_mesh t (F1).

    s = 0 is the instant a new tooth pair enters contact; the pair before it is still in
    contact until s = eps_alpha - 1 (double contact), then one pair carries the load.
    """
    k_lo, k_hi = stiffness_levels(eps_alpha, k_mean, ratio)
    return np.where(np.mod(s, 1.0) < eps_alpha - 1.0, k_hi, k_lo)


def stiffness_harmonics(
    eps_alpha: float, k_mean: float, n_harmonics: int, ratio: float = ISO_DOUBLE_TO_SINGLE
) -> list[tuple[float, float]]:
    """Fourier series (F2) of stiffness_wave: [(A_r [N/m], phi_r [rad]) for r = 1..n].

    k(t) = k_mean + sum_r A_r cos(r w_mesh t + phi_r), t = 0 as in stiffness_wave. With the
    double-contact length d = eps_alpha - 1 and jump dk = k_hi - k_lo, the pulse train gives
    A_r = 2 dk |sin(pi r d)| / (pi r), phi_r = -pi r d (+ pi where sin(pi r d) < 0).
    """
    k_lo, k_hi = stiffness_levels(eps_alpha, k_mean, ratio)
    d = eps_alpha - 1.0
    out = []
    for r in range(1, n_harmonics + 1):
        sine = math.sin(math.pi * r * d)
        phase = -math.pi * r * d + (math.pi if sine < 0.0 else 0.0)
        phase = math.atan2(math.sin(phase), math.cos(phase))  # wrap to (-pi, pi]
        out.append((2.0 * (k_hi - k_lo) * abs(sine) / (math.pi * r), phase))
    return out


def _material(spec) -> dict[str, float]:
    if isinstance(spec, str):
        try:
            return MATERIALS[spec]
        except KeyError:
            raise ValueError(f"unknown material {spec!r}; known: {sorted(MATERIALS)}") from None
    return {k: float(spec[k]) for k in ("density", "youngs_modulus", "poisson")}


def r_bore(gear: dict) -> float:
    """Bore radius [m] of a gear dict ("bore_diameter", default 0 = solid)."""
    return float(gear.get("bore_diameter", 0.0)) / 2.0


def _q(value, unit: str, source: str) -> dict:
    return {"value": value, "unit": unit, "source": source}


def pair_from_geometry(
    driver: dict,
    driven: dict,
    stiffness_method: str = "iso6336",
    tangential_load: float | None = None,
    n_harmonics: int = 10,
) -> dict:
    """Derived physical quantities of an external spur pair, each {"value", "unit", "source"}.

    Each gear dict: "teeth" z, "module" m_n [m], "face_width" b [m], "pressure_angle" alpha_n
    [rad], "profile_shift" x [-] (default 0), "bore_diameter" [m] (default 0), "material" (a
    MATERIALS name or {"density", "youngs_modulus", "poisson"}), optional
    "dedendum_coefficient" h_fP/m_n (default 1.25, ISO 53 A). Both gears need the same module
    and pressure angle; the mesh face width is the smaller b. tangential_load: F_t K_A [N] for
    the low-load correction (S5). ISO's pinion (index 1 of S1) is the gear with fewer teeth,
    whichever one drives.
    """
    if stiffness_method != "iso6336":
        raise ValueError(f"unknown stiffness_method {stiffness_method!r}; only 'iso6336'")
    g1, g2 = driver, driven
    m, alpha = float(g1["module"]), float(g1["pressure_angle"])
    if not (math.isclose(m, g2["module"]) and math.isclose(alpha, g2["pressure_angle"])):
        raise ValueError("driver and driven need the same module and pressure angle")
    z1, z2 = int(g1["teeth"]), int(g2["teeth"])
    x1, x2 = float(g1.get("profile_shift", 0.0)), float(g2.get("profile_shift", 0.0))
    b = min(float(g1["face_width"]), float(g2["face_width"]))
    mat1, mat2 = _material(g1["material"]), _material(g2["material"])

    alpha_w = operating_pressure_angle(z1, z2, x1, x2, alpha)  # (G4)
    a_w = centre_distance(z1, z2, m, alpha, alpha_w)  # (G5)
    rb1, rb2 = base_radius(z1, m, alpha), base_radius(z2, m, alpha)  # (G2)
    ra1, ra2 = tip_radius(z1, m, x1), tip_radius(z2, m, x2)  # (G3)
    eps = transverse_contact_ratio(ra1, rb1, ra2, rb2, a_w, alpha_w, base_pitch(m, alpha))  # (G6)
    inertia = [  # (I1), r_o = reference radius
        disc_inertia(mt["density"], g["face_width"], reference_radius(z, m), r_bore(g))
        for g, z, mt in ((g1, z1, mat1), (g2, z2, mat2))
    ]

    (zp, xp), (zw, xw) = sorted([(z1, x1), (z2, x2)], key=lambda t: t[0])  # pinion first
    c_b = 0.5 * sum(basic_rack_factor(g.get("dedendum_coefficient", 1.25), alpha) for g in (g1, g2))
    e_f = material_factor(mat1["youngs_modulus"], mat2["youngs_modulus"])  # (S4)
    l_f = load_factor(tangential_load, b)  # (S5)
    c_single = single_stiffness_per_width(zp, zw, xp, xw, c_b=c_b, e_factor=e_f, l_factor=l_f)
    c_mesh = mesh_stiffness_per_width(c_single, eps)  # (S6)
    k_single = per_width_to_newton_per_metre(c_single, b)  # (S7)
    k_mean = per_width_to_newton_per_metre(c_mesh, b)
    harmonics = stiffness_harmonics(eps, k_mean, n_harmonics)  # (F2)

    iso = "ISO 6336-1:2019 cl. 9 (Method B)"
    disc = "solid disc with bore at the reference diameter: J = rho b pi/2 (r^4 - r_i^4)"
    return {
        "base_radius_driver": _q(rb1, "m", "involute geometry: r_b = (m z/2) cos(alpha)"),
        "base_radius_driven": _q(rb2, "m", "involute geometry: r_b = (m z/2) cos(alpha)"),
        "inertia_driver": _q(inertia[0], "kg*m^2", disc),
        "inertia_driven": _q(inertia[1], "kg*m^2", disc),
        "contact_ratio": _q(eps, "1", "involute geometry: path of contact / base pitch"),
        "single_pair_stiffness": _q(k_single, "N/m", f"{iso}: c' b, c' = c'_th C_M C_R C_B"),
        "mesh_stiffness": _q(k_mean, "N/m", f"{iso}: c_gamma_alpha b, (0.75 eps_alpha + 0.25) c'"),
        "stiffness_harmonics": _q(
            [{"amplitude": a, "phase": p} for a, p in harmonics],
            "N/m, rad",
            "Fourier series of the rectangular single/double-contact wave "
            f"(double/single = {ISO_DOUBLE_TO_SINGLE}, mean = mesh_stiffness)",
        ),
        "centre_distance": _q(a_w, "m", "involute geometry: a_w = a cos(alpha)/cos(alpha_w)"),
        "operating_pressure_angle": _q(
            alpha_w,
            "rad",
            "involute geometry: inv(alpha_w) = inv(alpha) + 2 tan(alpha)(x1 + x2)/(z1 + z2)",
        ),
        "single_stiffness_iso": _q(c_single, "N/(mm*um)", f"{iso}: c'"),
        "mesh_stiffness_iso": _q(c_mesh, "N/(mm*um)", f"{iso}: c_gamma_alpha"),
    }
