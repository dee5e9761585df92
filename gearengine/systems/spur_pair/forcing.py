"""Forcing terms of Eq. (9) as flat coefficient arrays, and the RK4 step plan.

    K(t) = 1  + sum_i k_amp_i cos(k_omega_i t + k_phase_i)     (Eq. 9)
    F(t) = Fm + sum_i f_amp_i cos(f_omega_i t + f_phase_i)

with stiffness terms k_amp = 2 k~_pr at r Omega_k, torque terms F~_pr at r Omega_p and
transmission-error terms (r Omega_e)^2 F~_er at r Omega_e (torque terms first, as gear_ref.c).

Only harmonics with a nonzero amplitude are kept. The step plan aligns the fixed RK4 steps to the
Poincare period T0 = 2 pi / Omega_0 so stroboscopic samples fall on step boundaries.
"""

from __future__ import annotations

import math

import numpy as np

from gearengine.model.frequencies import incommensurate_reason, poincare_frequency
from gearengine.model.params import GearParams
from gearengine.systems.base import StepPlan, resolving
from gearengine.systems.spur_pair.laws import LAWS


def packed_forcing(params: GearParams) -> tuple[np.ndarray, float, np.ndarray]:
    """(kc, fm, fc): the forcing as the kernels take it, kc and fc of shape (3, n_terms) with
    rows amplitude, omega, phase, and fm the mean force F~_m. Stiffness terms 2 k~_pr at
    r Omega_k; torque terms F~_pr at r Omega_p, then transmission-error terms
    (r Omega_e)^2 F~_er at r Omega_e (Eq. 9); only harmonics with a nonzero amplitude."""
    k: list[tuple[float, float, float]] = []
    f: list[tuple[float, float, float]] = []
    if params.stiffness is not None:
        w = params.stiffness.frequency
        k += [(2.0 * h.amplitude, r * w, h.phase) for r, h in params.stiffness.active()]
    if params.torque is not None:
        w = params.torque.frequency
        f += [(h.amplitude, r * w, h.phase) for r, h in params.torque.active()]
    if params.transmission_error is not None:
        w = params.transmission_error.frequency
        f += [
            ((r * w) * (r * w) * h.amplitude, r * w, h.phase)
            for r, h in params.transmission_error.active()
        ]
    kc = np.ascontiguousarray(np.array(k, dtype=np.float64).reshape(-1, 3).T)
    fc = np.ascontiguousarray(np.array(f, dtype=np.float64).reshape(-1, 3).T)
    return kc, float(params.mean_force), fc


def static_error(params: GearParams, t: np.ndarray) -> np.ndarray:
    """The static transmission error e(tau) = sum_r F~_er cos(r Omega_e tau + phi_r) in units
    of b at the times ``t`` (shape (n,)): Eq. (7)'s x = r_a theta_a - r_b theta_b - e excludes
    it, so r_a theta_a - r_b theta_b (what shaft encoders measure) is x + e."""
    e = np.zeros_like(t, dtype=np.float64)
    exc = params.transmission_error
    if exc is not None:
        for r, h in exc.active():
            e += h.amplitude * np.cos(r * exc.frequency * t + h.phase)
    return e


def contact_force_of(params: GearParams, t: np.ndarray, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The tooth contact force at samples (tau, x, x') of shape (n,), dimensionless (units of
    k_m b): the model's mesh force K(tau) f_h(x) + 2 mu x' (Eq. 9) where a flank touches
    (|x| > 1), clipped to that flank's sign (a flank pushes, never pulls), and 0 where the teeth
    are apart (|x| <= 1), where the model's damping term still acts."""
    kc, _, _ = packed_forcing(params)
    stiffness = 1.0 + np.sum(kc[0][:, None] * np.cos(kc[1][:, None] * t + kc[2][:, None]), axis=0)
    force = (
        stiffness * LAWS[params.backlash.model].f_h(params.backlash, x) + 2.0 * params.damping * v
    )
    contact = np.where(x > 1.0, np.maximum(force, 0.0), 0.0)
    return np.where(x < -1.0, np.minimum(force, 0.0), contact)


def fastest_excitation(params: GearParams) -> float | None:
    """Largest fundamental frequency Omega among excitations with a nonzero harmonic."""
    freqs = [exc.frequency for _, exc in params.excitations() if any(True for _ in exc.active())]
    return max(freqs) if freqs else None


def contact_frequency(params: GearParams) -> float:
    """The pair's fastest oscillation omega_max [omega_n]: in contact, sqrt of the largest mesh
    stiffness, K(tau) <= 1 + sum_i |k_amp_i| (Eq. 9)."""
    kc, _, _ = packed_forcing(params)
    return math.sqrt(1.0 + float(np.sum(np.abs(kc[0]))))


def step_plan(params: GearParams, steps_per_period: int) -> StepPlan:
    """RK4 grid with ``steps_per_period`` steps per period of the fastest active excitation,
    and at least enough that h omega_max <= ``H_OMEGA`` for the teeth in contact
    (``contact_frequency``; ``systems.base.resolving``): at low speed a mesh period holds many
    natural periods, and 128 steps a period left 2 steps for each at 400 rpm (a blow-up read
    as a DTE of 1.9e7 um)."""
    return resolving(_forcing_plan(params, steps_per_period), contact_frequency(params),
                     "the teeth in contact")  # fmt: skip


def _forcing_plan(params: GearParams, steps_per_period: int) -> StepPlan:
    """RK4 grid with ``steps_per_period`` steps per period of the fastest active excitation.

    Commensurate forcing: T0 = 2 pi / Omega_0 and N = round(steps_per_period Omega_fast / Omega_0)
    (= steps_per_period * Omega_fast / Omega_0 exactly when that ratio is an integer).
    Incommensurate: sampling interval 2 pi / Omega_fast, N = steps_per_period, no period.
    No active excitation: T0 = 2 pi (Omega_0 = 1), N = steps_per_period.
    """
    fast = fastest_excitation(params)
    if fast is None:
        note = "no active excitation: constant forcing, sampling interval T0 = 2 pi (Omega_0 = 1)"
        return StepPlan(1.0, 2.0 * math.pi, steps_per_period, 1.0, (note,))
    omega0 = poincare_frequency(params)
    if omega0 is None:
        note = (
            f"active frequencies {sorted(set(params.active_frequencies()))} are incommensurate "
            f"(no common Omega_0: {incommensurate_reason(params)}): the forcing is "
            "quasi-periodic and has no Poincare period; "
            f"strobes are taken every 2 pi / {fast:g} (fastest excitation) and the forcing is "
            "evaluated at absolute time"
        )
        return StepPlan(None, 2.0 * math.pi / fast, steps_per_period, fast, (note,))
    steps = max(1, round(steps_per_period * fast / omega0))
    notes: tuple[str, ...] = ()
    if not math.isclose(fast / omega0, round(fast / omega0), rel_tol=1e-9):
        notes = (f"T0 is shorter than the fastest excitation period; N = {steps} steps per T0",)
    return StepPlan(omega0, 2.0 * math.pi / omega0, steps, omega0, notes, steps / steps_per_period)
