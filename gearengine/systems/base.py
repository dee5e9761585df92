"""The System interface: a forced, piecewise-smooth oscillator that the numerics drive.

A system is an ODE y' = f(y, t) of state dimension n with its tangent equation
dy' = J(y, t) dy, forced periodically (or quasi-periodically) in t. Its first two coordinates are
the mesh coordinate x (the relative deflection along the line of action in units of the half
backlash b) and its rate v; every reading of a response (period, impacts, DTE, contact) is made
on them, and the full state identifies an attractor.

How to add a system (the contract, as ``scipy.integrate.OdeSolver`` states its own):

1. Subclass ``System``; set ``name``, ``n`` and ``coordinates`` (``coordinates[:2]`` the mesh
   coordinate and its rate).
2. ``plan(steps_per_period)``: the fixed RK4 grid (``StepPlan``) aligned to the Poincare period
   T0 of the forcing, or to the fastest excitation when it has none.
3. ``integrate(plan, start, n_trans, n_rec, stride)``: the transient and the record from
   ``start`` (shape (n,)) with the tangent vector renormalised every T0 (Benettin); a ``Run``.
   Write the step once per law (a numba kernel, ``cache=True``) and register it by law name.
4. ``stroboscopic_flow(steps_per_period)``: phi_{m T0}(X) and its n x n Jacobian (monodromy
   matrix) for Newton shooting and Floquet multipliers; ``trace_rate`` is trace J, constant for
   linear damping, so that det Phi = exp(trace_rate m T0) (Liouville) checks Phi.
5. ``method(plan)``: the integrator in words; ``start_state(x, v)``: a full start from a start of
   the mesh coordinate (the other coordinates at rest), as the basin starts are drawn.
6. For the studies (sweeps, the gate): ``params``, the parameter point of Eq. (9) whose scales
   and forcing the system shares; ``step_cost``, its RK4 step in steps of the pair's (compute
   budgets); ``dynamics_key()``, equal for two systems with equal dynamics (None: unknown).
7. For ensembles (optional): ``lane_group`` and ``run_lanes``, many runs in one lock-step
   kernel with the numbers of their own runs.
8. For run-ups (``studies.runup``, a driver speed that changes): ``ramp_start(x, v)``, the
   state (positions, rates and their tangents, shape (4, n / 2)) with ``mesh_column`` the
   column whose position and rate move x and v one for one; ``run_ramp``, one linear segment
   of the speed profile with the excitations at the integrated driver angle, by blocks
   (``spur_pair.kernels.ramp.BLOCK_COLUMNS`` of the mesh coordinate); ``step_limit()``, the
   largest RK4 step its own fast modes allow.

The spur pair of the paper (Eq. 9, ``spur_pair``) is the first system.
"""

from __future__ import annotations

import dataclasses
import math
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from gearengine.model.params import GearParams

H_OMEGA = 0.5
"""Largest h omega_max of an RK4 step against a system's fastest oscillation (RK4's stability
limit is 2.83; 0.5 keeps its phase error per step near 1e-4, and the LLE of the contact's damped
oscillation within 0.1 %: 16 steps per natural period gave -0.04003 for -0.04, 8 steps -0.0417,
2 steps a blow-up, for the design-geometry pair at 400 rpm)."""


@dataclass(frozen=True)
class StepPlan:
    """Fixed-step RK4 grid.

    Attributes:
        omega0: common frequency Omega_0 of the forcing, or None when incommensurate.
        period: sampling interval T0 (time units): 2 pi / Omega_0, or the period of the fastest
            excitation when there is no common period.
        steps: RK4 steps N per sampling interval; step h = period / steps.
        omega_ref: frequency the spectrum orders refer to, 2 pi / period.
        notes: human-readable remarks on the choices made.
        fast_periods: r = T0 / T_f, the periods of the fastest excitation in one T0 (the mesh
            periods physical time counts in, ``numerics.physical``), as the forcing's own grid
            counts them (its steps over ``steps_per_period``); unchanged when ``resolving``
            raises the steps.
    """

    omega0: float | None
    period: float
    steps: int
    omega_ref: float
    notes: tuple[str, ...]
    fast_periods: float = 1.0

    @property
    def h(self) -> float:
        """RK4 step h = T0 / N (time units)."""
        return self.period / self.steps


def resolving(plan: StepPlan, omega_max: float, what: str) -> StepPlan:
    """``plan`` with at least T0 omega_max / ``H_OMEGA`` steps per T0: an explicit step must
    resolve the system's fastest oscillation (``omega_max`` in units of omega_n), not only its
    forcing; at low speed one forcing period holds many natural periods. ``what`` names that
    oscillation in the plan's note."""
    need = math.ceil(plan.period * omega_max / H_OMEGA)
    if need <= plan.steps:
        return plan
    note = (
        f"{what} (omega = {omega_max:.4g} omega_n) needs {need} RK4 steps per T0 "
        f"(h omega <= {H_OMEGA}); {plan.steps} were asked"
    )
    return dataclasses.replace(plan, steps=need, notes=(*plan.notes, note))


@dataclass(frozen=True)
class Run:
    """What a system's integrator gives for one start (the spur pair's shapes are those of
    ``spur_pair.kernels.run_rk4``): the mesh coordinate x and its rate v at the strobes
    (``xs``, ``vs``, shape (n_rec,)), the log-stretching of the tangent vector per interval
    (``logs``), a thinned history (``hx``, ``hv``), the extremes of x and of the mesh force
    (fmin, fmax) over the record's steps, ``done`` intervals run (the record is
    ``xs[:recorded]``, shorter than n_rec when the run stopped early), and the ``final`` state of
    all n coordinates. ``strobes``: the full state at the strobes, shape (n_rec, n), for systems
    with n > 2 (None for the pair, whose state is (x, v)). ``states``: the state the
    stroboscopic flow takes (its X) at the strobes, shape (n_rec, n), for a system whose
    coordinates do not begin with (x, v) (a train: x = delta = w . u - e is not one of them;
    its ``strobes`` stay None and its runs are read on (x, v))."""

    xs: np.ndarray
    vs: np.ndarray
    logs: np.ndarray
    hx: np.ndarray
    hv: np.ndarray
    xmin: float
    xmax: float
    done: int
    final: tuple[float, ...]
    diverged: bool
    recorded: int
    fmin: float = math.nan
    fmax: float = math.nan
    strobes: np.ndarray | None = None
    states: np.ndarray | None = None


class StroboscopicFlow(Protocol):
    """The flow of a system sampled every T0: ``flow(X, m)`` gives phi_{m T0}(X), shape (n,),
    and its Jacobian Phi, shape (n, n); with the grid (``period``, ``steps``) and trace J."""

    period: float
    steps: int
    trace_rate: float

    def __call__(self, X: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]: ...


class System(ABC):
    """A forced oscillator of state dimension ``n`` that the numerics drive (see the module
    doc for the contract)."""

    name: str
    n: int
    coordinates: tuple[str, ...]
    params: GearParams
    """The parameter point of Eq. (9) whose scales and forcing the system shares (the pair's
    own; a train's equivalent pair's)."""
    step_cost: int = 1
    """One RK4 step of this system in RK4 steps of the pair's analysis, for compute budgets."""

    @abstractmethod
    def plan(self, steps_per_period: int) -> StepPlan:
        """The RK4 grid with ``steps_per_period`` steps per period of the fastest excitation."""

    @abstractmethod
    def integrate(
        self, plan: StepPlan, start: Sequence[float], n_trans: int, n_rec: int, stride: int
    ) -> Run:
        """Transient (``n_trans`` intervals T0) and record (``n_rec``) from ``start`` (n,),
        keeping every ``stride``-th step of the record in the history."""

    @abstractmethod
    def stroboscopic_flow(self, steps_per_period: int) -> StroboscopicFlow:
        """The flow sampled every T0; ValueError when the forcing has no Poincare period."""

    @abstractmethod
    def method(self, plan: StepPlan) -> str:
        """How ``integrate`` runs this system, in words."""

    def damping_rate(self) -> float | None:
        """The decay rate of free vibration per unit tau (the damping ratio mu of Eq. 9), for
        transients counted in damping time constants; None when the system has no single one."""
        return None

    def start_state(self, x: float, v: float) -> tuple[float, ...]:
        """A full start from (x, v) of the mesh coordinate, every other coordinate at rest."""
        return (x, v) + (0.0,) * (self.n - 2)

    ramp_method: str = "no run-up kernel"
    """How ``run_ramp`` integrates, in words."""
    mesh_column: int = 0
    """Column of the run-up state (``ramp_start``) whose position and rate are x and v, or move
    them one for one."""

    def step_limit(self) -> float:
        """Largest RK4 step [tau] this system's own modes allow (inf: the natural frequency
        1 and the excitations alone set the step)."""
        return math.inf

    def ramp_start(self, x: float, v: float) -> np.ndarray:
        """The run-up state from (x, v) of the mesh coordinate (``start_state``), with its
        tangent: rows positions, rates, their tangent components; shape (4, n / 2)."""
        raise NotImplementedError(f"{self.name} has no run-up kernel")

    def run_ramp(
        self, state: np.ndarray, kc: np.ndarray, fc: np.ndarray, ramp: np.ndarray,
        inertia: float, h: float, n_blocks: int, steps: int,
    ) -> tuple[np.ndarray, int]:  # fmt: skip
        """One segment of a speed profile from ``state`` (``ramp_start``'s layout, updated in
        place): n_blocks x steps RK4 steps of h. ``kc``, ``fc``, ``ramp``: the pair's forcing by
        order of the driver angle and the segment's record (F~_m0, F~_m1, Omega_0, beta, psi_0)
        (``spur_pair.kernels.phase``), of whose mean force ``inertia`` is the part that
        accelerates the train. Returns the block table (n_blocks, 9) and the blocks done."""
        raise NotImplementedError(f"{self.name} has no run-up kernel")

    def lane_group(self, plan: StepPlan) -> tuple | None:
        """The key of the lock-step group whose lanes this system's runs on ``plan`` join
        (``run_lanes``); None: they run one by one (``integrate``)."""
        return None

    def run_lanes(
        self, points: Sequence[System], owner: np.ndarray, starts: np.ndarray,
        plans: Sequence[StepPlan], n_trans: int, n_rec: int, stride: int,
    ) -> tuple:  # fmt: skip
        """Every lane of one group (``lane_group``) in lock-step: ``points`` (P) of the group
        (this one among them), the point of each lane ``owner`` (L,), their full starts
        (``start_state``, (L, n)) and plans; the arrays of ``numerics.lanes`` (xs, vs, logs,
        xmin, xmax, fmin, fmax, done, recorded, diverged, final x, final v), each lane's
        numbers those of its ``integrate`` with history ``stride``."""
        raise NotImplementedError(f"{self.name} has no lock-step kernel")

    def dynamics_key(self) -> tuple | None:
        """Equal for two systems that integrate the same equations (a sweep axis that leaves it
        unchanged changes nothing); None when the system cannot tell."""
        return None
