"""Modes of a train linearised in contact (f_h' = 1, mean stiffness k_m).

Undamped natural frequencies and shapes solve K_r phi = omega^2 M_r phi in the relative
coordinates of ``model.TrainModel.reduced`` (the free rotation removed; ``scipy.linalg.eigh``),
mapped back to the physical coordinates with no momentum in the free rotation. Damping ratios
come from the eigenvalues lambda of the damped first-order system (``scipy.linalg.eigvals``),
zeta = -Re(lambda) / |lambda|, matched to the undamped modes in order of |lambda|. The mesh's
share of a mode's strain energy is k_m (w . phi)^2 / (phi^T K phi); the mesh mode is the mode
with the largest share.

Shapes are given as displacements along the line of action (r_p th for motor and pinion,
r_g th for gear and load, y for the gear centres), the largest +1.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
from pydantic import BaseModel, ConfigDict, Field

from gearengine.model.units import shown
from gearengine.systems.gear_train.model import TrainModel


class Mode(BaseModel):
    """One mode of the train linearised in contact."""

    model_config = ConfigDict(frozen=True)

    frequency_hz: float = Field(description="Undamped natural frequency [Hz].")
    damping_ratio: float = Field(description="Damping ratio zeta = -Re(lambda) / |lambda|.")
    shape: dict[str, float] = Field(
        description="Mode shape by coordinate: displacement along the line of action (r theta "
        "for rotations, y for the gear centres), the largest +1."
    )
    mesh_energy_share: float = Field(
        description="Share of the mode's strain energy stored in the mesh spring, 0 to 1."
    )


class Modes(BaseModel):
    """The modes of a train, lowest first, and which one is the mesh mode."""

    model_config = ConfigDict(frozen=True)

    modes: list[Mode] = Field(description="Elastic modes, lowest frequency first.")
    mesh_mode: int = Field(description="Index of the mode with the largest mesh energy share.")
    stiff_limit_hz: float = Field(
        description="The pair's natural frequency with I_a = I_m + I_p, I_b = I_g + I_l: the "
        "mesh mode's limit with rigid shafts and bearings."
    )
    coordinates: list[str] = Field(description="The coordinates of the shapes.")


def eigen(model: TrainModel) -> tuple[np.ndarray, np.ndarray]:
    """(omega [rad/s], shapes q (n, n - 1) in physical coordinates): K_r phi = omega^2 M_r phi."""
    red = model.reduced()
    w = red.mesh_direction
    stiffness = red.stiffness + model.mesh_stiffness * np.outer(w, w)
    values, vectors = scipy.linalg.eigh(stiffness, red.mass)
    return np.sqrt(values), red.physical(vectors)


def damping_ratios(model: TrainModel) -> np.ndarray:
    """zeta of each mode, lowest |lambda| first, from the damped first-order system
    x' = [[0, I], [-M_r^-1 K_r, -M_r^-1 C_r]] x (the free rotation removed)."""
    red = model.reduced()
    w = red.mesh_direction
    k = red.stiffness + model.mesh_stiffness * np.outer(w, w)
    c = red.damping + model.mesh_damping * np.outer(w, w)
    n = k.shape[0]
    inv = np.linalg.inv(red.mass)
    system = np.block([[np.zeros((n, n)), np.eye(n)], [-inv @ k, -inv @ c]])
    lam = scipy.linalg.eigvals(system)
    upper = lam[lam.imag >= 0.0]
    if upper.size < n:  # an overdamped pair of real roots: keep the slower of each pair
        upper = np.sort_complex(lam)[-n:]
    upper = upper[np.argsort(np.abs(upper))][:n]
    return -upper.real / np.abs(upper)


def line_of_action(model: TrainModel, shapes: np.ndarray) -> np.ndarray:
    """Shapes (n, m) as displacements along the line of action: r_p th, r_g th, y."""
    rp, rg = model.radii
    factor = np.ones(model.size)
    factor[:4] = (rp, rp, rg, rg)
    return factor[:, None] * shapes


def mesh_energy_shares(model: TrainModel, shapes: np.ndarray) -> np.ndarray:
    """k_m (w . phi)^2 / (phi^T K phi) of each shape column (physical coordinates)."""
    strain = np.einsum("im,ij,jm->m", shapes, model.stiffness(), shapes)
    return model.mesh_stiffness * (model.mesh_direction @ shapes) ** 2 / strain


def modes(model: TrainModel, stiff_limit_hz: float) -> Modes:
    """The elastic modes of ``model`` linearised in contact (module docstring)."""
    omega, shapes = eigen(model)
    zeta = damping_ratios(model)
    shares = mesh_energy_shares(model, shapes)
    loa = line_of_action(model, shapes)
    out = []
    for k in range(omega.size):
        col = loa[:, k]
        col = col / col[np.argmax(np.abs(col))]
        out.append(
            Mode(
                frequency_hz=shown(omega[k] / (2.0 * math.pi)),
                damping_ratio=shown(float(zeta[k])),
                shape={
                    name: shown(float(v)) for name, v in zip(model.coordinates, col, strict=True)
                },
                mesh_energy_share=shown(float(shares[k])),
            )
        )
    return Modes(
        modes=out,
        mesh_mode=int(np.argmax(shares)),
        stiff_limit_hz=shown(stiff_limit_hz),
        coordinates=list(model.coordinates),
    )
