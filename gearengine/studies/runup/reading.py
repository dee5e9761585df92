"""Reading a run-up: block tables into speed bins, jumps, the finite-time Lyapunov exponent
and the lag behind the quasi-static hysteresis loop.

Finite-time Lyapunov exponent (FTLE). Every member carries its tangent vector (Eq. 9's tangent
equation), renormalised at the end of every block (Benettin et al., Meccanica 15, 1980); the
exponent of a bin is the growth of log |tangent| over the bin's window divided by its length in
tau, averaged over the ensemble of slightly perturbed starts: the ensemble-averaged finite-time
(instantaneous) Lyapunov exponent of systems under parameter drift (D. Janosi and T. Tel,
"Characterizing chaos in systems subjected to parameter drift", Phys. Rev. E 105, L062202
(2022); the ensemble view of their 2024 work that ChaosTools.jl PR #345 implements). The window
is one speed bin (``bin_rpm`` / rate seconds on a ramp); its standard error is that of the
rates of every member's blocks in the bin (batch means over members and blocks: members that
settle on one orbit agree to the last bit, so their spread alone would read as exactly 0).

Jumps: between neighbouring bins in the direction of travel, the DTE changes by at least
``JUMP_RATIO`` times and by at least ``JUMP_MIN_B`` half backlashes; the speed of a jump is the
edge between the two bins (for the quasi-static branches: the midpoint of two grid speeds, the
same edge); such steps in one sense at neighbouring edges are one jump (a bin that caught the
response half-way), placed at its largest step.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np

from gearengine.homoclinic.boundary import speed_windows
from gearengine.homoclinic.train_reduction import melnikov_point
from gearengine.model.units import RPM, Scales, shown, to_physical
from gearengine.signals.classify import LLE_FLOOR
from gearengine.studies.runup.profile import Branch, RunupPlan
from gearengine.studies.runup.request import RunupRequest, n_bins
from gearengine.studies.runup.results import (
    QuasiStatic,
    QuasiStaticBranch,
    QuasiStaticPoint,
    RunupBin,
    RunupBranch,
    RunupJump,
    RunupMethod,
    RunupResult,
)
from gearengine.studies.sweep.points import SweepPoint
from gearengine.studies.sweep.results import SweepResult

JUMP_RATIO = 1.25
"""Least ratio of the larger to the smaller DTE of two neighbouring bins that is a jump."""
JUMP_MIN_B = 0.1
"""Least change of DTE that is a jump, in half backlashes b."""

# block table columns (compute.member_blocks)
BRANCH, T0, T1, SPEED, FM, STEPS, XMIN, XMAX, FMIN, FMAX, SEP, BACK, BACK_IN, DRIVE_IN, LOG = range(
    15
)
CMIN, CMAX = 15, 16
"""The contact force's extremes (``kernels.ramp.BLOCK_COLUMNS``; absent from a table stored
before they were added: the bin's contact force is then null)."""


def differ(a: float, c: float, b_um: float) -> bool:
    """True if two DTEs [µm] differ as much as a jump: by ``JUMP_RATIO`` times and by
    ``JUMP_MIN_B`` half backlashes (``b_um`` µm each) or more."""
    lo, hi = min(a, c), max(a, c)
    return hi - lo >= JUMP_MIN_B * b_um and hi >= JUMP_RATIO * max(lo, 1e-12)


def jumps(speeds: Sequence[float], dte: Sequence[float | None], b_um: float) -> list[RunupJump]:
    """Jumps along a sequence in the order travelled: ``speeds`` are the edges between entries
    i and i+1 (len(dte) - 1 of them), ``dte`` [µm] the amplitudes. A jump spread over
    neighbouring edges in one sense (a bin caught half-way) is one jump, from its first
    amplitude to its last, at the edge of its largest step."""
    steps: list[tuple[int, float, float]] = []
    for i in range(len(speeds)):
        a, c = dte[i], dte[i + 1]
        if a is not None and c is not None and differ(a, c, b_um):
            steps.append((i, a, c))
    groups: list[list[tuple[int, float, float]]] = []
    for step in steps:
        last = groups[-1][-1] if groups else None
        if (
            last is not None
            and step[0] == last[0] + 1
            and (step[2] > step[1]) == (last[2] > last[1])
        ):
            groups[-1].append(step)
        else:
            groups.append([step])
    out = []
    for g in groups:
        i = max(g, key=lambda s: abs(s[2] - s[1]))[0]
        out.append(RunupJump(speed_rpm=shown(speeds[i]), from_um=shown(g[0][1]),
                             to_um=shown(g[-1][2])))  # fmt: skip
    return out


def with_lags(ramp: list[RunupJump], quasi: list[RunupJump], branch: Branch) -> list[RunupJump]:
    """Each ramp jump with the quasi-static jump of the same sense it lags, and its lag: the
    pairs nearest in speed first, each quasi-static jump paired once (a second ramp jump near
    an already paired one is a jump of the ramp's own, with no lag to give)."""
    sign = 1.0 if branch == "up" else -1.0
    pairs = sorted(
        ((abs(q.speed_rpm - j.speed_rpm), i, k) for i, j in enumerate(ramp)
         for k, q in enumerate(quasi) if (q.to_um > q.from_um) == (j.to_um > j.from_um)),
    )  # fmt: skip
    lagged: dict[int, RunupJump] = {}
    used: set[int] = set()
    for _, i, k in pairs:
        if i not in lagged and k not in used:
            lagged[i], used = quasi[k], used | {k}
    out = []
    for i, j in enumerate(ramp):
        q = lagged.get(i)
        if q is None:
            out.append(j)
            continue
        lag = sign * (j.speed_rpm - q.speed_rpm) + 0.0  # no -0
        out.append(j.model_copy(update={"quasi_static_speed_rpm": q.speed_rpm,
                                        "lag_rpm": shown(lag)}))  # fmt: skip
    return out


def _bins(request: RunupRequest, tables: list[np.ndarray], branch: Branch, lo: float,
          scales: Scales) -> list[tuple[int, RunupBin]]:  # fmt: skip
    """The bins of one branch in the order first reached, with their indices."""
    if not tables:
        return []
    sign = 1.0 if branch == "up" else -1.0
    nominal = tables[0]
    width = request.bin_rpm
    count = n_bins(lo, request.speed_range()[1] / RPM, width)
    rows = nominal[nominal[:, BRANCH] == sign]
    index = np.minimum(((rows[:, SPEED] - lo) // width).astype(int), count - 1)
    out = []
    for k in dict.fromkeys(index.tolist()):
        mine = rows[index == k]
        block_ids = np.flatnonzero(nominal[:, BRANCH] == sign)[index == k]
        steps = mine[:, STEPS].sum()
        ok = not np.isnan(mine[:, XMAX]).any()
        span = [lo + k * width, min(lo + (k + 1) * width, request.speed_range()[1] / RPM)]
        lle = stderr = None
        logs = np.array([t[block_ids, LOG].sum() for t in tables if len(t)])
        tau = float(((mine[:, T1] - mine[:, T0]).sum()) * scales.natural_frequency)
        if ok and len(logs) == len(tables) and np.isfinite(logs).all() and tau > 0:
            lle = float((logs / tau).mean())
            # the spread of the rates of every member's blocks in the bin: members that settle
            # on one orbit agree to the last bit, and their spread alone would read as 0
            taus = (mine[:, T1] - mine[:, T0]) * scales.natural_frequency
            rates = np.concatenate([t[block_ids, LOG] / taus for t in tables if len(t)])
            stderr = float(rates.std(ddof=1) / math.sqrt(len(rates))) if len(rates) > 1 else None
        sep = back = None
        contact = None
        if ok:
            sep = float(mine[:, SEP].sum() / steps)
            back = float(mine[:, BACK].sum() / steps)
            contact = "both_flanks" if back > 0 else ("separation" if sep > 0 else "drive_flank")
        factor = None
        if ok and (mine[:, FM] > 0).all():  # each block at its own mean force (a torque ramp)
            blocks = zip(mine[:, FMAX].tolist(), mine[:, FM].tolist(), strict=True)
            factor = shown(max(to_physical("dynamic_factor", f, scales.at(fm)) for f, fm in blocks))
        dte = float(mine[:, XMAX].max() - mine[:, XMIN].min())
        contact_kept = mine.shape[1] > CMAX
        out.append((k, RunupBin(
            speed_rpm=[shown(span[0]), shown(span[1])],
            time_s=[shown(float(mine[:, T0].min())), shown(float(mine[:, T1].max()))],
            dte_peak_to_peak_um=shown(to_physical("dte", dte, scales)) if ok else None,
            force_max_n=shown(to_physical("mesh_force", float(mine[:, FMAX].max()), scales))
            if ok else None,
            force_min_n=shown(to_physical("mesh_force", float(mine[:, FMIN].min()), scales))
            if ok else None,
            contact_force_max_n=shown(to_physical("mesh_force", float(mine[:, CMAX].max()),
                                                  scales)) if ok and contact_kept else None,
            contact_force_min_n=shown(to_physical("mesh_force", float(mine[:, CMIN].min()),
                                                  scales)) if ok and contact_kept else None,
            dynamic_factor=factor,
            separation_fraction=None if sep is None else shown(sep),
            back_flank_fraction=None if back is None else shown(back),
            contact=contact,
            back_flank_impacts=int(mine[:, BACK_IN].sum()) if ok else None,
            drive_flank_impacts=int(mine[:, DRIVE_IN].sum()) if ok else None,
            lle=None if lle is None else shown(lle),
            lle_stderr=None if stderr is None else shown(stderr),
            chaotic=None if lle is None else bool(
                lle > LLE_FLOOR and (stderr is None or lle > 3.0 * stderr)),
        )))  # fmt: skip
    return out


def _edges(bins: list[tuple[int, RunupBin]], branch: Branch) -> list[float]:
    """The edge between consecutive bins in travel order (upper edge going up)."""
    return [b.speed_rpm[1] if branch == "up" else b.speed_rpm[0] for _, b in bins[:-1]]


def _quasi_branch(points: list[SweepPoint], branch: Branch, b_um: float) -> QuasiStaticBranch:
    mine = [p for p in points if p.branch == branch]
    out = []
    for p in mine:
        phys = p.physical or {}
        dte, factor = phys.get("dte"), phys.get("dynamic_factor")
        out.append(QuasiStaticPoint(
            speed_rpm=phys["speed"].value,
            dte_peak_to_peak_um=None if dte is None else dte.value,
            dynamic_factor=None if factor is None else factor.value,
            classification=p.classification, impact_regime=p.impact_regime, lle=p.lle,
        ))  # fmt: skip
    edges = [shown(0.5 * (a.speed_rpm + c.speed_rpm)) for a, c in itertools.pairwise(out)]
    return QuasiStaticBranch(points=out, jumps=jumps(edges, [p.dte_peak_to_peak_um for p in out],
                                                     b_um))  # fmt: skip


def transient_chaos(branch: RunupBranch, quasi: QuasiStaticBranch) -> list[list[float]]:
    """Speed spans [rpm] of ``branch``'s chaotic bins where the steady state at the bin centre
    (``quasi``, the continuation of the same direction: one start followed from speed to speed)
    is not chaotic: the ramp's transient, or an attractor the continuation did not follow (a
    check with basin starts may find chaos there: the two are not the same question)."""
    steady = {round(p.speed_rpm, 6): p.classification for p in quasi.points}
    spans: list[list[float]] = []
    for b in sorted(branch.bins, key=lambda b: b.speed_rpm[0]):
        centre = round(0.5 * (b.speed_rpm[0] + b.speed_rpm[1]), 6)
        if b.chaotic and steady.get(centre) not in ("chaotic", "diverged"):
            if spans and spans[-1][1] == b.speed_rpm[0]:
                spans[-1][1] = b.speed_rpm[1]
            else:
                spans.append(list(b.speed_rpm))
    return spans


def transient_note(name: str, spans: list[list[float]]) -> str:
    """ "run-up: chaotic bins at 3500-3600 rpm where the steady state is not chaotic ..."."""
    where = ", ".join(f"{lo:.0f}-{hi:.0f}" for lo, hi in spans)
    return (f"run-{name}: chaotic bins at {where} rpm where the quasi-static continuation (one "
            "start followed from speed to speed, at the bin centres) is not chaotic: chaos of the "
            "ramp's transient, or of an attractor the continuation does not follow (gearengine "
            "check, with its basin starts, may find chaos there too)")  # fmt: skip


def start_note(name: str, branch: RunupBranch, quasi: QuasiStaticBranch, b_um: float) -> str | None:
    """A note when the ramp's branch ``name`` and the quasi-static one of the same direction
    start on different responses: the DTE of the ramp's first bin and of the continuation at
    its centre differ as a jump does (``differ``); None when they agree (or cannot be read)."""
    first = branch.bins[0]
    lo, hi = first.speed_rpm
    centre = round(0.5 * (lo + hi), 6)
    point = next((p for p in quasi.points if round(p.speed_rpm, 6) == centre), None)
    a = first.dte_peak_to_peak_um
    c = None if point is None else point.dte_peak_to_peak_um
    if a is None or c is None or not differ(a, c, b_um):
        return None
    return (f"run-{name} and the quasi-static {name} start on different responses: "
            f"{a:.3g} µm in the ramp's first bin ({lo:.0f}-{hi:.0f} rpm), {c:.3g} µm on the "
            f"continuation at {centre:.0f} rpm (coexisting attractors, or the ramp's lag behind "
            "a jump near its start)")  # fmt: skip


def read_runup(
    request: RunupRequest,
    plan: RunupPlan,
    tables: list[list],
    quasi: SweepResult,
    loop: tuple[Branch, Branch],
) -> RunupResult:
    """The run-up's document from the members' block tables and the quasi-static sweep (its
    lines computed in the order ``loop``), read with the system and conversion of ``plan``
    (the design converted once)."""
    design, system, conv = request.design, plan.system, plan.conversion
    assert design is not None
    arrays = [np.array(t, dtype=float).reshape(-1, len(t[0]) if t else CMAX + 1)
              for t in tables]  # fmt: skip
    lo, hi = (w / RPM for w in request.speed_range())
    scales = conv.scales
    b_um = to_physical("dte", 1.0, scales)  # one half backlash b in the DTE's unit
    qs = QuasiStatic(
        up=_quasi_branch(quasi.points, "up", b_um),
        down=_quasi_branch(quasi.points, "down", b_um),
        grid_step_rpm=request.bin_rpm,
        torque_nm=design.torque,
    )
    branches: dict[str, RunupBranch | None] = {"up": None, "down": None}
    for branch in ("up", "down"):
        bins = _bins(request, arrays, branch, lo, scales)
        if not bins:
            continue
        found = jumps(_edges(bins, branch), [b.dte_peak_to_peak_um for _, b in bins], b_um)
        quasi_jumps = getattr(qs, branch).jumps
        branches[branch] = RunupBranch(bins=[b for _, b in bins],
                                       jumps=with_lags(found, quasi_jumps, branch))  # fmt: skip
    steps = plan.work(request.ensemble.size)
    notes = [
        f"settled for {request.settle_periods} mesh periods at {request.knots()[0][1] / RPM:g} "
        "rpm before the profile starts",
        "the quasi-static loop is the continuation sweep at the design's torque "
        f"({design.torque:g} N m), on the bin centres, {' then '.join(loop)}: the {loop[0]} "
        f"line from the members' start, the {loop[1]} line from where the {loop[0]} line ended",
        "the ramp and the loop follow the response they start on: other responses can "
        "coexist at a speed (gearengine basins, or check's basin starts, searches them)",
    ]
    if request.to_torque is not None:
        notes.append(f"the torque ramps linearly in time to {request.to_torque:g} N m")
    for name, branch in branches.items():
        if branch is None:
            continue
        spans = transient_chaos(branch, getattr(qs, name))
        notes += [transient_note(name, spans)] if spans else []
        apart = start_note(name, branch, getattr(qs, name), b_um)
        notes += [apart] if apart is not None else []
    judged = melnikov_point(system)  # a train's mesh-mode reduction, when it holds
    windows = [] if judged is None else speed_windows(judged, conv.speed_rpm, lo, hi)
    if system.n > 2:
        notes.append(
            f"gear train ({system.n} states): numerics of the train, scales of its equivalent "
            "pair (I_a = I_m + I_p, I_b = I_g + I_l); Melnikov windows "
            + ("of its mesh-mode reduction (a reduction)" if judged is not None else
               "not given: no single mode carries the mesh")
        )  # fmt: skip
    return RunupResult(
        up=branches["up"],
        down=branches["down"],
        quasi_static=qs,
        melnikov_windows_rpm=windows,
        time_scale_s=conv.time_scale_s,
        duration_s=plan.duration,
        method=RunupMethod(
            integration=f"{system.ramp_method}, {request.steps_per_period} steps per period of "
            "the fastest of the natural frequency and the excitations at each segment's top "
            "speed; excitations at the integrated driver angle (systems.spur_pair.kernels.phase)",
            lyapunov="ensemble-averaged finite-time Lyapunov exponent over each bin's window: "
            "tangent equation renormalised every block (Benettin 1980), averaged over "
            f"{request.ensemble.size} perturbed starts (Janosi & Tel, Phys. Rev. E 105, "
            "L062202, 2022), per unit tau",
            jumps=f"DTE of neighbouring bins differing by x{JUMP_RATIO:g} and by "
            f"{JUMP_MIN_B:g} b ({JUMP_MIN_B * b_um:g} µm) or more",
            ensemble=request.ensemble.size,
            steps=steps,
            bin_rpm=request.bin_rpm,
        ),
        notes=notes,
    )
