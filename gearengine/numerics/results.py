"""Result documents of the numerical verdict (the ``numerics`` part of /v1/analyses, and the
points of a sweep)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, PrivateAttr

from gearengine.model.answers import FiniteAnswer
from gearengine.signals.nolds_check import NoldsResult

BATCH_POINCARE = 64
"""Strobes returned per point by ``simulate_batch``."""


class SpectrumPeak(FiniteAnswer):
    """One peak of the amplitude spectrum of x."""

    frequency: float = Field(description="Angular frequency, rad per unit tau.")
    amplitude: float = Field(description="Amplitude of x at that frequency (units of b).")
    order: float = Field(
        description="frequency / Omega_0 (or / fastest excitation frequency if incommensurate)."
    )


class TimeHistory(FiniteAnswer):
    """Decimated samples of the last recorded intervals."""

    t: list[float] = Field(description="Dimensionless time tau.")
    x: list[float] = Field(description="Displacement x (units of b).")
    v: list[float] = Field(description="Velocity x'.")


class StartSummary(FiniteAnswer):
    """Verdict for one initial state."""

    initial_state: list[float]
    classification: str
    period: int | None
    lle: float | None
    lle_stderr: float | None
    impact_regime: str | None
    final_state: list[float] | None


Bifurcation = Literal["period_doubling", "fold", "neimark_sacker"]
"""How a Floquet multiplier leaves the unit circle: through -1, through +1, or as a complex pair."""


class FloquetResult(FiniteAnswer):
    """Floquet analysis of one periodic orbit of period n T0, Newton-refined by shooting
    (``numerics.floquet``; docs/floquet.md)."""

    period: int = Field(description="Period n of the orbit, in sampling intervals T0.")
    steps_per_period: int = Field(description="RK4 steps N per T0 used for the flow and Phi.")
    multipliers: list[list[float]] = Field(
        description="Floquet multipliers (eigenvalues of the monodromy matrix Phi) "
        "[[re, im], [re, im]], largest modulus first."
    )
    stability_margin: float = Field(
        description="1 - max |lambda|: > 0 stable, < 0 unstable; distance to the unit circle."
    )
    nearest_bifurcation: Bifurcation = Field(
        description="Where the dominant multiplier points now (not a prediction along a "
        "parameter path): period_doubling (real, negative: would leave through -1), fold "
        "(real, positive: through +1), neimark_sacker (complex pair; impossible for Eq. 9 with "
        "constant damping, see notes)."
    )
    orbit_state: list[float] = Field(description="Refined orbit state [x, v] at t = 0 mod T0.")
    orbit_residual: float = Field(description="|phi_{n T0}(X) - X| at the refined state X.")
    newton_steps: int = Field(description="Newton updates applied to the initial state.")
    converged: bool = Field(description="orbit_residual < 1e-11 max(1, |X|).")
    liouville_error: float = Field(
        description="|det Phi - exp(-2 mu n T0)| / exp(-2 mu n T0): the RK4 error of Phi."
    )
    notes: list[str] = Field(description="Remarks on the result.")


class Attractor(FiniteAnswer):
    """One attractor found from the basin starts (``numerics.attractors``, docs/basins.md)."""

    label: str = Field(
        description="How the gate and the summary name it: 'periodic 1T, teeth always in contact', "
        "'chaotic, back-flank impacts'.",
        examples=["chaotic, back-flank impacts"],
    )
    classification: str = Field(description="periodic | chaotic | quasi_periodic.")
    period: int | None = Field(description="Period in units of T0, null if not periodic.")
    lle: float | None = Field(description="Mean LLE of the starts that reached it, per unit tau.")
    lle_stderr: float | None = Field(description="Standard error of that mean.")
    impact_regime: str | None = Field(
        description="no_impact | single_sided | double_sided (the worst seen on the attractor)."
    )
    x_peak_to_peak: float | None = Field(description="Largest max x - min x seen (units of b).")
    dte_um: float | None = Field(
        None, description="With a design: dynamic transmission error peak to peak [µm]."
    )
    dynamic_factor: float | None = Field(
        None, description="With a design: largest mesh force / static force."
    )
    force_max_n: float | None = Field(
        None, description="With a design: largest mesh force of the model seen on it [N]."
    )
    force_min_n: float | None = Field(
        None,
        description="With a design: smallest mesh force of the model seen on it [N] "
        "(negative: back-flank contact, or the damping term while apart).",
    )
    fraction: float = Field(description="count / basins.starts: the basin fraction.")
    interval: list[float] = Field(
        description="95 % Wilson score interval [low, high] of the fraction "
        "(scipy.stats.binomtest(count, starts).proportion_ci)."
    )
    count: int = Field(description="Starts that reached it.")
    start: list[float] = Field(description="One start [x0, v0] that reached it (dimensionless).")
    strobes: list[list[float]] = Field(
        description="Its stroboscopic orbit [[x, v], ...]: the n points of a period-n orbit, "
        "else the representative start's last strobes (<= 64)."
    )


class FromAttractor(FiniteAnswer):
    """The attractor a shown magnitude comes from (``numerics.attractors.most_adverse``)."""

    attractor: int = Field(
        description="Its index in attractors (worst first, from 0; the CSV's attractor_K_ columns)."
    )
    label: str = Field(description="Its label, as attractors[attractor].label.")
    classification: str = Field(description="periodic | chaotic | quasi_periodic.")
    fraction: float = Field(description="Its basin fraction.")


class WorstValue(FromAttractor):
    """A magnitude's most adverse value over the attractors above basins.min_fraction, with
    the attractor it comes from."""

    value: float = Field(description="The value, in unit.")
    unit: str = Field(description="Its unit: um, 1, N.")


class BasinCounts(FiniteAnswer):
    """How the basin starts ended (``settings.basins``)."""

    starts: int = Field(description="Initial states run.")
    diverged: int = Field(description="Starts whose state left the divergence bound.")
    unsettled: int = Field(
        description="Starts with neither a period <= 64 nor a positive LLE under commensurate "
        "forcing: an unfinished transient or a longer period (more transient_periods decide)."
    )
    labels: list[int] = Field(
        description="Per start, in the order of settings.basins: the index of its attractor "
        "in attractors, -1 diverged, -2 unsettled."
    )
    grid: list[int] | None = Field(
        description="[nx, nv] of a grid of starts (x fastest); null for random draws."
    )
    box: list[list[float]] = Field(
        description="The box of the starts, dimensionless: [[xmin, xmax] in half backlashes b, "
        "[vmin, vmax] in b omega_n]."
    )
    box_um_mm_s: list[list[float]] | None = Field(
        None,
        description="With a design: the same box in gear units, [[xmin, xmax] µm (x b), "
        "[vmin, vmax] mm/s (v b omega_n)]; null for dimensionless params.",
    )


class RunLength(FiniteAnswer):
    """How long one part of a run (the transient or the record) lasted, and why it stopped."""

    periods: int = Field(description="Intervals T0 (Poincare periods).")
    mesh_periods: float = Field(
        description="The same time in periods of the fastest excitation (the mesh)."
    )
    tau: float = Field(description="The same time in dimensionless time tau.")
    seconds: float | None = Field(
        None, description="The same time in seconds (null without a design's time scale)."
    )
    reason: str = Field(
        description="Why it stopped. Transient: settled | transient_extended | cap | "
        "diverged | fixed; record: period | lle_stderr | cap | diverged | fixed "
        "(numerics.physical)."
    )


class NumericsResult(FiniteAnswer):
    """Numerical verdict. Detailed fields describe the worst-case start (``worst_case``)."""

    classification: str = Field(
        description="periodic | chaotic | quasi_periodic | diverged: the worst of the settings' "
        "own starts. With settings.basins the design's verdict is the worst attractor's "
        "(verdict.decided_by, verdict.chaotic): this field, worst_case, floquet and the "
        "records below stay the settings' start's answer (notes says so)."
    )
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
    force_max: float | None = Field(
        None,
        description="Largest dimensionless mesh force K(t) f_h(x) + 2 mu x' over the record's "
        "steps (the kernel's extremes, as a sweep point's); null if diverged.",
    )
    force_min: float | None = Field(
        None, description="Smallest dimensionless mesh force over the record; null if diverged."
    )
    spectrum_peaks: list[SpectrumPeak] = Field(description="Largest peaks of the spectrum of x.")
    poincare: list[list[float]] = Field(description="Last strobes [[x, v], ...] (<= 256).")
    time_history: TimeHistory | None = Field(description="Last 20 intervals, <= 2000 samples.")
    nolds: NoldsResult | None = Field(description="nolds.lyap_r cross-check, if requested.")
    steps_per_forcing_period: int = Field(description="RK4 steps per sampling interval.")
    method: str = Field(description="Integrator used.")
    starts: list[StartSummary] = Field(description="One verdict per initial state.")
    worst_case: StartSummary = Field(
        description="The worst of the settings' own starts (not the basins' attractors: with "
        "settings.basins the verdict is verdict.decided_by's)."
    )
    notes: list[str] = Field(description="Remarks on choices and limitations.")
    floquet: FloquetResult | None = Field(
        None,
        description="Floquet multipliers and stability margin of the worst settings' start's "
        "periodic orbit (with settings.basins not necessarily the deciding attractor's); "
        "null when the response is not periodic, the forcing has no common period or Newton "
        "shooting did not converge (floquet_note says which).",
    )
    floquet_note: str | None = Field(None, description="Why floquet is null; else null.")
    transient: RunLength | None = Field(
        None, description="How long the worst start's transient ran and why it stopped."
    )
    record: RunLength | None = Field(
        None, description="How long the worst start's record ran and why it stopped."
    )
    attractors: list[Attractor] | None = Field(
        None,
        description="With settings.basins: every distinct attractor found, worst first; "
        "null without.",
    )
    basins: BasinCounts | None = Field(
        None, description="With settings.basins: the starts, and those that diverged or did "
        "not settle.",
    )  # fmt: skip


class BatchPoint(FiniteAnswer):
    """Verdict of ``simulate_batch`` for one parameter point (its worst start)."""

    classification: str
    period: int | None
    lle: float | None
    lle_stderr: float | None
    final_state: list[float] | None
    impact_regime: str | None = Field(description="no_impact | single_sided | double_sided.")
    poincare: list[list[float]] = Field(
        description=f"Last <= {BATCH_POINCARE} strobes; empty when only their x was asked for "
        "(poincare_x)."
    )
    poincare_x: list[float] | None = Field(
        None,
        description="x of the last strobes when only those were asked for (``x_only`` of "
        "``simulate_batch``: a map's points), else null.",
    )
    start_index: int = Field(description="Index of the worst start in settings.starts().")
    x_peak_to_peak: float | None = Field(
        None, description="max x - min x over the record (units of b), null if diverged."
    )
    periods_run: int | None = Field(
        None,
        description="Intervals T0 the reported start actually ran: transient_periods + "
        "record_periods, fewer when it stopped early (adaptive) or diverged.",
    )
    force_max: float | None = Field(
        None,
        description="Largest dimensionless mesh force K(t) f_h(x) + 2 mu x' over the record's "
        "step ends; null if diverged.",
    )
    force_min: float | None = Field(
        None, description="Smallest dimensionless mesh force over the record; null if diverged."
    )
    _record: int | None = PrivateAttr(None)
    """Which record of its kernel call the numbers are (``batch.physical_lanes`` numbers every
    record; the basin starts of a point joined to one cycle share one), None outside physical
    time: estimates from one record are one estimate (``attractors``' LLE statistics). The
    numbers are per call, and all of a point's lanes are in one call."""
