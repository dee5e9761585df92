"""Media types and the documented error responses of every route."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal

from fastapi import Query, Request

from service.errors import PROBLEM_JSON, Problem

if TYPE_CHECKING:  # the figures' module loads matplotlib: only when a figure is drawn
    from gearengine.plots import ImageFormat

JSON = "application/json"
PNG = "image/png"
SVG = "image/svg+xml"


def _problem(description: str) -> dict[str, Any]:
    return {"model": Problem, "description": description, "content": {PROBLEM_JSON: {}}}


PROBLEMS: dict[int | str, dict[str, Any]] = {
    400: _problem("The body could not be read (not JSON, bad encoding)."),
    401: _problem("Missing or invalid API key (when keys are configured)."),
    413: _problem("Request body over the size limit."),
    415: _problem("The body is not sent as JSON: send Content-Type: application/json."),
    422: _problem("Invalid input or over a limit; `errors` names each bad field."),
}


def header(description: str) -> dict[str, Any]:
    """An OpenAPI response header (a string)."""
    return {"description": description, "schema": {"type": "string"}}


RETRY_AFTER_HEADER = header("Seconds to wait before asking again.")
ETAG_HEADERS: dict[str, Any] = {
    "ETag": header("Strong validator of the canonical request; send it in If-None-Match."),
    "Cache-Control": header("no-cache: revalidate with If-None-Match."),
}
CACHE_HEADERS: dict[str, Any] = {
    **ETAG_HEADERS,
    "X-Cache": header("hit or miss: whether the in-memory LRU answered."),
    "Server-Timing": header("compute;dur=MILLISECONDS, on a miss."),
}
NOT_MODIFIED: dict[int | str, dict[str, Any]] = {
    304: {"description": "If-None-Match holds the ETag: what you have is current (no body).",
          "headers": ETAG_HEADERS},
}  # fmt: skip

CACHED: dict[int | str, dict[str, Any]] = {
    **PROBLEMS,
    **NOT_MODIFIED,
    200: {"description": "Successful Response", "headers": CACHE_HEADERS},
}
"""Responses of a route answered through the LRU (``deps.cached_compute``)."""

IMAGE_RESPONSES: dict[int | str, dict[str, Any]] = {
    **CACHED,
    200: {
        "content": {PNG: {}, SVG: {}},
        "description": "The figure as PNG or SVG.",
        "headers": CACHE_HEADERS,
    },
}
FormatQuery = Query(None, description="png or svg; default from the Accept header, else png.")


def image_format(request: Request, fmt: Literal["png", "svg"] | None) -> ImageFormat:
    """?format= wins; otherwise SVG when the Accept header prefers it, else PNG."""
    if fmt is not None:
        return fmt
    accept = request.headers.get("accept", "")
    return "svg" if SVG in accept and PNG not in accept else "png"
