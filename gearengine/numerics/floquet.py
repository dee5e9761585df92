"""Stability margins of periodic responses: Floquet multipliers by Newton shooting, for any
``System`` (n x n monodromy matrix); written here for the spur pair of Eq. (9), n = 2.

    x' = v,   v' = -2 mu v - K(t) f_h(x) + F(t)                              (Eq. 9)

A periodic response of period n T0 is a fixed point X* = (x, v) of the stroboscopic map
P^n = phi_{n T0} (the flow over n sampling intervals T0 from a strobe time t = 0 mod T0; x in
units of the half backlash b, time tau dimensionless). Its monodromy matrix
Phi = D phi_{n T0}(X*) solves the variational equation

    Phi' = J(t) Phi,   J = [[0, 1], [-K(t) f_h'(x(t)), -2 mu]],   Phi(0) = I,

and its eigenvalues lambda_1, lambda_2 are the Floquet multipliers. The orbit is asymptotically
stable when both lie inside the unit circle; the stability margin is 1 - max |lambda|. It
bifurcates when a multiplier leaves the circle: at -1 (period doubling), at +1 (fold, cyclic
saddle-node) or as a complex pair (Neimark-Sacker).

Liouville: trace J = -2 mu, so det Phi = exp(-2 mu n T0) exactly, for any orbit. A complex pair
therefore has modulus exp(-mu n T0) < 1 and can never reach the unit circle: in this planar
system with constant damping only real multipliers lose stability. ``nearest_bifurcation``
still names a complex dominant pair "neimark_sacker" (the generic label) and a note says why it
cannot happen here.

Piecewise law (Eq. 8): no saltation matrix is needed. The law is continuous at |x| = 1 (only
its slope jumps), so the vector field of Eq. (9) is continuous across the switching surface and
so is the flow's Jacobian (see ``kernels.monodromy``).

References:
    R. Seydel, Practical Bifurcation and Stability Analysis, 3rd ed., Springer 2010, ch. 7
        (shooting, monodromy matrix, Floquet multipliers).
    T. S. Parker, L. O. Chua, Practical Numerical Algorithms for Chaotic Systems, Springer 1989,
        ch. 3-4 (Poincare maps, shooting for periodic solutions, variational equations).
    P. E. Farrell, A. Birkisson, S. W. Funke, Deflation techniques for finding distinct
        solutions of nonlinear PDEs, SIAM J. Sci. Comput. 37 (2015) A2026-A2045 (deflation).

Accuracy, limits and cost: docs/floquet.md.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from gearengine.model.params import GearParams
from gearengine.numerics.results import Bifurcation, FloquetResult, NumericsResult
from gearengine.numerics.runs import as_system
from gearengine.numerics.settings import SimulationSettings
from gearengine.systems.base import StroboscopicFlow, System

NEWTON_MAX_STEPS = 8
"""Largest number of Newton updates of the orbit state."""
NEWTON_TOL = 1e-11
"""Convergence: |G(X)| < NEWTON_TOL * max(1, |X|) with G(X) = phi_{n T0}(X) - X."""
LIOUVILLE_WARN = 1e-4
"""liouville_error above which the result carries a note (``liouville_words``)."""


def multipliers(phi: np.ndarray) -> tuple[complex, ...]:
    """Eigenvalues of the n x n monodromy matrix, largest modulus first.

    For n = 2 from trace and determinant; the smaller real one is det / lambda_1 (no
    cancellation, so tiny multipliers of long, strongly damped orbits keep their relative
    accuracy). For n > 2 from ``numpy.linalg.eigvals``.
    """
    if phi.shape != (2, 2):
        lam = np.linalg.eigvals(phi)
        return tuple(complex(v) for v in sorted(lam, key=abs, reverse=True))
    tr = float(phi[0, 0] + phi[1, 1])
    det = float(phi[0, 0] * phi[1, 1] - phi[0, 1] * phi[1, 0])
    disc = 0.25 * tr * tr - det
    if disc < 0.0:
        root = complex(0.5 * tr, math.sqrt(-disc))
        return root, root.conjugate()
    big = 0.5 * tr + math.copysign(math.sqrt(disc), tr)
    small = det / big if big != 0.0 else 0.0
    return complex(big), complex(small)


def determinant(phi: np.ndarray) -> float:
    """det Phi (the 2 x 2 formula for the pair, as its multipliers use)."""
    if phi.shape == (2, 2):
        return float(phi[0, 0] * phi[1, 1] - phi[0, 1] * phi[1, 0])
    return float(np.linalg.det(phi))


def norm(v: np.ndarray) -> float:
    """Euclidean norm of a state (``numpy.hypot`` for the pair's (x, v))."""
    return float(np.hypot(*v)) if v.shape == (2,) else math.hypot(*v)


def liouville_error(det: float, trace_rate: float, duration: float) -> float:
    """|det Phi - exp(tr J t)| / exp(tr J t) over t = ``duration`` (tau units; tr J = -2 mu for
    the pair), computed in logarithms (the exponential underflows for long, strongly damped
    orbits)."""
    log_exact = trace_rate * duration
    if det > 0.0:
        return abs(math.expm1(min(math.log(det) - log_exact, 700.0)))
    return 1.0 + (math.exp(min(math.log(-det) - log_exact, 700.0)) if det < 0.0 else 0.0)


def liouville_words(error: float, margin: float, dims: int) -> str:
    """The note on a Liouville check missed by ``error`` (relative, > ``LIOUVILLE_WARN``): the
    multipliers' moduli carry an error of about error / dims (det Phi is the product of the
    ``dims`` multipliers of a state of that dimension), judged against the stability ``margin``
    1 - |lambda_max| it could move. The state of dimension 2 is the pair's, tr J = -2 mu (as the
    complex-pair note of ``refine`` reads it)."""
    exact = "exp(-2 mu n T0)" if dims == 2 else "exp(tr J n T0)"
    words = (f"det Phi differs from {exact} by {error:.3g} (relative): the multipliers' moduli "
             "carry an integration error of about that size (more steps per period reduce it, "
             "or the smaller multiplier is below its rounding error)")  # fmt: skip
    if error / dims < 0.1 * abs(margin):
        return f"{words}; small against the stability margin {margin:.3g}"
    return (f"{words}; not small against the stability margin {margin:.3g}: the margin and "
            "the nearest bifurcation are uncertain at this resolution")  # fmt: skip


def classify_multiplier(lam: complex) -> Bifurcation:
    """Bifurcation type when the multiplier ``lam`` reaches the unit circle."""
    if lam.imag != 0.0:
        return "neimark_sacker"
    return "period_doubling" if lam.real < 0.0 else "fold"


def stroboscopic_flow(model: GearParams | System, steps_per_period: int) -> StroboscopicFlow:
    """The flow of a system (a parameter point of Eq. 9: the spur pair) sampled every T0 (RK4
    grid as ``simulate``'s); ValueError when the forcing is incommensurate (no Poincare
    period)."""
    return as_system(model).stroboscopic_flow(steps_per_period)


def _deflation(X: np.ndarray, u: np.ndarray, avoid: Sequence[np.ndarray]) -> float:
    """Factor of the Newton step u when the roots ``avoid`` are deflated.

    Newton on M(X) G(X), M = prod_k (1 / |X - r_k|^2 + 1), takes the step u / (1 - grad(log M) u)
    (Farrell, Birkisson & Funke 2015): the known roots r_k repel the iteration and it converges
    to another root of G, if any is near.
    """
    g = 0.0
    for r in avoid:
        d = X - r
        d2 = max(float(d @ d), 1e-300)
        g -= 2.0 * float(d @ u) / (d2 * (1.0 + d2))
    return 1.0 / (1.0 - g) if g != 1.0 else 1.0


def _shoot(
    flow: StroboscopicFlow, X: np.ndarray, n: int, avoid: Sequence[np.ndarray] = ()
) -> tuple[np.ndarray, np.ndarray, float, int]:
    """Newton shooting on G(X) = phi_{n T0}(X) - X, DG = Phi - I (Seydel 2010, sec. 7.3).

    Returns the last state X, Phi at X, |G(X)| and the number of Newton updates. Stops when
    |G| < NEWTON_TOL max(1, |X|), after NEWTON_MAX_STEPS updates, or when Phi - I is singular
    or an update leaves the finite numbers (the last finite iterate is returned). The states
    ``avoid`` (strobes of a shorter orbit, also fixed points of phi_{n T0}) are deflated.
    """
    end, phi = flow(X, n)
    if not (np.all(np.isfinite(end)) and np.all(np.isfinite(phi))):
        raise ValueError(f"the flow from {X.tolist()} over {n} T0 is not finite")
    res = norm(end - X)
    steps = 0
    while res >= NEWTON_TOL * max(1.0, norm(X)) and steps < NEWTON_MAX_STEPS:
        try:
            u = np.linalg.solve(phi - np.eye(len(X)), X - end)
        except np.linalg.LinAlgError:
            break
        X_new = X + _deflation(X, u, avoid) * u
        end_new, phi_new = flow(X_new, n)
        if not (np.all(np.isfinite(end_new)) and np.all(np.isfinite(phi_new))):
            break
        X, end, phi = X_new, end_new, phi_new
        res = norm(end - X)
        steps += 1
    return X, phi, res, steps


def refine(
    flow: StroboscopicFlow, X: np.ndarray, n: int, avoid: Sequence[np.ndarray] = ()
) -> FloquetResult:
    """Newton-refined period-n orbit through X (the states ``avoid`` deflated) and its
    multipliers, margin, Liouville check and notes."""
    X, phi, res, steps = _shoot(flow, X, n, avoid)
    lam = multipliers(phi)
    lv_error = liouville_error(determinant(phi), flow.trace_rate, n * flow.period)
    converged = res < NEWTON_TOL * max(1.0, norm(X))
    notes = []
    if not converged:
        notes.append(
            f"Newton shooting stopped after {steps} updates with |G| = {res:.3g}: the multipliers "
            "belong to an approximate orbit"
        )
    margin = 1.0 - abs(lam[0])
    if lv_error > LIOUVILLE_WARN:
        notes.append(liouville_words(lv_error, margin, len(X)))
    if lam[0].imag != 0.0 and len(X) == 2:
        notes.append(
            f"complex pair of modulus exp(-mu n T0) = {abs(lam[0]):.6g}: with constant "
            "damping det Phi is fixed, so the pair cannot reach the unit circle; stability can "
            "only be lost after it meets on the real axis"
        )
    return FloquetResult(
        period=n,
        steps_per_period=flow.steps,
        multipliers=[[m.real, m.imag] for m in lam],
        stability_margin=margin,
        nearest_bifurcation=classify_multiplier(lam[0]),
        orbit_state=[float(x) for x in X],
        orbit_residual=res,
        newton_steps=steps,
        converged=converged,
        liouville_error=lv_error,
        notes=notes,
    )


def floquet(
    params: GearParams | System,
    settings: SimulationSettings,
    state: Sequence[float],
    period_n: int,
) -> FloquetResult:
    """Floquet multipliers and stability margin of the period-n response through ``state``.

    Args:
        params: parameter point of Eq. (9), or any ``System``; its forcing must be periodic
            (commensurate).
        settings: only ``steps_per_period`` is used (RK4 steps per period of the fastest
            excitation, as in ``simulate``).
        state: a strobe [x, v] of the settled response at a time t = 0 mod T0, e.g. the last
            Poincare point ``simulate(...).poincare[-1]``.
        period_n: period of the response in units of T0 (``simulate(...).period``).

    Returns:
        The Newton-refined orbit (a few shooting steps) and the eigenvalues of its monodromy
        matrix. Check ``converged`` before trusting the margin.

    Raises:
        ValueError: incommensurate forcing, period_n < 1, or a non-finite flow from ``state``.
    """
    if period_n < 1:
        raise ValueError(f"period_n must be >= 1, got {period_n}")
    flow = stroboscopic_flow(params, settings.steps_per_period)
    return refine(flow, np.array(state, dtype=np.float64), period_n)


def floquet_of(
    system: System,
    settings: SimulationSettings,
    result: NumericsResult,
    state: Sequence[float] | None = None,
) -> tuple[FloquetResult | None, str | None]:
    """The ``floquet`` and ``floquet_note`` fields of ``simulate(system, settings)``'s result:
    the Floquet result of its (worst start's) periodic response (``refine`` on the system's own
    stroboscopic flow, as ``floquet``), or None and the reason. ``state``: the full last strobe
    of a system with more than (x, v) (the pair's is the last Poincare point)."""
    if result.classification != "periodic" or result.period is None or not result.poincare:
        return None, f"the response is {result.classification}: no periodic orbit to linearise"
    if result.forcing_period is None:
        return None, "incommensurate forcing: no Poincare period, hence no Floquet multipliers"
    try:
        last = result.poincare[-1] if state is None else state
        flow = system.stroboscopic_flow(settings.steps_per_period)
        fl = refine(flow, np.array(last, dtype=np.float64), result.period)
    except ValueError as exc:
        return None, f"Floquet analysis failed: {exc}"
    if not fl.converged:
        return None, (
            f"Newton shooting on the period-{fl.period} orbit did not converge "
            f"(|G| = {fl.orbit_residual:.3g} after {fl.newton_steps} updates)"
        )
    return fl, None
