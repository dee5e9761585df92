"""The points of a sweep's result: one ``SweepPoint`` per grid point and branch, its physical
values, the located bifurcations and the speed windows (``results.SweepResult`` holds them)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, SerializerFunctionWrapHandler, model_serializer

from gearengine.numerics.results import Attractor, BasinCounts, FromAttractor
from gearengine.studies.sweep.request import SweepBranch


class PhysicalValue(BaseModel):
    """A value with its unit."""

    model_config = ConfigDict(frozen=True, allow_inf_nan=False)

    value: float
    unit: str


BASIN_FIELDS = (
    "attractors",
    "basins",
    "coexisting",
    "decided_by",
    "decided_fraction",
    "magnitudes_from",
)
"""Point fields that exist only with settings.basins (left out of a point without them)."""


class SweepPoint(BaseModel):
    """Numerical and Melnikov verdicts of one point of the sweep."""

    model_config = ConfigDict(frozen=True, allow_inf_nan=False)

    values: dict[str, float] = Field(
        description="The axes' parameter values at this point: a design's fields in SI "
        "(speed in rad/s, torque in N*m; the result's values_units names each, physical has "
        "them in display units), dimensionless aliases as they are.",
        examples=[{"F_e1": 0.2}],
    )
    branch: SweepBranch | None = Field(
        description="With continuation: up (forward) or down (backward) branch; else null."
    )
    classification: str | None = Field(
        None,
        description="periodic | chaotic | quasi_periodic | diverged; with settings.basins the "
        "worst attractor's above basins.min_fraction (decided_by names it; period, lle, "
        "lle_stderr and impact_regime are its too; physical's dte, dynamic_factor, force_max "
        "and force_min are the most adverse over those attractors, magnitudes_from names "
        "each one's). This "
        "and every field below are left out of the stored and returned points that a "
        "sweep's outputs do not name (null when read back into this model).",
    )
    period: int | None = Field(None, description="Period in units of T0, null if none found.")
    lle: float | None = Field(None, description="Largest Lyapunov exponent per unit tau.")
    lle_stderr: float | None = Field(None, description="Standard error of lle.")
    impact_regime: str | None = Field(
        None,
        description="no_impact (contact throughout) | single_sided (separation: the teeth "
        "separate, not reaching the back flank) | double_sided (back_flank: back-flank "
        "impacts), the words of --fail-on and P(...) (docs/units.md, Contact words); null when "
        "not reported.",
    )
    melnikov_chaos_possible: bool | None = Field(
        None,
        description="Melnikov verdict at this point; null when not applicable (a or c <= 0).",
    )
    poincare_x: list[float] | None = Field(
        None, description="x of the last stroboscopic points (units of b)."
    )
    x_peak_to_peak: float | None = Field(
        None, description="max x - min x over the record (units of b); null if diverged."
    )
    periods_run: int | None = Field(
        None,
        description="Intervals T0 the point actually ran (fewer than transient + record when "
        "it stopped early, settings.adaptive).",
    )
    force_max: float | None = Field(
        None,
        description="Largest dimensionless mesh force K(t) f_h(x) + 2 mu x' over the record, "
        "in units of b k_m (with a design physical.force_max has it in N); null if diverged.",
    )
    force_min: float | None = Field(
        None, description="Smallest dimensionless mesh force over the record; null if diverged."
    )
    physical: dict[str, PhysicalValue] | None = Field(
        None,
        description="With a design: the physical axes' values in display units (rpm, N*m, "
        "µm, ...), the dynamic transmission error dte (µm peak to peak), the "
        "dynamic_factor (largest mesh force / static force F~_m), and force_max and force_min "
        "in N: the record's (the fields force_max and force_min x b k_m), or with "
        "settings.basins the most adverse over the attractors above basins.min_fraction "
        "(largest dte, dynamic_factor and force_max, smallest force_min; magnitudes_from "
        "names the attractor of each).",
        examples=[{"speed": {"value": 1500.0, "unit": "rpm"}, "torque": {"value": 40.0,
                   "unit": "N*m"}, "dte": {"value": 3.4, "unit": "um"}}],
    )  # fmt: skip
    dimensionless: dict[str, float] | None = Field(
        None,
        description="With physical axes: the point's dimensionless aliases (mu, F_m, F_e1, "
        "Omega_e, ...) after conversion.",
    )
    attractors: list[Attractor] | None = Field(
        None,
        description="With settings.basins: the attractors reached from the point's basin "
        "starts, worst first (as numerics.attractors of an analysis). The verdict fields "
        "(classification, period, lle, lle_stderr, impact_regime) are the worst attractor's "
        "above basins.min_fraction (decided_by names it); physical's dte, dynamic_factor, "
        "force_max and force_min the most adverse over those attractors (magnitudes_from); "
        "the record fields (poincare_x, x_peak_to_peak, force_max, force_min) describe the "
        "worst of settings' own starts.",
    )
    basins: BasinCounts | None = Field(
        None, description="With settings.basins: how the point's basin starts ended."
    )
    coexisting: list[str] | None = Field(
        None,
        description="Continuation with settings.basins: the attractors other than the followed "
        "branch's found at this point, as 'label from NN % of starts'; null otherwise.",
    )

    decided_by: str | None = Field(
        None,
        description="With settings.basins: the attractor (or divergence) that decided the "
        "verdict fields, with its basin fraction: 'chaotic, back-flank impacts from 31 % of "
        "starts'; null without basins (or when no basin is above basins.min_fraction).",
    )
    decided_fraction: float | None = Field(
        None, description="With settings.basins: the basin fraction of decided_by's attractor."
    )
    magnitudes_from: dict[str, FromAttractor] | None = Field(
        None,
        description="With settings.basins and a design: per magnitude of physical (dte, "
        "dynamic_factor, force_max, force_min), the attractor its most adverse value comes "
        "from (index in attractors, label, class, basin fraction): the verdict is the worst "
        "attractor by class, a magnitude the largest (force_min the smallest) over the "
        "attractors above basins.min_fraction, which may be another one.",
    )

    @model_serializer(mode="wrap")
    def _without_absent_basins(self, handler: SerializerFunctionWrapHandler):
        """Leave out ``BASIN_FIELDS`` that are null: a sweep without basins keeps its bytes,
        and the stored, streamed and dumped points agree."""
        data = handler(self)
        for key in BASIN_FIELDS:
            if key in data and data[key] is None:
                del data[key]
        return data


class SweepBifurcation(BaseModel):
    """A bifurcation point located on a line of a continuation sweep (``numerics.bifurcations``):
    where the followed periodic orbit's largest Floquet multiplier crosses the unit circle."""

    model_config = ConfigDict(frozen=True, allow_inf_nan=False)

    parameter: str = Field(description="The swept parameter alias.", examples=["F_e1"])
    value: float | None = Field(
        description="Located parameter value (to 1e-10); null for orbit_lost.",
        examples=[0.2119437371],
    )
    type: Literal["period_doubling", "fold", "neimark_sacker", "orbit_lost"] = Field(
        description="period_doubling (multiplier through -1), fold (+1), neimark_sacker "
        "(complex pair), or orbit_lost (Newton lost the branch without a crossing, e.g. past "
        "a fold; value null)."
    )
    period_before: int = Field(description="Period of the orbit before the point, units of T0.")
    period_after: int | None = Field(
        description="Period of the stable orbit found beyond it; null if none (e.g. chaos)."
    )
    branch: SweepBranch = Field(description="up (start -> stop) or down (stop -> start).")
    bracket: list[float] = Field(description="The two grid values around the point.")
    critical_multiplier: list[float] | None = Field(
        description="The dominant multiplier [re, im] at the point (about [-1, 0] for a "
        "period doubling); null for orbit_lost."
    )
    physical: PhysicalValue | None = Field(
        None,
        description="With a physical axis: the located value in its display unit (the speed "
        "in rpm of a period doubling, say).",
    )


class SpeedWindows(BaseModel):
    """Speed intervals [rpm] at one level of the other axis (or of the whole one-axis sweep)."""

    model_config = ConfigDict(frozen=True)

    level: dict[str, PhysicalValue] = Field(
        description='The other axis at this row, e.g. {"torque": {"value": 40, '
        '"unit": "N*m"}}; empty for a one-axis speed sweep.'
    )
    response: dict[str, list[list[float]]] = Field(
        description="Per response (periodic 1T, periodic 2T, ..., quasi-periodic, chaotic, "
        "diverged): [first, last] speeds [rpm] of each run of grid points."
    )
    contact: dict[str, list[list[float]]] = Field(
        description="Runs of grid speeds by contact, the words of --fail-on and P(...) "
        "(docs/units.md): separation (the teeth apart at some time, on either flank's side) "
        "and back_flank (back-flank impacts, within separation's runs)."
    )
    melnikov: list[list[float]] = Field(
        description="Runs of grid speeds where the Melnikov criterion allows chaos."
    )
    melnikov_not_applicable: list[list[float]] = Field(
        default_factory=list,
        description="Runs of grid speeds where the Melnikov criterion does not apply (the mean "
        "load is above the critical torque: no saddle, no homoclinic orbit; for a gear train "
        "also where no single mode holds 90 % of the mesh strain energy: no one-mode reduction).",
    )
