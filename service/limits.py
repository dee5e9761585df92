"""Limits checked before any compute; each refusal is a 422 problem naming the limit."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from pydantic import BaseModel

from gearengine.homoclinic.schemas import ThresholdsRequest
from gearengine.studies import jobs
from service.core.config import Settings
from service.errors import FieldError, ProblemError
from service.speed import KernelSpeed

SWEEP_HINT = "submit it as a sweep job: POST /v1/sweeps"
"""Where an analysis over the synchronous budget can run."""
JOB_WAYS = (
    "use fewer points (axes[].num, or a narrower range at the same spacing), starts "
    "(settings.basins.starts), samples, periods or steps per period; or ask the server's "
    "operator to raise GEARCHAOS_MAX_JOB_STEPS"
)
"""The ways out of a job over the budget, in the API's fields."""
BASINS_HINT = (
    "submit it as a job, POST /v1/basins (the same request; its /plot is the basin picture), "
    "or use fewer basin starts or periods"
)
"""Where one design's basins over the synchronous budget can run: the job kind ``basins``."""


@dataclass(frozen=True)
class Limits:
    """The service limits of one app (from Settings; the synchronous budget from the kernels'
    speed, ``service.speed``)."""

    settings: Settings
    speed: KernelSpeed = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "speed", KernelSpeed(self.settings))

    def document(self, spec: dict[str, Any]) -> None:
        """Write the limits that bound one field into the OpenAPI document, so that its schema
        refuses what these checks refuse: the ``num`` of a threshold curve (max_curve_points)
        and of a sweep axis (max_job_points: one axis can hold no more); under a cap below
        its default, num is required."""
        schemas = spec.get("components", {}).get("schemas", {})
        caps = {
            "ThresholdsRequest": self.settings.max_curve_points,
            "SweepAxis": self.settings.max_job_points,
        }
        for name, cap in caps.items():
            schema = schemas.get(name, {})
            num = schema.get("properties", {}).get("num")
            if num is not None:
                num["maximum"] = min(num.get("maximum", cap), cap)
                if num.get("default", 0) > cap:  # the default is refused: num must be given
                    del num["default"]
                    schema.setdefault("required", []).append("num")

    def check_curve(self, body: ThresholdsRequest) -> None:
        cap = self.settings.max_curve_points
        if body.num > cap:
            raise over_limit("num", f"at most {cap} frequencies per curve (max_curve_points)")

    def check_budget(self, steps: int, hint: str = SWEEP_HINT, field: str = "settings") -> None:
        """Refuse work over the synchronous budget, naming ``field`` (``settings.basins.starts``
        when basin starts are asked for: they multiply the cost) and saying where such work
        can run (``hint``)."""
        cap = self.speed.sync_steps
        if steps > cap:
            raise over_limit(
                field,
                f"this analysis needs up to {steps} RK4 steps (its full transient and record; "
                "a run that settles ends sooner, which is not known before it runs), over the "
                f"synchronous compute budget of {cap} steps ({self.speed.describe()}); {hint}",
                kind="over-budget",
            )

    def check_job(self, kind: str, body: BaseModel, noun: str, path: str = "axes") -> None:
        """Refuse a job whose total work (its kind's ``work``, in RK4 steps) is over the per-job
        budget (max_job_steps, for jobs of every kind); ``path`` is the field to shrink."""
        why = jobs.budget_refusal(kind, body, noun, self.settings.max_job_steps, JOB_WAYS)
        if why is not None:
            raise over_limit(path, why, kind="over-budget")


def over_limit(path: str, message: str, kind: str = "limit") -> ProblemError:
    pointer = "/" + path.replace(".", "/")
    return ProblemError(
        422,
        kind,
        "Over a limit",
        message,
        [FieldError(path=path, pointer=pointer, message=message)],
    )
