"""/v1/runups: run-ups and run-downs of a design as durable jobs (``gearengine.studies.runup``).

The kind-generic routes of ``routes.jobs``: submit (202 + ``Location``), list, status, result
(the document ``gearengine runup --json`` writes), cancel; and the figure of a succeeded run-up
(``/plot``, the figure of ``gearengine runup --plot``). Bad ramps (zero or negative rate,
speeds outside the plausible range, a profile over the work budget) are 422 problems naming
the field, from the request's checks, before anything is stored or computed.
"""

from __future__ import annotations

from fastapi import Request

from gearengine.plots import runup_figure
from gearengine.studies.runup.profile import checked_runup
from gearengine.studies.runup.request import RunupRequest
from gearengine.studies.runup.results import RunupResult
from service.api.routes.jobs import JobRoutes
from service.core.config import Settings


def _check(body: RunupRequest, request: Request, settings: Settings) -> None:
    checked_runup(body)


RUNUPS = JobRoutes(
    kind="runup",
    prefix="runups",
    noun="runup",
    plural="runups",
    submit_summary="Submit a run-up or run-down of a design",
    submit_doc="Validate and store the run-up; it runs on the workers (one chunk per ensemble "
    "member and\ntwo for the quasi-static loop). Answers 202 with the job and its "
    "``Location``; poll it and\nfetch ``/result`` or ``/plot`` once succeeded.",
    result_model=RunupResult,
    result_summary="Result of a succeeded run-up: bins against speed, jumps, quasi-static loop",
    check=_check,
    budget_path="rate",
)
router = RUNUPS.router()


RUNUPS.figure_route(
    router,
    "Figure of a succeeded run-up (PNG or SVG)",
    "Speed on x: the DTE envelope up and down over the quasi-static hysteresis loop, jumps\n"
    "marked, contact-status bands, the finite-time Lyapunov exponent, the Melnikov window.",
    runup_figure,
)
