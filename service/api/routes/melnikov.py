"""POST /v1/melnikov: the Melnikov verdict of one design; POST /v1/melnikov/batch: verdicts and
margins of many."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request, Response
from pydantic import ValidationError
from starlette.concurrency import run_in_threadpool
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from gearengine.analysis import MelnikovAnswer, answer_melnikov
from gearengine.homoclinic import (
    MelnikovBatchRequest,
    MelnikovBatchResult,
    MelnikovRequest,
    melnikov_batch,
)
from gearengine.jsonio import dumps
from gearengine.model.errors import InputError
from service.api.deps import cached_compute, require_key
from service.api.responses import CACHED, JSON, PROBLEMS
from service.errors import ProblemError, engine_error_response

router = APIRouter(prefix="/v1", dependencies=[Depends(require_key)])


class VerdictLane:
    """ASGI middleware: POST /v1/melnikov with an ``application/json`` body that validates,
    answered without the router.

    FastAPI's routing through the included routers, its request wrapper (two exit stacks and
    the exception wrapper) and the exception middleware cost about as much CPU as the
    one-harmonic verdict itself. The lane reads the body, validates it, checks the key
    (``require_key``) and answers with ``post_melnikov``, as the route does; anything else
    (another path or media type, a body that does not parse or validate, a refused key) goes to
    the app behind it with the body replayed, so every such error is FastAPI's own. A verdict
    the engine refuses is answered as the app's handlers answer it (``engine_error_response``),
    and an unexpected error is raised to the server-error handler, as from the route: neither
    is computed again. It sits inside the body limit and the access log, which name the
    route as the router would; a body without Content-Length (streamed, whose excess the body
    limit finds while it is read) goes to the route unread.
    """

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["path"] != ROUTE.path or scope["method"] != "POST":
            await self.app(scope, receive, send)
            return
        request = Request(scope, receive)
        media = request.headers.get("content-type", "").partition(";")[0].strip().lower()
        if media != JSON or "content-length" not in request.headers:
            await self.app(scope, receive, send)  # a streamed body's 413 is the route's
            return
        messages: list[Message] = []
        while not messages or _more(messages[-1]):
            messages.append(await receive())
        body = None
        if messages[-1]["type"] == "http.request":
            try:  # a body that does not validate or a refused key: the route's own errors
                body = MelnikovRequest.model_validate_json(b"".join(_body(m) for m in messages))
                await require_key(request)
            except (ValidationError, ProblemError):
                body = None
        if body is None:
            await self.app(scope, _replay(messages, receive), send)
            return
        scope["route"] = ROUTE
        try:  # computed once: a refusal answered as the app's handlers answer it, a crash raised
            response = await post_melnikov(body, request)
        except (ProblemError, ValidationError, InputError) as exc:
            response = engine_error_response(exc)
        await response(scope, receive, send)


def _more(message: Message) -> bool:
    """Whether a body message is followed by more of the body."""
    return message["type"] == "http.request" and message.get("more_body", False)


def _body(message: Message) -> bytes:
    return message.get("body", b"")


def _replay(messages: list[Message], receive: Receive) -> Receive:
    """``receive`` that gives ``messages`` first (the body the lane read), then the rest."""
    pending = list(messages)

    async def replayed() -> Message:
        return pending.pop(0) if pending else await receive()

    return replayed


async def post_melnikov(body: MelnikovRequest, request: Request) -> Response:
    """Can the stable and unstable manifolds of the saddle intersect transversally?

    Returns both branches' extrema of M(tau0), the threshold of each control parameter with the
    design's margin, and the corrected closed-form (or quadrature) coefficients. With a
    ``design`` in physical units, also the ``params`` used and the ``engineering`` block: the
    driver speeds [rpm] where chaos is possible and the thresholds in gear units.
    """
    return await cached_compute(
        request,
        "melnikov",
        body.model_dump_json(),
        lambda: (dumps(answer_melnikov(body)).encode(), JSON),
        inline=one_sinusoid(body),
    )


router.add_api_route(
    "/melnikov",
    post_melnikov,
    methods=["POST"],
    response_model=MelnikovAnswer,
    responses=CACHED,
    summary="Melnikov verdict, thresholds and margins of one design",
)
ROUTE = router.routes[-1]
"""The route of POST /v1/melnikov, named in the access log of what ``VerdictLane`` answers."""


def one_sinusoid(body: MelnikovRequest) -> bool:
    """True when the verdict is a fraction of a millisecond, shorter than a worker thread's hop:
    closed-form coefficients, dimensionless params (a design adds the speed windows, hundreds of
    verdicts) and at most one harmonic with an amplitude (M = A + B sin(Omega tau0 + phi): no
    extrema grid along the Omega_e scan)."""
    if body.design is not None or body.method != "closed_form":
        return False
    return sum(1 for _, exc in body.params.excitations() for _ in exc.active()) <= 1


@router.post(
    "/melnikov/batch",
    response_model=MelnikovBatchResult,
    responses=PROBLEMS,
    summary="Melnikov verdicts and parameter margins of up to 10,000 designs (for optimisers)",
)
async def post_melnikov_batch(body: MelnikovBatchRequest) -> Response:
    """Per design, in order: chaos possible, and the margin of F_e1, mu, k_p1 and F_p1 to their
    nearest critical values (the thresholds of POST /v1/melnikov without the Omega_e scan).
    More designs than the cap are refused with 422 naming ``designs``.
    """

    def compute() -> bytes:
        results = melnikov_batch(body.designs, body.mean_load)
        result = MelnikovBatchResult.model_construct(results=results)
        return result.model_dump_json().encode()

    return Response(await run_in_threadpool(compute), media_type=JSON)
