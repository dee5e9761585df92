"""The plots room: figures engineers read, as PNG or SVG bytes.

``analysis`` draws one design (the four-panel response, the threshold curves), ``basins`` its
basin picture (starts coloured by attractor), ``sweep`` a
sweep (bifurcation diagram, chaos map); both go through ``style`` (one symbol table, one render
path). Rendering only: imports the result documents of the other rooms, computes nothing but
the Melnikov boundary it draws (from ``homoclinic.thresholds``).

The names below load on first use (PEP 562): ``gearengine sweep`` imports ``plots.sweep``
alone, not ``plots.analysis`` and the whole analysis stack behind it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gearengine.lazyload import lazy_names

if TYPE_CHECKING:
    from gearengine.plots.analysis import analysis_figure, threshold_figure
    from gearengine.plots.basins import basins_figure
    from gearengine.plots.campbell import campbell_figure
    from gearengine.plots.runup import runup_figure
    from gearengine.plots.signal import signal_figure
    from gearengine.plots.style import MEDIA_TYPES, ImageFormat
    from gearengine.plots.sweep import sweep_figure

__all__ = [
    "MEDIA_TYPES",
    "ImageFormat",
    "analysis_figure",
    "basins_figure",
    "campbell_figure",
    "runup_figure",
    "signal_figure",
    "sweep_figure",
    "threshold_figure",
]

_HOMES = {
    "MEDIA_TYPES": ("gearengine.plots.style", "MEDIA_TYPES"),
    "ImageFormat": ("gearengine.plots.style", "ImageFormat"),
    "analysis_figure": ("gearengine.plots.analysis", "analysis_figure"),
    "basins_figure": ("gearengine.plots.basins", "basins_figure"),
    "campbell_figure": ("gearengine.plots.campbell", "campbell_figure"),
    "runup_figure": ("gearengine.plots.runup", "runup_figure"),
    "signal_figure": ("gearengine.plots.signal", "signal_figure"),
    "sweep_figure": ("gearengine.plots.sweep", "sweep_figure"),
    "threshold_figure": ("gearengine.plots.analysis", "threshold_figure"),
}
"""(module, attribute) of each public name (none is also a module's name)."""

__getattr__, __dir__ = lazy_names(__name__, _HOMES)
