"""POST /v1/thresholds and /v1/thresholds/plot: Melnikov threshold curves over a frequency."""

from __future__ import annotations

from typing import Literal

from fastapi import APIRouter, Depends, Request, Response

from gearengine.engineering.thresholds import threshold_units
from gearengine.homoclinic import ThresholdCurve
from gearengine.homoclinic.schemas import ThresholdsRequest
from gearengine.homoclinic.thresholds import curve_of
from gearengine.jsonio import dumps
from gearengine.model.aliases import get_alias
from gearengine.plots import MEDIA_TYPES, threshold_figure
from service.api.deps import AppLimits, cached_compute, require_key
from service.api.responses import CACHED, IMAGE_RESPONSES, JSON, FormatQuery, image_format

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])


def _design_frequency(body: ThresholdsRequest) -> float | None:
    """The design's value of the swept frequency: where the figure marks the design."""
    return None if body.params is None else get_alias(body.params, body.frequency_parameter)


@router.post(
    "/thresholds",
    response_model=ThresholdCurve,
    responses=CACHED,
    summary="Threshold curves of a control parameter over a frequency range",
)
async def post_thresholds(body: ThresholdsRequest, request: Request, limits: AppLimits) -> Response:
    """Where each Melnikov branch starts or stops changing sign as a frequency is swept
    (paper Figs. 5, 12, 18): per frequency, the intervals of the parameter without chaos."""
    limits.check_curve(body)
    return await cached_compute(
        request,
        "thresholds",
        body.model_dump_json(),
        lambda: (dumps(curve_of(body)).encode(), JSON),
    )


def figure(body: ThresholdsRequest, fmt: Literal["png", "svg"]) -> bytes:
    """The curves' figure; a design's in gear units (its parameter's unit over the speed)."""
    conv, name, freq = body.conversion, body.parameter, body.frequency_parameter
    units = None if conv is None else threshold_units(conv, name, freq)
    return threshold_figure(curve_of(body), fmt, _design_frequency(body), units)


@router.post(
    "/thresholds/plot",
    response_class=Response,
    responses=IMAGE_RESPONSES,
    summary="Melnikov threshold curves as a figure",
)
async def post_threshold_plot(
    body: ThresholdsRequest,
    request: Request,
    limits: AppLimits,
    format: Literal["png", "svg"] | None = FormatQuery,
) -> Response:
    """The paper's Figs. 5, 12, 18: critical values of the parameter against the frequency,
    the band without chaos shaded, the design's value marked."""
    fmt = image_format(request, format)
    limits.check_curve(body)
    return await cached_compute(
        request,
        f"thresholds/plot.{fmt}",
        body.model_dump_json(),
        lambda: (figure(body, fmt), MEDIA_TYPES[fmt]),
    )
