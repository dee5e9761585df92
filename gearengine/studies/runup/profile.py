"""A run-up's speed profile as kernel work: segments linear in time, their forcing on the
integrated driver angle, their RK4 step and blocks.

Time: Eq. (9) runs in tau = w_n t with w_n = sqrt(k_m / m), which does not depend on the speed
(docs/conversion.md), so the design's own time scale maps seconds to tau for the whole profile
and the speed enters only through the excitation phases and the transmission-error force
(``systems.spur_pair.kernels.phase``). On a segment from speed w0 at t0 to w1 at t1 the driver
angle is psi_a = psi_0 + Omega_0 tau + beta tau^2 / 2 exactly, Omega = w / w_n, beta = (w1 - w0) /
(t1 - t0) / w_n^2; psi_0 carries over from the segment before, so the phases are continuous.

Mean force: the driver follows the profile (speed-controlled) against the braking torque that
balances the design's torque, so the tooth force also accelerates the driven inertia:
F^_m = T_a / r_a + I_b (d w_b / dt) / r_b (the driven gear's free body; w_b = w_a r_a / r_b).
At 1000 rpm/s on ``examples/ci/design.json`` the second term is 0.1 % of the first. A train
(its equivalent pair's scales, I_b = I_g + I_l) takes that force as the motor torque that
accelerates it (``TrainSystem.run_ramp``), and its fast modes bound the step
(``System.step_limit``).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import ValidationError
from pydantic_core import InitErrorDetails

from gearengine.model.errors import Problems
from gearengine.model.fields import design_with
from gearengine.model.params import GearParams
from gearengine.model.reduction import DesignConversion
from gearengine.model.units import RPM, in_si
from gearengine.studies.runup.request import MAX_RUNUP_STEPS, RunupRequest, request_errors
from gearengine.systems.base import System
from gearengine.systems.designs import design_model, params_of
from gearengine.systems.spur_pair.forcing import packed_forcing

BLOCKS_PER_BIN = 4
"""Blocks (the kernel's unit of output) per speed bin on a ramp."""
SETTLE_BLOCK_PERIODS = 50
"""Mesh periods per block where the speed does not change (the settling, flat stretches)."""

Branch = Literal["up", "down"]


@dataclass(frozen=True)
class Segment:
    """A stretch of the profile linear in time, cut into ``n_blocks`` x ``steps`` RK4 steps.

    Attributes:
        t0, t1: start and end [s] (the settling before the profile has t0 < 0 = t1).
        w0, w1: driver speed at t0 and t1 [rad/s].
        branch: up or down (rising or falling speed; a flat stretch keeps the one before);
            None for the settling, which is not read.
        n_blocks, steps: blocks and RK4 steps per block; h the step [tau].
    """

    t0: float
    t1: float
    w0: float
    w1: float
    branch: Branch | None
    n_blocks: int
    steps: int
    h: float


@dataclass(frozen=True)
class RampForcing:
    """The design's excitations by order of the driver angle (``kernels.phase`` layout)."""

    kc: np.ndarray
    fc: np.ndarray
    omega_n: float
    """Natural frequency w_n [rad/s] (tau = w_n t)."""
    fastest_order: float
    """Largest order q of an active excitation (0 when none)."""


def ramp_forcing(params: GearParams, speed: float, omega_n: float) -> RampForcing:
    """The forcing of ``params`` (converted at driver speed ``speed`` rad/s) by order q of
    the driver angle: q = Omega / Omega_a, transmission-error amplitudes back to F~_er."""
    kc, _, fc = packed_forcing(params)
    omega_a = speed / omega_n
    n_te = 0 if params.transmission_error is None else len(list(params.transmission_error.active()))
    kind = np.zeros(fc.shape[1])
    kind[fc.shape[1] - n_te :] = 1.0
    amp = np.where(kind == 1.0, fc[0] / np.maximum(fc[1], 1e-300) ** 2, fc[0])
    k = np.ascontiguousarray(np.vstack([kc[0], kc[1] / omega_a, kc[2]]))
    f = np.ascontiguousarray(np.vstack([amp, fc[1] / omega_a, fc[2], kind]))
    orders = [*k[1], *f[1]]
    return RampForcing(k, f, omega_n, max(orders) if orders else 0.0)


@dataclass(frozen=True)
class RunupPlan:
    """Everything a member's integration needs, from the request alone (deterministic)."""

    system: System
    """What the members integrate (``RunupRequest.model``)."""
    conversion: DesignConversion
    """The conversion whose scales read the members (``RunupRequest.model``, converted once
    with ``system``)."""
    segments: list[Segment]
    forcing: RampForcing
    mean_force: tuple[float, float]
    """F~_m at the start and at the end of the profile (the torque ramp, Eq. 7 / (b k_m))."""
    inertia_force: float
    """F~ per unit of driver acceleration: I_b (r_a / r_b) / r_b / (b k_m) [1 / (rad/s^2)]."""
    duration: float
    """Length of the profile [s]."""

    def mean_force_at(self, t: float, acceleration: float) -> float:
        """F~_m at time t [s] with driver acceleration [rad/s^2] (torque ramp + inertia)."""
        f0, f1 = self.mean_force
        share = 0.0 if self.duration <= 0 else min(max(t / self.duration, 0.0), 1.0)
        return f0 + (f1 - f0) * share + self.inertia_force * acceleration

    def ramp_record(self, seg: Segment, psi0: float) -> np.ndarray:
        """The kernel's ramp record (F~_m0, F~_m1, Omega_0, beta, psi_0) of ``seg``."""
        wn = self.forcing.omega_n
        span = seg.t1 - seg.t0
        accel = (seg.w1 - seg.w0) / span
        f0 = self.mean_force_at(seg.t0, accel)
        f1 = (self.mean_force_at(seg.t1, accel) - f0) / (span * wn)
        if seg.branch is None:  # settling: the start's force, no acceleration
            f0, f1 = self.mean_force_at(0.0, 0.0), 0.0
        return np.array([f0, f1, seg.w0 / wn, accel / wn**2, psi0])

    def inertia(self, seg: Segment) -> float:
        """The part of ``ramp_record``'s F~_m0 that accelerates the driven side (0 while
        settling)."""
        if seg.branch is None:
            return 0.0
        return self.inertia_force * (seg.w1 - seg.w0) / (seg.t1 - seg.t0)

    def work(self, members: int) -> int:
        """RK4 steps of ``members`` runs of the whole plan, in the pair's steps
        (``System.step_cost``)."""
        return members * self.system.step_cost * sum(s.n_blocks * s.steps for s in self.segments)


def _segment(
    request: RunupRequest, forcing: RampForcing, limit: float, t0: float, t1: float, w0: float,
    w1: float, branch: Branch | None,
) -> Segment:  # fmt: skip
    wn = forcing.omega_n
    fastest = max(1.0, forcing.fastest_order * max(w0, w1) / wn)  # natural frequency is 1
    h_max = min(2.0 * math.pi / fastest / request.steps_per_period, limit)
    span = abs(w1 - w0) / RPM
    if span > 0.0 and branch is not None:
        n_blocks = max(1, math.ceil(span / (request.bin_rpm / BLOCKS_PER_BIN) - 1e-9))
    else:
        assert request.design is not None
        mesh_periods = (t1 - t0) * request.design.driver.teeth * max(w0, w1) / (2.0 * math.pi)
        n_blocks = max(1, math.ceil(mesh_periods / SETTLE_BLOCK_PERIODS))
    tau_block = (t1 - t0) * wn / n_blocks
    steps = max(1, math.ceil(tau_block / h_max - 1e-9))
    return Segment(t0, t1, w0, w1, branch, n_blocks, steps, tau_block / steps)


def profile_segments(request: RunupRequest, forcing: RampForcing, limit: float) -> list[Segment]:
    """The profile of ``request`` as segments (``_segment``, RK4 steps at most ``limit``
    [tau]): the settling at the start speed (``settle_periods``), then one segment between
    each two knots, up or down as the speed goes (a flat stretch keeps the branch before)."""
    assert request.design is not None
    knots = request.knots()
    segments: list[Segment] = []
    if request.settle_periods > 0:
        w = knots[0][1]
        settle = request.settle_periods * 2.0 * math.pi / (request.design.driver.teeth * w)
        segments.append(_segment(request, forcing, limit, -settle, 0.0, w, w, None))
    branch: Branch = "up" if knots[-1][1] >= knots[0][1] else "down"
    for (t0, w0), (t1, w1) in itertools.pairwise(knots):
        branch = "up" if w1 > w0 else ("down" if w1 < w0 else branch)
        segments.append(_segment(request, forcing, limit, t0, t1, w0, w1, branch))
    return segments


def runup_plan(request: RunupRequest) -> RunupPlan:
    """Segments (``profile_segments``), forcing and mean force of a run-up.

    Raises ValueError (message starting with the field) when a torque ramp changes more than
    the mean force (a load-dependent ISO 6336 stiffness).
    """
    design, (system, conv) = request.design, request.model()
    assert design is not None
    params = conv.params
    omega_n = 1.0 / conv.time_scale_s
    forcing = ramp_forcing(params, design.speed, omega_n)
    segments = profile_segments(request, forcing, system.step_limit())
    f0 = params.mean_force
    f1 = f0
    if request.to_torque is not None:
        end = params_of(design_model(design_with(design, {"torque": request.to_torque}))[0])
        if end.model_copy(update={"mean_force": f0}) != params:
            raise ValueError("to_torque: this design's mesh stiffness depends on the load "
                             "(iso6336); a torque ramp needs mesh.stiffness in N/m")  # fmt: skip
        f1 = end.mean_force
    ra = float(conv.derived["base_radius_driver"].value)  # type: ignore[arg-type]
    rb = float(conv.derived["base_radius_driven"].value)  # type: ignore[arg-type]
    ib = float(conv.derived["inertia_driven"].value)  # type: ignore[arg-type]
    force_scale = in_si("mesh_force", 1.0, conv.scales)  # N per unit force, b k_m
    return RunupPlan(
        system=system,
        conversion=conv,
        segments=segments,
        forcing=forcing,
        mean_force=(f0, f1),
        inertia_force=ib * (ra / rb) / rb / force_scale,
        duration=segments[-1].t1,
    )


def segment_angle(seg: Segment) -> float:
    """Driver angle psi_a [rad] gained over ``seg``: the integral of Omega d tau = of w dt,
    exact for the linear ramp."""
    return 0.5 * (seg.w0 + seg.w1) * (seg.t1 - seg.t0)


def mid_speeds_rpm(seg: Segment) -> np.ndarray:
    """Driver speed [rpm] at the middle of each block of ``seg``."""
    s = (np.arange(seg.n_blocks) + 0.5) / seg.n_blocks
    return (seg.w0 + (seg.w1 - seg.w0) * s) / RPM


def budget_errors(request: RunupRequest) -> list[InitErrorDetails]:
    """The work budget (``MAX_RUNUP_STEPS``) of a request whose fields ``request_errors``
    passed, as pydantic error details naming the field that sets the length."""
    problems = Problems("runup")
    add, errors = problems.add, problems.details

    try:
        steps = runup_plan(request).work(request.ensemble.size)
    except ValueError as exc:  # a torque ramp on a load-dependent stiffness
        field, _, message = str(exc).partition(": ")
        add((field,), message, getattr(request, field, None))
        return errors
    if steps > MAX_RUNUP_STEPS:
        field = "points" if request.points is not None else (
            "duration" if request.duration is not None else "rate")  # fmt: skip
        add((field,), f"this profile needs {steps} RK4 steps ({request.ensemble.size} members), "
            f"over the budget of {MAX_RUNUP_STEPS}; shorten it, raise the rate or use fewer "
            "ensemble members", getattr(request, field))  # fmt: skip
    return errors


def checked_runup(request: RunupRequest) -> RunupRequest:
    """``request`` if ``request_errors`` and ``budget_errors`` find nothing; else
    ``ValidationError`` naming each field (the checks the API and the CLI share)."""
    errors = request_errors(request) or budget_errors(request)
    if errors:
        raise ValidationError.from_exception_data("RunupRequest", errors)
    return request


def validated_runup(data: object) -> RunupRequest:
    """Parse and check a run-up request document; raises ``ValidationError`` naming each field."""
    return checked_runup(RunupRequest.model_validate(data))
