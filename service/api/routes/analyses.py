"""POST /v1/analyses and /v1/analyses/plot: the numerical verdict next to the Melnikov verdict."""

from __future__ import annotations

from typing import Literal

from fastapi import APIRouter, Depends, Request, Response

from gearengine import plots  # its figures load matplotlib on first use, not at start-up
from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
from gearengine.jsonio import dumps
from gearengine.numerics import work
from service.api.deps import cached_compute, require_key
from service.api.responses import CACHED, IMAGE_RESPONSES, JSON, FormatQuery, image_format

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])


def _analysis(request: Request, body: AnalysisRequest) -> AnalysisResult:
    result = analyze(body)
    request.app.state.metrics.analyses.labels(result.numerics.classification).inc()
    return result


@router.post(
    "/analyses",
    response_model=AnalysisResult,
    responses=CACHED,
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
        lambda: (plots.analysis_figure(_analysis(request, body), fmt), plots.MEDIA_TYPES[fmt]),
    )
