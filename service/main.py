"""The FastAPI application: routes under /v1, problem+json errors, offline docs."""

from __future__ import annotations

import logging
from collections.abc import AsyncIterator, Callable
from contextlib import asynccontextmanager
from importlib.metadata import version
from typing import Any

from fastapi import FastAPI
from fastapi_offline import FastAPIOffline
from starlette.concurrency import run_in_threadpool

from service import errors
from service.api.deps import load_key_hashes
from service.api.links import add_job_links
from service.api.routes import (
    analyses,
    basins,
    conversions,
    explorer,
    health,
    melnikov,
    remedies,
    robustness,
    runups,
    signals,
    sweeps,
    thresholds,
)
from service.api.rules import add_cross_field_rules
from service.cache import ResponseCache
from service.core.config import Settings
from service.jobs.runtime import JobQueue
from service.limits import Limits
from service.metrics import Metrics
from service.middleware import AccessLog, BodyLimit
from service.warmup import KernelWarmUp

DESCRIPTION = """
Periodic or chaotic? Answers for a spur-gear pair with backlash, time-varying mesh stiffness,
torque fluctuation and transmission error (Farshidianfar & Saghafi 2014, Eq. 9).

* **Melnikov verdict**: whether the saddle's manifolds can intersect transversally, with the
  threshold of each control parameter and the design's margin (`POST /v1/melnikov`).
* **Conversions** from physical gear data (`POST /v1/conversions/physical`).
* **Numerical verdict**: period, largest Lyapunov exponent, classification and its agreement
  with Melnikov (`POST /v1/analyses`).
* **Threshold curves** over a frequency range (`POST /v1/thresholds`).
* **Figures** as PNG or SVG (`/v1/analyses/plot`, `/v1/thresholds/plot`).
* **Sweeps**: bifurcation diagrams (one axis) and 2-D chaos maps (two axes) as durable jobs
  (`POST /v1/sweeps`, then poll, fetch `/result` as JSON or CSV and `/plot`).
* **Signals**: a recorded series (transmission error, accelerometer) read as periodic,
  quasi-periodic, chaotic or stochastic, with the model beside it (`POST /v1/signals`).
* **Robustness**: probabilities of chaos and rattle over a design's manufacturing tolerances
  (ISO 1328 class, backlash band, distributions), with Sobol indices (`POST /v1/robustness`).

Every error is RFC 9457 `application/problem+json` naming the bad field. With API keys
configured, send `Authorization: Bearer KEY` or `X-API-Key: KEY`.
"""


def create_app(settings: Settings | None = None) -> FastAPI:
    """Build the app for ``settings`` (default: from GEARCHAOS_* environment variables)."""
    settings = settings or Settings()
    ready_checks: dict[str, Callable[[], bool]] = {}

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        jobs = app.state.jobs = await run_in_threadpool(JobQueue.open, settings)
        ready_checks["job_store"] = jobs.ready
        speed = app.state.limits.speed  # measured after the warm-up: the synchronous budget
        warming = app.state.warm_up = KernelWarmUp(jobs, settings, speed)  # after the ready line
        ready_checks["kernels"] = warming.done.is_set
        warming.start()
        yield
        await run_in_threadpool(warming.stop)
        await run_in_threadpool(jobs.close)

    app = FastAPIOffline(
        title="gearchaos",
        version=version("gearchaos"),
        description=DESCRIPTION,
        lifespan=lifespan,
        telemetry={"tracing": False, "metrics": False, "logs": False},
    )
    app.state.settings = settings
    app.state.cache = ResponseCache(settings.cache_entries)
    app.state.metrics = Metrics()
    app.state.limits = Limits(settings)
    base_openapi = app.openapi

    def openapi() -> dict[str, Any]:  # the schema states this app's limits (Limits.document)
        if app.openapi_schema is None:
            app.state.limits.document(base_openapi())
            add_job_links(app.openapi_schema)  # submit -> status, result, plot, cancel
            add_cross_field_rules(app.openapi_schema)  # what the schema cannot say
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
    app.state.key_hashes = load_key_hashes(settings)
    app.state.ready_checks = ready_checks
    errors.install(app)
    app.include_router(health.router, tags=["health"])
    app.include_router(melnikov.router, tags=["melnikov"])
    app.include_router(conversions.router, tags=["melnikov"])
    app.include_router(thresholds.router, tags=["melnikov"])
    app.include_router(analyses.router, tags=["analyses"])
    app.include_router(sweeps.router, tags=["sweeps"])
    app.include_router(remedies.router, tags=["remedies"])
    app.include_router(runups.router, tags=["runups"])
    app.include_router(robustness.router, tags=["robustness"])
    app.include_router(basins.router, tags=["basins"])
    app.include_router(signals.jobs_router, tags=["signals"])
    app.include_router(signals.router, tags=["signals"])
    app.include_router(explorer.router)
    app.add_middleware(melnikov.VerdictLane)  # innermost: behind the body limit and the log
    app.add_middleware(
        BodyLimit,
        limit=settings.max_body_bytes,
        per_path={
            "/v1/melnikov/batch": settings.max_batch_body_bytes,
            **dict.fromkeys(signals.PATHS, settings.max_batch_body_bytes),
        },
    )
    app.add_middleware(AccessLog, metrics=app.state.metrics)
    logging.getLogger("gearchaos").setLevel(logging.INFO)
    return app
