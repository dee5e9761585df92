"""The engine's typed refusals: one ``InputError`` for a field at fault, and ``Problems``, the
one collector of refusals across fields.

An ``InputError`` carries the path of the request field at fault (dotted, from the request's
top: ``design.driven.base_radius``, ``steps_per_period``; empty when no single field is), the
message, and the pydantic location of that field (``loc``: the path's parts unless given, as a
toleranced field ``("design", "tolerances", "mesh.damping_ratio")`` whose name holds dots). It
is a ``ValueError``, so pydantic turns one raised in a validator into a validation error whose
context keeps it (``ctx["error"]``); the service reads the path from the object, never from the
message's text.

``Problems`` collects the checks across fields that a request model cannot state field by field
(constraints as data, as scikit-learn's ``_param_validation`` does): each refusal is a pydantic
error detail naming its field, and ``raise_if_any`` raises them together as one
``ValidationError`` before any compute, which the API answers with 422 and the CLI prints one
line per field.
"""

from __future__ import annotations

from pydantic import ValidationError
from pydantic_core import InitErrorDetails, PydanticCustomError


class InputError(ValueError):
    """Input the engine refuses: ``path`` names the request field, ``message`` says why."""

    def __init__(self, path: str, message: str, loc: tuple[str | int, ...] | None = None) -> None:
        self.path = path
        self.message = message
        self.loc = loc if loc is not None else tuple(path.split(".")) if path else ()
        super().__init__(f"{path}: {message}" if path else message)


class Problems:
    """Refusals of one request (``kind`` names the error type: ``sweep``, ``runup``, ...)."""

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self.details: list[InitErrorDetails] = []

    def add(self, loc: tuple[str | int, ...], message: str, value: object) -> None:
        """Refuse the field at ``loc`` (its given ``value``) with ``message``."""
        self.details.append(
            {"type": PydanticCustomError(self.kind, message), "loc": loc, "input": value}
        )

    def add_error(self, error: InputError, value: object) -> None:
        """Refuse the field an ``InputError`` names."""
        self.add(error.loc, error.message, value)

    def raise_if_any(self, title: str) -> None:
        """Raise every refusal as one ``ValidationError`` (``title``: the request model)."""
        if self.details:
            raise ValidationError.from_exception_data(title, self.details)
