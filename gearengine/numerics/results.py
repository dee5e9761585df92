"""Result documents of the numerical verdict (the ``numerics`` part of /v1/analyses, and the
points of a sweep)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from gearengine.numerics.nolds_check import NoldsResult

BATCH_POINCARE = 64
"""Strobes returned per point by ``simulate_batch``."""


class _Result(BaseModel):
    model_config = ConfigDict(frozen=True, allow_inf_nan=False)


class SpectrumPeak(_Result):
    """One peak of the amplitude spectrum of x."""

    frequency: float = Field(description="Angular frequency, rad per unit tau.")
    amplitude: float = Field(description="Amplitude of x at that frequency (units of b).")
    order: float = Field(
        description="frequency / Omega_0 (or / fastest excitation frequency if incommensurate)."
    )


class TimeHistory(_Result):
    """Decimated samples of the last recorded intervals."""

    t: list[float] = Field(description="Dimensionless time tau.")
    x: list[float] = Field(description="Displacement x (units of b).")
    v: list[float] = Field(description="Velocity x'.")


class StartSummary(_Result):
    """Verdict for one initial state."""

    initial_state: list[float]
    classification: str
    period: int | None
    lle: float | None
    lle_stderr: float | None
    impact_regime: str | None
    final_state: list[float] | None


class NumericsResult(_Result):
    """Numerical verdict. Detailed fields describe the worst-case start (``worst_case``)."""

    classification: str = Field(description="periodic | chaotic | quasi_periodic | diverged.")
    period: int | None = Field(description="Period in units of T0, null if none found.")
    forcing_period: float | None = Field(description="T0 = 2 pi / Omega_0, null if none.")
    sampling_interval: float = Field(description="Interval between strobes, tau units.")
    lle: float | None = Field(description="Largest Lyapunov exponent per unit tau (Benettin).")
    lle_stderr: float | None = Field(description="Standard error of lle from 10 blocks.")
    lle_first_half: float | None = Field(description="lle over the first half of the record.")
    lle_converged: bool = Field(description="First half and whole record agree.")
    impact_regime: str | None = Field(description="no_impact | single_sided | double_sided.")
    x_rms: float | None = Field(description="sqrt(mean x^2) over the record.")
    x_peak_to_peak: float | None = Field(description="max x - min x over the record.")
    spectrum_peaks: list[SpectrumPeak] = Field(description="Largest peaks of the spectrum of x.")
    poincare: list[list[float]] = Field(description="Last strobes [[x, v], ...] (<= 256).")
    time_history: TimeHistory | None = Field(description="Last 20 intervals, <= 2000 samples.")
    nolds: NoldsResult | None = Field(description="nolds.lyap_r cross-check, if requested.")
    steps_per_forcing_period: int = Field(description="RK4 steps per sampling interval.")
    method: str = Field(description="Integrator used.")
    starts: list[StartSummary] = Field(description="One verdict per initial state.")
    worst_case: StartSummary = Field(description="The worst start.")
    notes: list[str] = Field(description="Remarks on choices and limitations.")


class BatchPoint(_Result):
    """Verdict of ``simulate_batch`` for one parameter point (its worst start)."""

    classification: str
    period: int | None
    lle: float | None
    lle_stderr: float | None
    final_state: list[float] | None
    impact_regime: str | None = Field(description="no_impact | single_sided | double_sided.")
    poincare: list[list[float]] = Field(description=f"Last <= {BATCH_POINCARE} strobes.")
    start_index: int = Field(description="Index of the worst start in settings.starts().")
