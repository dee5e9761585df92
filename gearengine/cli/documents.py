"""What every engine command shares: reading a request document and refusing bad input.

Exit codes: 0 success (check: pass), 1 check failed, 2 invalid input (one line per problem on
standard error, naming the field).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from pydantic import BaseModel, ValidationError

from gearengine.jsonio import error_lines, load_document
from gearengine.studies import jobs

EXIT_OK, EXIT_FAIL, EXIT_INVALID = 0, 1, 2
EXIT_PIPE = 141
"""Standard output's reader went away (``| head``): 128 + SIGPIPE, as the shell reports a
Unix tool that the signal stopped; distinct from a failed check (1)."""
EXIT_INTERNAL = 70
"""An unexpected error, a bug (EX_SOFTWARE of sysexits.h): never confused with a failed check."""

R = TypeVar("R", bound=BaseModel)


GATED = ("chaotic", "quasi_periodic", "diverged", "separation", "back_flank",
         "dynamic_factor_above_limit", "melnikov_chaos_possible")  # fmt: skip
"""Probabilities ``check --max-probability`` may limit, as its help and its refusal list them
(the old word ``impacts`` refused: ``IMPACTS_REFUSED``)."""


class InvalidInputError(Exception):
    """Input that cannot be used; carries one message line per problem."""

    def __init__(self, lines: list[str]) -> None:
        super().__init__("\n".join(lines))
        self.lines = lines


def read_document(path: str) -> object:
    """The parsed JSON of a file or ``-`` (stdin); raises InvalidInputError."""
    try:
        text = sys.stdin.read() if path == "-" else Path(path).read_text()
    except OSError as exc:
        raise InvalidInputError([f"{path}: {exc.strerror}"]) from None
    try:
        return load_document(text)
    except ValueError as exc:
        raise InvalidInputError([f"{path}: {exc}"]) from None


def validated_input(
    validate: Callable[[object], R], data: object, path: str, options: Options | None = None
) -> R:
    """``validate(data)``, its ValueErrors (pydantic's included) as InvalidInputError lines;
    a line about a field a command-line option gave is named by that option (``options``)."""
    try:
        return validate(data)
    except ValidationError as exc:
        raise InvalidInputError(by_options(error_lines(exc), options or {})) from None
    except ValueError as exc:
        raise InvalidInputError([f"{path}: {exc}"]) from None


STARTS_FIELD = "settings.basins.starts"
"""The field ``--starts`` sets: a refusal of it is named by the option ("--starts 0" was
"settings.basins.starts: Input should be greater than or equal to 1")."""

Options = dict[str, str]
"""The option that gave each field of a request the CLI built: {"axes[0].stop": "--speed (its
high end)", "samples": "--samples"}; a field inside one (``levers[0].bounds[1]``) is named by
its own entry if it has one, else by its nearest enclosing field's."""


def by_options(lines: list[str], options: Options) -> list[str]:
    """Each error line "path: message" whose path (or an enclosing field) an option gave, as
    "option: message": the user reads what they typed, not the request's internal path."""
    named = []
    for line in lines:
        path, sep, text = line.partition(": ")
        fields = [f for f in options if path == f or path.startswith((f"{f}.", f"{f}["))]
        named.append(f"{options[max(fields, key=len)]}{sep}{text}" if sep and fields else line)
    return named


def axis_options(axes: list[dict[str, object]], given: list[int], name: str = "axes") -> Options:
    """The options of the axes in ``given`` (those --speed/--torque built): start, stop and num
    of ``axes[i]`` as "--speed (its low end)", "--speed (its high end)", "--speed-points"."""
    options = {}
    for i in given:
        option = f"--{axes[i]['parameter']}"
        options |= {f"{name}[{i}].start": f"{option} (its low end)",
                    f"{name}[{i}].stop": f"{option} (its high end)",
                    f"{name}[{i}].num": f"{option}-points"}  # fmt: skip
    return options


def read_request(path: str, model: type[R]) -> R:
    """Read and validate a request document from a file or ``-`` (stdin)."""
    return validated_input(model.model_validate, read_document(path), path)


def counted_points(axes: object, noun: str) -> int:
    """The operating points of ``axes`` (``points_of``), refused over the job limit
    (``studies.jobs.too_many_points``) before the request's checks cost each point's design."""
    n = points_of(axes)
    why = jobs.too_many_points(n, noun)
    if why is not None:
        raise InvalidInputError([why])
    return n


def points_of(axes: object) -> int:
    """The operating points of a request's ``axes`` (their ``num`` multiplied; 1 without
    axes), counted before validation so that a count over the limit is refused at once."""
    n = 1
    for a in axes if isinstance(axes, list) else []:
        num = a.get("num", 1) if isinstance(a, dict) else 1
        n *= num if isinstance(num, int) and num > 0 else 1
    return n
