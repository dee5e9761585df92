"""POST /v1/analyses and the figures: the numerical verdict next to the Melnikov verdict."""

from __future__ import annotations

from typing import Literal

from fastapi import APIRouter, Depends, Query, Request, Response

from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
from gearengine.jsonio import dumps
from gearengine.plots import MEDIA_TYPES, ImageFormat, analysis_figure, threshold_figure
from gearengine.requests import ThresholdsRequest
from gearengine.simulation import work
from service.api.deps import cached_compute, require_key
from service.api.responses import JSON, PNG, PROBLEMS, SVG
from service.api.routes.melnikov import curve_of

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])

IMAGE_RESPONSES = {
    **PROBLEMS,
    200: {"content": {PNG: {}, SVG: {}}, "description": "The figure as PNG or SVG."},
}
FormatQuery = Query(None, description="png or svg; default from the Accept header, else png.")


def image_format(request: Request, fmt: Literal["png", "svg"] | None) -> ImageFormat:
    """?format= wins; otherwise SVG when the Accept header prefers it, else PNG."""
    if fmt is not None:
        return fmt
    accept = request.headers.get("accept", "")
    return "svg" if SVG in accept and PNG not in accept else "png"


def _analysis(request: Request, body: AnalysisRequest) -> AnalysisResult:
    result = analyze(body)
    request.app.state.metrics.analyses.labels(result.numerics.classification).inc()
    return result


@router.post(
    "/analyses",
    response_model=AnalysisResult,
    responses=PROBLEMS,
    summary="Melnikov and numerical verdicts of one design",
)
async def post_analysis(body: AnalysisRequest, request: Request) -> Response:
    """Integrates Eq. (9) with RK4 and its tangent equation: period from Poincaré sections,
    largest Lyapunov exponent (Benettin), classification, gear diagnostics, and whether the
    result agrees with the Melnikov verdict. Work above the synchronous budget is refused with
    422; submit it to `/v1/sweeps`."""
    request.app.state.limits.check_budget(work(body.params, body.settings))
    return await cached_compute(
        request,
        "analyses",
        body.model_dump_json(),
        lambda: (dumps(_analysis(request, body)).encode(), JSON),
    )


@router.post(
    "/analyses/plot",
    response_class=Response,
    responses=IMAGE_RESPONSES,
    summary="Four-panel figure of an analysis (time history, phase plane, Poincaré, spectrum)",
)
async def post_analysis_plot(
    body: AnalysisRequest,
    request: Request,
    format: Literal["png", "svg"] | None = FormatQuery,
) -> Response:
    """The paper's Figs. 7-11 for any design: (a) time history, (b) phase plane with the
    Poincaré points, (c) Poincaré section, (d) amplitude spectrum."""
    fmt = image_format(request, format)
    request.app.state.limits.check_budget(work(body.params, body.settings))
    return await cached_compute(
        request,
        f"analyses/plot.{fmt}",
        body.model_dump_json(),
        lambda: (analysis_figure(_analysis(request, body), fmt), MEDIA_TYPES[fmt]),
    )


@router.post(
    "/thresholds/plot",
    response_class=Response,
    responses=IMAGE_RESPONSES,
    summary="Melnikov threshold curves as a figure",
)
async def post_threshold_plot(
    body: ThresholdsRequest,
    request: Request,
    format: Literal["png", "svg"] | None = FormatQuery,
) -> Response:
    """The paper's Figs. 5, 12, 18: critical values of the parameter against the frequency,
    the band without chaos shaded, the design's value marked."""
    fmt = image_format(request, format)
    request.app.state.limits.check_curve(body)
    return await cached_compute(
        request,
        f"thresholds/plot.{fmt}",
        body.model_dump_json(),
        lambda: (threshold_figure(curve_of(body), fmt), MEDIA_TYPES[fmt]),
    )
