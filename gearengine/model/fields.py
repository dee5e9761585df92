"""A design's fields by their dotted paths ("mesh.half_backlash", "driver.teeth",
"transmission_error.harmonics.0.amplitude"): read one (``field_value``, its SI number
``si_value``), ask whether it holds an integer (``is_integer_field``), and the design with some
set and re-validated (``design_with``): the one way the studies and gates (sweep axes,
tolerances, remedies' levers) move a design.
"""

from __future__ import annotations

from typing import Any

from gearengine.model.design import Design
from gearengine.model.units import si_numbers


def _set(tree: dict[str, Any], path: str, value: object) -> None:
    """Set the field at ``path``; a whole float on an integer field (a grid value 19.0 of
    ``driver.teeth``) is set as that integer, since the design refuses floats there."""
    *head, last = path.split(".")
    node: Any = tree
    for key in head:
        node = node[int(key)] if key.isdigit() else node[key]
    key: int | str = int(last) if last.isdigit() else last
    if not last.isdigit() and not (isinstance(node, dict) and last in node):
        raise KeyError(last)
    if _is_int(node[key]) and isinstance(value, float) and value.is_integer():
        value = int(value)
    node[key] = value


def _is_int(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def is_integer_field(design: Design, path: str) -> bool:
    """True when the design's field at ``path`` holds an integer (``driver.teeth``): its axis
    values must be whole numbers."""
    try:
        return _is_int(_get(design.model_dump(), path))
    except (KeyError, IndexError, TypeError):
        return False


def _get(tree: Any, path: str) -> Any:
    for key in path.split("."):
        tree = tree[int(key)] if key.isdigit() else tree[key]
    return tree


def field_value(design: Design, path: str) -> Any:
    """The design's field at ``path`` (SI units); KeyError or IndexError for a missing one."""
    return _get(design.model_dump(), path)


def design_with(design: Design, values: dict[str, object]) -> Design:
    """``design`` with physical fields set (unit strings or SI numbers), re-validated.

    Raises KeyError for a path the design does not have, ValidationError for a bad value.
    """
    tree = design.model_dump()
    for path, value in values.items():
        _set(tree, path, value)
    for k, share in design.ripple_shares.items():  # a ripple in % follows the mean torque
        path = f"torque_fluctuation.harmonics.{k}.amplitude"
        if path not in values:
            _set(tree, path, f"{share!r} %")
    with si_numbers():  # the dump's numbers are SI: no note on them
        return Design.model_validate(tree)


def si_value(design: Design, path: str, value: object) -> float:
    """The SI number of ``value`` (a unit string or a number) for the field at ``path``."""
    return float(_get(design_with(design, {path: value}).model_dump(), path))
