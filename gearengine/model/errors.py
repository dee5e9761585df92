"""The engine's typed input error: bad input found beyond what pydantic validates.

An ``InputError`` carries the path of the request field at fault (dotted, from the request's
top: ``design.driven.base_radius``, ``steps_per_period``; empty when no single field is) and the
message. It is a ``ValueError``, so pydantic turns one raised in a validator into a validation
error whose context keeps it (``ctx["error"]``); the service reads the path from the object,
never from the message's text.
"""

from __future__ import annotations


class InputError(ValueError):
    """Input the engine refuses: ``path`` names the request field, ``message`` says why."""

    def __init__(self, path: str, message: str) -> None:
        self.path = path
        self.message = message
        super().__init__(f"{path}: {message}" if path else message)
