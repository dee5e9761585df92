"""The result document of a signal reading (``POST /v1/signals``, ``gearengine signal --json``).

Every number is in physical units, named in its field: seconds, hertz, revolutions, the unit
of the values; exponents per second, per revolution and per mesh period.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from gearengine.model.answers import FiniteAnswer

Verdict = Literal["periodic", "quasi_periodic", "chaotic", "stochastic", "undetermined"]


class Record(FiniteAnswer):
    """What was read."""

    samples: int
    sample_rate_hz: float
    duration_s: float
    quantity: str
    unit: str
    rms: float = Field(description="Root mean square about the mean, unit of the values.")
    peak_to_peak: float = Field(description="Unit of the values.")


class Reference(FiniteAnswer):
    """What one cycle is: a mesh period, a revolution, or the series' own fundamental."""

    source: Literal["speed", "tach", "spectrum", "none"]
    shaft_hz: float | None = Field(description="Mean shaft speed, rev/s.")
    shaft_rpm: float | None
    teeth: int | None
    mesh_hz: float | None
    cycle: Literal["mesh_period", "revolution", "fundamental"] | None
    cycle_hz: float | None = Field(description="Cycles per second: the strobe rate.")
    samples_per_cycle: int | None = Field(description="Of the angle-domain (or time) series.")
    cycles: float | None = Field(description="Cycles in the record.")


class SpectrumLine(FiniteAnswer):
    """A line of the amplitude spectrum."""

    frequency_hz: float
    order: float | None = Field(description="Frequency / shaft speed (with a speed or tach).")
    amplitude: float = Field(description="Unit of the values (a sinusoid A gives A).")
    ratio_db: float = Field(description="Height over the local floor, dB.")
    label: str = Field(description="e.g. 'mesh order 18', 'shaft order 1', '1/2 mesh'.")


class Spectrum(FiniteAnswer):
    """Lines and a compact spectrum for the picture (orders with a speed, else Hz)."""

    axis: Literal["order", "frequency_hz"]
    x: list[float] = Field(description="Bin centres (max-pooled to <= 2048 points).")
    amplitude: list[float] = Field(description="Unit of the values.")
    lines: list[SpectrumLine]


class Periodicity(FiniteAnswer):
    """The period found by synchronous averaging."""

    cycles: int | None = Field(description="Period in cycles (null: none up to 64).")
    seconds: float | None
    revolutions: float | None
    unexplained: list[float] = Field(
        description="u_n, n = 1, 2, ...: variance the n-cycle synchronous average leaves."
    )
    threshold: float = Field(
        description="The most a periodic record's average may leave (orders.periodic_bound)."
    )
    noise_share: float = Field(
        description="Share of the variance that is white noise (from the upper half band)."
    )


class EmbeddingReport(FiniteAnswer):
    """The delay embedding chosen."""

    delay_samples: int = Field(description="In the analysed (decimated) series.")
    delay_s: float
    dimension: int
    delay_rule: str
    decimation: int = Field(description="Every q-th sample of the (angle-domain) series.")
    sample_interval_s: float = Field(description="Spacing of the analysed series.")
    mutual_information: list[float] = Field(description="I(T), nats, T = 0, 1, ... samples.")
    false_neighbours: list[float] = Field(description="False fraction, d = 1, 2, ...")
    attractor: list[list[float]] = Field(
        description="The last <= 2000 delay vectors (x_i, x_i+tau, x_i+2 tau), unit of the "
        "values: the reconstructed attractor."
    )


class ZeroOneReport(FiniteAnswer):
    """The 0-1 test for chaos (correlation method)."""

    k: float = Field(description="Median of K_c over the frequencies c: ~0 regular, ~1 chaotic.")
    k_quartiles: list[float]
    k_range: list[float]
    frequencies: int
    points: int
    series: str = Field(description="Which series was tested, and its spacing.")
    spacing_s: float
    path_c: float = Field(description="The c of the (p, q) path.")
    p: list[float] = Field(description="p_c(n), decimated to <= 2000 points.")
    q: list[float]


class LyapunovReport(FiniteAnswer):
    """Largest Lyapunov exponent (Rosenstein)."""

    per_second: float | None
    per_revolution: float | None
    per_mesh_period: float | None
    implementation: str
    points: int
    dimension: int
    delay_s: float
    min_separation_s: float
    fit_range_s: list[float]
    divergence_t_s: list[float]
    divergence: list[float] = Field(description="<ln distance> at each time, ln of unit.")


class SurrogateReport(FiniteAnswer):
    """IAAFT surrogate test of the 0-1 test's series."""

    statistic: str
    value: float
    surrogate_values: list[float]
    p_value: float
    rejected: bool = Field(description="p <= alpha: more deterministic than linear noise.")
    alpha: float
    surrogates: int
    points: int
    method: str


class LeverTrial(FiniteAnswer):
    """The model with one uncertain quantity of the design scaled."""

    quantity: str = Field(description="damping | half_backlash | transmission_error.")
    factor: float = Field(description="Multiplies the design's value.")
    value: str = Field(description="The value tried, with its unit.")
    classification: str | None = Field(description="The model's verdict then (null: refused).")
    matches_signal: bool


class ModelReport(FiniteAnswer):
    """The model's verdict for the design at the signal's speed."""

    speed_rpm: float
    torque_nm: float
    classification: str
    period: int | None = Field(description="In the model's forcing periods.")
    lle_per_second: float | None
    agrees: bool | None = Field(description="Same verdict family (periodic / chaotic) as the "
                                "signal's; null when the signal's is undetermined.")  # fmt: skip
    lines: list[SpectrumLine] = Field(
        description="The model's spectrum lines in orders, amplitudes in µm of relative "
        "displacement (ratio_db 0: the model has no noise floor)."
    )
    sweep: list[LeverTrial] = Field(
        default_factory=list,
        description="When the verdicts disagree: each uncertain quantity halved and doubled.",
    )
    summary: str


class SignalResult(FiniteAnswer):
    """The reading of a recorded series."""

    verdict: Verdict
    summary: str = Field(description="In plain words.")
    evidence: list[str] = Field(description="What decided the verdict.")
    record: Record
    reference: Reference
    spectrum: Spectrum
    periodicity: Periodicity | None
    strobes: list[float] = Field(description="The last <= 512 strobes (unit of the values).")
    embedding: EmbeddingReport | None
    zero_one: ZeroOneReport | None
    lyapunov: LyapunovReport | None
    correlation_dimension: float | None = Field(description="nolds.corr_dim of the embedding.")
    surrogates: SurrogateReport | None
    model: ModelReport | None = None
    notes: list[str]
