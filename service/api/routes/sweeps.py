"""/v1/sweeps: the durable queue of bifurcation sweeps and chaos maps.

Submit, list, status and cancel are the generic job routes (``routes/jobs.py``: owner isolation,
Retry-After, 429); sweeps add their own result (JSON streamed chunk by chunk, or CSV) and plot.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Annotated, Literal

from fastapi import Query, Request, Response
from fastapi.responses import StreamingResponse

from gearengine import plots  # its figures load matplotlib on first use, not at start-up
from gearengine.studies.sweep import (
    DEFAULT_CHUNK_POINTS,
    SweepPoint,
    SweepRequest,
    SweepResult,
    balanced_chunk_points,
    checked,
    chunk_bifurcations,
    csv_rows,
    points_of_chunk,
    result_json,
    text_blocks,
)
from gearengine.studies.sweep.points import SpeedWindows
from gearengine.studies.sweep.windows import SPEED, speed_windows
from service.api.deps import Jobs, Owner
from service.api.responses import JSON, PROBLEMS, RETRY_AFTER_HEADER, header
from service.api.routes.jobs import (
    CONFLICT,
    NOT_FOUND,
    PARTIAL_HEADER,
    JobRoutes,
    poll_headers,
)
from service.core.config import Settings
from service.jobs.runtime import JobQueue


def _check(body: SweepRequest, request: Request, settings: Settings) -> None:
    checked(body, settings.max_job_points)


def _chunk_points(body: SweepRequest, settings: Settings) -> int:
    """The job's points per chunk: the setting, or ``balanced_chunk_points`` over the workers
    (a continuation sweep keeps ``DEFAULT_CHUNK_POINTS``: its chunks are its lines)."""
    if settings.sweep_chunk_points is not None:
        return settings.sweep_chunk_points
    if body.continuation:
        return DEFAULT_CHUNK_POINTS
    return balanced_chunk_points(body.n_points(), settings.workers)


SWEEPS = JobRoutes(
    kind="sweep",
    prefix="sweeps",
    noun="sweep",
    plural="sweeps",
    submit_summary="Submit a bifurcation sweep (one axis) or a chaos map (two axes)",
    submit_doc="Validate and store the sweep; it runs on the workers. Answers 202 with the job "
    "and its\n``Location``; poll it (``Retry-After``) and fetch ``/result`` or ``/plot`` once "
    "succeeded.",
    check=_check,
    chunk_size=_chunk_points,
)
router = SWEEPS.router(result=False)

CSV = "text/csv"


def _windows(jobs: JobQueue, job_id: str, sweep: SweepRequest) -> list[SpeedWindows] | None:
    """The speed windows of a sweep over the driver speed; None, without reading a point,
    for other sweeps (a map's result streams chunk by chunk)."""
    if SPEED not in [a.parameter for a in sweep.axes]:
        return None
    return speed_windows(sweep, list(_points(jobs, job_id)))


def _stored_points(jobs: JobQueue, job_id: str) -> Iterator[dict[str, object]]:
    """The stored points as their JSON objects (the workers wrote them from valid points; no
    model is built: ``csv_rows`` reads the fields by name), one chunk in memory at a time: the
    CSV of a million-point map streams at the speed of its writer."""
    for array in jobs.store.chunk_results(job_id):
        yield from points_of_chunk(array)


def _most_attractors(jobs: JobQueue, job_id: str) -> int:
    """The most attractors a stored point has (a sweep with settings.basins): the CSV's
    header has that many attractors' columns, so the points are read once before it."""
    return max((len(p.get("attractors") or []) for p in _stored_points(jobs, job_id)), default=0)


def _points(jobs: JobQueue, job_id: str) -> Iterator[SweepPoint]:
    for array in jobs.store.chunk_results(job_id):
        for item in points_of_chunk(array):
            yield SweepPoint.model_validate(item)


@router.get(
    "/{job_id}/result",
    response_model=SweepResult,
    responses={
        **PROBLEMS,
        **NOT_FOUND,
        **CONFLICT,
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
    job = (SWEEPS.job_or_404 if partial else SWEEPS.succeeded)(jobs, job_id, owner)
    missing = job.status != "succeeded"
    headers = {PARTIAL_HEADER: "true", **poll_headers(job)} if missing else {}
    sweep = SweepRequest.model_validate_json(jobs.store.request_json(job_id))
    axes = sweep.axes
    if format == "csv":
        designed = sweep.design is not None
        basins = sweep.settings.basins is not None
        most = _most_attractors(jobs, job_id) if basins else 0
        name = f"sweep-{job_id}{'-partial' if missing else ''}.csv"
        return StreamingResponse(
            text_blocks(
                csv_rows(axes, _stored_points(jobs, job_id), sweep.outputs, designed, basins, most)
            ),
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


def _draw(jobs: JobQueue, job_id: str, fmt: Literal["png", "svg"]) -> bytes:
    sweep = SweepRequest.model_validate_json(jobs.store.request_json(job_id))
    located = chunk_bifurcations(jobs.store.chunk_results(job_id))
    return plots.sweep_figure(sweep, list(_points(jobs, job_id)), fmt, located)


SWEEPS.plot_route(
    router,
    "Figure of a succeeded sweep: bifurcation diagram or chaos map (PNG or SVG)",
    "One axis: Poincare x against the parameter, the LLE underneath, the Melnikov threshold\n"
    "marked. Two axes: the map coloured by LLE, the Melnikov boundary overlaid and a table of\n"
    "agreement between the numerical and the Melnikov verdicts.",
    _draw,
)
