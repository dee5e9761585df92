"""RK4 of the dimensionless train along one linear segment of a speed profile (run-ups).

The train's step (``kernel.train_step``) with its excitations at the integrated driver angle,
as the pair's run-up kernel (``systems.spur_pair.kernels.phase``): on a segment with
Omega_a(tau) = Omega_0 + beta tau and psi_a(tau) = psi_0 + Omega_0 tau + beta tau^2 / 2,

    K = 1 + sum kc0 cos(q psi_a + kc2),    e = sum ec0 cos(q psi_a + ec2),
    e' = -sum ec0 q Omega_a sin(q psi_a + ec2),    T = sum tc0 cos(q psi_a + tc2)

(orders q in row 1) and the mean force f(tau) = f_0 + f_1 tau (already through A^-1: the
torque ramp, and the motor torque that accelerates the train, ``TrainSystem.run_ramp``). The
transmission error enters the mesh deflection delta = w . u - e, not as a force, so no e''
term appears. The 2n-dimensional tangent rides along (Benettin, renormalised at the end of every
block); per block the kernel keeps the pair's ``spur_pair.kernels.ramp.BLOCK_COLUMNS`` of delta.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from gearengine.jitcache import drop_stale
from gearengine.systems.gear_train import kernel
from gearengine.systems.gear_train.kernel import forcing_at_phase, renormalised, train_step
from gearengine.systems.spur_pair.kernels import ramp as pair_ramp
from gearengine.systems.spur_pair.kernels import smooth
from gearengine.systems.spur_pair.kernels.ramp import (
    BLOCK_COLUMNS,
    TANGENT_FLOOR,
    fresh_tally,
    tallied,
    write_block,
)
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, law_force, region

drop_stale(
    "ramp",
    [Path(__file__), Path(kernel.__file__), Path(smooth.__file__), Path(pair_ramp.__file__)],
    Path(__file__).parent / "__pycache__",
)
"""Before any kernel runs: numba watches only this file; ``train_step`` lives in kernel,
``law_force`` in smooth and the block tally in the pair's ``kernels.ramp``."""


@njit(**JIT_OPTIONS)
def ramp_train_forcing(
    t: float, kc: np.ndarray, ec: np.ndarray, tc: np.ndarray, ramp: np.ndarray
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """K, e, e' and T at tau = t after the segment's start; ``ramp`` = (Omega_0, beta, psi_0)."""
    omega = ramp[0] + ramp[1] * t
    psi = ramp[2] + ramp[0] * t + 0.5 * ramp[1] * t * t
    return forcing_at_phase(psi, omega, kc, ec, tc)


@njit(**JIT_OPTIONS)
def run_ramp(
    law: int,
    a: float,
    c: float,
    alpha: float,
    mu: float,
    AK: np.ndarray,
    AC: np.ndarray,
    g: np.ndarray,
    w: np.ndarray,
    p: np.ndarray,
    kc: np.ndarray,
    ec: np.ndarray,
    tc: np.ndarray,
    means: np.ndarray,
    ramp: np.ndarray,
    y: np.ndarray,
    h: float,
    n_blocks: int,
    steps: int,
    bound: float,
):  # pragma: no cover - compiled
    """Integrate one segment from y = (u, v, du, dv), shape (4, n), updated in place.

    Args:
        law, a, c, alpha: backlash law; mu: mesh damping mu~; AK, AC, g, w, p: the train
            (``kernel`` module docstring).
        kc, ec, tc: stiffness, transmission-error and torque terms by order, shape (3, terms).
        means: rows f_0 and f_1 of the mean force f_0 + f_1 tau, shape (2, n).
        ramp: (Omega_0, beta, psi_0) of the segment, tau from its start.
        h: RK4 step; n_blocks x steps steps in all; bound: divergence bound on |u_i|, |v_i|.

    Returns:
        the block table (n_blocks, 11) of ``spur_pair.kernels.ramp.BLOCK_COLUMNS`` for delta, the
        mesh force W = K f_h(delta) + 2 mu delta' and the tooth contact force (W clipped to the
        touching flank's sign, 0 while apart) (NaN past a divergence); blocks completed.
    """
    n = y.shape[1]
    twomu = 2.0 * mu
    out = np.full((n_blocks, len(BLOCK_COLUMNS)), np.nan)
    k = np.empty((4, 4, n))
    s = np.empty((4, n))
    forcing = np.empty((3, 4))
    f = np.empty((3, n))
    delta = -ramp_train_forcing(0.0, kc, ec, tc, ramp)[1]
    for i in range(n):
        delta += w[i] * y[0, i]
    reg = region(delta)
    for blk in range(n_blocks):
        tally = fresh_tally()
        grown = 0.0
        t0 = blk * steps * h
        for j in range(steps):
            for q in range(3):
                tq = t0 + j * h + 0.5 * q * h
                forcing[q, 0], forcing[q, 1], forcing[q, 2], forcing[q, 3] = ramp_train_forcing(
                    tq, kc, ec, tc, ramp
                )
                for i in range(n):
                    f[q, i] = means[0, i] + means[1, i] * tq
            train_step(law, a, c, alpha, twomu, AK, AC, g, w, f, p, forcing, y, k, s, h)
            prev = reg
            delta = -forcing[2, 1]
            deltad = -forcing[2, 2]
            squared = 0.0
            for i in range(n):
                delta += w[i] * y[0, i]
                deltad += w[i] * y[1, i]
                squared += y[2, i] * y[2, i] + y[3, i] * y[3, i]
            if squared < TANGENT_FLOOR or squared > 1.0 / TANGENT_FLOOR:
                scale = math.sqrt(squared)
                grown += math.log(scale)
                for i in range(n):
                    y[2, i] /= scale
                    y[3, i] /= scale
            reg = region(delta)
            force = forcing[2, 0] * law_force(law, a, c, alpha, delta)[0] + twomu * deltad
            tally = tallied(tally, reg, prev, delta, force)
        nrm, big = renormalised(y)
        if not big < bound:
            return out, blk
        write_block(out[blk], tally, grown + math.log(nrm))
    return out, n_blocks
