"""The sweeps room: bifurcation diagrams (one axis) and chaos maps (two axes).

Data flow: ``request`` (axes, validation) -> ``plan`` (chunks, cost) -> ``compute`` (each chunk's
points through ``numerics.batch`` and the Melnikov verdict) -> ``results`` (documents) ->
``export`` (JSON assembled from chunks, CSV, agreement table). Imports the model, melnikov and
numerics rooms.
"""

from gearengine.sweeps.compute import compute_chunk, compute_chunk_json, run_local
from gearengine.sweeps.export import (
    agreement_table,
    chunk_bifurcations,
    chunk_json,
    chunk_points,
    csv_rows,
    result_json,
    text_blocks,
    to_csv,
)
from gearengine.sweeps.plan import DEFAULT_CHUNK_POINTS, SweepPlan, sweep_work
from gearengine.sweeps.request import (
    SweepAxis,
    SweepRequest,
    checked,
    request_errors,
    validated,
)
from gearengine.sweeps.results import SweepBifurcation, SweepPoint, SweepResult

__all__ = [
    "DEFAULT_CHUNK_POINTS",
    "SweepAxis",
    "SweepBifurcation",
    "SweepPlan",
    "SweepPoint",
    "SweepRequest",
    "SweepResult",
    "agreement_table",
    "checked",
    "chunk_bifurcations",
    "chunk_json",
    "chunk_points",
    "compute_chunk",
    "compute_chunk_json",
    "csv_rows",
    "request_errors",
    "result_json",
    "run_local",
    "sweep_work",
    "text_blocks",
    "to_csv",
    "validated",
]
