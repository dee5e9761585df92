"""POST /v1/conversions/physical: physical gear data to the dimensionless model."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request, Response

from gearengine.jsonio import dumps
from gearengine.model.conversion import Conversion, PhysicalGearData, to_dimensionless
from service.api.deps import cached_compute, require_key
from service.api.responses import JSON, PROBLEMS

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])


@router.post(
    "/conversions/physical",
    response_model=Conversion,
    responses=PROBLEMS,
    summary="Physical gear data to the dimensionless parameters of Eq. (9)",
)
async def post_conversion(body: PhysicalGearData, request: Request) -> Response:
    """Inertias, radii, teeth, speed, stiffness, damping, backlash, torques and transmission
    error (SI units) to the dimensionless model, with m, omega_n and the time scale."""
    return await cached_compute(
        request,
        "conversion",
        body.model_dump_json(),
        lambda: (dumps(to_dimensionless(body)).encode(), JSON),
    )
