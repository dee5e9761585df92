"""The gear train's linear structure and mesh: mass, stiffness and damping matrices.

Physical coordinates q (``COORDINATES``): motor, pinion, gear and load angles [rad], and with
bearings the pinion and gear centre displacements along the line of action [m]. With the mesh
deflection delta = w . q - e(t) = r_p th_p - r_g th_g + y_p - y_g - e(t) and the mesh force
W = k_m(t) f_h(delta) + c_m delta' (Eq. 2 and 6, the design's backlash law):

    M q'' + C_s q' + K_s q + w W = F(t)                                   (docs/gear-trains.md)

M = diag(I_m, I_p, I_g, I_l, m_p, m_g); K_s, C_s the shafts (torsional springs and dampers
between motor and pinion, gear and load) and bearings (springs and dampers to ground);
F = (T_m(t), 0, 0, -T_l, 0, 0): the driver torque and its fluctuation on the motor, the braking
torque on the load. Linearised in contact (f_h' = 1): K = K_s + k_m w w^T, C = C_s + c_m w w^T.

The train turns freely: phi_0 = (1, 1, r_p/r_g, r_p/r_g, 0, 0) spans the null space of K and C.
``reduced`` removes it: q = phi_0 s + Q u with relative coordinates u (input-shaft twist,
output-shaft twist, mesh rotation r_p th_p - r_g th_g, y_p, y_g); eliminating s'' from the
momentum equation phi_0^T (M q'' - F) = 0 leaves

    M_r u'' + C_r u' + K_r u + w_r W = P F(t),
    M_r = Q^T M Q - Q^T M phi_0 phi_0^T M Q / m_0,  P = Q^T - Q^T M phi_0 phi_0^T / m_0,
    m_0 = phi_0^T M phi_0,  K_r = Q^T K_s Q,  C_r = Q^T C_s Q,  w_r = Q^T w.

The stiff limit (shafts and bearings rigid) is the pair of Eq. (7) with I_a = I_m + I_p and
I_b = I_g + I_l: ``equivalent_design`` builds it, and the train's dimensionless form uses its
time scale, forcing and mesh damping (``dimensionless``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from gearengine.model.design import Design
from gearengine.model.reduction import DesignConversion, convert_design, physical_data

COORDINATES = ("motor", "pinion", "gear", "load", "pinion_y", "gear_y")
"""Physical coordinates of a train with bearings (without: the first four)."""
UNITS = ("rad", "rad", "rad", "rad", "m", "m")
"""Units of ``COORDINATES``."""
RELATIVE = ("input_shaft_twist", "output_shaft_twist", "mesh_rotation", "pinion_y", "gear_y")
"""Relative coordinates u of ``reduced`` (without bearings: the first three)."""


@dataclass(frozen=True)
class TrainModel:
    """A train's matrices in the physical coordinates q (shape (n,) for n = 4 or 6).

    Attributes:
        mass: M [kg m^2 on angles, kg on displacements], (n, n).
        structure_stiffness, structure_damping: K_s, C_s of shafts and bearings, (n, n).
        mesh_direction: w with delta = w . q - e(t) [m per coordinate unit], (n,).
        mesh_stiffness: k_m [N/m]; mesh_damping: c_m [N s/m] (the pair's, Eq. 7).
        radii: base radii (r_p, r_g) [m].
        torque, braking_torque: mean driver torque on the motor, braking torque on the load [N m].
    """

    mass: np.ndarray
    structure_stiffness: np.ndarray
    structure_damping: np.ndarray
    mesh_direction: np.ndarray
    mesh_stiffness: float
    mesh_damping: float
    radii: tuple[float, float]
    torque: float
    braking_torque: float

    @property
    def size(self) -> int:
        """Number n of physical coordinates (4 torsional, 6 with bearings)."""
        return self.mass.shape[0]

    @property
    def coordinates(self) -> tuple[str, ...]:
        return COORDINATES[: self.size]

    @property
    def units(self) -> tuple[str, ...]:
        return UNITS[: self.size]

    def stiffness(self) -> np.ndarray:
        """K = K_s + k_m w w^T [SI], the train linearised in contact (f_h' = 1)."""
        w = self.mesh_direction
        return self.structure_stiffness + self.mesh_stiffness * np.outer(w, w)

    def damping(self) -> np.ndarray:
        """C = C_s + c_m w w^T [SI]."""
        w = self.mesh_direction
        return self.structure_damping + self.mesh_damping * np.outer(w, w)

    def rigid_mode(self) -> np.ndarray:
        """phi_0 = (1, 1, r_p / r_g, r_p / r_g[, 0, 0]): the free rotation, K phi_0 = 0."""
        rp, rg = self.radii
        phi = np.zeros(self.size)
        phi[:4] = (1.0, 1.0, rp / rg, rp / rg)
        return phi

    def stiffened(self, factor: float) -> TrainModel:
        """The same train with shafts and bearings ``factor`` times stiffer, their damping
        ratios kept (dampers sqrt(factor) times stronger): the stiff-limit check."""
        return replace(
            self,
            structure_stiffness=self.structure_stiffness * factor,
            structure_damping=self.structure_damping * math.sqrt(factor),
        )

    def relative_basis(self) -> np.ndarray:
        """Q, shape (n, n - 1): q = phi_0 s + Q u with u the ``RELATIVE`` coordinates and
        s = th_p (the pinion angle)."""
        rg = self.radii[1]
        n = self.size
        q = np.zeros((n, n - 1))
        q[0, 0] = 1.0  # motor = s + input twist
        q[3, 1] = -1.0  # load = gear - output twist
        q[2, 2] = q[3, 2] = -1.0 / rg  # gear = (r_p s - mesh rotation) / r_g
        for k in range(4, n):
            q[k, k - 1] = 1.0
        return q

    def reduced(self) -> Reduced:
        """The equations in the relative coordinates u (module docstring)."""
        m, phi, q = self.mass, self.rigid_mode(), self.relative_basis()
        m0 = phi @ m @ phi
        coupling = q.T @ m @ phi
        project = q.T - np.outer(coupling, phi) / m0
        return Reduced(
            mass=q.T @ m @ q - np.outer(coupling, coupling) / m0,
            stiffness=q.T @ self.structure_stiffness @ q,
            damping=q.T @ self.structure_damping @ q,
            mesh_direction=q.T @ self.mesh_direction,
            projection=project,
            basis=q,
            rigid=phi,
            rigid_mass=m0,
            rigid_coupling=coupling,
        )


@dataclass(frozen=True)
class Reduced:
    """The train in relative coordinates u (``TrainModel.reduced``), SI units.

    ``mass``, ``stiffness``, ``damping`` (n-1, n-1) exclude the mesh; ``mesh_direction`` w_r
    (n-1,); ``projection`` P (n-1, n) maps the physical forces F to u; ``basis`` Q (n, n-1),
    ``rigid`` phi_0, ``rigid_mass`` m_0 and ``rigid_coupling`` Q^T M phi_0 rebuild q."""

    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    mesh_direction: np.ndarray
    projection: np.ndarray
    basis: np.ndarray
    rigid: np.ndarray
    rigid_mass: float
    rigid_coupling: np.ndarray

    def physical(self, u: np.ndarray) -> np.ndarray:
        """q of relative vectors u (columns), with no momentum in the free rotation:
        s = -phi_0^T M Q u / m_0."""
        s = -(self.rigid_coupling @ u) / self.rigid_mass
        return self.basis @ u + np.multiply.outer(self.rigid, s)


def shaft_damping(stiffness: float, zeta: float, j1: float, j2: float) -> float:
    """c = 2 zeta sqrt(k J_eq), J_eq = J_1 J_2 / (J_1 + J_2) [N m s/rad]: the damping ratio
    of the two-inertia mode of a shaft of stiffness k [N m/rad] between J_1, J_2 [kg m^2]."""
    return 2.0 * zeta * math.sqrt(stiffness * j1 * j2 / (j1 + j2))


def train_model(design: Design) -> TrainModel:
    """The matrices of a design with a ``train`` (raises ValueError without one)."""
    train = design.train
    if train is None:
        raise ValueError("the design has no train")
    data, _, _ = physical_data(design)
    ip, ig = data.inertia_a, data.inertia_b
    rp, rg = data.base_radius_a, data.base_radius_b
    im, il = train.motor.inertia, train.load.inertia
    n = 4 if train.bearings is None else 6
    mass = np.zeros((n, n))
    stiff = np.zeros((n, n))
    damp = np.zeros((n, n))
    mass[range(4), range(4)] = (im, ip, ig, il)
    for (i, j), shaft, (j1, j2) in (
        ((0, 1), train.input_shaft, (im, ip)),
        ((2, 3), train.output_shaft, (ig, il)),
    ):
        k = shaft.stiffness
        c = shaft_damping(k, shaft.damping_ratio, j1, j2)
        for matrix, value in ((stiff, k), (damp, c)):
            matrix[i, i] += value
            matrix[j, j] += value
            matrix[i, j] -= value
            matrix[j, i] -= value
    w = np.zeros(n)
    w[1:3] = (rp, -rg)
    if train.bearings is not None:
        for k, bearing in ((4, train.bearings.driver), (5, train.bearings.driven)):
            mass[k, k] = bearing.mass
            stiff[k, k] = bearing.stiffness
            damp[k, k] = 2.0 * bearing.damping_ratio * math.sqrt(bearing.stiffness * bearing.mass)
        w[4:6] = (1.0, -1.0)
    return TrainModel(
        mass=mass,
        structure_stiffness=stiff,
        structure_damping=damp,
        mesh_direction=w,
        mesh_stiffness=data.mesh_stiffness,
        mesh_damping=data.mesh_damping,
        radii=(rp, rg),
        torque=data.torque_a_mean,
        braking_torque=data.torque_b_mean,
    )


def equivalent_design(design: Design, model: TrainModel | None = None) -> Design:
    """The stiff limit of a train as a pair: I_a = I_m + I_p, I_b = I_g + I_l, the train's
    mesh damping c_m [N s/m] (the pair's of ``design``), no train; ``model`` its matrices when
    the caller has them (``train_model``)."""
    model = train_model(design) if model is None else model
    assert design.train is not None
    ip, ig = model.mass[1, 1], model.mass[2, 2]
    data = design.model_dump(exclude={"train", "tolerances"})
    data["driver"]["inertia"] = ip + design.train.motor.inertia
    data["driven"]["inertia"] = ig + design.train.load.inertia
    data["mesh"]["damping"], data["mesh"]["damping_ratio"] = model.mesh_damping, None
    return Design.model_validate(data)


@dataclass(frozen=True)
class Dimensionless:
    """The train in dimensionless relative coordinates: u~ = D u / b with D = diag(r_p, r_g,
    1, 1, 1) (rotations as displacements along the line of action), tau = omega_n t with the
    equivalent pair's omega_n = sqrt(k_m / m_e) (``equivalent_design``):

        A u~'' + C~ u~' + K~ u~ + w~ (K(tau) f_h(delta) + 2 mu~ delta') = f~ + p~ T~(tau)

    A = D^-1 M_r D^-1 / m_e, K~ = D^-1 K_r D^-1 / k_m, C~ = D^-1 C_r D^-1 / (m_e omega_n),
    w~ = D^-1 w_r, delta = w~ . u~ - e(tau) / b, f~ = D^-1 P F_mean / (b k_m) and p~ the
    motor-torque direction D^-1 P e_motor r_p, T~ = T_p / (r_p b k_m). ``load_direction``:
    f~ per unit of the pair's mean force F~_m = T / (r_p b k_m), D^-1 P (r_p e_motor - r_g
    e_load) (the driver torque and the braking torque that balances it; a torque ramp).
    """

    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    mesh_direction: np.ndarray
    mean_force: np.ndarray
    torque_direction: np.ndarray
    load_direction: np.ndarray
    scale: np.ndarray
    conversion: DesignConversion


def dimensionless(model: TrainModel, pair: DesignConversion) -> Dimensionless:
    """The dimensionless train on the scales of its equivalent pair ``pair``
    (``convert_design(equivalent_design(design))``)."""
    red = model.reduced()
    rp, rg = model.radii
    n = red.mass.shape[0]
    scale = np.ones(n)
    scale[:2] = (rp, rg)
    inv = 1.0 / scale
    b, k_m = pair.half_backlash_m, pair.mesh_stiffness_n_per_m
    m_e = pair.equivalent_mass_kg
    omega_n = 1.0 / pair.time_scale_s
    force = np.zeros(model.size)
    force[0], force[3] = model.torque, -model.braking_torque
    motor = np.zeros(model.size)
    motor[0] = rp
    load = motor.copy()
    load[3] = -rg
    return Dimensionless(
        mass=inv[:, None] * red.mass * inv[None, :] / m_e,
        stiffness=inv[:, None] * red.stiffness * inv[None, :] / k_m,
        damping=inv[:, None] * red.damping * inv[None, :] / (m_e * omega_n),
        mesh_direction=inv * red.mesh_direction,
        mean_force=inv * (red.projection @ force) / (b * k_m),
        torque_direction=inv * (red.projection @ motor),
        load_direction=inv * (red.projection @ load),
        scale=scale,
        conversion=pair,
    )


def train_of(design: Design) -> tuple[TrainModel, DesignConversion]:
    """The matrices of a train and the conversion of its equivalent pair (its scales)."""
    model = train_model(design)
    return model, convert_design(equivalent_design(design, model))
