"""The one configuration object: ``GEARCHAOS_*`` environment variables, overridden by CLI flags.

Every limit of the service lives here with its default; change one with an environment variable
(``GEARCHAOS_MAX_BODY_BYTES=2097152``) or, for the network settings, a ``gearengine serve`` flag.
"""

from __future__ import annotations

import os
from functools import cached_property
from pathlib import Path

from pydantic import AliasChoices, Field
from pydantic_settings import BaseSettings, SettingsConfigDict

from gearengine.studies.jobs import MAX_JOB_POINTS, MAX_JOB_STEPS


def _job_alias(what: str) -> AliasChoices:
    """The environment variables of the ``max_job_<what>`` setting: its own and its name from
    before jobs had kinds (still read, an alias). Keywords and flags use the field name."""
    return AliasChoices(f"GEARCHAOS_MAX_JOB_{what.upper()}", f"GEARCHAOS_MAX_SWEEP_{what.upper()}")


class Settings(BaseSettings):
    """Service settings; field names are the environment variables without ``GEARCHAOS_``."""

    model_config = SettingsConfigDict(
        env_prefix="GEARCHAOS_", extra="ignore", frozen=True, populate_by_name=True
    )

    host: str = Field("127.0.0.1", description="Address the API binds to.")
    port: int = Field(8000, ge=0, le=65535, description="TCP port of the API.")
    data_dir: Path = Field(Path("data"), description="Directory holding all state (job store).")
    workers: int = Field(
        max(1, os.cpu_count() or 1), ge=0, le=256, description="Sweep worker processes."
    )
    http_processes: int = Field(
        max(1, os.cpu_count() or 1),
        ge=1,
        le=64,
        description="HTTP server processes sharing the listening socket (``gearengine serve "
        "--http-processes``), one per core by default; only the first runs the sweep "
        "dispatcher. Each has its own response cache and metrics.",
    )
    api_keys: str = Field(
        "", description="Comma-separated API keys; empty = no auth (loopback only)."
    )
    insecure: bool = Field(False, description="Allow a non-loopback bind without API keys.")
    dask_scheduler: str | None = Field(None, description="Dask scheduler address for sweeps.")
    database_url: str | None = Field(
        None,
        description="PostgreSQL job store shared by every replica "
        "(``postgresql://user:password@host:5432/gearchaos``); unset, the job store is the SQLite "
        "file jobs.sqlite3 in data_dir, for one machine (docs/scale-out.md).",
    )
    database_pool_size: int = Field(
        8, ge=2, le=100, description="Most PostgreSQL connections of one process (a pool)."
    )
    database_listen: bool = Field(
        True,
        description="Dispatchers on a PostgreSQL store LISTEN for submissions of every replica "
        "and wake at once (one more connection per dispatcher); false: they poll every 0.5 s "
        "(for a pooler that cannot LISTEN, such as PgBouncer in transaction mode).",
    )

    keep_alive_seconds: float = Field(
        30.0,
        gt=0.0,
        le=3600.0,
        description="Idle keep-alive of HTTP connections; longer than clients' (httpx: 5 s) so "
        "the server never closes a connection a client is about to reuse.",
    )
    max_body_bytes: int = Field(1 << 20, ge=1024, description="Largest request body, bytes.")
    max_batch_body_bytes: int = Field(
        16 << 20, ge=1024, description="Largest body of POST /v1/melnikov/batch, bytes."
    )
    max_sync_steps: int | None = Field(
        None,
        ge=1000,
        description="Compute budget of one synchronous analysis in RK4 steps over all starts, "
        "set by hand (the default analysis is 200 000); unset, sync_seconds at the kernels' "
        "measured speed (service.speed).",
    )
    sync_seconds: float = Field(
        0.5,
        gt=0.0,
        le=600.0,
        description="Compute budget of one synchronous analysis in seconds of kernel time, "
        "turned into RK4 steps with the kernels' speed measured at start (about 6 M steps on a "
        "loaded 2-core machine; docs/scale-out.md).",
    )
    kernel_steps_per_second: float | None = Field(
        None,
        gt=0.0,
        description="Pins the kernels' speed in RK4 steps/s (reproducible budgets, tests); "
        "unset, it is measured after the warm-up (10 M steps/s assumed until then).",
    )
    max_curve_points: int = Field(2000, ge=2, description="Most frequencies in a threshold curve.")
    cache_entries: int = Field(512, ge=0, description="Responses kept in the in-memory LRU.")

    max_job_points: int = Field(
        MAX_JOB_POINTS,
        ge=1,
        validation_alias=_job_alias("points"),
        description="Most points of one job (every axis and branch counted). Environment: "
        "GEARCHAOS_MAX_JOB_POINTS, or its old name GEARCHAOS_MAX_SWEEP_POINTS (an alias).",
    )
    max_job_steps: int = Field(
        MAX_JOB_STEPS,
        ge=1000,
        validation_alias=_job_alias("steps"),
        description="Compute budget of one job in RK4 steps (points x periods x steps x "
        "starts); how long that takes depends on the machine. Environment: "
        "GEARCHAOS_MAX_JOB_STEPS, or its old name GEARCHAOS_MAX_SWEEP_STEPS (an alias).",
    )
    max_queued_jobs: int = Field(
        64, ge=1, description="Most unfinished (queued or running) sweep jobs; then 429."
    )
    max_status_wait_s: float = Field(
        30.0, ge=0.0, le=30.0, description="Longest hold of a status request's ?wait [s] (the "
        "API accepts up to 30): lower it behind a proxy that closes idle requests sooner; 0 "
        "answers every status at once (a fuzzing run, whose jobs never finish)."
    )  # fmt: skip
    sweep_chunk_points: int | None = Field(
        None,
        ge=1,
        le=10_000,
        description="Points per chunk of a sweep without continuation; unset, about four chunks "
        "per worker, 64 to 1024 points (gearengine.studies.sweep.plan.balanced_chunk_points).",
    )
    lease_seconds: float = Field(
        30.0, gt=0.0, le=3600.0, description="Lease of a claimed chunk, renewed every third."
    )
    max_retries: int = Field(
        3, ge=0, le=100, description="Retries of a chunk whose worker died before the job fails."
    )

    @cached_property
    def key_list(self) -> list[str]:
        """The configured API keys, stripped, without empties."""
        return [k.strip() for k in self.api_keys.split(",") if k.strip()]
