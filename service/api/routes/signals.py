"""POST /v1/signals, /v1/signals/upload and /v1/signals/plot: a recorded series read as
periodic, quasi-periodic, chaotic or noise (``gearengine.signals``).

The JSON body is ``SignalRequest``; the upload takes the samples as CSV or text (one value a
line, or columns: the last is read, a first column of increasing times sets the rate) with the
other fields as query parameters. Bad input is a 422 problem naming the field
(``signal.values[3]`` for a NaN, ``signal.sample_rate`` below twice the mesh frequency); a
series longer than ``SYNC_SAMPLES`` is refused before any compute with the budget named
(``gearengine signal FILE`` reads up to ``MAX_SAMPLES``).
"""

from __future__ import annotations

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
from service.api.deps import cached_compute, engine_refusal, require_key
from service.api.responses import CACHED, IMAGE_RESPONSES, JSON, FormatQuery, image_format
from service.limits import over_limit

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])

PATHS = ("/v1/signals", "/v1/signals/upload", "/v1/signals/plot")
"""The routes whose bodies hold a recording (a larger body limit, ``service.main``)."""


def check_signal_budget(body: SignalRequest) -> None:
    """422 naming signal.values when the series is over the synchronous budget."""
    n = len(body.signal.values)
    if n > SYNC_SAMPLES:
        raise over_limit(
            "signal.values",
            f"{n} samples, over the synchronous budget of {SYNC_SAMPLES} samples per request; "
            "read longer recordings where no budget applies: gearengine signal FILE --rate ...",
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


@router.post(
    "/signals/upload",
    response_model=SignalResult,
    responses=CACHED,
    summary="Read a recorded series uploaded as CSV or text",
    openapi_extra=UPLOAD_BODY,
)
async def post_signal_upload(
    request: Request,
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
) -> Response:
    """As ``POST /v1/signals``, the samples in the body as CSV or text."""
    try:
        values, table_rate = read_table((await request.body()).decode("utf-8", "replace"))
    except InputError as exc:
        raise engine_refusal(exc) from None
    signal: dict[str, Any] = {"values": values.tolist(), "quantity": quantity, "unit": unit}
    sample_rate = rate if rate is not None else table_rate
    if sample_rate is not None:
        signal["sample_rate"] = _number_or_text(sample_rate)
    doc: dict[str, Any] = {"signal": signal, "seed": seed}
    if speed is not None:
        doc["speed"] = _number_or_text(speed)
    if teeth is not None:
        doc["teeth"] = teeth
    body = SignalRequest.model_validate(doc)  # ValidationError: 422 naming the field
    return await _answer(request, body)


def _number_or_text(text: str | float) -> str | float:
    if isinstance(text, float):
        return text
    try:
        return float(text)
    except ValueError:
        return text


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
    from gearengine.plots.signal import signal_figure

    fmt = image_format(request, format)
    check_signal_budget(body)
    return await cached_compute(
        request, f"signals/plot.{fmt}", body.model_dump_json(),
        lambda: (signal_figure(read_signal(body), fmt), MEDIA_TYPES[fmt]),
    )  # fmt: skip
