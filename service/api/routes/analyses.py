"""POST /v1/analyses, /v1/analyses/plot and /v1/analyses/basins/plot: the numerical verdict
next to the Melnikov verdict, its figure, and the basin picture of its attractors;
/v1/analyses/campbell and /v1/analyses/campbell/plot: a gear train's modes and Campbell
diagram."""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

from fastapi import APIRouter, Depends, Request, Response

from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
from gearengine.jsonio import dumps
from gearengine.numerics.settings import BasinSettings
from gearengine.plots import MEDIA_TYPES, analysis_figure, basins_figure, campbell_figure
from gearengine.systems.gear_train.campbell import Campbell, CampbellRequest, campbell
from service.api.deps import AppLimits, AppMetrics, cached_compute, require_key
from service.api.responses import CACHED, IMAGE_RESPONSES, JSON, FormatQuery, image_format
from service.limits import BASINS_HINT, Limits
from service.metrics import Metrics

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])


def check_analysis_budget(limits: Limits, body: AnalysisRequest) -> None:
    """422 before any compute when the analysis (its starts and basin starts) is over the
    synchronous budget; names settings.basins.starts when basins are asked for. The work is
    that of the request's system (``AnalysisRequest.work``: a train counts its own steps,
    raised for stiff shafts and bearings, at their cost), on the step plan the request made
    when validated and hands to ``analyze``."""
    if body.settings.basins is None:
        limits.check_budget(body.work)
    else:
        limits.check_budget(body.work, hint=BASINS_HINT, field="settings.basins.starts")


def _analysis(metrics: Metrics, body: AnalysisRequest) -> AnalysisResult:
    result = analyze(body)
    metrics.analyses.labels(result.numerics.classification).inc()
    return result


async def _figure(
    request: Request,
    body: AnalysisRequest,
    limits: Limits,
    metrics: Metrics,
    fmt: Literal["png", "svg"],
    route: str,
    draw: Callable[[AnalysisResult, Literal["png", "svg"]], bytes],
) -> Response:
    """A figure of the analysis of ``body``: budget checked first, then cached by route."""
    check_analysis_budget(limits, body)
    return await cached_compute(
        request,
        f"{route}.{fmt}",
        body.model_dump_json(),
        lambda: (draw(_analysis(metrics, body), fmt), MEDIA_TYPES[fmt]),
    )


@router.post(
    "/analyses",
    response_model=AnalysisResult,
    responses=CACHED,
    summary="Melnikov and numerical verdicts of one design",
)
async def post_analysis(
    body: AnalysisRequest, request: Request, limits: AppLimits, metrics: AppMetrics
) -> Response:
    """Integrates Eq. (9) with RK4 and its tangent equation: period from Poincaré sections,
    largest Lyapunov exponent (Benettin), classification, gear diagnostics, and whether the
    result agrees with the Melnikov verdict. Work above the synchronous budget is refused with
    422; submit it to `/v1/sweeps`."""
    check_analysis_budget(limits, body)
    return await cached_compute(
        request,
        "analyses",
        body.model_dump_json(),
        lambda: (dumps(_analysis(metrics, body)).encode(), JSON),
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
    limits: AppLimits,
    metrics: AppMetrics,
    format: Literal["png", "svg"] | None = FormatQuery,
) -> Response:
    """The paper's Figs. 7-11 for any design: (a) time history, (b) phase plane with the
    Poincaré points, (c) Poincaré section, (d) amplitude spectrum."""
    fmt = image_format(request, format)
    return await _figure(request, body, limits, metrics, fmt, "analyses/plot", analysis_figure)


@router.post(
    "/analyses/basins/plot",
    response_class=Response,
    responses=IMAGE_RESPONSES,
    summary="Basin picture of a design: the starts (x, v) coloured by the attractor they reach",
)
async def post_basins_plot(
    body: AnalysisRequest,
    request: Request,
    limits: AppLimits,
    metrics: AppMetrics,
    format: Literal["png", "svg"] | None = FormatQuery,
) -> Response:
    """The plane of initial states coloured by attractor, each attractor's strobes on top and
    its basin fraction with a 95 % interval in the legend; axes in µm and mm/s for a design.
    Without `settings.basins` the default basin settings are used (16 starts)."""
    if body.settings.basins is None:
        settings = body.settings.model_copy(update={"basins": BasinSettings()})
        body = body.model_copy(update={"settings": settings})
    fmt = image_format(request, format)
    return await _figure(request, body, limits, metrics, fmt, "analyses/basins/plot",
                         basins_figure)  # fmt: skip


@router.post(
    "/analyses/campbell",
    response_model=Campbell,
    responses=CACHED,
    summary="Modes and Campbell diagram of a gear train (a design with `train`)",
)
async def post_campbell(body: CampbellRequest, request: Request) -> Response:
    """Natural frequencies, damping ratios, mode shapes and mesh strain-energy shares of the
    train linearised in contact, the excitation order lines (mesh, shafts, torque fluctuation)
    and their crossings with the modes in rpm over the design's `speed_range`."""
    return await cached_compute(
        request,
        "analyses/campbell",
        body.model_dump_json(),
        lambda: (dumps(campbell(body)).encode(), JSON),
    )


@router.post(
    "/analyses/campbell/plot",
    response_class=Response,
    responses=IMAGE_RESPONSES,
    summary="Campbell diagram of a gear train as PNG or SVG",
)
async def post_campbell_plot(
    body: CampbellRequest, request: Request, format: Literal["png", "svg"] | None = FormatQuery
) -> Response:
    """Natural frequencies against driver speed, the order lines, and the crossings marked in
    rpm (the mesh mode bold, the design speed and the mesh resonance as vertical lines)."""
    fmt = image_format(request, format)
    return await cached_compute(
        request,
        f"analyses/campbell/plot.{fmt}",
        body.model_dump_json(),
        lambda: (campbell_figure(campbell(body), fmt), MEDIA_TYPES[fmt]),
    )
