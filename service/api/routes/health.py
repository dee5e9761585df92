"""Liveness, readiness and Prometheus metrics (never behind auth)."""

from __future__ import annotations

from fastapi import APIRouter, Request, Response
from pydantic import BaseModel, Field

from service.api.deps import AppMetrics, ReadyChecks
from service.errors import ProblemError

router = APIRouter()


class Health(BaseModel):
    """Liveness or readiness."""

    status: str = Field(description="ok, or what is not ready.", examples=["ok"])
    version: str = Field(description="Service version.", examples=["0.1.0"])
    checks: dict[str, bool] = Field(
        default_factory=dict, description="Readiness checks (kernels warmed, job store reachable)."
    )


@router.get("/v1/health", response_model=Health, summary="Liveness")
async def health(request: Request) -> Health:
    """The process answers."""
    return Health(status="ok", version=request.app.version)


@router.get(
    "/v1/ready",
    response_model=Health,
    summary="Readiness: kernels warmed and job store reachable",
    responses={503: {"description": "Not ready yet."}},
)
def ready(request: Request, ready_checks: ReadyChecks) -> Health:
    # a plain def: FastAPI runs it in its thread pool, so a store that is slow to answer (a
    # PostgreSQL outage) holds up this probe, never the event loop of every other request
    checks = {name: bool(check()) for name, check in ready_checks.items()}
    if not all(checks.values()):
        failing = ", ".join(k for k, v in checks.items() if not v)
        raise ProblemError(503, "not-ready", "Not ready", f"not ready: {failing}")
    return Health(status="ok", version=request.app.version, checks=checks)


@router.get(
    "/metrics",
    summary="Prometheus metrics",
    response_class=Response,
    responses={200: {"content": {"text/plain": {}}, "description": "Text exposition format."}},
)
async def metrics(metrics: AppMetrics) -> Response:
    return Response(metrics.exposition(), media_type="text/plain; version=0.0.4")
