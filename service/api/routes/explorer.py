"""GET /: the design explorer, a small page over the API (service/explorer/).

The page and its script are static files of the service; the only library it uses, plotly.js
for the interactive envelope map, is served from the ``plotly`` package installed in the
Python environment, so the page works offline and requests nothing outside the service. The
page itself is public; the API calls it makes carry the key typed into it.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

from fastapi import APIRouter
from fastapi.responses import FileResponse

from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.train import EXAMPLE_TRAIN
from service.errors import ProblemError

router = APIRouter(include_in_schema=False)

PAGE_DIR = Path(__file__).resolve().parents[2] / "explorer"
ASSETS = {
    "explorer.js": "text/javascript; charset=utf-8",
    "robustness.js": "text/javascript; charset=utf-8",
    "signal.js": "text/javascript; charset=utf-8",
    "runup.js": "text/javascript; charset=utf-8",
    "explorer.css": "text/css; charset=utf-8",
}
"""The page's own files, by name, with their media types (nothing else is served)."""
GEOMETRY_EXAMPLE = {
    "driver": {"teeth": 18, "module": "3 mm", "face_width": "25 mm", "pressure_angle": "20 deg",
               "profile_shift": 0.0, "bore": "20 mm", "material": "steel"},
    "driven": {"teeth": 30, "module": "3 mm", "face_width": "25 mm", "pressure_angle": "20 deg",
               "profile_shift": 0.0, "bore": "30 mm", "material": "steel"},
    "speed": "3000 rpm",
    "torque": "60 N*m",
    "mesh": {"stiffness": "iso6336", "damping_ratio": 0.04, "half_backlash": "40 um"},
    "transmission_error": {"harmonics": [{"amplitude": "8 um", "phase": 0.0}]},
    "backlash_law": "piecewise",
}  # fmt: skip
"""The geometry form's prefill (examples/design-geometry.json)."""


def plotly_js() -> Path | None:
    """The ``plotly.min.js`` shipped inside the installed ``plotly`` package, if any."""
    spec = importlib.util.find_spec("plotly")
    if spec is None or not spec.submodule_search_locations:
        return None
    path = Path(next(iter(spec.submodule_search_locations))) / "package_data" / "plotly.min.js"
    return path if path.is_file() else None


@router.api_route("/", methods=["GET", "HEAD"])
async def explorer_page() -> FileResponse:
    """The explorer (links to /docs and /redoc in its header)."""
    return FileResponse(PAGE_DIR / "index.html", media_type="text/html; charset=utf-8")


@router.get("/explorer/defaults.json")
async def explorer_defaults() -> dict[str, Any]:
    """What the form is prefilled with: the README's design (direct form), a geometry-form
    design, the paper's dimensionless parameters for the advanced switch, and issue 32's gear
    train for the train box's example button."""
    return {"direct": EXAMPLE_DESIGN, "geometry": GEOMETRY_EXAMPLE, "params": PAPER_SECTION_41,
            "train": EXAMPLE_TRAIN}  # fmt: skip


@router.get("/explorer/{name}")
async def explorer_asset(name: str) -> FileResponse:
    if name not in ASSETS:
        raise ProblemError(404, "not-found", "Not found", f"no explorer file {name}")
    return FileResponse(PAGE_DIR / name, media_type=ASSETS[name])


@router.get("/static/plotly.min.js")
async def plotly_asset() -> FileResponse:
    path = plotly_js()
    if path is None:
        raise ProblemError(404, "not-found", "Not found", "plotly is not installed")
    return FileResponse(path, media_type=ASSETS["explorer.js"])
