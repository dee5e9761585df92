"""The documents a run-up returns (``POST /v1/runups`` and ``gearengine runup --json``)."""

from __future__ import annotations

from pydantic import Field

from gearengine.model.answers import Answer


class RunupBin(Answer):
    """What the gear did while its speed crossed one bin (on one branch)."""

    speed_rpm: list[float] = Field(description="[low, high] driver speed of the bin [rpm].")
    time_s: list[float] = Field(description="[first, last] time the profile spent in it [s].")
    dte_peak_to_peak_um: float | None = Field(
        description="Dynamic transmission error b (x_max - x_min) over the bin [µm]."
    )
    force_max_n: float | None = Field(
        description="Largest mesh force of the model [N]: k_m b (K f_h(x) + 2 mu x') at step "
        "ends, whose damping term acts in the clearance too."
    )
    force_min_n: float | None = Field(
        description="Smallest mesh force of the model [N] (negative: back-flank contact, or "
        "the damping term while the teeth are apart)."
    )
    contact_force_max_n: float | None = Field(
        None,
        description="Largest tooth contact force [N]: the model's force where a flank touches "
        "(|x| > 1; drive flank >= 0, back flank <= 0), zero while the teeth are apart.",
    )
    contact_force_min_n: float | None = Field(
        None,
        description="Smallest tooth contact force [N]: 0 in a bin where the teeth separate "
        "without reaching the back flank, negative only with back-flank contact.",
    )
    dynamic_factor: float | None = Field(
        description="Largest mesh force over the mean force F^_m of the moment (torque ramp "
        "and acceleration included)."
    )
    separation_fraction: float | None = Field(
        description="Share of the time with no tooth contact (|x| <= 1)."
    )
    back_flank_fraction: float | None = Field(description="Share of the time on the back flank.")
    contact: str | None = Field(
        description="drive_flank (always in contact), separation (the teeth separate at times, "
        "separation_fraction says how long; the gate's --fail-on separation), both_flanks "
        "(reaches the back flank: back_flank). Was no_contact, which read as never touching."
    )
    back_flank_impacts: int | None = Field(description="Entries onto the back flank.")
    drive_flank_impacts: int | None = Field(
        description="Re-engagements of the drive flank after a separation."
    )
    lle: float | None = Field(
        description="Ensemble-averaged finite-time Lyapunov exponent over the bin, per unit "
        "tau (x 1/time_scale_s for 1/s); null where a member diverged."
    )
    lle_stderr: float | None = Field(
        description="Its standard error: of the rates of every member's blocks in the bin "
        "(members settled on one orbit agree exactly, so the ensemble's spread alone is 0)."
    )
    chaotic: bool | None = Field(
        description="lle > 1e-3 and > 3 lle_stderr (signals.classify's rule)."
    )


class RunupJump(Answer):
    """A sudden change of the response amplitude between neighbouring bins."""

    speed_rpm: float = Field(description="Where it happened: the edge between the two bins.")
    from_um: float = Field(description="DTE before it, in the direction of travel [µm].")
    to_um: float = Field(description="DTE after it [µm].")
    quasi_static_speed_rpm: float | None = Field(
        None, description="The quasi-static jump of the same branch and sense nearest to it."
    )
    lag_rpm: float | None = Field(
        None, description="How far past the quasi-static jump, in the direction of travel, "
        "the ramp jumped [rpm] (positive: later)."
    )  # fmt: skip


class RunupBranch(Answer):
    """One direction of the profile: its bins in the order travelled, and its jumps."""

    bins: list[RunupBin]
    jumps: list[RunupJump]


class QuasiStaticPoint(Answer):
    """The steady state of the continuation sweep at one bin centre."""

    speed_rpm: float
    dte_peak_to_peak_um: float | None
    dynamic_factor: float | None
    classification: str | None
    impact_regime: str | None
    lle: float | None = Field(description="Largest Lyapunov exponent per unit tau.")


class QuasiStaticBranch(Answer):
    """One branch of the hysteresis loop (continuation up or down, in that order)."""

    points: list[QuasiStaticPoint]
    jumps: list[RunupJump]


class QuasiStatic(Answer):
    """The quasi-static answer: the continuation sweep on the bin centres, up and down."""

    up: QuasiStaticBranch
    down: QuasiStaticBranch
    grid_step_rpm: float = Field(description="Spacing of the sweep's speeds [rpm].")
    torque_nm: float = Field(description="Torque of the sweep (the design's) [N m].")


class RunupMethod(Answer):
    """How the run-up was integrated and read, in words and numbers."""

    integration: str
    lyapunov: str
    jumps: str
    ensemble: int
    steps: int = Field(description="RK4 steps of all members.")
    bin_rpm: float


class RunupResult(Answer):
    """A run-up or run-down of a design: bins against speed, jumps, and the quasi-static loop."""

    up: RunupBranch | None
    down: RunupBranch | None
    quasi_static: QuasiStatic
    melnikov_windows_rpm: list[list[float]] = Field(
        description="Speeds [rpm] where the Melnikov criterion allows chaos (design's torque)."
    )
    time_scale_s: float = Field(description="1 / w_n [s]: tau = t / time_scale_s.")
    duration_s: float
    method: RunupMethod
    notes: list[str]
