"""POST /v1/melnikov, /v1/conversions/physical, /v1/thresholds: the analytical answers."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request, Response

from gearengine.conversion import Conversion, PhysicalGearData, to_dimensionless
from gearengine.jsonio import dumps
from gearengine.melnikov_analysis import melnikov
from gearengine.melnikov_result import MelnikovResult, ThresholdCurve
from gearengine.requests import MelnikovRequest, ThresholdsRequest
from gearengine.thresholds import threshold_curve
from service.api.deps import cached_compute, require_key
from service.api.responses import JSON, PROBLEMS

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])


@router.post(
    "/melnikov",
    response_model=MelnikovResult,
    responses=PROBLEMS,
    summary="Melnikov verdict, thresholds and margins of one design",
)
async def post_melnikov(body: MelnikovRequest, request: Request) -> Response:
    """Can the stable and unstable manifolds of the saddle intersect transversally?

    Returns both branches' extrema of M(tau0), the threshold of each control parameter with the
    design's margin, and the corrected closed-form (or quadrature) coefficients.
    """
    return await cached_compute(
        request,
        "melnikov",
        body.model_dump_json(),
        lambda: (dumps(melnikov(body.params, method=body.method)).encode(), JSON),
    )


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


@router.post(
    "/thresholds",
    response_model=ThresholdCurve,
    responses=PROBLEMS,
    summary="Threshold curves of a control parameter over a frequency range",
)
async def post_thresholds(body: ThresholdsRequest, request: Request) -> Response:
    """Where each Melnikov branch starts or stops changing sign as a frequency is swept
    (paper Figs. 5, 12, 18): per frequency, the intervals of the parameter without chaos."""
    request.app.state.limits.check_curve(body)
    return await cached_compute(
        request,
        "thresholds",
        body.model_dump_json(),
        lambda: (dumps(curve_of(body)).encode(), JSON),
    )


def curve_of(body: ThresholdsRequest) -> ThresholdCurve:
    return threshold_curve(
        body.params, body.parameter, body.frequency_parameter, body.start, body.stop, body.num
    )
