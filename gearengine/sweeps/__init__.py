"""The sweeps room: bifurcation diagrams (one axis) and chaos maps (two axes).

Data flow: ``request`` (axes, validation) -> ``plan`` (chunks, cost) -> ``compute`` (each chunk's
points through ``numerics.batch`` and the Melnikov verdict) -> ``results`` (documents) ->
``export`` (JSON assembled from chunks, CSV, agreement table); ``windows`` and ``gate`` read
the results for speed windows and the CI gate. Imports the model, homoclinic and numerics rooms
(and ``gearengine.jobs``, the job-kind registry it runs through).
"""

from gearengine.sweeps.compute import compute_chunk, compute_chunk_json, run_local
from gearengine.sweeps.export import (
    agreement_table,
    chunk_bifurcations,
    chunk_json,
    csv_rows,
    points_of_chunk,
    result_json,
    text_blocks,
    to_csv,
)
from gearengine.sweeps.plan import (
    DEFAULT_CHUNK_POINTS,
    SweepPlan,
    balanced_chunk_points,
    sweep_work,
)
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
    "balanced_chunk_points",
    "checked",
    "chunk_bifurcations",
    "chunk_json",
    "compute_chunk",
    "compute_chunk_json",
    "csv_rows",
    "points_of_chunk",
    "request_errors",
    "result_json",
    "run_local",
    "sweep_work",
    "text_blocks",
    "to_csv",
    "validated",
]
