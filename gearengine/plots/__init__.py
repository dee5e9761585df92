"""The plots room: figures engineers read, as PNG or SVG bytes.

``analysis`` draws one design (the four-panel response, the threshold curves), ``sweep`` a
sweep (bifurcation diagram, chaos map); both go through ``style`` (one symbol table, one render
path). Rendering only: imports the result documents of the other rooms, computes nothing but
the Melnikov boundary it draws (from ``homoclinic.thresholds``).
"""

from gearengine.plots.analysis import analysis_figure, threshold_figure
from gearengine.plots.style import MEDIA_TYPES, ImageFormat
from gearengine.plots.sweep import sweep_figure

__all__ = ["MEDIA_TYPES", "ImageFormat", "analysis_figure", "sweep_figure", "threshold_figure"]
