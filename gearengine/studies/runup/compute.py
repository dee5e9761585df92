"""Computing a run-up as a job: one chunk per ensemble member (the whole profile on the
integrated driver angle through the system's ``run_ramp``: the pair's kink-accurate RK4,
``systems.spur_pair.kernels.ramp``, or a train's, ``systems.gear_train.ramp``), and the two
lines of the quasi-static continuation sweep (up and down, ``studies.sweep.compute``, on the bin
centres); the assembly reads them into bins, jumps and lags (``studies.runup.reading``).

Member m starts from the state of the settling (``settle_periods`` mesh periods at the start
speed from the static contact x = 1 + F~_m, v = 0; a train's shafts and bearings at their static
deflection), member 0 as it is, the others' x and v perturbed by ``ensemble.perturbation``
(normal, ``numpy.random.default_rng([seed, m])``). A chunk depends only
on (request, index), so a resumed job gives the same bytes.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable

import numpy as np

from gearengine.model.units import RPM
from gearengine.studies import jobs
from gearengine.studies.runup.profile import RunupPlan, mid_speeds_rpm, runup_plan, segment_angle
from gearengine.studies.runup.reading import read_runup
from gearengine.studies.runup.request import RunupRequest, n_bins
from gearengine.studies.runup.results import RunupResult
from gearengine.studies.sweep.plan import sweep_work
from gearengine.studies.sweep.request import SweepRequest

QUASI_STATIC_CHUNKS = 2
"""Chunks after the members: the up and the down line of the continuation sweep."""


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


def quasi_static_request(request: RunupRequest) -> SweepRequest:
    """The continuation sweep, up and down, on the centres of the run-up's speed bins.

    The design's torque is a second axis of one value: a one-axis line would also locate its
    bifurcation points by Newton shooting, which the run-up does not read (and which costs
    more than the line).
    """
    assert request.design is not None
    torque = request.design.torque
    lo, hi = (w / RPM for w in request.speed_range())
    n = n_bins(lo, hi, request.bin_rpm)
    first, last = lo + 0.5 * request.bin_rpm, lo + (n - 0.5) * request.bin_rpm
    return SweepRequest.model_validate(
        {
            "design": request.design,
            "settings": request.quasi_static,
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
            "direction": "both",
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


def chunk_counts(request: RunupRequest, size: int) -> list[int]:
    """One unit of work per chunk: the members, then the two quasi-static lines."""
    return [1] * (request.ensemble.size + QUASI_STATIC_CHUNKS)


def work(request: RunupRequest) -> int:
    """RK4 steps of the whole job: every member's profile and the quasi-static sweep."""
    return runup_plan(request).work(request.ensemble.size) + sweep_work(
        quasi_static_request(request)
    )


def compute_chunk(request: RunupRequest, index: int, chunk_points: int = 1) -> str:
    """Chunk ``index`` as JSON text: a member's block table, or a quasi-static line."""
    members = request.ensemble.size
    if index < members:
        return json.dumps({"member": index, "blocks": member_blocks(request, runup_plan(request),
                                                                    index)})  # fmt: skip
    sweep = jobs.kind("sweep")
    return sweep.compute_chunk(quasi_static_request(request), index - members, 1)


def assemble(request: RunupRequest, chunks: list[str]) -> RunupResult:
    """The run-up's document from its chunks in index order.

    Chunks say what they hold (a member's ``{"member": m, "blocks": ...}`` or a quasi-static
    line), so the finished chunks of an unfinished job (``?partial=true``) assemble too: the
    lowest member present is read as the nominal one, a missing line leaves its branch empty.
    """
    members: list[list] = []
    lines: list[str] = []
    for text in chunks:
        doc = json.loads(text)
        if isinstance(doc, dict) and "member" in doc:
            members.append(doc["blocks"])
        else:
            lines.append(text)
    quasi = jobs.kind("sweep").assemble(quasi_static_request(request), lines)
    return read_runup(request, runup_plan(request), members, quasi)


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
