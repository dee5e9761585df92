"""/v1/remedies: what to change in a failing design, by how much, as a durable job.

One chunk per lever (``gearengine.gate.remedies.search``), then the two-lever combination; the
result is the document ``gearengine remedies --json`` writes. Bad levers and envelopes are
refused (422 naming the field) by the request model, before any compute.
"""

from __future__ import annotations

from gearengine.gate.remedies import RemediesResult
from service.api.routes.jobs import JobRoutes

REMEDIES = JobRoutes(
    kind="remedies",
    prefix="remedies",
    noun="remedies",
    plural="remedies_jobs",
    submit_summary="Submit a failing design and its envelope: the smallest change of each lever "
    "that makes it pass",
    submit_doc="Validate and store the search; it runs on the workers, one chunk per lever. "
    "Answers 202 with the job and its\n``Location``; poll it (``Retry-After``) and fetch "
    "``/result`` once succeeded. Cancelling stops it after the running lever.",
    result_model=RemediesResult,
    result_summary="Remedies of a succeeded job: ranked, each with its verified envelope report",
    budget_path="envelope",
)
router = REMEDIES.router()
