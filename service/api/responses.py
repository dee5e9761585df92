"""Media types and the documented error responses of every route."""

from __future__ import annotations

from typing import Any, Literal

from fastapi import Query, Request

from gearengine.plots import ImageFormat
from service.errors import PROBLEM_JSON, Problem

JSON = "application/json"
PNG = "image/png"
SVG = "image/svg+xml"


def _problem(description: str) -> dict[str, Any]:
    return {"model": Problem, "description": description, "content": {PROBLEM_JSON: {}}}


PROBLEMS: dict[int | str, dict[str, Any]] = {
    400: _problem("The body could not be read (not JSON, bad encoding)."),
    401: _problem("Missing or invalid API key (when keys are configured)."),
    413: _problem("Request body over the size limit."),
    422: _problem("Invalid input or over a limit; `errors` names each bad field."),
}


IMAGE_RESPONSES: dict[int | str, dict[str, Any]] = {
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
