"""Request documents shared by the CLI and the HTTP API (one definition each)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, Field, ValidationInfo, field_validator

from gearengine.melnikov import Method
from gearengine.params import GearParams, request_config

PAPER_SECTION_41 = {
    "damping": 0.07,
    "mean_force": 0.01,
    "backlash": {"model": "cubic", "a": 0.1667, "c": 0.1667},
    "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2, "phase": 0.0}]},
}
"""The paper's section 4.1 design at F~_e1 = 0.2 (Fig. 6), the documented example."""


class MelnikovRequest(BaseModel):
    """``{"params": {...}}``: the Melnikov verdict of one design."""

    model_config = request_config({"params": PAPER_SECTION_41})

    params: GearParams = Field(description="Dimensionless parameters of Eq. (9).")
    method: Method = Field(
        "closed_form",
        description="closed_form: corrected Eq. (19); quadrature: Eq. (18) integrated numerically.",
    )


class ThresholdsRequest(BaseModel):
    """Threshold curves of ``parameter`` while ``frequency_parameter`` runs over a range."""

    model_config = request_config()

    params: GearParams = Field(description="The design; other parameters stay fixed.")
    parameter: Literal["F_e1", "mu", "k_p1", "F_p1"] = Field(
        "F_e1", description="Control parameter whose critical values are traced."
    )
    frequency_parameter: Literal["Omega_e", "Omega_k", "Omega_p"] = Field(
        "Omega_e", description="Frequency swept along the horizontal axis."
    )
    start: float = Field(0.05, gt=0.0, le=1e3, description="First frequency (dimensionless).")
    stop: float = Field(2.5, gt=0.0, le=1e3, description="Last frequency (dimensionless).")
    num: int = Field(100, ge=2, le=100_000, description="Number of frequencies.")

    @field_validator("stop")
    @classmethod
    def _after_start(cls, stop: float, info: ValidationInfo) -> float:
        start = info.data.get("start")
        if start is not None and stop <= start:
            raise ValueError("stop must be greater than start")
        return stop
