"""ROSS (ross-rotordynamics, a test-only check), imported past its plotly theme."""

from __future__ import annotations

from types import ModuleType

import pytest


def import_ross() -> ModuleType:
    """``ross``: ross 2.3.0 registers a template with the ``scattermapbox`` trace that
    plotly >= 6 no longer has, so ``import ross`` raises; the template is built leniently
    (invalid entries skipped) for the import only. Skips the test when ROSS is absent."""
    go = pytest.importorskip("plotly.graph_objects")
    layout = go.layout
    strict = layout.Template

    class Lenient(strict):  # type: ignore[misc, valid-type]
        def __init__(self, arg=None, **kwargs):
            super().__init__(arg, skip_invalid=True, **kwargs)

    layout.Template = Lenient
    try:
        return pytest.importorskip("ross")
    finally:
        layout.Template = strict
