"""Cross-check of the largest Lyapunov exponent from the sampled x(t) alone.

Method: M. T. Rosenstein, J. J. Collins, C. J. De Luca, "A practical method for calculating
largest Lyapunov exponents from small data sets", Physica D 65 (1993) 117-134, as implemented by
``nolds.lyap_r`` (C. Schölzel, nolds, doi:10.5281/zenodo.3814723).

``nolds.lyap_r`` embeds the scalar series, follows nearest neighbours and fits the mean log
divergence. Parameters are chosen from the signal:

* the series is decimated to about ``SAMPLES_PER_PERIOD`` samples per mean period (2 pi over the
  dominant angular frequency of the spectrum) and cut to the last ``MAX_POINTS`` samples;
* lag = first zero crossing of the autocorrelation (first drop below 1/e if there is none),
  capped at a quarter of the mean period (the zero of a pure oscillation's autocorrelation; slow
  drifts of chaotic gear responses otherwise push the lag far beyond it and nolds then
  underestimates the exponent by a factor ~3 on the paper's Fe = 0.25 case);
* min_tsep = one mean period in samples (neighbours must be at least that far apart in time);
* trajectory_len = ``TRAJECTORY_PERIODS`` mean periods; emb_dim = ``EMB_DIM``; fit = "poly".

nolds returns the slope per sample; with tau = sample spacing it is per unit time.
An exactly periodic orbit makes nolds return -inf (log of zero distances): the value is then
reported as None with a note. Slow (O(n^2) in the number of points), so off by default.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

SAMPLES_PER_PERIOD = 16
MAX_POINTS = 3000
EMB_DIM = 6
TRAJECTORY_PERIODS = 2


class NoldsResult(BaseModel):
    """Outcome of the nolds.lyap_r cross-check."""

    model_config = ConfigDict(frozen=True)

    lle: float | None = Field(description="LLE per unit dimensionless time, or null.")
    emb_dim: int = Field(description="Embedding dimension.")
    lag: int = Field(description="Embedding lag, samples.")
    min_tsep: int = Field(description="Minimal temporal separation of neighbours, samples.")
    trajectory_len: int = Field(description="Length of the divergence fit, samples.")
    sample_interval: float = Field(description="Time between samples of the series, tau units.")
    n_points: int = Field(description="Number of samples used.")
    notes: list[str] = Field(default_factory=list)


def first_decorrelation(x: np.ndarray) -> int:
    """Lag (samples, >= 1) of the first zero of the autocorrelation, else of its first 1/e drop."""
    y = x - x.mean()
    ac = np.correlate(y, y, mode="full")[y.size - 1 :]
    if not ac[0] > 0.0:
        return 1
    ac = ac / ac[0]
    for threshold in (0.0, 1.0 / math.e):
        below = np.flatnonzero(ac <= threshold)
        if below.size:
            return max(1, int(below[0]))
    return 1


def lyap_r_check(x: np.ndarray, dt: float, omega_dominant: float) -> NoldsResult:
    """Run nolds.lyap_r on samples x (shape (n,), spacing dt) with parameters from the signal.

    Args:
        x: samples of x(t) over the record.
        dt: sample spacing, time units.
        omega_dominant: dominant angular frequency of x (rad per unit time), > 0.
    """
    import nolds  # ~0.08 s to import (it loads pkg_resources); only this opt-in check needs it

    decim = max(1, round(2.0 * math.pi / omega_dominant / dt / SAMPLES_PER_PERIOD))
    series = x[::decim][-MAX_POINTS:]
    step = decim * dt
    per = max(2, round(2.0 * math.pi / omega_dominant / step))
    lag = min(first_decorrelation(series), max(1, round(per / 4)))
    traj = TRAJECTORY_PERIODS * per
    notes: list[str] = []
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        value = float(
            nolds.lyap_r(
                series,
                emb_dim=EMB_DIM,
                lag=lag,
                min_tsep=per,
                tau=step,
                trajectory_len=traj,
                fit="poly",
            )
        )
    lle: float | None = value
    if value == -math.inf:
        lle = None
        notes.append("exact periodic orbit, nolds returned -inf")
    elif not math.isfinite(value):
        lle = None
        notes.append(f"nolds returned {value}")
    return NoldsResult(
        lle=lle,
        emb_dim=EMB_DIM,
        lag=lag,
        min_tsep=per,
        trajectory_len=traj,
        sample_interval=step,
        n_points=int(series.size),
        notes=notes,
    )
