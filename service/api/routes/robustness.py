"""/v1/robustness: probabilities of chaos and rattle for the gears that will be built (a durable
job of kind ``robustness``, ``gearengine.studies.robustness.study``), on the generic job routes."""

from __future__ import annotations

from fastapi import Request

from gearengine.studies.robustness.results import RobustnessResult
from gearengine.studies.robustness.study import RobustnessRequest, checked
from service.api.routes.jobs import JobRoutes
from service.core.config import Settings


def _check(body: RobustnessRequest, request: Request, settings: Settings) -> None:
    checked(body, settings.max_job_points)


ROBUSTNESS = JobRoutes(
    kind="robustness",
    prefix="robustness",
    noun="robustness",
    plural="robustness",
    submit_summary="Submit a robustness study: probabilities over a design's tolerances",
    submit_doc="Validate and store the study (scrambled Sobol samples of the design's "
    "tolerances at each operating point; with sensitivity also Sobol indices); it runs on the "
    "workers. Answers 202 with the job and its ``Location``; poll it and fetch ``/result``.",
    result_model=RobustnessResult,
    result_summary="Result of a succeeded robustness study",
    result_doc="Per operating point: the probability of each class and event with its 95 % "
    "interval and sample count, the DTE spread and, with sensitivity, Sobol indices ranked in "
    "plain words.",
    check=_check,
    budget_path="samples",
)
router = ROBUSTNESS.router()
