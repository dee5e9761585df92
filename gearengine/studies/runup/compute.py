"""Computing a run-up as a job: one chunk per ensemble member (the whole profile on the
integrated driver angle through the system's ``run_ramp``: the pair's kink-accurate RK4,
``systems.spur_pair.kernels.ramp``, or a train's, ``systems.gear_train.ramp``), and the two
quasi-static continuation loop in one more (``studies.sweep.compute``, on the bin centres); the
assembly reads them into bins, jumps and lags (``studies.runup.reading``).

The loop is traced as the profile first travels (up then down, or down then up for a profile
that starts by falling): its first line from the state the members settle from (the static
contact x = 1 + F~_m, v = 0), the second continuing from the state the first ended in, as the
ramp's run-down continues from where its run-up ended; one chunk, as its lines depend on each
other. (Two independent lines, the down one from the sweep's default start in the backlash gap,
gave the z = 23/67 example a loop that did not join: 7.9 µm up and 18.3 µm down in the top bin,
and a down jump the ramp's run-down in the same output never made.)

Member m starts from the state of the settling (``settle_periods`` mesh periods at the start
speed from the static contact x = 1 + F~_m, v = 0; a train's shafts and bearings at their static
deflection), member 0 as it is, the others' x and v perturbed by ``ensemble.perturbation``
(normal, ``numpy.random.default_rng([seed, m])``). A chunk depends only
on (request, index), so a resumed job gives the same bytes.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Callable

import numpy as np

from gearengine.model.units import RPM
from gearengine.studies import jobs
from gearengine.studies.runup.profile import (
    Branch,
    RunupPlan,
    mid_speeds_rpm,
    runup_plan,
    segment_angle,
)
from gearengine.studies.runup.reading import read_runup
from gearengine.studies.runup.request import RunupRequest, n_bins
from gearengine.studies.runup.results import RunupResult
from gearengine.studies.sweep.compute import continuation_line, starting_from
from gearengine.studies.sweep.plan import sweep_work
from gearengine.studies.sweep.request import SweepRequest

QUASI_STATIC_CHUNKS = 1
"""Chunks after the members: the quasi-static loop (its second line continues the first)."""


def member_blocks(request: RunupRequest, plan: RunupPlan, member: int) -> list[list[float | None]]:
    """The block table of ensemble member ``member`` over the profile (settling not kept).

    Rows: branch (+1 up, -1 down), t0 [s], t1 [s], speed [rpm] at the block's middle, F~_m of
    the block, steps, then ``kernels.ramp.BLOCK_COLUMNS`` (None where the run diverged).
    """
    system, f = plan.system, plan.forcing
    state = system.ramp_start(1.0 + plan.mean_force[0], 0.0)
    mesh = system.mesh_column
    psi = 0.0
    rows: list[list[float | None]] = []
    for seg in plan.segments:
        if seg.branch is not None and member > 0 and not rows:
            rng = np.random.default_rng([request.ensemble.seed, member])
            state[:2, mesh] += request.ensemble.perturbation * rng.standard_normal(2)
        ramp = plan.ramp_record(seg, psi)
        table, _ = system.run_ramp(state, f.kc, f.fc, ramp, plan.inertia(seg), seg.h,
                                   seg.n_blocks, seg.steps)  # fmt: skip
        psi += segment_angle(seg)
        if seg.branch is None:
            continue
        edges = np.linspace(seg.t0, seg.t1, seg.n_blocks + 1)
        sign = 1.0 if seg.branch == "up" else -1.0
        for k, speed in enumerate(mid_speeds_rpm(seg)):
            fm = float(ramp[0] + ramp[1] * (k + 0.5) * seg.steps * seg.h)
            cells = [None if math.isnan(c) else float(c) for c in table[k]]
            rows.append([sign, float(edges[k]), float(edges[k + 1]), float(speed), fm,
                         float(seg.steps), *cells])  # fmt: skip
    return rows


def quasi_static_request(
    request: RunupRequest, direction: str = "both", start: list[float] | None = None
) -> SweepRequest:
    """The continuation sweep on the centres of the run-up's speed bins: ``direction``
    "both" (the loop's document, its cost) or one line ("forward" up, "backward" down) from
    ``start`` [x, v] (None: the request's ``quasi_static`` starts).

    The design's torque is a second axis of one value: a one-axis line would also locate its
    bifurcation points by Newton shooting, which the run-up does not read (and which costs
    more than the line).
    """
    assert request.design is not None
    torque = request.design.torque
    lo, hi = (w / RPM for w in request.speed_range())
    n = n_bins(lo, hi, request.bin_rpm)
    first, last = lo + 0.5 * request.bin_rpm, lo + (n - 0.5) * request.bin_rpm
    settings = request.quasi_static
    return SweepRequest.model_validate(
        {
            "design": request.design,
            "settings": settings if start is None else starting_from(settings, start),
            "axes": [
                {
                    "parameter": "speed",
                    "start": f"{first!r} rpm",
                    "stop": f"{last!r} rpm",
                    "num": n,
                },
                {"parameter": "torque", "start": torque, "stop": torque, "num": 1},
            ],
            "continuation": True,
            "direction": direction,
            "outputs": [
                "classification",
                "lle",
                "impact_regime",
                "x_peak_to_peak",
                "force_max",
                "physical",
            ],
        }
    )


def loop_order(request: RunupRequest) -> tuple[Branch, Branch]:
    """The quasi-static loop's lines in the order the profile first travels: ("down", "up")
    for a profile whose first change of speed is a fall, else ("up", "down")."""
    speeds = [w for _, w in request.knots()]
    falls = next((b < a for a, b in itertools.pairwise(speeds) if b != a), False)
    return ("down", "up") if falls else ("up", "down")


def quasi_static_loop(request: RunupRequest, plan: RunupPlan) -> dict[str, list[str]]:
    """The quasi-static loop's chunk: ``{"quasi_static": [up line, down line]}`` (each the
    sweep's chunk output), computed in ``loop_order``: the first line from the members' start
    (x = 1 + F~_m, v = 0), the second from the state the first ended in (the start again if it
    diverged)."""
    start = [1.0 + plan.mean_force[0], 0.0]
    texts: dict[str, str] = {}
    for branch in loop_order(request):
        line = quasi_static_request(request, SWEEP_DIRECTION[branch], start)
        texts[branch], end = continuation_line(line, 0)
        start = start if end is None else end
    return {"quasi_static": [texts["up"], texts["down"]]}


SWEEP_DIRECTION = {"up": "forward", "down": "backward"}
"""A run-up branch's direction of the continuation sweep."""


def chunk_counts(request: RunupRequest, size: int) -> list[int]:
    """One unit of work per chunk: the members, then the quasi-static loop."""
    return [1] * (request.ensemble.size + QUASI_STATIC_CHUNKS)


def work(request: RunupRequest) -> int:
    """RK4 steps of the whole job: every member's profile and the quasi-static sweep."""
    return runup_plan(request).work(request.ensemble.size) + sweep_work(
        quasi_static_request(request)
    )


def compute_chunk(request: RunupRequest, index: int, chunk_points: int = 1) -> str:
    """Chunk ``index`` as JSON text: a member's block table, or the quasi-static loop."""
    members = request.ensemble.size
    plan = runup_plan(request)
    if index < members:
        return json.dumps({"member": index, "blocks": member_blocks(request, plan, index)})
    if index - members >= QUASI_STATIC_CHUNKS:
        raise IndexError(f"chunk {index} out of range 0..{members + QUASI_STATIC_CHUNKS - 1}")
    return json.dumps(quasi_static_loop(request, plan))


def assemble(request: RunupRequest, chunks: list[str]) -> RunupResult:
    """The run-up's document from its chunks in index order.

    Chunks say what they hold (a member's ``{"member": m, "blocks": ...}`` or the quasi-static
    loop's ``{"quasi_static": [up, down]}``), so the finished chunks of an unfinished job
    (``?partial=true``) assemble too: the lowest member present is read as the nominal one, a
    missing loop leaves its branches empty.
    """
    members: list[list] = []
    lines: list[str] = []
    for text in chunks:
        doc = json.loads(text)
        if "member" in doc:
            members.append(doc["blocks"])
        else:
            lines += doc["quasi_static"]
    quasi = jobs.kind("sweep").assemble(quasi_static_request(request), lines)
    return read_runup(request, runup_plan(request), members, quasi, loop_order(request))


def run_local(
    request: RunupRequest,
    progress_callback: Callable[[int, int], None] | None = None,
    workers: int = 1,
) -> RunupResult:
    """Every chunk in this process (``jobs.run_local``): the CLI's document."""
    result = jobs.run_local("runup", request, progress_callback, 1, workers)
    assert isinstance(result, RunupResult)
    return result


RUNUP_JOB = jobs.JobKind(
    name="runup",
    request=RunupRequest,
    chunk_points=1,
    chunk_counts=chunk_counts,
    work=work,
    compute_chunk=compute_chunk,
    assemble=assemble,
)
"""Run-ups as a kind of job (``gearengine.studies.jobs.KINDS``)."""
