"""Request documents shared by the CLI and the HTTP API (one definition each)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from gearengine.melnikov import Method
from gearengine.params import GearParams


class MelnikovRequest(BaseModel):
    """``{"params": {...}}``: the Melnikov verdict of one design."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    params: GearParams = Field(description="Dimensionless parameters of Eq. (9).")
    method: Method = Field(
        "closed_form",
        description="closed_form: corrected Eq. (19); quadrature: Eq. (18) integrated numerically.",
    )
