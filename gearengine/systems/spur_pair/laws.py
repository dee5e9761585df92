"""The spur pair's backlash laws: one registry, one entry per law with everything the engine
does with it (f_h, the cubic the Melnikov analysis uses, the single-run integrator and the
lock-step lanes), as scipy's ``METHODS`` of ``solve_ivp`` map a name to a solver.

How to add a law (the contract):

1. Write f_h(x) on arrays in ``model/backlash.py`` (x and f_h in units of the half backlash b),
   and its parameters as a model of ``model/params.py`` (the ``backlash.model`` name).
2. Give the cubic -a x + c x^3 the Melnikov analysis uses for it (a fit, with a note saying so,
   when the law has no smooth homoclinic orbit): ``melnikov_cubic``.
3. Give its step to the kernels: a ``kernel_code`` that ``kernels.smooth.law_force`` and
   ``kernels.monodromy`` switch on (a smooth law), or a kernel of its own that splits the steps
   at its kinks (as ``kernels.kink``); ``run`` calls it with the common arguments.
4. Optionally ``lanes``: a lock-step kernel over many lanes, the one lane scheduler with the
   law's steps: a ``kernels.scheduler.LaneLaw`` (per-lane arrays, load, steps, keep) made into a
   kernel by ``lane_kernel``, as ``kernels.lockstep.CUBIC``; without it the lanes of that law
   run one by one through ``run``.
5. Register it in ``LAWS``; ``tests/test_kernels.py`` and ``tests/test_scipy_crosscheck.py``
   hold a new law against scipy's DOP853 (with events at its kinks).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gearengine.model.backlash import collocation_fit, fh_cubic, fh_piecewise
from gearengine.model.params import CubicBacklash, GearParams, PiecewiseBacklash
from gearengine.signals.classify import DIVERGENCE_BOUND
from gearengine.systems.base import StepPlan
from gearengine.systems.spur_pair import kernels


@dataclass(frozen=True)
class Law:
    """Backlash law f_h as kernel arguments: its name and code in ``LAWS``, the
    cubic's (a, c) and the piecewise law's alpha (the unused ones are 0)."""

    name: str
    code: int
    a: float
    c: float
    alpha: float


Kernel = Callable[..., tuple]
"""A kernel call: (law, mu, start, forcing, plan, n_trans, n_rec, stride) -> kernel outputs."""


def run_smooth(lw: Law, mu: float, start: Sequence[float], forcing: tuple, plan: StepPlan,
            n_trans: int, n_rec: int, stride: int) -> tuple:  # fmt: skip
    return kernels.run_rk4(
        lw.code, lw.a, lw.c, lw.alpha, mu, start[0], start[1], *forcing, plan.omega0 is not None,
        plan.period, plan.steps, n_trans, n_rec, stride, DIVERGENCE_BOUND,
    )  # fmt: skip


def run_kink(lw: Law, mu: float, start: Sequence[float], forcing: tuple, plan: StepPlan,
          n_trans: int, n_rec: int, stride: int) -> tuple:  # fmt: skip
    return kernels.run_kink(
        lw.alpha, mu, start[0], start[1], *forcing, plan.period, plan.steps, n_trans, n_rec,
        stride, DIVERGENCE_BOUND, plan.omega0 is not None,
    )  # fmt: skip


LanesKernel = Callable[..., tuple]
"""A lock-step call: (laws, inverse, packed, mu, x0, v0, tables, shared, carry) -> kernel
outputs, laws one per parameter point, ``inverse`` the point of each lane (see
``numerics.batch``), ``carry`` the lanes' ``Carry``."""

Carry = tuple[np.ndarray, np.ndarray, np.ndarray]
"""What a lane's run carries from one lock-step call into the next, shape (L,) each: its tangent
vector (dx, dv) and its region of Eq. (8) (the piecewise law's; ``kernels.NO_REGION``: that of
x0). The kernels start each lane from it and overwrite it with where the lane ended, so a
record run on from a call's end has the numbers of one longer call."""


def fresh_carry(lanes: int) -> Carry:
    """The ``Carry`` of runs started afresh: tangent (1, 1)/sqrt 2, the region of x0."""
    tangent = np.full(lanes, kernels.SQRT1_2)
    return tangent, tangent.copy(), np.full(lanes, kernels.NO_REGION, dtype=np.int64)


def lanes_cubic(laws: list[Law], inverse: np.ndarray, packed: list, mu: np.ndarray,
                x0: np.ndarray, v0: np.ndarray, tabled: tuple, shared: tuple,
                carry: Carry) -> tuple:  # fmt: skip
    a = np.array([lw.a for lw in laws])[inverse]
    c = np.array([lw.c for lw in laws])[inverse]
    return kernels.run_batch(mu, x0, v0, carry[0], carry[1], *tabled, *shared, a, c)


def lanes_piecewise(laws: list[Law], inverse: np.ndarray, packed: list, mu: np.ndarray,
                    x0: np.ndarray, v0: np.ndarray, tabled: tuple, shared: tuple,
                    carry: Carry) -> tuple:  # fmt: skip
    alpha = np.array([lw.alpha for lw in laws])[inverse]
    kc, nk = padded_terms([f[0] for f in packed])
    fc, nf = padded_terms([f[2] for f in packed])
    fm = np.array([f[1] for f in packed])
    return kernels.run_kink_batch(mu, x0, v0, carry[0], carry[1], *tabled, *shared, alpha,
                                  carry[2], kc, nk, fm, fc, nf)  # fmt: skip


def padded_terms(terms: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Forcing coefficients of shape (3, n_i) of M points as one array (M, 3, max n_i), zero
    padded, and the counts n_i, shape (M,)."""
    count = np.array([t.shape[1] for t in terms], dtype=np.int64)
    padded = np.zeros((len(terms), 3, max(1, int(count.max(initial=0)))))
    for m, t in enumerate(terms):
        padded[m, :, : t.shape[1]] = t
    return padded, count


@dataclass(frozen=True)
class BacklashLaw:
    """One backlash law f_h, as every part of the engine uses it.

    Attributes:
        name: the ``backlash.model`` of the parameters (``cubic`` or ``piecewise``).
        kernel_code: the ``law`` argument of the numba kernels (``systems.spur_pair.kernels``).
        f_h: f_h(model, x) on arrays, x and f_h in units of the half backlash b.
        melnikov_cubic: (a, c, notes) of the cubic law the Melnikov analysis uses for it.
        label: the law in words, for figures and notes.
        run: the single-run integrator (one start, ``SpurPair.integrate``).
        method: the integrator in words.
        lanes: the lock-step kernel of many lanes (``numerics.batch``), or None.
    """

    name: str
    kernel_code: int
    f_h: Callable[[CubicBacklash | PiecewiseBacklash, ArrayLike], NDArray[np.float64]]
    melnikov_cubic: Callable[[CubicBacklash | PiecewiseBacklash], tuple[float, float, list[str]]]
    label: str
    run: Kernel
    method: str
    lanes: LanesKernel | None


def _cubic_as_is(model: CubicBacklash | PiecewiseBacklash) -> tuple[float, float, list[str]]:
    assert isinstance(model, CubicBacklash)
    return model.a, model.c, []


def _piecewise_fit(model: CubicBacklash | PiecewiseBacklash) -> tuple[float, float, list[str]]:
    """The piecewise law has no smooth homoclinic orbit: the Melnikov analysis uses its cubic
    through x = 0, 1, 2 (``collocation_fit``), which is the paper's a = c = 1/6 for alpha = 0."""
    assert isinstance(model, PiecewiseBacklash)
    fit = collocation_fit(model.alpha)
    return (
        fit.a,
        fit.c,
        [
            f"the Melnikov criterion needs a smooth law: the exact piecewise backlash "
            f"(alpha = {model.alpha:g}) is replaced there by its cubic fit "
            f"f_h = -{fit.a:.6g} x + {fit.c:.6g} x^3 ({fit.note}); the numerical verdict uses "
            "the exact law"
        ],
    )


LAWS: dict[str, BacklashLaw] = {
    "cubic": BacklashLaw(
        "cubic", 0, lambda m, x: fh_cubic(x, m.a, m.c), _cubic_as_is, "cubic -a x + c x^3 (Eq. 9)",
        run_smooth, "rk4", lanes_cubic,
    ),
    "piecewise": BacklashLaw(
        "piecewise", 1, lambda m, x: fh_piecewise(x, m.alpha), _piecewise_fit,
        "piecewise linear (Eq. 8)", run_kink,
        "rk4 split at the kinks |x| = 1 (Newton from the Hermite root)", lanes_piecewise,
    ),
}  # fmt: skip
"""Backlash laws by name (the ``backlash.model`` field)."""


def melnikov_cubic(model: CubicBacklash | PiecewiseBacklash) -> tuple[float, float, list[str]]:
    """(a, c, notes) of the cubic law the Melnikov analysis uses for a backlash model."""
    return LAWS[model.model].melnikov_cubic(model)


def law(params: GearParams) -> Law:
    """Kernel arguments of the backlash law f_h."""
    b = params.backlash
    code = LAWS[b.model].kernel_code
    if isinstance(b, CubicBacklash):
        return Law(b.model, code, float(b.a), float(b.c), 0.0)
    return Law(b.model, code, 0.0, 0.0, float(b.alpha))
