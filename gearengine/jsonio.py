"""Canonical JSON of results and readable errors, shared by the CLI and the API.

The CLI's ``--json`` output and the API's response body are the same bytes: both come from
``dumps``.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from pydantic import BaseModel, ValidationError

from gearengine.model.errors import InputError


def dumps(result: BaseModel) -> str:
    """Compact, deterministic JSON of a result model (field order as declared)."""
    return result.model_dump_json()


def field_path(loc: tuple[Any, ...]) -> str:
    """Dotted JSON path of a pydantic error location: params.backlash.a, axes[0].num."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or "(body)"


def located(error: Mapping[str, Any], loc: tuple[Any, ...] | None = None) -> tuple[tuple, str]:
    """(location, message) of a pydantic error: an ``InputError`` raised in a model's validator
    adds its field path to the model's location (``loc``, default the error's) and gives its
    own message, read from the object, not from the text."""
    loc = tuple(error["loc"]) if loc is None else loc
    cause = (error.get("ctx") or {}).get("error")
    if isinstance(cause, InputError):
        parts = (int(p) if p.isdigit() else p for p in cause.path.split(".") if p)
        return (*loc, *parts), cause.message
    return loc, message(error)


def error_lines(exc: ValidationError) -> list[str]:
    """One line per problem: 'path: message'."""
    return [
        f"{field_path(loc)}: {text}" for loc, text in map(located, exc.errors(include_url=False))
    ]


def message(error: Mapping[str, Any]) -> str:
    """A pydantic error's message without the "Value error, " that pydantic puts before the
    engine's own sentences."""
    return str(error["msg"]).removeprefix("Value error, ")


def load_document(text: str) -> Any:
    """Parse JSON text; raises ValueError with the line and column of a syntax error, or
    'empty input' when there is nothing but whitespace (an empty file or stdin)."""
    if not text.strip():
        raise ValueError("empty input")
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(
            f"invalid JSON at line {exc.lineno} column {exc.colno}: {exc.msg}"
        ) from None
