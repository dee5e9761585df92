"""Bifurcation points of the periodic responses of Eq. (9) along a one-parameter sweep.

Natural-parameter continuation by shooting (Seydel 2010, ch. 4 and 7; Parker & Chua 1989,
ch. 4): the periodic orbit found at one grid value is Newton-refined at the next
(``floquet.refine``) and its Floquet multipliers are watched. When the largest modulus crosses 1
between two grid values, the crossing is located by brentq on p -> 1 - max |lambda(p)| (each
trial orbit Newton-refined from the last), and the new attractor beyond it is found by branch
switching: simulate from the old orbit state offset by ``KICK``, then Newton with the old
orbit's strobes deflated (Farrell, Birkisson & Funke 2015), so that Newton does not fall back
onto the parent orbit, which is also a fixed point of P^(2n).

A period doubling shows up as a multiplier through -1. Successive doubling points p_k of a
cascade give ratios (p_k - p_{k-1}) / (p_{k+1} - p_k) that tend to Feigenbaum's
delta = 4.6692... (M. J. Feigenbaum, J. Stat. Phys. 19 (1978) 25-52).

Accuracy, the paper's cascade and limits (folds, grazing, coexisting attractors):
docs/floquet.md.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np

from gearengine.model.aliases import with_alias
from gearengine.model.params import GearParams
from gearengine.numerics.floquet import refine, stroboscopic_flow
from gearengine.numerics.results import FloquetResult
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import simulate
from gearengine.systems.base import StroboscopicFlow

Path = Callable[[float], GearParams]
"""The parameters of Eq. (9) at a value of the swept parameter."""

KICK = 1e-3
"""Offset in x (units of b) added to a just destabilised orbit before simulating beyond it."""
WALK = 8
"""Pieces of a grid step in which a destabilised orbit is followed to bracket its crossing."""
COLLAPSE_TOL = 1e-8
"""|P^d(X) - X| < COLLAPSE_TOL max(1, |X|) for a divisor d < n: X lies on a shorter orbit."""


class PointResponse(NamedTuple):
    """A simulated response at one grid value (e.g. a continuation sweep's point)."""

    classification: str
    period: int | None
    strobe: list[float] | None
    """Last stroboscopic point [x, v] (t = 0 mod T0), None when there is none."""
    final: tuple[float, float] | None
    """Final state [x, v], None if diverged."""


class _Attractor(NamedTuple):
    """The response at one grid point: its stable refined orbit (or None), period, end state."""

    orbit: FloquetResult | None
    period: int | None
    final: tuple[float, float] | None


class _OrbitLostError(Exception):
    """No orbit of the followed period was found.

    ``parent``: the shorter orbit Newton collapsed onto, when there is one; the followed orbit
    has merged into it (a period doubling met from the doubled side).
    """

    def __init__(self, parent: FloquetResult | None = None) -> None:
        super().__init__()
        self.parent = parent


def _strobes(flow: StroboscopicFlow, X: np.ndarray, n: int) -> list[np.ndarray]:
    """The strobes X, P(X), ..., P^(n-1)(X) of the period-n orbit through X."""
    out = [X]
    for _ in range(n - 1):
        out.append(flow(out[-1], 1)[0])
    return out


def _refine_deflated(flow: StroboscopicFlow, X: np.ndarray, n: int, avoid: Sequence[np.ndarray]):
    """Deflated Newton from X (the strobes ``avoid`` of a shorter orbit repel it), then plain
    Newton to polish: deflation slows convergence to a root close to a deflated one (a young
    period-doubled orbit). The caller checks the result against collapse (``_shorter_period``).
    """
    fl = refine(flow, X, n, avoid)
    return refine(flow, np.array(fl.orbit_state), n) if avoid else fl


def _shorter_period(flow: StroboscopicFlow, X: np.ndarray, n: int) -> int | None:
    """Largest proper divisor d of n with P^d(X) = X (to COLLAPSE_TOL), else None."""
    divisors = sorted({n // q for q in range(2, n + 1) if n % q == 0}, reverse=True)
    for d in divisors:
        end = flow(X, d)[0]
        if np.hypot(*(end - X)) < COLLAPSE_TOL * max(1.0, float(np.hypot(*X))):
            return d
    return None


def _parent(flow: StroboscopicFlow, X: np.ndarray, n: int) -> FloquetResult | None:
    """A shorter orbit (period a proper divisor of n, largest first) Newton finds from X: what
    a period-n orbit that no longer exists (met from the doubled side) has merged into."""
    for d in sorted({n // q for q in range(2, n + 1) if n % q == 0}, reverse=True):
        fl = refine(flow, X, d)
        if fl.converged:
            return fl
    return None


def _follow(flow: StroboscopicFlow, orbit: FloquetResult) -> FloquetResult:
    """Newton-refine ``orbit``'s branch at a new parameter value, starting from ``orbit``.

    When Newton lands on a shorter orbit (a young period-doubled orbit collapsing onto its
    parent, also a fixed point of P^n), the parent's strobes are deflated and Newton restarts.
    Raises ``_OrbitLostError`` (with the parent, if any) when no period-n orbit is found.
    """
    X0 = np.array(orbit.orbit_state)
    fl = refine(flow, X0, orbit.period)
    d = _shorter_period(flow, np.array(fl.orbit_state), orbit.period) if fl.converged else None
    if d is None and fl.converged:
        return fl
    if d is None:
        raise _OrbitLostError(_parent(flow, X0, orbit.period))
    parent = refine(flow, np.array(fl.orbit_state), d)
    fl = _refine_deflated(flow, X0, orbit.period, _strobes(flow, np.array(parent.orbit_state), d))
    if fl.converged and _shorter_period(flow, np.array(fl.orbit_state), orbit.period) is None:
        return fl
    raise _OrbitLostError(parent)


def _simulated(params: GearParams, settings: SimulationSettings, start: Sequence[float]):
    """``simulate`` from the single state ``start``, as a ``PointResponse``."""
    run = settings.model_copy(
        update={"initial_state": list(start), "initial_states": None, "random_initial_states": None}
    )
    r = simulate(params, run)
    final = r.worst_case.final_state
    strobe = r.poincare[-1] if r.poincare else None
    return PointResponse(
        r.classification, r.period, strobe, None if final is None else tuple(final)
    )


def _settle(
    params: GearParams,
    settings: SimulationSettings,
    response: PointResponse,
    doubled: FloquetResult | None = None,
) -> _Attractor:
    """Newton-refine a simulated response; keep the orbit if it is stable.

    ``doubled``: the unstable orbit just past its period doubling. Its strobes are deflated, and
    when the simulated strobes show no period (the new orbit's multiplier is near +1, so it
    settles too slowly for ``detect_period``) the period 2n is tried.
    """
    period = response.period or (2 * doubled.period if doubled is not None else None)
    if response.classification == "diverged" or period is None or response.strobe is None:
        return _Attractor(None, None, response.final)
    flow = stroboscopic_flow(params, settings.steps_per_period)
    avoid = [] if doubled is None else _strobes(flow, np.array(doubled.orbit_state), doubled.period)
    try:
        fl = _refine_deflated(flow, np.array(response.strobe), period, avoid)
    except ValueError:  # the flow from the strobe is not finite
        return _Attractor(None, response.period, response.final)
    d = _shorter_period(flow, np.array(fl.orbit_state), period) if fl.converged else None
    if d is not None:  # strobes not yet settled on a shorter orbit (slow transient)
        fl = refine(flow, np.array(fl.orbit_state), d)
    if fl.converged and fl.stability_margin > 0.0:
        return _Attractor(fl, fl.period, response.final)
    return _Attractor(None, response.period, response.final)


def _locate(
    path: Path, bracket: tuple[float, float], orbit: FloquetResult, steps: int, xtol: float
) -> tuple[float, FloquetResult]:
    """Root of the stability margin of ``orbit``'s branch in ``bracket``, and the orbit there.

    brentq on p -> 1 - max |lambda(p)|, each trial orbit followed from the already refined
    orbit nearest in p (so the two ends, evaluated first, are never recomputed from elsewhere
    on the branch). Raises ``_OrbitLostError`` when the margin has the same sign at both ends.
    """
    from scipy.optimize import brentq  # scipy loads in ~0.2 s; only this root finding needs it

    known: dict[float, FloquetResult] = {}

    def margin(p: float) -> float:
        if p not in known:
            near = min(known, key=lambda q: abs(q - p)) if known else None
            flow = stroboscopic_flow(path(p), steps)
            known[p] = _follow(flow, orbit if near is None else known[near])
        return known[p].stability_margin

    if margin(bracket[0]) * margin(bracket[1]) > 0.0:
        raise _OrbitLostError
    root = float(brentq(margin, min(bracket), max(bracket), xtol=xtol))
    margin(root)
    return root, known[root]


def _walk(
    path: Path, bracket: tuple[float, float], orbit: FloquetResult, steps: int
) -> tuple[tuple[float, float], FloquetResult]:
    """The part of ``bracket`` (one of WALK equal pieces) where ``orbit``'s margin turns
    negative, and the orbit at its start: the orbit is followed piece by piece, so a branch
    that Newton cannot reach in one grid step (far beyond the crossing) is still located.
    Raises ``_OrbitLostError`` (from ``_follow``) when the orbit is lost before."""
    grid = np.linspace(bracket[0], bracket[1], WALK + 1)
    for lo, hi in itertools.pairwise(grid.tolist()):
        nxt = _follow(stroboscopic_flow(path(hi), steps), orbit)
        if nxt.stability_margin <= 0.0:
            return (lo, hi), orbit
        orbit = nxt
    raise _OrbitLostError


def _beyond(flow: StroboscopicFlow, orbit: FloquetResult) -> FloquetResult | None:
    """``orbit``'s branch followed to ``flow``'s parameter value, None when lost."""
    try:
        return _follow(flow, orbit)
    except _OrbitLostError:
        return None


def _crossing(
    path: Path, bracket: tuple[float, float], orbit: FloquetResult,
    settings: SimulationSettings, xtol: float,
) -> tuple[dict[str, Any], _Attractor]:  # fmt: skip
    """The event where ``orbit`` stops being a stable orbit inside ``bracket``, and the attractor
    simulated at bracket[1] (from the orbit state offset by KICK in x).

    Either the orbit's own multiplier leaves the unit circle (located on its branch), or the
    orbit merges into a shorter parent orbit (met from the doubled side: located where the
    parent's multiplier crosses the circle), or it is lost (value None, type orbit_lost).
    """
    steps = settings.steps_per_period
    point = path(bracket[1])
    event: dict[str, Any] = {"period_before": orbit.period, "bracket": list(bracket)}
    doubled = None
    try:
        try:
            sub, near = _walk(path, bracket, orbit, steps)
            root, crit = _locate(path, sub, near, steps, xtol)
            if crit.nearest_bifurcation == "period_doubling":
                doubled = _beyond(stroboscopic_flow(point, steps), crit)
        except _OrbitLostError as lost:
            if lost.parent is None:
                raise
            root, crit = _locate(path, bracket, lost.parent, steps, xtol)
        event |= {"value": root, "type": crit.nearest_bifurcation}
        event["critical_multiplier"] = crit.multipliers[0]
    except _OrbitLostError:
        event |= {"value": None, "type": "orbit_lost", "critical_multiplier": None}
    kicked = (orbit.orbit_state[0] + KICK, orbit.orbit_state[1])
    att = _settle(point, settings, _simulated(point, settings, kicked), doubled)
    return {**event, "period_after": att.period}, att


def locate_bifurcations(
    params: GearParams,
    alias: str,
    values: Sequence[float],
    settings: SimulationSettings | None = None,
    xtol: float = 1e-10,
    responses: Sequence[PointResponse] | None = None,
    path: Path | None = None,
) -> list[dict[str, Any]]:
    """Bifurcation points of the periodic responses along a sweep of one parameter.

    At ``values[0]`` the response is simulated and, when periodic, Newton-refined; at each next
    grid value the orbit is Newton-refined from the previous one (``_follow``). A crossing of
    the unit circle between two grid values is located to ``xtol`` (``_locate``), and the new
    attractor is found by branch switching (``_crossing``). While no stable periodic orbit is
    known (chaos), each grid value is simulated from the previous end state until a stable
    periodic response appears again.

    Args:
        params: base parameter point of Eq. (9) (commensurate forcing).
        alias: swept parameter, e.g. "F_e1" (see ``gearengine.model.aliases.ALIASES``).
        values: strictly monotone grid of the swept parameter (at least two values).
        settings: simulation settings (transient, record, steps per period, initial state).
        xtol: absolute tolerance of the located points in the swept parameter.
        responses: the responses already simulated at ``values`` by continuation (e.g. a
            continuation sweep's points), used instead of simulating there again; only the
            branch switch after an event is then simulated.
        path: the parameters at a value of the swept parameter, when it is not the alias set
            on ``params`` (a physical field of a design, converted at each value; ``alias``
            then only names it in the events).

    Returns:
        One dict per event, in sweep order: {"parameter", "value", "type", "period_before",
        "period_after", "branch", "bracket", "critical_multiplier"}. ``type`` is
        period_doubling / fold / neimark_sacker (from the critical multiplier [re, im] at the
        located point), or "orbit_lost" with ``value`` None when Newton shooting stops
        converging on the branch without a multiplier crossing the unit circle (e.g. beyond a
        fold). ``branch`` is "up" for an increasing sweep, "down" for a decreasing one;
        ``bracket`` the two grid values. Several doublings inside one grid step show up as
        period_after > 2 period_before; ``period_after`` is None when no stable periodic
        orbit is found beyond the event.
    """
    settings = settings or SimulationSettings()
    grid = [float(v) for v in values]
    diffs = np.diff(grid)
    if len(grid) < 2 or not (np.all(diffs > 0.0) or np.all(diffs < 0.0)):
        raise ValueError("values must hold at least two strictly monotone parameter values")
    if responses is not None and len(responses) != len(grid):
        raise ValueError(f"{len(responses)} responses for {len(grid)} values")
    base = {"parameter": alias, "branch": "up" if diffs[0] > 0.0 else "down"}
    if path is None:
        path = functools.partial(with_alias, params, alias)

    def attractor(i: int, start: Sequence[float] | None) -> _Attractor:
        point = path(grid[i])
        if responses is not None:
            return _settle(point, settings, responses[i])
        return _settle(point, settings, _simulated(point, settings, start or (0.0, 0.0)))

    att = attractor(0, settings.starts()[0])
    orbit, start = att.orbit, att.final
    events: list[dict[str, Any]] = []
    for i, (lo, hi) in enumerate(itertools.pairwise(grid), start=1):
        if orbit is None:
            att = attractor(i, start or settings.starts()[0])
            orbit, start = att.orbit, att.final
            continue
        try:
            nxt = _follow(stroboscopic_flow(path(hi), settings.steps_per_period), orbit)
            if nxt.stability_margin > 0.0:
                orbit = nxt
                continue
        except _OrbitLostError:
            pass
        event, att = _crossing(path, (lo, hi), orbit, settings, xtol)
        events.append({**base, **event})
        orbit, start = att.orbit, att.final
    return events


def feigenbaum_ratios(points: Sequence[float]) -> list[float]:
    """Ratios (p_k - p_{k-1}) / (p_{k+1} - p_k) of successive period-doubling points p_k.

    For a period-doubling cascade they tend to Feigenbaum's delta = 4.6692... (Feigenbaum 1978).
    """
    gaps = np.diff(np.asarray(points, dtype=np.float64))
    return (gaps[:-1] / gaps[1:]).tolist()
