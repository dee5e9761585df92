"""POST /v1/melnikov: the Melnikov verdict of one design."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request, Response

from gearengine.homoclinic import MelnikovRequest, MelnikovResult, melnikov
from gearengine.jsonio import dumps
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
