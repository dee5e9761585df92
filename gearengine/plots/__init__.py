"""The plots room: figures engineers read, as PNG or SVG bytes.

``analysis`` draws one design (the four-panel response, the threshold curves), ``sweep`` a
sweep (bifurcation diagram, chaos map); both go through ``style`` (one symbol table, one render
path). Rendering only: imports the result documents of the other rooms, computes nothing but
the Melnikov boundary it draws (from ``homoclinic.thresholds``).

The names below load on first use (PEP 562): ``gearengine sweep`` imports ``plots.sweep``
alone, not ``plots.analysis`` and the whole analysis stack behind it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from gearengine.plots.analysis import analysis_figure, threshold_figure
    from gearengine.plots.style import MEDIA_TYPES, ImageFormat
    from gearengine.plots.sweep import sweep_figure

__all__ = ["MEDIA_TYPES", "ImageFormat", "analysis_figure", "sweep_figure", "threshold_figure"]

_HOMES = {
    "MEDIA_TYPES": "gearengine.plots.style",
    "ImageFormat": "gearengine.plots.style",
    "analysis_figure": "gearengine.plots.analysis",
    "sweep_figure": "gearengine.plots.sweep",
    "threshold_figure": "gearengine.plots.analysis",
}
"""The module of each public name (none is also a module's name: caching it would hide one)."""


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first access and kept."""
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_HOMES[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The public names with what is loaded."""
    return sorted({*__all__, *globals()})
