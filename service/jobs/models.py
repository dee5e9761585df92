"""The job object of the sweep queue, as the API shows it."""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Literal

from pydantic import BaseModel, Field

JobStatus = Literal["queued", "running", "succeeded", "failed", "cancelled"]
UNFINISHED: tuple[JobStatus, ...] = ("queued", "running")


class Progress(BaseModel):
    """Points finished (committed) out of all points of the sweep."""

    done: int = Field(description="Points whose chunk is committed.", examples=[128])
    total: int = Field(description="All points, every branch counted.", examples=[301])


class JobAxis(BaseModel):
    """An axis of the job's sweep, as requested."""

    parameter: str = Field(description="Parameter alias.", examples=["F_e1"])
    start: float | str = Field(
        description="First value (a number, or a string with a unit).", examples=[0.0, "500 rpm"]
    )
    stop: float | str = Field(description="Last value, as start.", examples=[0.3, "6000 rpm"])
    num: int = Field(description="Number of values.", examples=[301])


class Job(BaseModel):
    """A sweep job of the durable queue."""

    id: str = Field(description="Job id (32 hex digits).")
    label: str | None = Field(None, description="The request's label, else null.")
    status: JobStatus = Field(description="queued | running | succeeded | failed | cancelled.")
    progress: Progress
    axes: list[JobAxis] = Field(
        default_factory=list, description="The sweep's axes (parameter, start, stop, num)."
    )
    created_at: datetime = Field(description="When the job was stored (UTC).")
    started_at: datetime | None = Field(description="When its first chunk was claimed (UTC).")
    finished_at: datetime | None = Field(description="When it succeeded, failed or was cancelled.")
    error: str | None = Field(description="Why it failed, else null.")


class JobPage(BaseModel):
    """One page of the caller's jobs, newest first."""

    items: list[Job]
    total: int = Field(description="Jobs matching the filter.")
    next_offset: int | None = Field(description="Offset of the next page, null on the last.")


def utc(seconds: float | None) -> datetime | None:
    """A POSIX time as an aware UTC datetime (None stays None)."""
    return None if seconds is None else datetime.fromtimestamp(seconds, UTC)
