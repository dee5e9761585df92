"""The synchronous budget is seconds of kernel time: ``sync_seconds`` at the kernels' speed,
measured after the warm-up (``service.speed``) or pinned by ``kernel_steps_per_second``."""

from __future__ import annotations

import math
from pathlib import Path

from gearengine.analysis import AnalysisRequest
from gearengine.numerics import work
from service.core.config import Settings
from service.main import create_app
from service.speed import DEFAULT_STEPS_PER_SECOND, KernelSpeed
from tests.conftest import PAPER_PARAMS, started

BODY = {"params": PAPER_PARAMS, "settings": {"record_periods": 400}}
"""An analysis of about 1 M RK4 steps."""


def steps_of(body: dict) -> int:
    request = AnalysisRequest.model_validate(body)
    return work(request.params, request.settings)


def test_the_budget_is_the_seconds_at_the_pinned_speed(tmp_path: Path) -> None:
    """The same request is answered when its steps fit sync_seconds at the pinned speed and
    refused (422 naming the seconds, the speed and the job route) when they do not."""
    steps = steps_of(BODY)
    slow = steps / 0.5 / 2.0  # at this speed the request takes 1 s: over 0.5 s
    fast = steps / 0.5 * 2.0  # 0.25 s
    for speed, status in ((slow, 422), (fast, 200)):
        settings = Settings(data_dir=tmp_path, workers=0, kernel_steps_per_second=speed)
        with started(create_app(settings)) as c:
            r = c.post("/v1/analyses", json=BODY)
            assert r.status_code == status, r.text
            if status == 422:
                detail = r.json()["detail"]
                assert f"budget of {int(0.5 * speed)} steps" in detail
                assert "0.5 s (sync_seconds)" in detail and "pinned" in detail
                assert "/v1/sweeps" in detail


def test_max_sync_steps_set_by_hand_overrides_the_speed(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path, kernel_steps_per_second=1e12, max_sync_steps=1000)
    speed = KernelSpeed(settings)
    assert speed.sync_steps == 1000 and speed.describe() == "max_sync_steps"


def test_the_speed_is_measured_after_the_warm_up(tmp_path: Path) -> None:
    """Unpinned, the budget is DEFAULT_STEPS_PER_SECOND x sync_seconds until the warm-up has
    timed both probes, then sync_seconds at the slower probe's measured speed."""
    settings = Settings(
        data_dir=tmp_path, workers=0, kernel_steps_per_second=None, sync_seconds=0.25
    )
    assert KernelSpeed(settings).sync_steps == int(0.25 * DEFAULT_STEPS_PER_SECOND)
    app = create_app(settings)
    with started(app):
        speed = app.state.limits.speed
        assert speed.source == "measured" and set(speed.rates) == {"run", "lanes"}
        assert all(math.isfinite(r) and r > 0 for r in speed.rates.values())
        assert speed.steps_per_second == min(speed.rates.values())
        assert speed.sync_steps == int(0.25 * speed.steps_per_second)
