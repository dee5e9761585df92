"""Result documents of a sweep: one ``SweepPoint`` per grid point and branch, and the whole
``SweepResult`` (the /v1/sweeps/{id}/result contract)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from gearengine.sweeps.request import SweepAxis, SweepBranch


class SweepPoint(BaseModel):
    """Numerical and Melnikov verdicts of one point of the sweep."""

    model_config = ConfigDict(frozen=True, allow_inf_nan=False)

    values: dict[str, float] = Field(
        description="The axes' parameter values at this point.", examples=[{"F_e1": 0.2}]
    )
    branch: SweepBranch | None = Field(
        description="With continuation: up (forward) or down (backward) branch; else null."
    )
    classification: str = Field(description="periodic | chaotic | quasi_periodic | diverged.")
    period: int | None = Field(description="Period in units of T0, null if none found.")
    lle: float | None = Field(description="Largest Lyapunov exponent per unit tau.")
    lle_stderr: float | None = Field(description="Standard error of lle.")
    impact_regime: str | None = Field(
        description="no_impact | single_sided | double_sided, null when not reported."
    )
    melnikov_chaos_possible: bool | None = Field(
        description="Melnikov verdict at this point; null when not applicable (a or c <= 0)."
    )
    poincare_x: list[float] = Field(description="x of the last stroboscopic points (units of b).")


class SweepResult(BaseModel):
    """All points of a sweep, in chunk order (first axis fastest; branch up before down)."""

    model_config = ConfigDict(frozen=True)

    axes: list[SweepAxis] = Field(description="The axes of the request.")
    points: list[SweepPoint] = Field(description="One entry per point and branch.")
