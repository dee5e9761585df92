"""The routes every kind of durable job has: submit, list, status, result, cancel.

``JobRoutes(kind, prefix, ...).router()`` gives, for a kind of ``gearengine.studies.jobs.KINDS``:
``POST /v1/<prefix>`` (202, ``Location``, ``Retry-After``), ``GET /v1/<prefix>`` (the caller's
jobs of that kind, newest first), ``GET /v1/<prefix>/{id}`` (``?wait=S``: held until the job
finishes, at most S seconds), ``GET /v1/<prefix>/{id}/result``
(409 until succeeded; ``?partial=true`` for the finished chunks) and ``DELETE
/v1/<prefix>/{id}`` (cancel). Jobs belong to the API key that submitted them (``require_key``'s
key id; None with auth off): another key, or another kind's route, gets 404 and does not list
them. A kind with a result of its own (sweeps: CSV, windows) sets ``result=False`` and adds its
routes to the router returned.

No ``from __future__ import annotations`` here: the endpoints are closures whose annotations
(the kind's request model) FastAPI reads at run time.
"""

import asyncio
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any, Literal

from fastapi import APIRouter, Query, Request, Response
from pydantic import BaseModel
from starlette.concurrency import run_in_threadpool

from gearengine.studies import jobs as job_kinds
from service.api.deps import AppSettings, Jobs, Owner, app_limits
from service.api.responses import JSON, PNG, PROBLEMS, RETRY_AFTER_HEADER, SVG, header
from service.core.config import Settings
from service.errors import ProblemError
from service.jobs.models import UNFINISHED, Job, JobPage, JobStatus
from service.jobs.runtime import JobQueue
from service.jobs.store import QueueFullError

RETRY_AFTER = {"queued": "5", "running": "2"}
"""Seconds a client should wait before polling an unfinished job again."""
MAX_WAIT_S = 30.0
"""Longest ``wait`` of a status request [s] (``Settings.max_status_wait_s`` may lower it)."""
WAIT_RECHECK_S = 0.02
"""How often a status request with ``wait`` reads its job again [s]: a store read every 20 ms
in the server costs a fraction of a client's poll every 10 ms (a whole request each: about
0.8 ms of the server's CPU, 0.25 s of it over a served 100 x 100 map, issue 31)."""
WAIT_DOC = (
    "Seconds to hold the request while the job is queued or running: it answers as soon as the "
    "job finishes, or after wait seconds, unfinished, with Retry-After. One request instead of "
    "a poll every few milliseconds."
)
QUEUE_FULL_RETRY = "30"
PARTIAL_HEADER = "X-Partial-Result"
"""Set to true on a result with chunks missing (?partial=true on a job that did not succeed)."""

NOT_FOUND = {404: {"description": "No such job for this API key."}}
RETRY = {"Retry-After": RETRY_AFTER_HEADER}
CONFLICT = {
    409: {
        "description": "The job has not succeeded (yet); ?partial=true gives its finished "
        "chunks. Retry-After while it is queued or running.",
        "headers": RETRY,
    }
}

PLOT_RESPONSES = {
    **PROBLEMS,
    **NOT_FOUND,
    **CONFLICT,
    200: {"content": {PNG: {}, SVG: {}}, "description": "The figure."},
    406: {"description": "Neither PNG nor SVG is acceptable."},
}
"""Responses of a job's ``/{job_id}/plot`` route."""

PlotFormat = Annotated[
    Literal["png", "svg"] | None, Query(description="png or svg; else the Accept header.")
]
"""The ``format`` query of a job's ``/plot`` route."""


def plot_format(fmt: str | None, accept: str) -> Literal["png", "svg"]:
    """The figure's format: ``fmt`` when given, else the first acceptable of the ``Accept``
    header (406 when neither PNG nor SVG is)."""
    if fmt is not None:
        return fmt  # type: ignore[return-value]
    types = [part.split(";")[0].strip() for part in accept.split(",") if part.strip()]
    for t in types or ["*/*"]:
        if t in (PNG, "image/*", "*/*"):
            return "png"
        if t == SVG:
            return "svg"
    raise ProblemError(406, "not-acceptable", "Not acceptable", f"plots are {PNG} or {SVG}")


def poll_headers(job: Job) -> dict[str, str]:
    """``Retry-After`` while the job is queued or running."""
    return {"Retry-After": RETRY_AFTER[job.status]} if job.status in UNFINISHED else {}


def no_check(body: BaseModel, request: Request, settings: Settings) -> None:
    """A kind whose request model and work budget say everything."""


@dataclass(frozen=True)
class JobRoutes:
    """The routes of one kind of job.

    Attributes:
        kind: its name in ``gearengine.studies.jobs.KINDS``.
        prefix: the routes' prefix, ``/v1/<prefix>``.
        noun, plural: how messages, summaries and operation ids name one job and several.
        submit_summary, submit_doc: the POST route's summary and description.
        result_model, result_summary, result_doc: the result route's model and texts.
        check: ``(body, request, settings)``: refusals beyond the model (422 problems), before
            the work budget (the kind's ``work`` against max_job_steps) is checked.
        chunk_size: ``(request, settings) -> units of work per chunk`` (default: the kind's).
        budget_path: the field a refusal over the work budget names.
    """

    kind: str
    prefix: str
    noun: str
    plural: str
    submit_summary: str
    submit_doc: str
    result_model: type[BaseModel] | None = None
    result_summary: str = ""
    result_doc: str = ""
    check: Callable[[Any, Request, Settings], None] = no_check
    chunk_size: Callable[[Any, Settings], int] | None = None
    budget_path: str = "axes"

    def job_or_404(self, jobs: JobQueue, job_id: str, owner: str | None) -> Job:
        """The caller's job of this kind, else 404."""
        job = jobs.store.get(job_id, owner, self.kind)
        if job is None:
            raise ProblemError(404, "not-found", "Not found", f"no {self.noun} job {job_id}")
        return job

    def succeeded(self, jobs: JobQueue, job_id: str, owner: str | None) -> Job:
        """The caller's succeeded job, else 404 or 409 (with Retry-After while unfinished)."""
        job = self.job_or_404(jobs, job_id, owner)
        if job.status != "succeeded":
            raise ProblemError(
                409,
                "not-finished" if job.status in UNFINISHED else "no-result",
                "No result",
                f"{self.noun} {job_id} is {job.status}: the full result exists only once it has "
                "succeeded; ?partial=true gives the points of its finished chunks",
                headers=poll_headers(job),
            )
        return job

    def submit(
        self, body: BaseModel, request: Request, response: Response, owner: str | None,
        settings: Settings, jobs: JobQueue,
    ) -> Job:  # fmt: skip
        """Check, plan and store a job; 429 when the queue is full."""
        self.check(body, request, settings)
        app_limits(request).check_job(self.kind, body, self.noun, self.budget_path)
        kind = job_kinds.kind(self.kind)
        size = kind.chunk_points if self.chunk_size is None else self.chunk_size(body, settings)
        try:
            job = jobs.store.submit(
                owner, body.model_dump_json(), kind.chunk_counts(body, size), size,
                settings.max_queued_jobs, kind=self.kind,
            )  # fmt: skip
        except QueueFullError as exc:
            raise ProblemError(
                429,
                "queue-full",
                "Too many requests",
                f"{exc} (max_queued_jobs); retry later",
                headers={"Retry-After": QUEUE_FULL_RETRY},
            ) from None
        jobs.wake()
        response.headers["Location"] = f"/v1/{self.prefix}/{job.id}"
        response.headers.update(poll_headers(job))
        return job

    def router(self, result: bool = True) -> APIRouter:
        """The kind's routes (with its generic result route unless ``result`` is False)."""
        routes = self
        router = APIRouter(prefix=f"/v1/{self.prefix}")
        model = job_kinds.kind(self.kind).request

        def post(
            body: model,  # type: ignore[valid-type]
            request: Request,
            response: Response,
            owner: Owner,
            settings: AppSettings,
            jobs: Jobs,
        ) -> Job:
            return routes.submit(body, request, response, owner, settings, jobs)

        def listing(
            owner: Owner,
            jobs: Jobs,
            status: Annotated[
                JobStatus | None, Query(description="Only jobs in this status.")
            ] = None,
            limit: Annotated[int, Query(ge=1, le=100, description="Jobs per page.")] = 20,
            offset: Annotated[
                int, Query(ge=0, le=2**31, description="Jobs to skip (newest first).")
            ] = 0,
        ) -> JobPage:
            items, total = jobs.store.list(owner, status, limit, offset, routes.kind)
            more = offset + len(items) < total
            return JobPage(
                items=items, total=total, next_offset=offset + len(items) if more else None
            )

        async def status(
            job_id: str,
            response: Response,
            owner: Owner,
            jobs: Jobs,
            settings: AppSettings,
            wait: Annotated[
                float, Query(ge=0.0, le=MAX_WAIT_S, allow_inf_nan=False, description=WAIT_DOC)
            ] = 0.0,
        ) -> Job:
            job = await run_in_threadpool(routes.job_or_404, jobs, job_id, owner)
            deadline = time.monotonic() + min(wait, settings.max_status_wait_s)
            while job.status in UNFINISHED and time.monotonic() < deadline:
                await asyncio.sleep(min(WAIT_RECHECK_S, max(0.0, deadline - time.monotonic())))
                job = await run_in_threadpool(routes.job_or_404, jobs, job_id, owner)
            response.headers.update(poll_headers(job))
            return job

        def cancel(job_id: str, owner: Owner, jobs: Jobs) -> Job:
            routes.job_or_404(jobs, job_id, owner)
            job = jobs.store.cancel(job_id, owner, routes.kind)
            assert job is not None
            if job.status not in ("cancelled", *UNFINISHED):
                raise ProblemError(
                    409, "finished", "Already finished", f"{routes.noun} {job_id} {job.status}"
                )
            jobs.wake()
            return job

        router.add_api_route(
            "",
            post,
            methods=["POST"],
            name=f"post_{self.noun}",
            status_code=202,
            response_model=Job,
            responses={
                **PROBLEMS,
                202: {
                    "description": "Stored and queued.",
                    "headers": {
                        "Location": header("URL of the job: poll it."),
                        "Retry-After": RETRY_AFTER_HEADER,
                    },
                },
                429: {
                    "description": "Too many unfinished jobs; see Retry-After.",
                    "headers": RETRY,
                },
            },
            summary=self.submit_summary,
            description=self.submit_doc,
        )
        router.add_api_route(
            "",
            listing,
            methods=["GET"],
            name=f"list_{self.plural}",
            response_model=JobPage,
            responses=PROBLEMS,
            summary=f"The caller's {self.noun} jobs",
            description="Newest first, paginated with ``limit`` and ``offset``.",
        )
        router.add_api_route(
            "/{job_id}",
            status,
            methods=["GET"],
            name=f"get_{self.noun}",
            response_model=Job,
            responses={**PROBLEMS, **NOT_FOUND, 200: {"description": "The job.", "headers": RETRY}},
            summary=f"Status and progress of a {self.noun} job",
            description="``Retry-After`` is set while the job is queued or running; ``?wait=S`` "
            "holds the request until the job finishes, at most S seconds.",
        )
        router.add_api_route(
            "/{job_id}",
            cancel,
            methods=["DELETE"],
            name=f"cancel_{self.noun}",
            response_model=Job,
            responses={**PROBLEMS, **NOT_FOUND, 409: {"description": "The job already finished."}},
            summary=f"Cancel a {self.noun} job",
            description="No new chunk of the job starts; running chunks are dropped. Cancelling "
            "a cancelled job\nis a no-op; a succeeded or failed job cannot be cancelled (409).",
        )
        if result:
            self._result_route(router)
        return router

    def assembled(self, jobs: JobQueue, job_id: str) -> BaseModel:
        """The kind's result document of job ``job_id``: its stored request and chunk results
        joined by the kind's ``assemble`` (ValueError from a kind with no partial result)."""
        kind = job_kinds.kind(self.kind)
        request = job_kinds.validated_json(kind, jobs.store.request_json(job_id))
        return kind.assemble(request, list(jobs.store.chunk_results(job_id)))

    def figure_route(
        self,
        router: APIRouter,
        summary: str,
        description: str,
        figure: Callable[[Any, Literal["png", "svg"]], bytes],
    ) -> None:
        """``plot_route`` for a kind whose figure is drawn from its result document alone:
        ``figure(result, fmt)`` of the ``assembled`` result of a succeeded job."""
        routes = self

        def draw(jobs: JobQueue, job_id: str, fmt: Literal["png", "svg"]) -> bytes:
            return figure(routes.assembled(jobs, job_id), fmt)

        self.plot_route(router, summary, description, draw)

    def plot_route(
        self,
        router: APIRouter,
        summary: str,
        description: str,
        draw: Callable[[JobQueue, str, Literal["png", "svg"]], bytes],
    ) -> None:
        """Add ``GET /{job_id}/plot`` to ``router``: the figure ``draw(jobs, job_id, fmt)`` of a
        succeeded job of the kind (409 before), PNG or SVG by ``?format`` or ``Accept``."""
        routes = self

        async def plot(
            job_id: str, request: Request, owner: Owner, jobs: Jobs, format: PlotFormat = None
        ) -> Response:
            fmt = plot_format(format, request.headers.get("accept", ""))
            await run_in_threadpool(routes.succeeded, jobs, job_id, owner)
            body = await run_in_threadpool(draw, jobs, job_id, fmt)
            return Response(body, media_type=PNG if fmt == "png" else SVG)

        router.add_api_route(
            "/{job_id}/plot",
            plot,
            methods=["GET"],
            name="get_plot",
            response_class=Response,
            responses=PLOT_RESPONSES,
            summary=summary,
            description=description,
        )

    def _result_route(self, router: APIRouter) -> None:
        routes = self

        async def result(
            job_id: str,
            owner: Owner,
            jobs: Jobs,
            partial: Annotated[
                bool,
                Query(
                    description="Also answer for a job that did not succeed (cancelled, failed, "
                    "or still running): the result of its finished chunks, with "
                    f"{PARTIAL_HEADER}: true."
                ),
            ] = False,
        ) -> Response:
            check = routes.job_or_404 if partial else routes.succeeded
            job = await run_in_threadpool(check, jobs, job_id, owner)
            missing = job.status != "succeeded"

            def assemble() -> bytes:
                try:
                    document = routes.assembled(jobs, job_id)
                except ValueError as exc:  # a kind with no partial result before its chunks
                    raise ProblemError(
                        409, "no-result", "No result", f"{routes.noun} {job_id}: {exc}",
                        headers=poll_headers(job),
                    ) from None  # fmt: skip
                return document.model_dump_json().encode()

            body = await run_in_threadpool(assemble)
            headers = {PARTIAL_HEADER: "true", **poll_headers(job)} if missing else {}
            return Response(body, media_type=JSON, headers=headers)

        router.add_api_route(
            "/{job_id}/result",
            result,
            methods=["GET"],
            name="get_result",
            response_model=self.result_model,
            responses={
                **PROBLEMS,
                **NOT_FOUND,
                **CONFLICT,
                200: {
                    "description": f"The {self.noun}'s result.",
                    "headers": {
                        PARTIAL_HEADER: header("true when chunks are missing (?partial=true)."),
                        "Retry-After": RETRY_AFTER_HEADER,
                    },
                },
            },
            summary=self.result_summary or f"Result of a succeeded {self.noun} job",
            description=self.result_doc,
        )
