"""POST /v1/signals, /v1/signals/upload and /v1/signals/plot: a recorded series read as
periodic, quasi-periodic, chaotic or noise (``gearengine.signals``).

The JSON body is ``SignalRequest``; the upload takes the samples as CSV or text (one value a
line, or columns: the last is read, a first column of increasing times sets the rate) with the
other fields as query parameters. Bad input is a 422 problem naming the field
(``signal.values[3]`` for a NaN, ``signal.sample_rate`` below twice the mesh frequency); a
series longer than ``SYNC_SAMPLES`` is refused before any compute with the budget named and
the job route to use: ``POST /v1/signals/jobs`` reads the same request as a durable job (kind
``signal``, ``gearengine.rig.SIGNAL_JOB``) up to ``MAX_SAMPLES`` and the body limit, with the
generic job routes and the figure of a succeeded reading (``/plot``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any, Literal

from fastapi import APIRouter, Depends, Query, Request, Response

from gearengine.jsonio import dumps
from gearengine.model.errors import InputError
from gearengine.plots import MEDIA_TYPES
from gearengine.rig import read_signal
from gearengine.signals.schema import SignalResult
from gearengine.signals.series import (
    EXAMPLE_VALUES,
    SYNC_SAMPLES,
    Quantity,
    SignalRequest,
    read_table,
)
from service.api.deps import cached_compute, engine_refusal, require_key, response_cache
from service.api.responses import CACHED, IMAGE_RESPONSES, JSON, FormatQuery, image_format
from service.api.routes.jobs import JobRoutes
from service.cache import etag_for
from service.limits import over_limit

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])

PATHS = (
    "/v1/signals", "/v1/signals/upload", "/v1/signals/plot", "/v1/signals/upload/plot",
    "/v1/signals/jobs",
)  # fmt: skip
"""The routes whose bodies hold a recording (a larger body limit, ``service.main``)."""
JOB_HINT = (
    "submit it as a job: POST /v1/signals/jobs (the same JSON body; poll the job, then its "
    "/result and /plot)"
)
"""Where a recording over the synchronous budget is read."""

SIGNAL_JOBS = JobRoutes(
    kind="signal",
    prefix="signals/jobs",
    noun="signal",
    plural="signals",
    submit_summary="Submit a long recording to be read as a job",
    submit_doc="The request of ``POST /v1/signals`` with any number of samples up to the "
    f"reader's limit (not the synchronous budget of {SYNC_SAMPLES} samples) and the body "
    "limit of signal routes (max_batch_body_bytes). It runs on the workers as one chunk; "
    "answers 202 with the job and its ``Location``; poll it and fetch ``/result`` or ``/plot`` "
    "once succeeded.",
    result_model=SignalResult,
    result_summary="Result of a succeeded signal job: the reading",
    result_doc="The body ``POST /v1/signals`` returns for the same request (``gearengine "
    "signal FILE --json``): the verdict, its evidence, the summary in plain words and, with a "
    "design, the model beside it.",
    budget_path="design",
)
jobs_router = SIGNAL_JOBS.router()


def check_signal_budget(body: SignalRequest) -> None:
    """422 naming signal.values when the series is over the synchronous budget."""
    n = len(body.signal.values)
    if n > SYNC_SAMPLES:
        raise over_limit(
            "signal.values",
            f"{n} samples, over the synchronous budget of {SYNC_SAMPLES} samples per request; "
            f"{JOB_HINT}, or read it with gearengine signal FILE --rate ...",
            kind="over-budget",
        )


def _answer(request: Request, body: SignalRequest) -> Any:
    check_signal_budget(body)
    return cached_compute(
        request,
        "signals",
        body.model_dump_json(),
        lambda: (dumps(read_signal(body)).encode(), JSON),
    )


@router.post(
    "/signals",
    response_model=SignalResult,
    responses=CACHED,
    summary="Read a recorded series: periodic, quasi-periodic, chaotic or stochastic",
)
async def post_signal(body: SignalRequest, request: Request) -> Response:
    """Resamples per shaft revolution with a speed or tach (order spectrum, mesh orders,
    strobes), finds the period by synchronous averaging, and otherwise runs the 0-1 test for
    chaos, an IAAFT surrogate test and Rosenstein's largest Lyapunov exponent on the delay
    embedding chosen by mutual information and false nearest neighbours. With a ``design``,
    the model's verdict at the same speed beside the signal's. Every number in physical units.
    """
    return await _answer(request, body)


UPLOAD_EXAMPLE = "time,te\n" + "".join(
    f"{k * 5e-5:.5f},{v}\n" for k, v in enumerate(EXAMPLE_VALUES)
)
"""A table the reading accepts (512 samples at 20 kHz, times in the first column)."""
UPLOAD_BODY = {
    "requestBody": {
        "required": True,
        "content": {
            media: {"schema": {"type": "string"}, "example": UPLOAD_EXAMPLE}
            for media in ("text/csv", "text/plain")
        },
        "description": "Samples: one value a line, or columns (the last is read; a first "
        "column of increasing times in seconds sets the rate when ``rate`` is not given).",
    }
}


@dataclass(frozen=True)
class UploadFields:
    """The query of the upload routes: what the CSV or text does not say."""

    rate: str | None
    speed: str | None
    teeth: int | None
    quantity: Quantity
    unit: str
    seed: int


def upload_fields(
    rate: Annotated[
        str | None, Query(description="Sample rate, e.g. '20 kHz' (Hz if bare).")
    ] = None,
    speed: Annotated[
        str | None, Query(description="Shaft speed, e.g. '1500 rpm' (rad/s if bare).")
    ] = None,
    teeth: Annotated[int | None, Query(ge=1, le=1000, description="Teeth on that shaft.")] = None,
    quantity: Annotated[Quantity, Query(description="What was measured.")] = "other",
    unit: Annotated[str, Query(max_length=40, description="Unit of the values.")] = "1",
    seed: Annotated[int, Query(ge=0, le=2**32 - 1, description="Seed of the tests.")] = 0,
) -> UploadFields:
    return UploadFields(rate, speed, teeth, quantity, unit, seed)


Upload = Annotated[UploadFields, Depends(upload_fields)]


async def uploaded(request: Request, fields: UploadFields) -> SignalRequest:
    """The ``SignalRequest`` of an upload: the samples from the body (``read_table``: one value
    a line, or columns whose first may be times setting the rate), the rest from the query;
    422 naming the field for bad input."""
    try:
        values, table_rate = read_table((await request.body()).decode("utf-8", "replace"))
    except InputError as exc:
        raise engine_refusal(exc) from None
    signal: dict[str, Any] = {
        "values": values.tolist(), "quantity": fields.quantity, "unit": fields.unit
    }  # fmt: skip
    sample_rate = fields.rate if fields.rate is not None else table_rate
    if sample_rate is not None:
        signal["sample_rate"] = _number_or_text(sample_rate)
    doc: dict[str, Any] = {"signal": signal, "seed": fields.seed}
    if fields.speed is not None:
        doc["speed"] = _number_or_text(fields.speed)
    if fields.teeth is not None:
        doc["teeth"] = fields.teeth
    return SignalRequest.model_validate(doc)  # ValidationError: 422 naming the field


@router.post(
    "/signals/upload",
    response_model=SignalResult,
    responses=CACHED,
    summary="Read a recorded series uploaded as CSV or text",
    openapi_extra=UPLOAD_BODY,
)
async def post_signal_upload(request: Request, fields: Upload) -> Response:
    """As ``POST /v1/signals``, the samples in the body as CSV or text."""
    return await _answer(request, await uploaded(request, fields))


def _number_or_text(text: str | float) -> str | float:
    if isinstance(text, float):
        return text
    try:
        return float(text)
    except ValueError:
        return text


def _reading(request: Request, body: SignalRequest) -> SignalResult:
    """The reading of ``body``: the one ``POST /v1/signals`` cached for it when there is one
    (the explorer asks for the verdict, then the figure), else computed."""
    hit = response_cache(request).get(etag_for("signals", body.model_dump_json()))
    if hit is not None:
        return SignalResult.model_validate_json(hit[0])
    return read_signal(body)


async def _figure_answer(
    request: Request, body: SignalRequest, format: Literal["png", "svg"] | None
) -> Response:
    fmt = image_format(request, format)
    check_signal_budget(body)
    return await cached_compute(
        request, f"signals/plot.{fmt}", body.model_dump_json(),
        lambda: (_figure(_reading(request, body), fmt), MEDIA_TYPES[fmt]),
    )  # fmt: skip


@router.post(
    "/signals/plot",
    response_class=Response,
    responses=IMAGE_RESPONSES,
    summary="Figure of a signal reading (order spectrum, strobe map, attractor, 0-1 path, "
    "surrogates)",
)
async def post_signal_plot(
    body: SignalRequest,
    request: Request,
    format: Literal["png", "svg"] | None = FormatQuery,
) -> Response:
    """The figure of ``gearengine signal FILE --plot``: order (or frequency) spectrum with the
    model's lines, strobe map (x_k, x_k+1), reconstructed attractor, the 0-1 test's (p, q)
    path, Rosenstein's divergence with its fit, and the surrogate distribution."""
    return await _figure_answer(request, body, format)


@router.post(
    "/signals/upload/plot",
    response_class=Response,
    responses=IMAGE_RESPONSES,
    summary="Figure of the reading of a series uploaded as CSV or text",
    openapi_extra=UPLOAD_BODY,
)
async def post_signal_upload_plot(
    request: Request,
    fields: Upload,
    format: Literal["png", "svg"] | None = FormatQuery,
) -> Response:
    """As ``POST /v1/signals/plot``, the samples in the body as CSV or text (the query of
    ``POST /v1/signals/upload``)."""
    return await _figure_answer(request, await uploaded(request, fields), format)


def _figure(result: SignalResult, fmt: Literal["png", "svg"]) -> bytes:
    from gearengine.plots.signal import signal_figure

    return signal_figure(result, fmt)


SIGNAL_JOBS.figure_route(
    jobs_router,
    "Figure of a succeeded signal job (PNG or SVG)",
    "The figure of ``POST /v1/signals/plot`` for the job's request: order spectrum, strobe "
    "map,\nattractor, the 0-1 test's (p, q) path, Rosenstein's divergence, the surrogates.",
    _figure,
)
