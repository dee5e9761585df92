"""/v1/basins: one design's coexisting attractors and basin picture as a durable job (kind
``basins``, ``gearengine.studies.basins``), for analyses with basins over the synchronous budget.

The kind-generic routes of ``routes.jobs``: submit (202 + ``Location``), list, status, result
(the document ``gearengine basins FILE --json`` prints), cancel; and the basin picture of a
succeeded job (``/plot``, the bytes of ``gearengine basins FILE --plot``).
"""

from __future__ import annotations

from gearengine.analysis import AnalysisResult
from gearengine.plots import basins_figure
from service.api.routes.jobs import JobRoutes

BASINS = JobRoutes(
    kind="basins",
    prefix="basins",
    noun="basins",
    plural="basins",
    submit_summary="Submit the basins of one design: its attractors and the fraction of starts "
    "reaching each",
    submit_doc="An analysis request (``settings.basins``; the defaults, 16 starts, when absent) "
    "of any size up to the job budget (max_job_steps), unlike ``POST /v1/analyses``, which is "
    "bound by the synchronous budget. It runs on the workers; answers 202 with the job and its "
    "``Location``; poll it and fetch ``/result`` or ``/plot`` once succeeded.",
    result_model=AnalysisResult,
    result_summary="Result of a succeeded basins job: the analysis with its attractors",
    result_doc="The body ``POST /v1/analyses`` returns for the same request (``gearengine "
    "basins FILE --json``): the Melnikov and numerical verdicts, the attractors with their "
    "basin fractions, 95 % intervals and start counts.",
    budget_path="settings.basins.starts",
)
router = BASINS.router()


BASINS.figure_route(
    router,
    "Basin picture of a succeeded basins job (PNG or SVG)",
    "The starts coloured by the attractor they reach, with the attractors' stroboscopic points "
    "(the\nbytes of ``POST /v1/analyses/basins/plot`` and ``gearengine basins FILE --plot``).",
    basins_figure,
)
