"""Melnikov for a train: the verdict of its mesh-mode reduction, when that reduction holds.

The Melnikov criterion (``homoclinic``) is for one degree of freedom. A train reduces to one
when a single mode carries the mesh: the mode phi (dimensionless relative coordinates of
``model.Dimensionless``, A-normalised, phi^T A phi = 1, omega_k^2 = phi^T (K~ + w~ w~^T) phi)
whose strain energy lies for a share s^2 / omega_k^2 >= ``SHARE_THRESHOLD`` in the mesh, with
s = w~ . phi. A one-mode Galerkin projection u~ = phi eta, delta = s eta - e, and the time
tau' = s tau give the pair's Eq. (9) for delta with

    mu' = (phi^T C~ phi + 2 mu~ s^2) / (2 s)          (mesh and structural damping of the mode)
    kappa = omega_k^2 / s^2 - 1 = (1 - share) / share (the mode's structural stiffness, in k_m)
    F~_m' = phi^T f~ / s,  F~_p' = (T_p / (r_p b k_m)) phi^T p~ / s,  Omega' = Omega / s,
    the same k~_pr and e_r / b,

and the restoring force f_h(delta) + kappa delta: for the Melnikov cubic -a x + c x^3 of the
backlash law (``model.backlash.melnikov_cubic``) this is a' = a - kappa. Neglected: the
structural damping and stiffness acting on e(t) (terms phi^T C~ phi e' and kappa e), and every
other mode. In the stiff limit s = 1, kappa = 0 and the reduction is the equivalent pair.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
from pydantic import BaseModel, ConfigDict, Field

from gearengine.homoclinic.schemas import MelnikovResult
from gearengine.homoclinic.verdict import melnikov
from gearengine.model.design import Design
from gearengine.model.params import CubicBacklash, Excitation, GearParams, Harmonic
from gearengine.systems.base import System
from gearengine.systems.designs import design_model
from gearengine.systems.gear_train.system import TrainSystem
from gearengine.systems.spur_pair.laws import melnikov_cubic

SHARE_THRESHOLD = 0.9
"""Smallest share of the mesh mode's strain energy in the mesh for the reduction to be used."""

REDUCTION = (
    "one-mode Galerkin projection onto the mesh mode (the mode with the largest share of "
    "strain energy in the mesh), time rescaled so that its mesh spring is 1; its structural "
    "stiffness kappa = (1 - share) / share lowers the cubic's a to a - kappa; other modes and "
    "the structural terms acting on the transmission error are neglected"
)


class TrainMelnikov(BaseModel):
    """The Melnikov answer of a train: the mesh-mode reduction's verdict, or why there is none."""

    model_config = ConfigDict(frozen=True)

    applicable: bool = Field(description="The mesh mode holds >= threshold of the mesh energy.")
    reason: str = Field(description="Why the reduction is or is not used.")
    threshold: float = Field(SHARE_THRESHOLD, description="Share threshold.")
    mesh_energy_share: float = Field(description="The mesh mode's share of strain energy.")
    reduction: str = Field(REDUCTION, description="How the train is reduced (a reduction).")
    params: GearParams | None = Field(description="Eq. (9) of the reduction (when applicable).")
    melnikov: MelnikovResult | None = Field(description="Its Melnikov verdict (a reduction).")


def mesh_mode(system: TrainSystem) -> tuple[np.ndarray, float, float]:
    """(phi, s, share) of the mode with the largest mesh share, phi^T A phi = 1."""
    form = system.form
    w = form.mesh_direction
    values, vectors = scipy.linalg.eigh(form.stiffness + np.outer(w, w), form.mass)
    s = w @ vectors
    shares = s**2 / values
    k = int(np.argmax(shares))
    phi = vectors[:, k] * np.sign(s[k])
    return phi, float(abs(s[k])), float(shares[k])


def reduced_params(system: TrainSystem, phi: np.ndarray, s: float, share: float) -> GearParams:
    """Eq. (9) of the mesh-mode reduction (module docstring)."""
    form, pair = system.form, system.params
    kappa = (1.0 - share) / share
    a, c, _ = melnikov_cubic(pair.backlash)
    torque_scale = system.torque_ratio * float(phi @ form.torque_direction) / s

    def scaled(exc: Excitation | None, factor: float) -> Excitation | None:
        if exc is None:
            return None
        harmonics = [Harmonic(amplitude=h.amplitude * factor, phase=h.phase) for h in exc.harmonics]
        return Excitation(frequency=exc.frequency / s, harmonics=harmonics)

    return GearParams(
        damping=float(phi @ form.damping @ phi + 2.0 * pair.damping * s * s) / (2.0 * s),
        mean_force=float(phi @ form.mean_force) / s,
        backlash=CubicBacklash(a=a - kappa, c=c),
        stiffness=scaled(pair.stiffness, 1.0),
        transmission_error=scaled(pair.transmission_error, 1.0),
        torque=scaled(pair.torque, torque_scale),
    )


def train_melnikov(system: TrainSystem) -> TrainMelnikov:
    """The Melnikov verdict of the mesh-mode reduction, or applicable: false with the reason."""
    phi, s, share = mesh_mode(system)
    if share < SHARE_THRESHOLD:
        reason = (
            f"the mesh mode holds {share:.1%} of its strain energy in the mesh, below "
            f"{SHARE_THRESHOLD:.0%}: the mesh is shared by several modes and no single degree "
            "of freedom carries it; use the train's numerical verdict"
        )
        return TrainMelnikov(applicable=False, reason=reason, mesh_energy_share=share,
                             params=None, melnikov=None)  # fmt: skip
    params = reduced_params(system, phi, s, share)
    reason = (
        f"the mesh mode holds {share:.1%} of its strain energy in the mesh (>= "
        f"{SHARE_THRESHOLD:.0%}): Melnikov of its one-mode reduction (a reduction, not the train)"
    )
    return TrainMelnikov(applicable=True, reason=reason, mesh_energy_share=share,
                         params=params, melnikov=melnikov(params))  # fmt: skip


def melnikov_point(model: GearParams | System) -> GearParams | None:
    """The parameter point of Eq. (9) whose Melnikov criterion judges ``model``: a parameter
    point itself, a system's own point (the pair), a train's mesh-mode reduction when it holds
    (``train_melnikov``'s, without its verdict), else None (the criterion does not apply)."""
    if isinstance(model, GearParams):
        return model
    if not isinstance(model, TrainSystem):
        return model.params
    phi, s, share = mesh_mode(model)
    return reduced_params(model, phi, s, share) if share >= SHARE_THRESHOLD else None


ABOVE_T_CRIT = ("above T_crit", "the criterion does not apply above the critical torque")
"""Why the pair's criterion judges no point where it does not (``not_judged_reason``)."""


def not_judged_reason(design: Design | None) -> tuple[str, str]:
    """Why the Melnikov criterion judges no point of ``design``'s operating envelope where it
    does not (in a window's words, in a report's): above the critical torque of the pair
    (``ABOVE_T_CRIT``), or of a train's mesh-mode reduction, or, for a train whose mesh no
    single mode carries, at every point (no one-mode reduction, ``melnikov_point``). Speed
    and torque leave a train's modes as they are, so the design decides it."""
    if design is None or design.train is None:
        return ABOVE_T_CRIT
    if melnikov_point(design_model(design)[0]) is not None:
        return ("above the mesh-mode reduction's T_crit",
                "the criterion of the train's mesh-mode reduction does not apply above its "
                "critical torque")  # fmt: skip
    share = f"no single mode of the train holds {SHARE_THRESHOLD:.0%} of the mesh strain energy"
    return share, f"{share}: the one-degree-of-freedom criterion has no reduction to judge"
