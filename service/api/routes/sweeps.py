"""/v1/sweeps: the durable queue of bifurcation sweeps and chaos maps.

Jobs belong to the API key that submitted them (``require_key``'s key id; None with auth off):
another key gets 404 and does not see them in listings.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Annotated, Literal

from fastapi import APIRouter, Query, Request, Response
from fastapi.responses import StreamingResponse
from starlette.concurrency import run_in_threadpool

from gearengine.plots import sweep_figure
from gearengine.sweeps import (
    SweepPlan,
    SweepPoint,
    SweepRequest,
    SweepResult,
    checked,
    chunk_bifurcations,
    csv_rows,
    points_of_chunk,
    result_json,
)
from gearengine.sweeps.results import SpeedWindows
from gearengine.sweeps.windows import SPEED, speed_windows
from service.api.deps import AppLimits, AppSettings, Jobs, Owner
from service.api.responses import JSON, PNG, PROBLEMS, RETRY_AFTER_HEADER, SVG, header
from service.errors import ProblemError
from service.jobs.models import UNFINISHED, Job, JobPage, JobStatus
from service.jobs.runtime import SweepJobs
from service.jobs.store import QueueFullError

router = APIRouter(prefix="/v1/sweeps")

CSV = "text/csv"
RETRY_AFTER = {"queued": "5", "running": "2"}
"""Seconds a client should wait before polling an unfinished job again."""
QUEUE_FULL_RETRY = "30"

_NOT_FOUND = {404: {"description": "No such job for this API key."}}
_RETRY = {"Retry-After": RETRY_AFTER_HEADER}
_CONFLICT = {
    409: {
        "description": "The job has not succeeded (yet); ?partial=true gives its finished "
        "chunks. Retry-After while it is queued or running.",
        "headers": _RETRY,
    }
}
PARTIAL_HEADER = "X-Partial-Result"
"""Set to true on a result with points missing (?partial=true on a job that did not succeed)."""


def _job_or_404(jobs: SweepJobs, job_id: str, owner: str | None) -> Job:
    job = jobs.store.get(job_id, owner)
    if job is None:
        raise ProblemError(404, "not-found", "Not found", f"no sweep job {job_id}")
    return job


def _poll_headers(job: Job) -> dict[str, str]:
    return {"Retry-After": RETRY_AFTER[job.status]} if job.status in UNFINISHED else {}


def _succeeded(jobs: SweepJobs, job_id: str, owner: str | None) -> Job:
    job = _job_or_404(jobs, job_id, owner)
    if job.status != "succeeded":
        raise ProblemError(
            409,
            "not-finished" if job.status in UNFINISHED else "no-result",
            "No result",
            f"sweep {job_id} is {job.status}: the full result exists only once it has "
            "succeeded; ?partial=true gives the points of its finished chunks",
            headers=_poll_headers(job),
        )
    return job


@router.post(
    "",
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
        429: {"description": "Too many unfinished jobs; see Retry-After.", "headers": _RETRY},
    },
    summary="Submit a bifurcation sweep (one axis) or a chaos map (two axes)",
)
def post_sweep(
    body: SweepRequest,
    response: Response,
    owner: Owner,
    settings: AppSettings,
    jobs: Jobs,
    limits: AppLimits,
) -> Job:
    """Validate and store the sweep; it runs on the workers. Answers 202 with the job and its
    ``Location``; poll it (``Retry-After``) and fetch ``/result`` or ``/plot`` once succeeded."""
    checked(body, settings.max_sweep_points)
    limits.check_sweep(body)
    plan = SweepPlan(body, settings.sweep_chunk_points)
    try:
        job = jobs.store.submit(
            owner, body.model_dump_json(), plan.point_counts(), plan.chunk_points,
            settings.max_queued_jobs,
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
    response.headers["Location"] = f"/v1/sweeps/{job.id}"
    response.headers.update(_poll_headers(job))
    return job


@router.get("", response_model=JobPage, responses=PROBLEMS, summary="The caller's sweep jobs")
def list_sweeps(
    owner: Owner,
    jobs: Jobs,
    status: Annotated[JobStatus | None, Query(description="Only jobs in this status.")] = None,
    limit: Annotated[int, Query(ge=1, le=100, description="Jobs per page.")] = 20,
    offset: Annotated[int, Query(ge=0, le=2**31, description="Jobs to skip (newest first).")] = 0,
) -> JobPage:
    """Newest first, paginated with ``limit`` and ``offset``."""
    items, total = jobs.store.list(owner, status, limit, offset)
    more = offset + len(items) < total
    return JobPage(items=items, total=total, next_offset=offset + len(items) if more else None)


@router.get(
    "/{job_id}",
    response_model=Job,
    responses={
        **PROBLEMS,
        **_NOT_FOUND,
        200: {"description": "The job.", "headers": _RETRY},
    },
    summary="Status and progress of a sweep job",
)
def get_sweep(job_id: str, response: Response, owner: Owner, jobs: Jobs) -> Job:
    """``Retry-After`` is set while the job is queued or running."""
    job = _job_or_404(jobs, job_id, owner)
    response.headers.update(_poll_headers(job))
    return job


@router.delete(
    "/{job_id}",
    response_model=Job,
    responses={**PROBLEMS, **_NOT_FOUND, 409: {"description": "The job already finished."}},
    summary="Cancel a sweep job",
)
def cancel_sweep(job_id: str, owner: Owner, jobs: Jobs) -> Job:
    """No new chunk of the job starts; running chunks are dropped. Cancelling a cancelled job
    is a no-op; a succeeded or failed job cannot be cancelled (409)."""
    _job_or_404(jobs, job_id, owner)
    job = jobs.store.cancel(job_id, owner)
    assert job is not None
    if job.status not in ("cancelled", *UNFINISHED):
        raise ProblemError(409, "finished", "Already finished", f"sweep {job_id} {job.status}")
    jobs.wake()
    return job


def _windows(jobs: SweepJobs, job_id: str, sweep: SweepRequest) -> list[SpeedWindows] | None:
    """The speed windows of a sweep over the driver speed; None, without reading a point,
    for other sweeps (a map's result streams chunk by chunk)."""
    if SPEED not in [a.parameter for a in sweep.axes]:
        return None
    return speed_windows(sweep, list(_points(jobs, job_id)))


def _stored_points(jobs: SweepJobs, job_id: str) -> Iterator[SweepPoint]:
    """The stored points unvalidated (``model_construct``: the workers wrote them from valid
    points; nested documents such as ``physical`` stay plain dicts), one chunk in memory at a
    time: the CSV of a million-point map streams at the speed of its writer, not of
    validation."""
    for array in jobs.store.chunk_results(job_id):
        for item in points_of_chunk(array):
            yield SweepPoint.model_construct(**item)


def _points(jobs: SweepJobs, job_id: str) -> Iterator[SweepPoint]:
    for array in jobs.store.chunk_results(job_id):
        for item in points_of_chunk(array):
            yield SweepPoint.model_validate(item)


@router.get(
    "/{job_id}/result",
    response_model=SweepResult,
    responses={
        **PROBLEMS,
        **_NOT_FOUND,
        **_CONFLICT,
        200: {
            "content": {JSON: {}, CSV: {}},
            "description": "The sweep's points.",
            "headers": {
                PARTIAL_HEADER: header("true when points are missing (?partial=true)."),
                "Retry-After": RETRY_AFTER_HEADER,
            },
        },
    },
    summary="Result of a succeeded sweep: JSON, or CSV with ?format=csv",
)
def get_result(
    job_id: str,
    owner: Owner,
    jobs: Jobs,
    format: Annotated[
        Literal["json", "csv"], Query(description="json or csv (streamed).")
    ] = "json",
    partial: Annotated[
        bool,
        Query(
            description="Also answer for a job that did not succeed (cancelled, failed, or "
            'still running): the points of its finished chunks, marked "partial": true and '
            f"{PARTIAL_HEADER}: true."
        ),
    ] = False,
) -> Response:
    """Every point with its axis values, classification, period, LLE, contact regime, Melnikov
    verdict and the x of its last stroboscopic (Poincare) points; a one-axis continuation
    sweep also its located bifurcation points (``bifurcations``)."""
    job = _job_or_404(jobs, job_id, owner) if partial else _succeeded(jobs, job_id, owner)
    missing = job.status != "succeeded"
    headers = {PARTIAL_HEADER: "true", **_poll_headers(job)} if missing else {}
    sweep = SweepRequest.model_validate_json(jobs.store.request_json(job_id))
    axes = sweep.axes
    if format == "csv":
        name = f"sweep-{job_id}{'-partial' if missing else ''}.csv"
        return StreamingResponse(
            csv_rows(axes, _stored_points(jobs, job_id), sweep.outputs, sweep.design is not None),
            media_type=CSV,
            headers={"Content-Disposition": f'attachment; filename="{name}"', **headers},
        )
    return StreamingResponse(
        result_json(
            axes,
            jobs.store.chunk_results(job_id),
            partial=missing,
            windows=_windows(jobs, job_id, sweep),
        ),
        media_type=JSON,
        headers=headers,
    )


def _plot_format(fmt: str | None, accept: str) -> Literal["png", "svg"]:
    if fmt is not None:
        return fmt  # type: ignore[return-value]
    types = [part.split(";")[0].strip() for part in accept.split(",") if part.strip()]
    for t in types or ["*/*"]:
        if t in (PNG, "image/*", "*/*"):
            return "png"
        if t == SVG:
            return "svg"
    raise ProblemError(406, "not-acceptable", "Not acceptable", f"plots are {PNG} or {SVG}")


@router.get(
    "/{job_id}/plot",
    response_class=Response,
    responses={
        **PROBLEMS,
        **_NOT_FOUND,
        **_CONFLICT,
        200: {"content": {PNG: {}, SVG: {}}, "description": "The figure."},
        406: {"description": "Neither PNG nor SVG is acceptable."},
    },
    summary="Figure of a succeeded sweep: bifurcation diagram or chaos map (PNG or SVG)",
)
async def get_plot(
    job_id: str,
    request: Request,
    owner: Owner,
    jobs: Jobs,
    format: Annotated[
        Literal["png", "svg"] | None, Query(description="png or svg; else the Accept header.")
    ] = None,
) -> Response:
    """One axis: Poincare x against the parameter, the LLE underneath, the Melnikov threshold
    marked. Two axes: the map coloured by LLE, the Melnikov boundary overlaid and a table of
    agreement between the numerical and the Melnikov verdicts."""
    fmt = _plot_format(format, request.headers.get("accept", ""))
    await run_in_threadpool(_succeeded, jobs, job_id, owner)

    def draw() -> bytes:
        sweep = SweepRequest.model_validate_json(jobs.store.request_json(job_id))
        located = chunk_bifurcations(jobs.store.chunk_results(job_id))
        return sweep_figure(sweep, list(_points(jobs, job_id)), fmt, located)

    body = await run_in_threadpool(draw)
    return Response(body, media_type=PNG if fmt == "png" else SVG)
