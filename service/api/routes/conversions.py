"""POST /v1/conversions/design and /v1/conversions/physical: physical gear data to the
dimensionless model."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request, Response

from gearengine.analysis import DesignReport, DesignRequest, convert
from gearengine.jsonio import dumps
from gearengine.model.conversion import Conversion, PhysicalGearData, to_dimensionless
from service.api.deps import cached_compute, require_key
from service.api.responses import CACHED, JSON

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])


@router.post(
    "/conversions/physical",
    response_model=Conversion,
    responses=CACHED,
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


@router.post(
    "/conversions/design",
    response_model=DesignReport,
    responses=CACHED,
    summary="A design in physical units: its parameters, derived quantities and engineering block",
)
async def post_design_conversion(body: DesignRequest, request: Request) -> Response:
    """Gear data with units ("1500 rpm", "50 um", "iso6336" stiffness from the geometry) to
    the dimensionless parameters of Eq. (9), every derived quantity with its source, and the
    Melnikov answer in gear units (speed windows in rpm, thresholds and margins)."""
    return await cached_compute(
        request,
        "conversion/design",
        body.model_dump_json(),
        lambda: (dumps(convert(body)).encode(), JSON),
    )
