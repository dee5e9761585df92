"""The synchronous budget in seconds: the kernels' speed, measured at start, turns the setting
``sync_seconds`` into RK4 steps (the unit every request is costed in, ``numerics.work``).

After the warm-up (``service.warmup``) two probes are timed, each the best of ``REPEATS`` runs:
the default analysis of the paper's section 4.1 design (one start, ``PROBE_RUN``: the
single-run kernel with its LLE, period and Floquet reading) and the same with ``PROBE_STARTS``
basin starts (the lock-step lanes and the attractor clustering). The slower probe's steps per
second is the speed: a synchronous analysis of either shape then takes about ``sync_seconds``
at its budget. The speed is per process, measured under whatever load the machine has then
(a loaded machine gets a smaller budget: the seconds are what the setting promises).

Until measured (the warm-up takes seconds from numba's cache, a minute or more compiling) and
when ``kernel_steps_per_second`` pins it (tests, reproducible budgets), the speed is that
setting or ``DEFAULT_STEPS_PER_SECOND``. ``max_sync_steps``, when set, is the budget in steps
and the speed is not used for it.
"""

from __future__ import annotations

import logging
import time

from service.core.config import Settings

log = logging.getLogger("gearchaos.startup")

DEFAULT_STEPS_PER_SECOND = 10_000_000.0
"""RK4 steps per second assumed before the measurement: the slower probe measured about
12.6 M steps/s on a 2-core machine at load 6 (docs/scale-out.md); rounded down."""
PROBE_STARTS = 16
"""Basin starts of the lanes probe."""
REPEATS = 3
"""Runs of each probe; the fastest counts (the others met a busy core)."""


def probe_rates(repeats: int = REPEATS) -> dict[str, float]:
    """Steps per second of each probe (``run``: one start; ``lanes``: ``PROBE_STARTS`` basin
    starts), the best of ``repeats`` timed runs after one untimed run each."""
    from gearengine.analysis import AnalysisRequest, analyze
    from gearengine.model.examples import PAPER_SECTION_41
    from gearengine.numerics import work
    from gearengine.studies.basins import basins_work

    run = AnalysisRequest.model_validate({"params": PAPER_SECTION_41})
    lanes = AnalysisRequest.model_validate(
        {"params": PAPER_SECTION_41, "settings": {"basins": {"starts": PROBE_STARTS}}}
    )
    probes = {"run": (run, work(run.params, run.settings)), "lanes": (lanes, basins_work(lanes))}
    rates = {}
    for name, (request, steps) in probes.items():
        analyze(request)
        best = float("inf")
        for _ in range(repeats):
            start = time.perf_counter()
            analyze(request)
            best = min(best, time.perf_counter() - start)
        rates[name] = steps / best
    return rates


class KernelSpeed:
    """The kernels' RK4 steps per second in this process, and the synchronous budget from it.

    Attributes:
        steps_per_second: the pinned, measured or default speed [steps/s].
        source: ``pinned``, ``measured`` or ``default`` (not measured yet).
        rates: each probe's steps/s once measured (``probe_rates``).
    """

    def __init__(self, settings: Settings) -> None:
        self.settings = settings
        pinned = settings.kernel_steps_per_second
        self.steps_per_second = DEFAULT_STEPS_PER_SECOND if pinned is None else pinned
        self.source = "default" if pinned is None else "pinned"
        self.rates: dict[str, float] = {}

    def measure(self) -> None:
        """Time the probes and take the slower one's speed (no-op when pinned)."""
        if self.source == "pinned":
            return
        self.rates = probe_rates()
        self.steps_per_second = min(self.rates.values())
        self.source = "measured"
        log.info(
            "kernel speed %.3g steps/s (%s): synchronous budget %d RK4 steps = %g s",
            self.steps_per_second,
            ", ".join(f"{k} {v:.3g}" for k, v in self.rates.items()),
            self.sync_steps,
            self.settings.sync_seconds,
        )

    @property
    def sync_steps(self) -> int:
        """The synchronous budget in RK4 steps: ``max_sync_steps`` when set, else
        ``sync_seconds`` x the speed."""
        if self.settings.max_sync_steps is not None:
            return self.settings.max_sync_steps
        return int(self.settings.sync_seconds * self.steps_per_second)

    def describe(self) -> str:
        """How the budget was set, for refusals: '0.5 s (sync_seconds) at 1.26e+07 steps/s,
        measured' or 'max_sync_steps'."""
        if self.settings.max_sync_steps is not None:
            return "max_sync_steps"
        return (
            f"{self.settings.sync_seconds:g} s (sync_seconds) at {self.steps_per_second:.3g} "
            f"RK4 steps/s, {self.source}; max_sync_steps sets it in steps"
        )
