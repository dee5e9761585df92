"""Probability limits decided point by point: sequential sampling within a compute budget.

A limit P(event) <= p at an operating point is decided when the 95 % Clopper-Pearson interval
of the study's estimate lies on one side of it: ``pass`` when its upper bound is at or below p
for every limit, ``fail`` when the lower bound of one is above its p; otherwise the point is
``undecided``. ``sequential`` samples each point with 64, 128, 256, ... samples (the seeded
Sobol points of 2N begin with those of N: a round computes only the new rows of the points not
yet decided) until each point is decided, ``most`` samples are reached, or the next round would
take the total work over ``budget`` RK4 steps; the points left are undecided, with their
samples and the reason. A gate must fail an undecided point (it proves nothing).

A point looked at several times must not get several chances to pass: the 5 % error of a
decision is shared over the looks a study may take (Bonferroni: ``looks``, 7 from 64 to 4,096
samples), so each look decides with the Clopper-Pearson interval at 1 - 0.05 / looks (99.3 %),
not at 95 % (``decision_confidence``). Proving P <= 1 % with no events then takes 561 samples,
not 368. A gate at a fixed sample count looks once and decides at 95 %.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from typing import Literal

from pydantic import BaseModel, Field

from gearengine.studies import jobs
from gearengine.studies.robustness.results import Probability, RobustnessPoint, RobustnessResult
from gearengine.studies.robustness.study import (
    DEFAULT_CHUNK_ROWS,
    MAX_SAMPLES,
    RobustnessRequest,
    assemble,
)
from gearengine.studies.robustness.tolerances import clopper_pearson, samples_to_prove
from gearengine.studies.sweep.axes import axis_unit
from gearengine.studies.sweep.request import SweepAxis

FIRST_SAMPLES = 64
"""Samples of the first round of ``sequential`` (a power of 2, a multiple of the chunk rows)."""

Verdict = Literal["pass", "fail", "undecided"]

ERROR = 0.05
"""The chance a decision may be wrong (a point passed whose probability is over its limit, or
failed under it), over all the looks a study takes at a point."""


def looks(first: int = FIRST_SAMPLES, most: int = MAX_SAMPLES) -> int:
    """How many times ``sequential`` may look at a point: first, 2 first, ..., most (7)."""
    return (most // first).bit_length()


def decision_confidence(first: int = FIRST_SAMPLES, most: int = MAX_SAMPLES) -> float:
    """The confidence of each look's interval: ``ERROR`` shared over the ``looks``
    (Bonferroni), 1 - 0.05 / 7 = 0.993 for 64 ... 4,096 samples."""
    return 1.0 - ERROR / looks(first, most)


def decision_interval(prob: Probability, confidence: float = 1.0 - ERROR) -> list[float] | None:
    """The interval a decision reads: the result's 95 % interval, or at ``confidence``."""
    if prob.interval is None or confidence == 1.0 - ERROR:
        return prob.interval
    return clopper_pearson(prob.count, prob.samples, confidence)


def verdict(point: RobustnessPoint, limits: dict[str, float], confidence: float = 1.0 - ERROR
            ) -> Verdict:  # fmt: skip
    """``fail`` when a lower bound is above its limit, ``pass`` when every upper bound is at or
    below its limit, else ``undecided`` (an interval holds its limit, or no samples); the
    intervals at ``confidence`` (``decision_interval``)."""
    return combined(_limit_verdict(decision_interval(point.probabilities[name], confidence),
                                   limit) for name, limit in limits.items())  # fmt: skip


def _limit_verdict(ci: list[float] | None, limit: float) -> Verdict:
    if ci is not None and ci[0] > limit:
        return "fail"
    return "pass" if ci is not None and ci[1] <= limit else "undecided"


def combined(verdicts: Iterable[Verdict]) -> Verdict:
    """A point's verdict from its limits' own: ``fail`` when one fails, ``pass`` when every one
    passes, else ``undecided``."""
    said = list(verdicts)
    if "fail" in said:
        return "fail"
    return "pass" if all(v == "pass" for v in said) else "undecided"


class SequentialResult(BaseModel):
    """The study as sampled (each point with its own samples) and each point's verdict."""

    result: RobustnessResult = Field(description="The points, each with the samples it took.")
    verdicts: list[Verdict] = Field(description="Per point, as ``verdict``.")
    rounds: list[int] = Field(description="Samples of each round run (64, 128, ...).")
    confidence: float = Field(
        description="The confidence of each look's decision interval: "
        "95 % shared over the looks the study may take (Bonferroni)."
    )
    steps: int = Field(description="RK4 steps run in all.")
    stopped: str = Field(description="Why sampling stopped, in words.")


def point_request(request: RobustnessRequest, values: dict[str, float], samples: int
                  ) -> RobustnessRequest:  # fmt: skip
    """``request`` at the one operating point ``values`` (SI) with ``samples`` samples and no
    Sobol indices."""
    axes = [SweepAxis(parameter=k, start=f"{v!r} {axis_unit(k)}", stop=f"{v!r} {axis_unit(k)}",
                      num=1) for k, v in values.items()]  # fmt: skip
    return request.model_copy(update={"axes": axes, "samples": samples, "sensitivity": False})


def unreachable(unit: list[int], limits: dict[str, float], budget: int,
                first: int = FIRST_SAMPLES, most: int = MAX_SAMPLES) -> str | None:  # fmt: skip
    """Why ``sequential`` cannot prove every limit at a point with no events within ``budget``
    RK4 steps at every point, a sample taking ``unit`` steps at each (``point_work``): the
    round that reaches the samples needed at the looks' confidence (561 for 1 % at 99.3 %,
    reached at the round of 1,024) against the samples a point the budget holds at all points;
    None when it can. Said before computing (a review's 256-sample study ended with 104 of 115
    points undecided, unsaid until then)."""
    confidence = decision_confidence(first, most)
    need = {name: samples_to_prove(limit, confidence) for name, limit in limits.items()}
    name, n = max(need.items(), key=lambda kv: kv[1] or 0)
    if n is None:
        return None
    rounds = [first << k for k in range(looks(first, most))]
    reach = next((r for r in rounds if r >= n), None)
    held = budget // max(1, sum(unit))
    if reach is not None and held >= reach:
        return None
    points = len(unit)
    where = (f"the {most} samples a point it may take" if reach is None else
             f"the round of {reach} samples")  # fmt: skip
    return (f"a point with no events needs {n} samples to prove P({name}) <= {limits[name]:g} "
            f"at {100 * confidence:.3g} % ({where}), and the job budget of {budget} RK4 steps "
            f"holds {held} samples at each of the {points} point{'s' if points != 1 else ''}: "
            "points without events will end undecided (fewer points, a looser limit, or a "
            "larger budget decide them)")  # fmt: skip


def sequential(
    request: RobustnessRequest, unit: list[int], limits: dict[str, float], budget: int,
    workers: int = 1, most: int = MAX_SAMPLES, first: int = FIRST_SAMPLES,
    progress: Callable[[int, int], None] | None = None,
) -> SequentialResult:  # fmt: skip
    """Sample each point of ``request`` until ``limits`` decide it (see the module), within
    ``budget`` RK4 steps in all, a sample taking ``unit`` steps at each point (``point_work``,
    as ``unreachable`` read them), and ``most`` samples a point; ``workers`` threads."""
    points = request.points() or [{}]
    confidence = decision_confidence(first, most)
    chunks: list[list[str]] = [[] for _ in points]
    answers: list[RobustnessPoint | None] = [None] * len(points)
    verdicts: list[Verdict] = ["undecided"] * len(points)
    rounds: list[int] = []
    spent, done, n = 0, 0, first
    stopped = ""
    while not stopped:
        todo = [k for k, v in enumerate(verdicts) if v == "undecided"]
        cost = sum(unit[k] for k in todo) * (n - done)
        if spent + cost > budget:
            stopped = (
                f"the budget of {budget} RK4 steps ran out: {len(todo)} points undecided "
                f"after {done} samples ({n} would take {spent + cost} steps in all)"
            )
            break  # fmt: skip
        asked = {k: point_request(request, points[k], n) for k in todo}  # once a round
        texts = {k: asked[k].model_dump_json() for k in todo}
        tasks = [(k, texts[k], i) for k in todo
                 for i in range(done // DEFAULT_CHUNK_ROWS, n // DEFAULT_CHUNK_ROWS)]  # fmt: skip
        with ThreadPoolExecutor(max(1, workers)) as pool:
            for (k, _, _), text in zip(tasks, pool.map(_chunk, tasks), strict=True):
                chunks[k].append(text)
        for k in todo:
            (answers[k],) = assemble(asked[k], chunks[k]).points
            verdicts[k] = verdict(answers[k], limits, confidence)  # type: ignore[arg-type]
        spent, done = spent + cost, n
        rounds.append(n)
        if progress is not None:
            progress(sum(v != "undecided" for v in verdicts), len(points))
        if all(v != "undecided" for v in verdicts):
            stopped = f"every point decided by {n} samples"
        elif n >= most:
            stopped = f"{verdicts.count('undecided')} points undecided at {n} samples, the most"
        n *= 2
    whole = assemble(request.model_copy(update={"samples": max(done, 2), "sensitivity": False}),
                     [_empty(len(points))])  # fmt: skip
    shown = [a if a is not None else p for a, p in zip(answers, whole.points, strict=True)]
    result = whole.model_copy(update={"points": shown, "samples": done, "partial": False})
    return SequentialResult(result=result, verdicts=verdicts, rounds=rounds, steps=spent,
                            stopped=stopped, confidence=confidence)  # fmt: skip


def _chunk(task: tuple[int, str, int]) -> str:
    """Chunk ``task[2]`` of the point request ``task[1]`` (JSON text)."""
    return jobs.compute_chunk_json("robustness", task[1], task[2], DEFAULT_CHUNK_ROWS)


def _empty(points: int) -> str:
    """A chunk with no rows (the frame of a result: its variables, model and units)."""
    return json.dumps({"index": 0, "first_row": 0, "runs": [[] for _ in range(points)]})
