"""Kinds of durable job: one registry from a kind's name to how its work is split and joined.

Every long answer of the engine (a sweep, a robustness study, remedies, a run-up) is a job: a
request document split into chunks, the unit of work of the service's queue (and of the CLI in
process). A chunk's result depends only on (request, chunk index, chunk size), so a chunk
computed twice gives the same bytes, and a job resumed after a crash equals an uninterrupted one,
whatever the kind. The service stores requests and chunk results as JSON text; workers call
``compute_chunk_json`` with the kind's name; the CLI calls ``run_local``.

A kind is registered in ``KINDS`` by the module path of its ``JobKind`` object, loaded on first
use, so importing this module loads no kind.
"""

from __future__ import annotations

import gc
import importlib
import os
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel

from gearengine.jsonio import dumps
from gearengine.model.units import si_numbers


@dataclass(frozen=True)
class JobKind:
    """How one kind of job is planned, computed chunk by chunk, and assembled.

    Attributes:
        name: the kind's name (the key of ``KINDS``; the service's ``/v1/<route>``).
        request: the request document's model.
        chunk_points: default units of work per chunk (points, samples, levers, ...).
        chunk_counts: ``(request, chunk_points) -> units of work of each chunk`` (progress is
            counted in these units; the list's length is the number of chunks).
        work: ``request -> RK4 steps`` of the whole job, for the compute budget.
        compute_chunk: ``(request, index, chunk_points) -> chunk result`` as JSON text.
        assemble: ``(request, chunk results in index order) -> result document``.
        terms: ``(request, budget in RK4 steps) -> its cost in the user's terms`` ("512 samples
            x 1 start x 115 points = 58880 runs; the budget allows 256 samples here, or 57
            points at 512"), said when the job is over the budget; None: steps alone.
    """

    name: str
    request: type[BaseModel]
    chunk_points: int
    chunk_counts: Callable[[Any, int], list[int]]
    work: Callable[[Any], int]
    compute_chunk: Callable[[Any, int, int], str]
    assemble: Callable[[Any, list[str]], BaseModel]
    terms: Callable[[Any, int], str] | None = None


def one_chunk_kind(
    name: str,
    request: type[BaseModel],
    result: type[BaseModel],
    units: Callable[[Any], int],
    work: Callable[[Any], int],
    compute: Callable[[Any], BaseModel],
) -> JobKind:
    """A kind whose whole answer is one chunk (an answer that cannot be split: the attractors of
    all basin starts clustered together, a recording read at once): ``compute(request)``'s
    document as JSON text (``jsonio.dumps``, the CLI's bytes), progress counted in
    ``units(request)``, and the job's result that document read back as ``result``."""

    def chunk(req: Any, index: int, chunk_points: int) -> str:
        return dumps(compute(req))

    def assemble(req: Any, chunks: list[str]) -> BaseModel:
        if not chunks:
            raise ValueError(f"the {name} job has no finished chunk yet")
        return result.model_validate_json(chunks[0])

    return JobKind(
        name=name,
        request=request,
        chunk_points=1,
        chunk_counts=lambda req, chunk_points: [units(req)],
        work=work,
        compute_chunk=chunk,
        assemble=assemble,
    )


MAX_JOB_POINTS = 40_000
"""Most operating points of one job (the service's default ``max_job_points``, every door)."""
MAX_JOB_STEPS = 20_000_000_000
"""Compute budget of one job in RK4 steps (the service's default ``max_job_steps``). No time is
said for it: the steps a second depend on the machine and its load (a 1.08e10-step check took
98 s on two shared cores, where 2.07e10 steps were said to take "about 1 min")."""


BUDGET_ENV = ("GEARCHAOS_MAX_JOB_STEPS", "GEARCHAOS_MAX_SWEEP_STEPS")
"""The environment variables of the job budget (the service's ``max_job_steps``; the second is
its old name), read by the CLI as by the service."""


def starts_words(lanes: int, basin_starts: int) -> str:
    """ "17 starts (16 basin starts and the settings' own start)", "1 start": the runs of one
    point in words, the basin starts named first as every report counts them ("16 starts a
    point"; the refusal said "17 starts (1 + 16 basin starts)")."""
    plural = "s" if lanes != 1 else ""
    if not basin_starts:
        return f"{lanes} start{plural}"
    own = lanes - basin_starts
    own_words = "the settings' own start" if own == 1 else f"the settings' own {own} starts"
    return f"{lanes} start{plural} ({basin_starts} basin starts and {own_words})"


def job_step_budget() -> int:
    """The compute budget of one job in RK4 steps: ``GEARCHAOS_MAX_JOB_STEPS`` (or its old name)
    from the environment when set, as the service reads it, else ``MAX_JOB_STEPS``.

    Raises ValueError naming the variable when it is not a whole number."""
    for name in BUDGET_ENV:
        text = os.environ.get(name)
        if text:
            try:
                return int(float(text))
            except ValueError:
                raise ValueError(f"{name}={text!r}: give a number of RK4 steps") from None
    return MAX_JOB_STEPS


def budget_refusal(name: str, request: BaseModel, noun: str, cap: int, ways: str) -> str | None:
    """Why a job of kind ``name`` is over the budget of ``cap`` RK4 steps, else None: its steps,
    its cost in the kind's own terms (``JobKind.terms``: samples x starts x points, what fits)
    and ``ways`` out (in the asker's words: options or fields); the one rule of the CLI and the
    API (``service.limits``)."""
    job = kind(name)
    steps = job.work(request)
    if steps <= cap:
        return None
    terms = "" if job.terms is None else f" ({job.terms(request, cap)})"
    return (f"this {noun} needs {steps} RK4 steps{terms}, over the budget of {cap} RK4 "
            f"steps per job (max_job_steps, environment {BUDGET_ENV[0]}); {ways}")  # fmt: skip


def too_many_points(points: int, noun: str) -> str | None:
    """Why a job of ``points`` operating points is over ``MAX_JOB_POINTS``, else None (checked
    first, so that no work is costed for them)."""
    if points > MAX_JOB_POINTS:
        return f"this {noun} has {points} points, the limit is {MAX_JOB_POINTS} (max_job_points)"
    return None


def over_budget(name: str, request: BaseModel, noun: str, ways: str) -> str | None:
    """Why a job of kind ``name`` is over this process's budget (``budget_refusal`` against
    ``job_step_budget``), else None: the CLI refuses what the API refuses, before computing (its
    points were counted before the request was validated, ``too_many_points``)."""
    return budget_refusal(name, request, noun, job_step_budget(), ways)


KINDS: dict[str, str] = {
    "sweep": "gearengine.studies.sweep.compute:SWEEP_JOB",
    "remedies": "gearengine.gate.remedies.compute:REMEDIES_JOB",
    "runup": "gearengine.studies.runup.compute:RUNUP_JOB",
    "robustness": "gearengine.studies.robustness.study:ROBUSTNESS_JOB",
    "basins": "gearengine.studies.basins:BASINS_JOB",
    "signal": "gearengine.rig:SIGNAL_JOB",
}
"""Kind name -> ``module:attribute`` of its ``JobKind``."""


def kind(name: str) -> JobKind:
    """The ``JobKind`` registered as ``name`` (KeyError for an unknown kind)."""
    module, attribute = KINDS[name].split(":")
    return getattr(importlib.import_module(module), attribute)


_pause_lock = threading.Lock()
_pauses = [0, False]  # chunks computing now, and whether the collector was on before the first


@contextmanager
def cyclic_gc_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off while a chunk computes (on again after the last
    of concurrent chunks, if it was on before the first).

    A chunk makes its results as many small containers (a 100 x 100 map: 10,000 points of 64
    strobes, ~650,000 lists), and each allocation burst makes the collector traverse every
    live container again: that traversal was 85 % of the time of those lists and a quarter of
    the chunk's time (measured on ``bench_map_serve``'s map). The chunk's objects hold no
    cycles that live past it; reference counting frees them as before."""
    with _pause_lock:
        if _pauses[0] == 0:
            _pauses[1] = gc.isenabled()
            gc.disable()
        _pauses[0] += 1
    try:
        yield
    finally:
        with _pause_lock:
            _pauses[0] -= 1
            if _pauses[0] == 0 and _pauses[1]:
                gc.enable()


def validated_json(job: JobKind, request_json: str) -> Any:
    """The request of a job read back from its JSON text (stored, or handed to a worker): its
    numbers are the engine's own SI values (``si_numbers``), read with no note, and read even
    where a user's bare number is refused (a run-up's speeds and rate)."""
    with si_numbers():
        return job.request.model_validate_json(request_json)


def compute_chunk_json(name: str, request_json: str, index: int, chunk_points: int) -> str:
    """Chunk ``index`` of a job of kind ``name`` from its request's JSON text (what workers run),
    with the cyclic collector paused (``cyclic_gc_paused``)."""
    job = kind(name)
    with cyclic_gc_paused():
        return job.compute_chunk(validated_json(job, request_json), index, chunk_points)


def run_local(
    name: str,
    request: BaseModel,
    progress_callback: Callable[[int, int], None] | None = None,
    chunk_points: int | None = None,
    workers: int = 1,
) -> BaseModel:
    """Every chunk of a job of kind ``name`` in this process, then its result document.

    ``progress_callback(done, total)`` counts the kind's units of work, each chunk as it
    completes (chunks completed together in index order: one worker keeps the index order).
    Awaited in index order, the remedies' six searches were all reported at the end, behind
    its slowest first chunk. ``workers`` > 1 runs chunks on that many threads (the kernels
    release the GIL); the result does not depend on it: it is assembled in index order.
    Chunks are computed from the request's JSON text, as a worker would, so the CLI's document
    equals the service's byte for byte.
    """
    job = kind(name)
    size = chunk_points or job.chunk_points
    counts = job.chunk_counts(request, size)
    text = request.model_dump_json()
    total, done = sum(counts), 0
    results: list[str] = [""] * len(counts)
    with ThreadPoolExecutor(max(1, workers)) as pool:
        index = {pool.submit(compute_chunk_json, name, text, i, size): i
                 for i in range(len(counts))}  # fmt: skip
        pending = set(index)
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in sorted(finished, key=index.__getitem__):
                i = index[future]
                results[i] = future.result()
                done += counts[i]
                if progress_callback is not None:
                    progress_callback(done, total)
    return job.assemble(request, results)
