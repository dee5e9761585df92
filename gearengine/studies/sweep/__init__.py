"""The sweep study: bifurcation diagrams (one axis) and chaos maps (two axes).

Data flow: ``axes`` (the point of each grid value) -> ``request`` (axes, validation) -> ``plan``
(chunks, cost) -> ``compute`` (each chunk's points through ``numerics.batch`` and the Melnikov
verdict) -> ``points`` (one document per point) -> ``export`` (JSON assembled from chunks, CSV
rows, agreement table) and ``windows`` (speed windows) -> ``results`` (the whole result and its
tables). ``gate.envelope`` reads the results for the CI gate. Imports the model, homoclinic and
numerics rooms (and ``studies.jobs``, the job-kind registry it runs through).
"""

from gearengine.studies.sweep.compute import compute_chunk, compute_chunk_json, run_local
from gearengine.studies.sweep.export import (
    agreement_table,
    chunk_bifurcations,
    chunk_json,
    csv_rows,
    points_of_chunk,
    result_json,
    text_blocks,
)
from gearengine.studies.sweep.plan import (
    DEFAULT_CHUNK_POINTS,
    SweepPlan,
    balanced_chunk_points,
    sweep_work,
)
from gearengine.studies.sweep.points import SweepBifurcation, SweepPoint
from gearengine.studies.sweep.request import (
    SweepAxis,
    SweepRequest,
    checked,
    request_errors,
    validated,
)
from gearengine.studies.sweep.results import SweepResult, to_csv

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
