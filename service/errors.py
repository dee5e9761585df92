"""RFC 9457 problem details: every 4xx/5xx body is ``application/problem+json``.

{"type": "https://gearchaos.dev/problems/validation", "title": "Invalid request",
 "status": 422, "detail": "...", "errors": [{"path": "params.damping",
 "pointer": "/params/damping", "message": "..."}]}
"""

from __future__ import annotations

import logging
import re
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import BaseModel, Field, ValidationError
from starlette.exceptions import HTTPException as StarletteHTTPException

from gearengine.jsonio import field_path, located
from gearengine.model.errors import InputError

PROBLEM_JSON = "application/problem+json"
TYPE_BASE = "https://gearchaos.dev/problems/"
log = logging.getLogger("gearchaos")


class FieldError(BaseModel):
    """One bad field of a request."""

    path: str = Field(description="Dotted path of the field in the body, e.g. params.damping.")
    pointer: str = Field(description="RFC 6901 JSON pointer of the field, e.g. /params/damping.")
    message: str = Field(description="What is wrong with it.")


class Problem(BaseModel):
    """RFC 9457 problem details."""

    type: str = Field(description="URI identifying the problem type.")
    title: str = Field(description="Short summary of the problem type.")
    status: int = Field(description="HTTP status code.")
    detail: str = Field(description="Explanation of this occurrence.")
    errors: list[FieldError] = Field(default_factory=list, description="The bad fields, if any.")


class ProblemError(Exception):
    """Raise to answer with a problem document."""

    def __init__(
        self,
        status: int,
        kind: str,
        title: str,
        detail: str,
        errors: list[FieldError] | None = None,
        headers: dict[str, str] | None = None,
    ) -> None:
        super().__init__(detail)
        self.problem = Problem(
            type=TYPE_BASE + kind, title=title, status=status, detail=detail, errors=errors or []
        )
        self.headers = headers or {}


def problem_response(problem: Problem, headers: dict[str, str] | None = None) -> JSONResponse:
    return JSONResponse(
        problem.model_dump(), status_code=problem.status, media_type=PROBLEM_JSON, headers=headers
    )


def field_errors(errors: list[dict[str, Any]], strip_body: bool = True) -> list[FieldError]:
    """FieldErrors from pydantic/FastAPI error dicts (dropping FastAPI's leading 'body')."""
    out = []
    for e in errors:
        loc = tuple(e["loc"])
        if e.get("type") == "json_invalid":  # loc holds a character offset, not a field
            at = loc[-1] if loc and isinstance(loc[-1], int) else "?"
            out.append(FieldError(path="", pointer="", message=f"{e['msg']} at character {at}"))
            continue
        if strip_body and loc[:1] == ("body",):
            loc = loc[1:]
        loc, text = located(e, loc)
        pointer = "/" + "/".join(str(p).replace("~", "~0").replace("/", "~1") for p in loc)
        out.append(FieldError(path=field_path(loc), pointer=pointer, message=text))
    return out


def validation_problem(errors: list[FieldError], detail: str | None = None) -> ProblemError:
    return ProblemError(
        422,
        "validation",
        "Invalid request",
        detail or "; ".join(f"{e.path}: {e.message}" if e.path else e.message for e in errors),
        errors,
    )


def _is_json(media: str) -> bool:
    return media == "application/json" or media.endswith("+json")


def unsupported_media_type(media: str) -> ProblemError:
    """415: a JSON body sent without a JSON media type (curl -d sends form data; FastAPI reads
    a body as JSON only under application/json or +json)."""
    sent = f"not {media}" if media else "and the request has no Content-Type"
    return ProblemError(
        415,
        "unsupported-media-type",
        "Unsupported media type",
        f"the body must be JSON, {sent}: send Content-Type: application/json "
        "(curl: -H content-type:application/json, or --json)",
    )


_TITLES = {
    400: "Bad request",
    401: "Unauthorized",
    404: "Not found",
    405: "Method not allowed",
    406: "Not acceptable",
    413: "Request body too large",
    429: "Too many requests",
}


def engine_refusal(exc: ValueError) -> ProblemError:
    """422 for a ValueError of the engine; an ``InputError`` names its field (typed, never
    read from the message's text)."""
    errors = []
    if isinstance(exc, InputError) and exc.path:
        pointer = "/" + exc.path.replace(".", "/")
        errors = [FieldError(path=exc.path, pointer=pointer, message=exc.message)]
    return ProblemError(422, "refused", "Refused by the engine", str(exc), errors)


def allowed_methods(request: Request) -> list[str]:
    """The documented methods of the request's path (the OpenAPI document's, so ``Allow``
    lists what the document says; Starlette's 405 names only the first matching route's:
    ``Allow: POST`` on ``/v1/sweeps``, which also has GET); empty for an undocumented path."""
    for template, ops in request.app.openapi().get("paths", {}).items():
        pattern = re.sub(r"\\\{[^/]+?\\\}", "[^/]+", re.escape(template))
        if re.fullmatch(pattern, request.url.path):
            return sorted(m.upper() for m in ops if m in HTTP_METHODS)
    return []


HTTP_METHODS = ("get", "put", "post", "delete", "options", "head", "patch", "trace")


def engine_error_response(exc: ProblemError | ValidationError | InputError) -> JSONResponse:
    """The problem+json of an error an endpoint raises: a ``ProblemError`` as it says, the
    engine's ``ValidationError`` as 422 naming each field, an ``InputError`` (an engine refusal
    found after validation: a design's radii while costing a job's work, say) as 422 naming its
    field, never 500. The app's handlers and ``VerdictLane`` answer with it."""
    if isinstance(exc, ProblemError):
        return problem_response(exc.problem, exc.headers)
    if isinstance(exc, ValidationError):
        errors = field_errors(list(exc.errors(include_url=False)), strip_body=False)
        return problem_response(validation_problem(errors).problem)
    return problem_response(engine_refusal(exc).problem)


def install(app: FastAPI) -> None:
    """Register the handlers that turn every error into problem+json."""

    @app.exception_handler(ProblemError)
    async def _problem(_: Request, exc: ProblemError) -> JSONResponse:
        return engine_error_response(exc)

    @app.exception_handler(RequestValidationError)
    async def _invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
        errors = list(exc.errors())
        media = request.headers.get("content-type", "").split(";")[0].strip().lower()
        if not _is_json(media) and any(tuple(e["loc"]) == ("body",) for e in errors):
            return problem_response(unsupported_media_type(media).problem)
        return problem_response(validation_problem(field_errors(errors)).problem)

    @app.exception_handler(ValidationError)
    async def _engine_invalid(_: Request, exc: ValidationError) -> JSONResponse:
        return engine_error_response(exc)

    @app.exception_handler(InputError)
    async def _refused(_: Request, exc: InputError) -> JSONResponse:
        return engine_error_response(exc)

    @app.exception_handler(StarletteHTTPException)
    async def _http(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        title = _TITLES.get(exc.status_code, "Error")
        slug = title.lower().replace(" ", "-")
        problem = Problem(
            type=TYPE_BASE + slug, title=title, status=exc.status_code, detail=str(exc.detail)
        )
        headers = dict(getattr(exc, "headers", None) or {})
        if exc.status_code == 405 and (methods := allowed_methods(request)):
            headers["Allow"] = ", ".join(methods)  # every method of the path
        return problem_response(problem, headers or None)

    @app.exception_handler(Exception)
    async def _crash(request: Request, exc: Exception) -> JSONResponse:
        log.exception("unhandled error on %s %s", request.method, request.url.path)
        problem = Problem(
            type=TYPE_BASE + "internal",
            title="Internal error",
            status=500,
            detail=f"{type(exc).__name__}: the server failed on this request",
        )
        return problem_response(problem)
