"""Forcing of Eq. (9) while the driver speed changes: every excitation follows the driver's
angle psi_a(tau) (the integral of its speed), not the speed times the time.

On one segment of a speed profile that is linear in time the driver speed and angle are, in the
time tau = w_n t of Eq. (9) (w_n does not depend on the speed, so tau is the design's own clock),

    Omega_a(tau) = Omega_0 + beta tau,    psi_a(tau) = psi_0 + Omega_0 tau + beta tau^2 / 2

exactly (beta = (d w_a / dt) / w_n^2). A term of order q (mesh stiffness and transmission error
q = r n_a, torque fluctuation q = r order) has the phase q psi_a + phi. The transmission-error
force is -e~'' of e~ = F~_er cos(q psi_a + phi) (Eq. 7, -m e'' / (b k_m)):

    F~_er [(q Omega_a)^2 cos(q psi_a + phi) + q beta sin(q psi_a + phi)]

which is the stationary (r Omega_e)^2 F~_er cos(...) of Eq. (9) when beta = 0. The mean force
is F~_m0 + F~_m1 tau (a torque ramp, and the force that accelerates the driven inertia).

Arguments as the kernels take them (``gearengine.studies.runup.profile`` packs them):

* ``kc`` (3, n): stiffness terms, rows amplitude 2 k~_pr, order q, phase;
* ``ramp`` (5,): F~_m0, F~_m1, Omega_0, beta, psi_0, with tau counted from the segment start;
* ``fc`` (4, n): force terms, rows amplitude (F~_pr, or F~_er for a transmission error),
  order q, phase, kind (0 a force, 1 a transmission-error displacement).

``excitation_at`` is the one entry of the kink-splitting step (``kernels.kink``): with a float
mean force it is the stationary ``forcing_at`` (same machine code as before), with a ramp
record it is ``ramp_forcing_at``; numba picks the branch at compile time from the type.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types
from numba.extending import overload

from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, forcing_at


@njit(**JIT_OPTIONS)
def ramp_forcing_at(
    t: float, kc: np.ndarray, ramp: np.ndarray, fc: np.ndarray
) -> tuple[float, float]:  # pragma: no cover - compiled
    """K(tau) and F(tau) of Eq. (9) at tau = t after the start of a linear speed segment."""
    omega = ramp[2] + ramp[3] * t
    psi = ramp[4] + ramp[2] * t + 0.5 * ramp[3] * t * t
    K = 1.0
    for i in range(kc.shape[1]):
        K += kc[0, i] * math.cos(kc[1, i] * psi + kc[2, i])
    F = ramp[0] + ramp[1] * t
    for i in range(fc.shape[1]):
        q = fc[1, i]
        arg = q * psi + fc[2, i]
        if fc[3, i] == 0.0:
            F += fc[0, i] * math.cos(arg)
        else:
            F += fc[0, i] * ((q * omega) ** 2 * math.cos(arg) + q * ramp[3] * math.sin(arg))
    return K, F


def excitation_at(t, kc, fm, fc):  # type: ignore[no-untyped-def]
    """K and F of Eq. (9) at time t: stationary (float ``fm``) or on a speed ramp (array)."""
    if isinstance(fm, np.ndarray):
        return ramp_forcing_at(t, kc, fm, fc)
    return forcing_at(t, kc, fm, fc)


@overload(excitation_at, jit_options=JIT_OPTIONS)
def _excitation_at(t, kc, fm, fc):  # type: ignore[no-untyped-def]
    if isinstance(fm, types.Array):
        return lambda t, kc, fm, fc: ramp_forcing_at(t, kc, fm, fc)
    return lambda t, kc, fm, fc: forcing_at(t, kc, fm, fc)
