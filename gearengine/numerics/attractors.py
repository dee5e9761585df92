"""Coexisting attractors of one design: many starts, each a lane of ``numerics.batch``, grouped
by the orbit they settle on, with the fraction of starts reaching each (its basin fraction).

The idea is that of Attractors.jl (``basins_fractions``, ``AttractorsViaRecurrences``; Datseris
& Wagemakers, Chaos 32, 2022): run every start of a box, recognise the attractor each lands on,
count. Here a start's attractor is read from its stroboscopic record (the last <= 64 strobes
X_k = (x, v) at t = k T0 after the transient), not from its class alone:

* periodic starts of period n are one attractor when their n-point orbits coincide as sets:
  every strobe of one lies within ``ORBIT_TOL`` x size of a strobe of the other, size the
  larger x peak-to-peak of the two (floored by ``SIZE_FLOOR``). Converged orbits from
  different starts agree to ~1e-8 of the size, distinct orbits of a gear pair (no-impact and
  impacting, or the n phases of a subharmonic seen as different orbits never happen: the set
  is phase-free) differ by a sizeable fraction of it;
* chaotic (and, under incommensurate forcing, quasi-periodic) starts are one attractor when
  the bounding boxes of their strobe clouds overlap by at least ``CLOUD_OVERLAP`` of the
  smaller box's area (boxes padded by ``ORBIT_TOL`` x size so a thin cloud has an area);
* starts that diverged, or under commensurate forcing found neither a period <= 64 nor a
  positive LLE (an unfinished transient), are counted apart: ``diverged`` and ``unsettled``.

Each start joins the first attractor (in start order) it matches, so the result is a function
of the request alone. Fractions are count / starts with the 95 % Wilson score interval
(``scipy.stats.binomtest``; Wilson, JASA 22, 1927; Brown, Cai & DasGupta, Stat. Sci. 16, 2001).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np

from gearengine.model.design import Design
from gearengine.model.params import GearParams
from gearengine.model.reduction import ParamsOrDesign
from gearengine.model.units import Scales, response_values, shown, to_physical
from gearengine.numerics.batch import run_lanes, run_verdict, simulate_batch_with, step_plans
from gearengine.numerics.headline import of_starts
from gearengine.numerics.results import Attractor, BasinCounts, BatchPoint
from gearengine.numerics.runs import integrate
from gearengine.numerics.settings import BasinSettings, SimulationSettings
from gearengine.signals.classify import severity
from gearengine.signals.periodicity import SIZE_FLOOR, same_cycle
from gearengine.systems.base import StepPlan, System

ORBIT_TOL = 1e-2
"""Distance, relative to the attractor size, within which two strobes are the same point."""
CLOUD_OVERLAP = 0.5
"""Share of the smaller strobe box two chaotic clouds must have in common to be one."""
CONFIDENCE = 0.95
"""Confidence level of the basin-fraction intervals."""
DIVERGED, UNSETTLED = -1, -2
"""Labels of starts that reached no attractor."""
IMPACT_ORDER = {None: -1, "no_impact": 0, "single_sided": 1, "double_sided": 2}
IMPACT_TEXT = {"no_impact": "teeth always in contact", "single_sided": "tooth separation",
               "double_sided": "back-flank impacts"}  # fmt: skip
"""An attractor's contact in the text words of docs/units.md's one contact vocabulary (the
impact regimes no_impact, single_sided and double_sided, in words; "single-sided impacts"
stood in gate lines beside windows that said "tooth separation")."""


def scale_pair(scales: Scales | None) -> tuple[float, float]:
    """(b [m], b omega_n [m/s]): the SI length of one unit of x and of v = dx/dtau (Eq. 8), or
    (1, 1) without a design."""
    if scales is None:
        return 1.0, 1.0
    return scales.half_backlash, scales.half_backlash * scales.natural_frequency


def physical_box(box: list[list[float]], scales: Scales) -> list[list[float]]:
    """A dimensionless box [[x0, x1], [v0, v1]] in µm and mm/s (x b, v b omega_n), rounded to
    6 significant digits."""
    b, v = scale_pair(scales)
    return [
        [float(f"{e * f:.6g}") for e in r] for r, f in zip(box, (b * 1e6, v * 1e3), strict=True)
    ]


def basin_starts(basins: BasinSettings, scales: Scales | None) -> list[tuple[float, float]]:
    """The dimensionless starts of ``basins``; a box in units needs a design's ``scales``."""
    if basins.physical() and scales is None:
        raise ValueError("settings.basins.box: a box in units needs a design, not params")
    return basins.states(*scale_pair(scales))


def _size(bp: BatchPoint) -> float:
    return max(bp.x_peak_to_peak or 0.0, SIZE_FLOOR)


def _orbit(bp: BatchPoint) -> np.ndarray:
    """The strobes that identify the start's attractor: its n-cycle, else its cloud; shape
    (k, n) for a system of state dimension n ((x, v) for the pair)."""
    pts = np.asarray(bp.poincare, dtype=float)
    pts = pts.reshape(len(pts), -1) if len(pts) else pts.reshape(-1, 2)
    return pts[-bp.period :] if bp.period else pts


def same_orbit(a: BatchPoint, b: BatchPoint) -> bool:
    """True when the periodic starts ``a`` and ``b`` settled on one orbit (see module doc)."""
    if a.period != b.period:
        return False
    return same_cycle(_orbit(a), _orbit(b), ORBIT_TOL * max(_size(a), _size(b)))


def same_cloud(a: BatchPoint, b: BatchPoint) -> bool:
    """True when the strobe clouds of two aperiodic starts overlap (see module doc)."""
    pad = ORBIT_TOL * max(_size(a), _size(b))
    boxes = []
    for p in (a, b):
        o = _orbit(p)
        boxes.append((o.min(axis=0) - pad, o.max(axis=0) + pad))
    lo = np.maximum(boxes[0][0], boxes[1][0])
    hi = np.minimum(boxes[0][1], boxes[1][1])
    common = float(np.prod(np.clip(hi - lo, 0.0, None)))
    smaller = min(float(np.prod(h - low)) for low, h in boxes)
    return common >= CLOUD_OVERLAP * smaller


def cluster(points: list[BatchPoint], commensurate: bool) -> list[int]:
    """The label of each start: the index of its group (first-come order), ``DIVERGED`` or
    ``UNSETTLED``."""
    reps: list[BatchPoint] = []
    labels = []
    for bp in points:
        if bp.classification == "diverged" or not bp.poincare:
            labels.append(DIVERGED)
            continue
        if commensurate and bp.classification == "quasi_periodic":
            labels.append(UNSETTLED)
            continue
        same = same_orbit if bp.classification == "periodic" else same_cloud
        for k, rep in enumerate(reps):
            if (rep.classification == bp.classification) and same(rep, bp):
                labels.append(k)
                break
        else:
            labels.append(len(reps))
            reps.append(bp)
    return labels


def wilson(count: int, n: int) -> list[float]:
    """The 95 % Wilson score interval of count / n (scipy.stats.binomtest)."""
    return list(_wilson(count, n))


@functools.lru_cache(maxsize=4096)
def _wilson(count: int, n: int) -> tuple[float, float]:
    """``wilson``, computed once per (count, n) in a process: scipy's binomtest costs ~1.5 ms,
    and a gate's points share a few counts out of the same number of starts."""
    from scipy.stats import binomtest

    ci = binomtest(count, n).proportion_ci(confidence_level=CONFIDENCE, method="wilson")
    return float(ci.low), float(ci.high)


def describe(classification: str, period: int | None, impact: str | None) -> str:
    """'periodic 1T, teeth always in contact', 'chaotic, back-flank impacts'."""
    kind = f"periodic {period}T" if period else classification.replace("_", "-")
    return f"{kind}, {IMPACT_TEXT[impact]}" if impact in IMPACT_TEXT else kind


def _attractor(
    members: list[tuple[tuple[float, float], BatchPoint]],
    n: int,
    scales: Scales | None,
) -> Attractor:
    """One group of starts as an ``Attractor``: its first start represents it; LLE the mean
    over its members' records (stderr of the mean of independent estimates: starts that share
    one record, ``BatchPoint._record``, are one estimate), DTE, force and impacts the largest
    seen."""
    start, rep = members[0]
    records: set[tuple[str, int]] = set()
    estimates = []  # one member per record, in start order
    for _, bp in members:
        key = ("own", id(bp)) if bp._record is None else ("shared", bp._record)
        if key not in records:
            records.add(key)
            estimates.append(bp)
    lles = [bp.lle for bp in estimates if bp.lle is not None]
    errs = [bp.lle_stderr for bp in estimates if bp.lle_stderr is not None]
    ptp = max((bp.x_peak_to_peak for _, bp in members if bp.x_peak_to_peak is not None),
              default=None)  # fmt: skip
    fmax = max((bp.force_max for _, bp in members if bp.force_max is not None), default=None)
    fmin = min((bp.force_min for _, bp in members if bp.force_min is not None), default=None)
    impact = max((bp.impact_regime for _, bp in members), key=IMPACT_ORDER.__getitem__)
    dte = factor = None
    forces: list[float | None] = [None, None]
    if scales is not None:
        response = response_values(ptp, fmax, scales)
        dte, factor = response["dte"], response["dynamic_factor"]
        forces = [None if f is None else shown(to_physical("mesh_force", f, scales))
                  for f in (fmax, fmin)]  # fmt: skip
    return Attractor(
        label=describe(rep.classification, rep.period, impact),
        classification=rep.classification,
        period=rep.period,
        lle=float(np.mean(lles)) if lles else None,
        lle_stderr=float(np.sqrt(np.sum(np.square(errs)))) / len(errs) if errs else None,
        impact_regime=impact,
        x_peak_to_peak=ptp,
        dte_um=dte,
        dynamic_factor=factor,
        force_max_n=forces[0],
        force_min_n=forces[1],
        fraction=len(members) / n,
        interval=wilson(len(members), n),
        count=len(members),
        start=list(start),
        strobes=_orbit(rep).tolist(),
    )


def attractors(
    params: GearParams | System,
    settings: SimulationSettings,
    scales: Scales | None = None,
) -> tuple[list[Attractor], BasinCounts]:
    """Every attractor reached from the starts of ``settings.basins`` (worst first, then the
    larger basin), and how the starts ended.

    Args:
        params: the design, dimensionless (Eq. 9: its starts run as lock-step lanes), or any
            ``System`` (each start of the mesh coordinate, the other coordinates at rest, run
            by its own integrator; attractors told apart by their strobes of all n
            coordinates).
        settings: periods and steps of every run; ``settings.basins`` the starts.
        scales: with a design, its scales (a box in units; DTE and dynamic factor).

    Returns:
        The attractors, and the ``BasinCounts`` with each start's label (its attractor's index
        in the returned list, -1 diverged, -2 unsettled).
    """
    spp = settings.steps_per_period
    plan = params.plan(spp) if isinstance(params, System) else step_plans([params], spp)[0]
    return planned_attractors(params, settings, plan, scales)


def planned_attractors(
    params: GearParams | System,
    settings: SimulationSettings,
    plan: StepPlan,
    scales: Scales | None = None,
) -> tuple[list[Attractor], BasinCounts]:
    """``attractors`` on ``plan``, the step plan of ``params`` at ``settings.steps_per_period``
    made already (an ``analysis.AnalysisRequest`` carries it, made once when validated)."""
    if isinstance(params, GearParams):
        return _lanes_attractors([params], settings, [scales], [plan])[0]
    basins = settings.basins or BasinSettings()
    starts = basin_starts(basins, scales)
    runs = [run_verdict(integrate(params, settings, params.start_state(*s), plan), s, plan, k)
            for k, s in enumerate(starts)]  # fmt: skip
    return _group(plan.omega0 is not None, scales, basins, starts, runs)


def points_attractors(
    points: Sequence[GearParams | System],
    settings: SimulationSettings,
    scales: list[Scales | None],
) -> list[tuple[list[Attractor], BasinCounts]]:
    """``attractors`` of many points at once (a sweep's chunk): all their basin starts are
    lanes of one ``run_lanes`` call, so they share the lock-step kernel.

    Args:
        points: the parameter points, shape (P,).
        settings: as for ``attractors``.
        scales: per point, its scales or None, shape (P,).
    """
    plans = step_plans(points, settings.steps_per_period)
    return _lanes_attractors(points, settings, scales, plans)


def _lanes_attractors(
    points: Sequence[GearParams | System],
    settings: SimulationSettings,
    scales: list[Scales | None],
    plans: list[StepPlan],
) -> list[tuple[list[Attractor], BasinCounts]]:
    """``points_attractors`` on the points' step ``plans``, shape (P,)."""
    basins = settings.basins or BasinSettings()
    starts = [basin_starts(basins, sc) for sc in scales]
    lanes = [(i, s) for i, ss in enumerate(starts) for s in ss]
    runs = run_lanes(points, lanes, settings, plans, sets=[0] * len(lanes))  # basin starts
    return _grouped(plans, settings, scales, starts, runs)


def verdicts_and_attractors(
    points: Sequence[GearParams | System],
    settings: SimulationSettings,
    scales: list[Scales | None],
) -> tuple[list[BatchPoint], list[tuple[list[Attractor], BasinCounts]]]:
    """``simulate_batch`` and ``points_attractors`` of the same points (a sweep's chunk with
    basins), the settings' starts and the basin starts as lanes of one kernel call
    (``batch.simulate_batch_with``): the same numbers as the two calls."""
    basins = settings.basins or BasinSettings()
    starts = [basin_starts(basins, sc) for sc in scales]
    lanes = [(i, s) for i, ss in enumerate(starts) for s in ss]
    verdicts, runs = simulate_batch_with(points, settings, lanes)
    plans = step_plans(points, settings.steps_per_period)  # kept per process: the same plans
    return verdicts, _grouped(plans, settings, scales, starts, runs)


def _grouped(
    plans: list[StepPlan],
    settings: SimulationSettings,
    scales: list[Scales | None],
    starts: list[list[tuple[float, float]]],
    runs: list[BatchPoint],
) -> list[tuple[list[Attractor], BasinCounts]]:
    """Each point's attractors and counts from the runs of its basin ``starts`` (in order)."""
    basins = settings.basins or BasinSettings()
    out = []
    for i, (plan, sc) in enumerate(zip(plans, scales, strict=True)):
        mine = runs[i * len(starts[i]) : (i + 1) * len(starts[i])]
        commensurate = plan.omega0 is not None
        out.append(_group(commensurate, sc, basins, starts[i], mine))
    return out


def _group(
    commensurate: bool,
    scales: Scales | None,
    basins: BasinSettings,
    starts: list[tuple[float, float]],
    points: list[BatchPoint],
) -> tuple[list[Attractor], BasinCounts]:
    """The attractors and counts of one point's runs ``points`` from ``starts``."""
    labels = cluster(points, commensurate)
    groups: dict[int, list] = {}
    for label, s, bp in zip(labels, starts, points, strict=True):
        if label >= 0:
            groups.setdefault(label, []).append((s, bp))
    found = [_attractor(m, len(starts), scales) for m in groups.values()]
    order = sorted(range(len(found)), key=lambda k: (severity(found[k].classification,
                   found[k].period), found[k].count), reverse=True)  # fmt: skip
    keys = list(groups)
    relabel = {keys[old]: new for new, old in enumerate(order)}
    found = _distinct_labels([found[k] for k in order])
    n = int(np.sqrt(len(starts)))
    box = basins.dimensionless_box(*scale_pair(scales))
    counts = BasinCounts(
        starts=len(starts),
        diverged=labels.count(DIVERGED),
        unsettled=labels.count(UNSETTLED),
        labels=[relabel.get(label, label) for label in labels],
        grid=[n, n] if basins.grid else None,
        box=box,
        box_um_mm_s=None if scales is None else physical_box(box, scales),
    )
    return found, counts


def _distinct_labels(found: list[Attractor]) -> list[Attractor]:
    """Number the attractors that would share a label: 'periodic 1T, back-flank impacts
    (2)'."""
    seen: dict[str, int] = {}
    out = []
    for a in found:
        seen[a.label] = seen.get(a.label, 0) + 1
        if seen[a.label] > 1:
            a = a.model_copy(update={"label": f"{a.label} ({seen[a.label]})"})
        out.append(a)
    return out


def follows(bp: BatchPoint, a: Attractor) -> bool:
    """True when the run ``bp`` settled on the attractor ``a`` (the rule of ``cluster``)."""
    if bp.classification != a.classification:
        return False
    rep = BatchPoint.model_construct(
        classification=a.classification,
        period=a.period,
        poincare=a.strobes,
        x_peak_to_peak=a.x_peak_to_peak,
    )
    return (same_orbit if a.period else same_cloud)(rep, bp)


def coexisting(bp: BatchPoint, found: list[Attractor], counts: BasinCounts) -> list[str]:
    """The attractors other than the one ``bp`` (a followed branch) settled on, as 'label from
    NN % of starts' (largest basin first)."""
    others = [a for a in found if not follows(bp, a)]
    return [of_starts(a.label, a.fraction) for a in sorted(others, key=lambda a: -a.count)]


def of_design(
    params_or_design: GearParams | Design | dict,
    settings: SimulationSettings | dict | None = None,
    **basins: object,
) -> tuple[list[Attractor], BasinCounts]:
    """``gearengine.attractors``: the attractors of a design and how its starts ended.

        >>> found, counts = attractors(design, {"transient_periods": 100}, starts=64)

    Args:
        params_or_design: ``GearParams``, a ``Design``, or a document {"params": ...} or
            {"design": ...} (physical units).
        settings: integration settings (``SimulationSettings`` or its document); its
            ``basins`` are used unless ``basins`` are given here.
        basins: fields of ``BasinSettings`` (starts, box, grid, seed, min_fraction).
    """
    if isinstance(params_or_design, GearParams):
        doc: dict = {"params": params_or_design}
    elif isinstance(params_or_design, Design):
        doc = {"design": params_or_design}
    else:
        doc = dict(params_or_design)
    request = ParamsOrDesign.model_validate(doc)
    base = SimulationSettings.model_validate(settings or {})
    if basins or base.basins is None:
        given = {} if base.basins is None else base.basins.model_dump()
        chosen = BasinSettings.model_validate({**given, **basins})
        base = base.model_copy(update={"basins": chosen})
    base.for_request(request.design is not None)
    conv = request.conversion
    assert request.params is not None
    return attractors(request.params, base, None if conv is None else conv.scales)
