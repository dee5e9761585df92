"""Kink-splitting RK4 of Eq. (9) along one linear segment of a speed profile (run-ups).

The same step as the stationary piecewise kernel (``kink.kink_step``, split at every switching
time |x| = 1) with the forcing of ``kernels.phase`` (excitations at the integrated driver
angle); the tangent equation rides along for the finite-time Lyapunov exponent (Benettin et
al., Meccanica 15, 1980: renormalised at the end of every block, the log of its norm kept).

The segment is cut into ``n_blocks`` blocks of ``steps`` RK4 steps of length h; per block the
kernel keeps what the reading of a run-up needs (``BLOCK_COLUMNS``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gearengine.systems.spur_pair.kernels.kink import kink_step
from gearengine.systems.spur_pair.kernels.phase import ramp_forcing_at
from gearengine.systems.spur_pair.kernels.smooth import JIT_OPTIONS, region, region_force

TANGENT_FLOOR = 1e-200
"""Squared tangent norm below which (or above whose inverse) a block renormalises the tangent
within itself, keeping the log: else a block of ~1e4 tau at low speed contracts it to 0 and
every later FTLE reads NaN."""

BLOCK_COLUMNS = (
    "x_min", "x_max", "force_min", "force_max", "steps_separated", "steps_back_flank",
    "back_flank_impacts", "drive_flank_impacts", "log_growth", "contact_force_min",
    "contact_force_max",
)  # fmt: skip
"""Columns of ``run_ramp``'s block table: extremes of x and of the dimensionless mesh force
K f_h(x) + 2 mu x' at step ends (the model's force: its damping term acts in the clearance
too); steps ending inside the clearance (|x| <= 1) and on the back flank (x < -1); entries into
the back flank and re-engagements of the drive flank (0 -> x > 1) at step ends; log of the
tangent norm over the block; extremes of the tooth contact force at step ends (the model's
force where a flank touches, clipped to that flank's sign, 0 while apart: as
``forcing.contact_force_of``)."""


@njit(**JIT_OPTIONS)
def fresh_tally() -> tuple:  # pragma: no cover - compiled
    """A block's tally before its first step: (x_min, x_max, force_min, force_max,
    steps_separated, steps_back_flank, back_flank_impacts, drive_flank_impacts,
    contact_force_min, contact_force_max) of ``BLOCK_COLUMNS``, extremes empty, counts 0."""
    return np.inf, -np.inf, np.inf, -np.inf, 0, 0, 0, 0, np.inf, -np.inf


@njit(**JIT_OPTIONS, inline="always")
def tallied(
    tally: tuple, reg: int, prev: int, x: float, force: float
) -> tuple:  # pragma: no cover - compiled
    """``tally`` with one more step end: deflection x in region ``reg`` of Eq. (8) (``prev``
    before the step) and mesh force ``force`` (the pair's x; a train's mesh deflection).
    Inlined by numba, so the ten values stay in registers as the written-out tallies did."""
    xmin, xmax, fmin, fmax, sep, back, back_in, drive_in, cmin, cmax = tally
    xmin = min(xmin, x)
    xmax = max(xmax, x)
    fmin = min(fmin, force)
    fmax = max(fmax, force)
    contact = 0.0  # apart: no contact force, whatever the model's damping term
    if reg == 0:
        sep += 1
    elif reg < 0:
        back += 1
        contact = min(force, 0.0)  # a flank pushes, never pulls
        if prev >= 0:
            back_in += 1
    else:
        contact = max(force, 0.0)
        if prev == 0:
            drive_in += 1
    cmin = min(cmin, contact)
    cmax = max(cmax, contact)
    return xmin, xmax, fmin, fmax, sep, back, back_in, drive_in, cmin, cmax


@njit(**JIT_OPTIONS)
def write_block(row: np.ndarray, tally: tuple, growth: float) -> None:  # pragma: no cover
    """A block's row of ``BLOCK_COLUMNS``: its tally and the log of the tangent's growth."""
    xmin, xmax, fmin, fmax, sep, back, back_in, drive_in, cmin, cmax = tally
    row[0], row[1], row[2], row[3] = xmin, xmax, fmin, fmax
    row[4], row[5], row[6], row[7] = sep, back, back_in, drive_in
    row[8] = growth
    row[9], row[10] = cmin, cmax


@njit(**JIT_OPTIONS)
def run_ramp(
    alpha: float,
    mu: float,
    state: np.ndarray,
    kc: np.ndarray,
    ramp: np.ndarray,
    fc: np.ndarray,
    h: float,
    n_blocks: int,
    steps: int,
    bound: float,
):  # pragma: no cover - compiled
    """Integrate one segment from ``state`` = [x, v, dx, dv] (updated in place to the end).

    Args:
        alpha: slope of f_h inside the clearance (Eq. 8); mu: damping ratio.
        kc, ramp, fc: the segment's forcing (``kernels.phase``), tau from the segment start.
        h: RK4 step (time units tau); n_blocks x steps steps in all.
        bound: divergence bound on |x| and |v| (checked at block ends).

    Returns:
        table of shape (n_blocks, len(BLOCK_COLUMNS)), rows past a divergence NaN;
        blocks completed.
    """
    twomu = 2.0 * mu
    out = np.full((n_blocks, 11), np.nan)
    x, v, dx, dv = state[0], state[1], state[2], state[3]
    reg = region(x)
    for n in range(n_blocks):
        tally = fresh_tally()
        grown = 0.0  # log of the tangent's norm taken out within the block
        t0 = n * steps * h
        for j in range(steps):
            prev = reg
            x, v, dx, dv, reg = kink_step(reg, alpha, twomu, kc, ramp, fc, t0 + j * h, h, x, v,
                                          dx, dv)  # fmt: skip
            squared = dx * dx + dv * dv
            if squared < TANGENT_FLOOR or squared > 1.0 / TANGENT_FLOOR:  # a long block (the
                scale = math.sqrt(squared)  # settling at low speed) would under- or overflow
                grown += math.log(scale)
                dx /= scale
                dv /= scale
            K = ramp_forcing_at(t0 + (j + 1) * h, kc, ramp, fc)[0]
            force = K * region_force(reg, alpha, x)[0] + twomu * v
            tally = tallied(tally, reg, prev, x, force)
        nrm = math.sqrt(dx * dx + dv * dv)
        dx /= nrm
        dv /= nrm
        if not (abs(x) < bound and abs(v) < bound):
            state[0], state[1], state[2], state[3] = x, v, dx, dv
            return out, n
        write_block(out[n], tally, grown + math.log(nrm))
    state[0], state[1], state[2], state[3] = x, v, dx, dv
    return out, n_blocks
