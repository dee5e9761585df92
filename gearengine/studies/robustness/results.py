"""The documents a robustness study answers with: per operating point the probability of each
class and event with its Clopper-Pearson interval and sample count, the DTE's spread, the Sobol
indices in numbers and words; and what the sampling and the model assume (``ASSUMPTIONS``)."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, Field

from gearengine.numerics.settings import SimulationSettings


class Probability(BaseModel):
    """k of n samples, with the Clopper-Pearson 95 % interval."""

    value: float | None = Field(description="k / n (null without samples).")
    interval: list[float] | None = Field(description="95 % interval [low, high].")
    count: int = Field(description="Samples k with the outcome.")
    samples: int = Field(description="Samples n counted.")


class RobustnessPoint(BaseModel):
    """The answer at one operating point."""

    values: dict[str, float] = Field(description="The axes' values (SI).")
    shown: dict[str, float] = Field(description="The axes' values in gear units (rpm, N*m).")
    samples: int = Field(description="Samples counted at this point.")
    probabilities: dict[str, Probability] = Field(
        description="Of each class (periodic, quasi_periodic, chaotic, diverged) and event "
        "(separation: the teeth separate, drive-flank or back-flank impacts, as the gate's "
        "--fail-on separation; back_flank: back-flank impacts, as --fail-on back_flank; "
        "dynamic_factor_above_limit; melnikov_chaos_possible)."
    )
    dte_um: dict[str, float | None] = Field(description="DTE over the samples: mean, p5, p95.")
    sensitivity: dict[str, dict[str, dict[str, float | None]] | None] | None = Field(
        None, description="Sobol indices by output (chaotic, separation, back_flank, dte, "
        "dynamic_factor) and field: first, total, and their 95 % half-widths.",
    )  # fmt: skip
    ranking: list[str] | None = Field(None, description="The indices in plain words.")


class RobustnessVariable(BaseModel):
    path: str = Field(description="The field.")
    distribution: str = Field(description="Its distribution, in words (SI units).")


class RobustnessResult(BaseModel):
    """Probabilities with intervals per operating point, and Sobol indices."""

    points: list[RobustnessPoint]
    samples: int = Field(description="Samples N requested.")
    seed: int
    variables: list[RobustnessVariable] = Field(description="The toleranced fields.")
    partial: bool = Field(False, description="True when chunks are missing.")
    model: list[str] = Field(description="What the sampling and the TE model assume.")
    values_units: dict[str, str] | None = Field(
        None, description="The unit of each axis in the points' values (SI: speed rad/s).",
        examples=[{"speed": "rad/s", "torque": "N*m"}],
    )  # fmt: skip
    shown_units: dict[str, str] | None = Field(
        None, description="The unit of each axis in the points' shown values (speed rpm).",
        examples=[{"speed": "rpm", "torque": "N*m"}],
    )  # fmt: skip
    settings: SimulationSettings | None = Field(None, description="The settings every run used.")
    dynamic_factor_limit: float = Field(
        1.5, description="The event dynamic_factor_above_limit: the largest dynamic mesh force "
        "above this many times the static force (the request's)."
    )  # fmt: skip
    starts_per_sample: int = Field(
        1, description="Initial states each sample ran: settings.basins' starts (the sample "
        "counts as its worst attractor above basins.min_fraction), else the settings' own "
        "starts (the worst of them)."
    )  # fmt: skip

    def starts_text(self) -> str:
        """ "16 starts a sample (settings.basins)", "1 start a sample": what decided a sample."""
        n = self.starts_per_sample
        basins = " (settings.basins)" if any("settings.basins" in m for m in self.model) else ""
        return f"{n} start{'s' if n != 1 else ''} a sample{basins}"


ASSUMPTIONS = [
    "tolerances vary independently; samples are scrambled Sobol points (seeded) mapped by "
    "each distribution's inverse CDF; intervals are Clopper-Pearson 95 %",
    "ISO 1328 class: the profile deviations drive the mesh-frequency transmission error; one "
    "gear's TE amplitude is at most F_alpha / 2, two gears add as a root-sum-square, and the "
    "amplitude is uniform between 0 and that bound (pitch deviations not modelled)",
    "backlash band: circumferential j_t, b = j_t cos(alpha_wt) / 2, uniform within the band",
    "a sample counts as its worst start (the single analysis' verdict)",
]


SALTELLI_SAMPLES = (
    "with sensitivity the probabilities are counted on the N base rows of SALib's Saltelli "
    "design (its own scrambled Sobol points), not on the N points of the study without "
    "sensitivity: the two give different samples, so their probabilities differ, within their "
    "intervals"
)
"""The model line of a study with ``sensitivity``: where its probabilities come from."""


def basin_assumption(basins: Any) -> str:
    """The model line of a study with ``settings.basins``: how a sample is decided."""
    return (f"with settings.basins a sample counts as its worst attractor whose basin fraction "
            f"is above {basins.min_fraction:g} (its class and contact; its DTE and dynamic "
            f"factor the largest over those attractors), found from {basins.starts} basin "
            "starts per sample (the gate's and the sweep's verdict of a point)")  # fmt: skip
