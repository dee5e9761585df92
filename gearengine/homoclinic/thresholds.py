"""Thresholds of the control parameters (the paper's Eqs. 23, 24, 28-30, generalised).

For each control parameter p in (F_e1, mu, k_p1, F_p1) M is affine in p, M = m0 + p g, so the
set of p where a branch does *not* change sign is a union of at most two closed intervals
(max M <= 0 or min M >= 0); their finite ends are the critical values, found by root finding
for every term and harmonic (the sets' algebra and the design's margin: ``margins``). Omega_e
enters M non-linearly and is scanned.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from gearengine.homoclinic.coefficients import (
    BRANCH_SIGN,
    BranchCoefficients,
    HomoclinicBranch,
    MeanLoad,
    Method,
    critical_mean_force,
    loop_load,
    melnikov_coefficients,
    saddle_loop,
)
from gearengine.homoclinic.extrema import (
    Interval,
    TrigSum,
    extrema,
    one_sinusoid_interval,
    sublevel_interval,
)
from gearengine.homoclinic.margins import (
    intersect,
    interval_ends,
    threshold_document,
    threshold_fields,
)
from gearengine.homoclinic.schemas import (
    ParameterThreshold,
    ThresholdCurve,
    ThresholdsRequest,
)
from gearengine.homoclinic.terms import packed_terms
from gearengine.model.aliases import get_alias, with_alias
from gearengine.model.errors import InputError
from gearengine.model.params import CubicBacklash, GearParams, PiecewiseBacklash
from gearengine.systems.spur_pair.laws import melnikov_cubic

CONTROL_PARAMETERS = ("F_e1", "mu", "k_p1", "F_p1")
"""Control parameters with thresholds; the amplitudes are first harmonics."""

_TERM_OF = {"F_e1": "transmission_error", "k_p1": "stiffness", "F_p1": "torque"}

UNBOUNDED = Interval(None, None)
DOMAIN = {"mu": Interval(0.0, None)}
"""Admissible range of a control parameter (damping is non-negative); others are ``UNBOUNDED``."""

OMEGA_SCAN = (0.05, 3.0, 60)
"""Default Omega_e scan for critical frequencies: start, stop, number of points."""

Coefficients = dict[HomoclinicBranch, BranchCoefficients]
"""Per-unit coefficients of both branches, inactive first harmonics included."""


def sign_change_strength(
    params: GearParams,
    a: float,
    c: float,
    method: Method = "closed_form",
    fm: float = 0.0,
) -> float:
    """max over branches of min(max M, -min M): > 0 iff some branch changes sign.

    Continuous in the parameters (for a fixed set of commensurate frequencies), so its roots
    are the critical values of any parameter. ``method`` names the coefficients (``METHODS``),
    ``fm`` the mean force the loops carry (``coefficients.loop_load``; the loops must exist,
    ``saddle_loop``).
    The closed form runs compiled (``kernels.scan_strength`` at the design's own speed, on the
    packed form of ``terms``); quadrature, and the rare design on which a coefficient underflows
    to 0, take the same algorithm on the pydantic documents.
    """
    if method == "closed_form":
        strength = packed_terms(params, a, c, fm).strength()
        if not math.isnan(strength):
            return strength
    strengths = []
    for br in BRANCH_SIGN:
        ext = extrema(melnikov_coefficients(params, a, c, br, method, fm=fm).trig_sum())
        strengths.append(min(ext.maximum.value, -ext.minimum.value))
    return max(strengths)


@functools.lru_cache(maxsize=1024)
def _cubic(backlash: CubicBacklash | PiecewiseBacklash) -> tuple[float, float]:
    """(a, c) of ``melnikov_cubic``, remembered per backlash model (frozen, hashable): the
    piecewise law's collocation fit costs more than a compiled verdict."""
    a, c, _ = melnikov_cubic(backlash)
    return a, c


def strength_at(params: GearParams, mean_load: MeanLoad = "unperturbed") -> float:
    """``sign_change_strength`` of ``params``; NaN without a saddle loop (the criterion does not
    apply there: no saddle, or |F_m| >= F_crit with the mean load in the unperturbed system).
    A path's point is made by the path (``boundary.Path``), not here."""
    a, c = _cubic(params.backlash)
    fm = loop_load(params, mean_load)
    if not saddle_loop(a, c, fm):
        return math.nan
    return sign_change_strength(params, a, c, fm=fm)


def chaos_possible(params: GearParams, mean_load: MeanLoad = "unperturbed") -> bool | None:
    """The Melnikov verdict (``melnikov(params).chaos_possible``) without the thresholds.

    Some branch changes sign iff ``sign_change_strength > 0``; None when the criterion does not
    apply (no saddle loop).
    """
    strength = strength_at(params, mean_load=mean_load)
    return None if math.isnan(strength) else strength > 0.0


Family = tuple[TrigSum, TrigSum] | tuple[float, float, float, float]
"""M = m0 + p g of one control parameter p: two trig sums sharing frequencies and phases, or for
at most one sinusoid the floats (m0.offset, g.offset, a, b) of ``extrema.one_sinusoid``."""


def _family(coef: BranchCoefficients, m: TrigSum | None, parameter: str) -> Family | None:
    """Split M = m0 + p g for the control parameter p (None if p's excitation is absent);
    ``m`` is ``coef.trig_sum()``, read once for every parameter (``trig_sums``: None for at most
    one term, read from ``coef`` itself)."""
    if coef.damping_per_unit is None:
        raise ValueError("coefficients read back from JSON carry no per-unit values (they are "
                         "not serialised): compute them again from the parameters")  # fmt: skip
    j = None
    if parameter != "mu":
        name = _TERM_OF[parameter]
        j = next((i for i, t in enumerate(coef.terms) if t.excitation == name and t.r == 1), None)
        if j is None:
            return None
    if m is None:  # the floats of one_sinusoid, without arrays
        only = float(coef.terms[0].coefficient) if coef.terms else 0.0
        if j is None:
            return 0.0, float(coef.damping_per_unit), only, 0.0
        return float(coef.damping), 0.0, 0.0, float(coef.terms[j].per_unit)
    zeros = np.zeros_like(m.amplitudes)
    if j is None:
        return (
            TrigSum(0.0, m.amplitudes, m.frequencies, m.phases),
            TrigSum(coef.damping_per_unit, zeros, m.frequencies, m.phases),
        )
    rest = m.amplitudes.copy()
    rest[j] = 0.0
    unit = zeros.copy()
    unit[j] = coef.terms[j].per_unit
    return (
        TrigSum(m.offset, rest, m.frequencies, m.phases),
        TrigSum(0.0, unit, m.frequencies, m.phases),
    )


def no_sign_change(family: Family) -> list[Interval]:
    """Intervals of p where m0 + p g keeps one sign: max <= 0 or min >= 0."""
    if len(family) == 4:  # the closed forms, on floats (-M: the same floats negated)
        below = one_sinusoid_interval(*family)
        return [s for s in (below, one_sinusoid_interval(*(-v for v in family))) if s is not None]
    m0, g = family
    sets = (sublevel_interval(m0, g), sublevel_interval(m0.negated(), g.negated()))
    return [s for s in sets if s is not None]


def unit_coefficients(
    params: GearParams, a: float, c: float, method: Method, mean_load: MeanLoad = "unperturbed"
) -> Coefficients:
    """Coefficients of both branches with the inactive first harmonics (for thresholds): built
    once per branch, then split per control parameter by ``_family``."""
    fm = loop_load(params, mean_load)
    return {
        br: melnikov_coefficients(params, a, c, br, method, include_inactive=True, fm=fm)
        for br in BRANCH_SIGN
    }


def parameter_threshold(
    params: GearParams,
    parameter: str,
    a: float,
    c: float,
    method: Method = "closed_form",
    coefs: Coefficients | None = None,
    mean_load: MeanLoad = "unperturbed",
) -> ParameterThreshold:
    """Critical values of one control parameter (others fixed) and the design's margin.

    ``coefs`` are the branches' ``unit_coefficients`` if already known (else computed with
    ``method`` and ``mean_load``).
    """
    coefs = unit_coefficients(params, a, c, method, mean_load) if coefs is None else coefs
    sums = trig_sums(coefs)
    return ParameterThreshold(**_threshold(parameter, get_alias(params, parameter), coefs, sums))


def trig_sums(coefs: Coefficients) -> dict[HomoclinicBranch, TrigSum | None]:
    """Each branch's ``trig_sum`` for ``_family``, read once for every control parameter; None
    for a branch of at most one term (its family is read from the coefficients as floats)."""
    return {br: coefs[br].trig_sum() if len(coefs[br].terms) > 1 else None for br in BRANCH_SIGN}


def parameter_thresholds(
    coefs: Coefficients,
    values: dict[str, float | None],
    forces: dict[str, float | None],
    f_crit: float,
) -> dict[str, dict]:
    """``parameter_threshold`` of every control parameter (``CONTROL_PARAMETERS``) as the
    fields of its document (validated with the verdict's), each branch's sum of ``coefs``
    (``unit_coefficients``) read once for all of them. ``values`` are
    the design's values of the parameters (``get_alias``); with the margin in the force scale
    ``f_crit``, ``forces`` being the largest force along the loops per unit of each parameter
    (``perturbations.force_per_unit``; None: no such force)."""
    sums = trig_sums(coefs)
    return {p: _threshold(p, values[p], coefs, sums, forces[p], f_crit) for p in CONTROL_PARAMETERS}


def _threshold(
    parameter: str,
    value: float | None,
    coefs: Coefficients,
    sums: dict[HomoclinicBranch, TrigSum | None],
    force: float | None = None,
    f_crit: float = 1.0,
) -> dict:
    """The fields of ``parameter_threshold`` of a design whose ``parameter`` is ``value``, from
    the branches' ``unit_coefficients`` and their ``trig_sums``; with ``force`` (the largest force
    along the loops per unit of the parameter) the margin also in the force scale ``f_crit``."""
    domain = DOMAIN.get(parameter, UNBOUNDED)
    branches: dict[HomoclinicBranch, dict] = {}
    sets: dict[HomoclinicBranch, list[Interval]] = {}
    for br in BRANCH_SIGN:
        family = _family(coefs[br], sums[br], parameter)
        if family is None:
            exc = _TERM_OF[parameter]
            return threshold_fields(
                parameter, value, [], [], note=f"{exc} is not given: no frequency for {parameter}"
            )
        sets[br] = intersect(no_sign_change(family), [domain])
        branches[br] = {  # a BranchThreshold, validated with the document in one pass
            "critical_values": interval_ends(sets[br], domain),
            "no_sign_change": [(i.lo, i.hi) for i in sets[br]],
        }
    overall = intersect(sets["plus"], sets["minus"])
    return threshold_fields(
        parameter,
        value,
        interval_ends(overall, domain),
        [(i.lo, i.hi) for i in overall],
        branches=branches,
        force=force,
        f_crit=f_crit,
    )


def frequency_threshold(
    params: GearParams,
    value: float | None,
    a: float,
    c: float,
    fm: float,
    scan: tuple = OMEGA_SCAN,
    method: Method = "closed_form",
) -> ParameterThreshold:
    """Critical Omega_e in a scan: where the verdict flips, located by brentq.

    Every excitation frequency is scaled with Omega_e (a change of running speed, their ratios
    fixed): the commensurability of the forcing, and so the extrema method, stays the same along
    the scan and the sign-change strength is continuous, so each root is a real flip. (Moving
    Omega_e alone would jump between exact extrema at rational ratios and the supremum between
    them, and the verdict would flip at isolated points.) The closed form runs compiled
    (``kernels.scan_roots``); quadrature, and the rare scan on which a coefficient underflows to
    0, take ``_scan_python``, the same algorithm on the pydantic documents.

    ``value`` is the design's Omega_e (None: no transmission error given) and ``fm`` the mean
    force its loops carry (``coefficients.loop_load``).
    """
    if value is None:
        return threshold_document(
            "Omega_e",
            None,
            [],
            [],
            scan=scan,
            note="transmission_error is not given: no Omega_e to scan",
        )
    found = _scan_compiled(params, a, c, fm, scan, value) if method == "closed_form" else None
    critical, no_chaos = found or _scan_python(params, a, c, scan, value, method, fm)
    return threshold_document(
        "Omega_e",
        value,
        critical,
        no_chaos,
        scan=scan,
        note="critical Omega_e found by scanning with every excitation frequency scaled "
        "alongside (ratios fixed, as a change of running speed); flips between scan points "
        "closer than the grid step may be missed",
    )


@functools.lru_cache(maxsize=256)
def scan_grid(start: float, stop: float, num: int) -> np.ndarray:
    """``numpy.linspace(start, stop, num)``, read-only and kept: a service answers many designs
    on the same Omega_e scan, and linspace costs as much as a verdict's root finding."""
    grid = np.linspace(start, stop, num)
    grid.flags.writeable = False
    return grid


def _scan_compiled(
    params: GearParams, a: float, c: float, fm: float, scan: tuple, value: float
) -> tuple[list[float], list[tuple[float, float]]] | None:
    """Critical Omega_e and no-chaos pieces by ``kernels.scan_roots``; None to fall back."""
    start, stop, num = scan
    omegas = scan_grid(start, stop, num)
    critical, flags, ok = packed_terms(params, a, c, fm).scan_roots(omegas, value)
    if not ok:
        return None
    edges = [float(start), *critical.tolist(), float(stop)]
    return critical.tolist(), [(edges[i], edges[i + 1]) for i in np.flatnonzero(flags)]


def _scan_python(
    params: GearParams,
    a: float,
    c: float,
    scan: tuple,
    value: float,
    method: Method,
    fm: float,
) -> tuple[list[float], list[tuple[float, float]]]:
    """The running-speed scan on the documents: ``sign_change_strength`` with ``method`` on
    the loops carrying the mean force ``fm``."""
    start, stop, num = scan

    def strength(om: float) -> float:
        factor = float(om) / value
        moved = {
            name: exc.model_copy(update={"frequency": exc.frequency * factor})
            for name, exc in params.excitations()
        }
        return sign_change_strength(params.model_copy(update=moved), a, c, method, fm)

    from scipy import optimize

    omegas = np.linspace(start, stop, num)
    values = [strength(om) for om in omegas]
    critical = [
        float(optimize.brentq(strength, lo, hi, xtol=1e-12))
        for lo, hi, f_lo, f_hi in zip(omegas, omegas[1:], values, values[1:], strict=False)
        if (f_lo > 0.0) != (f_hi > 0.0)
    ]
    edges = [float(start), *critical, float(stop)]
    no_chaos = [
        (edges[i], edges[i + 1])
        for i in range(len(edges) - 1)
        if strength(0.5 * (edges[i] + edges[i + 1])) <= 0.0
    ]
    return critical, no_chaos


def threshold_curve(
    params: GearParams,
    parameter: str,
    frequency_parameter: str = "Omega_e",
    start: float = 0.05,
    stop: float = 2.5,
    num: int = 100,
    mean_load: MeanLoad = "unperturbed",
) -> ThresholdCurve:
    """Critical values of ``parameter`` for ``num`` values of a frequency in [start, stop].

    Raises ``InputError`` naming the request field at fault (``parameter``,
    ``frequency_parameter``, ``params.backlash`` or ``params.mean_force``) when no curve can be
    drawn.

    Args:
        params: the design; its other parameters stay fixed.
        parameter: F_e1, mu, k_p1 or F_p1.
        frequency_parameter: Omega_e, Omega_k or Omega_p (the excitation must be given).
        start, stop, num: the frequency grid (dimensionless).
        mean_load: where F_m goes (``coefficients.MeanLoad``).
    """
    a, c, notes = melnikov_cubic(params.backlash)
    if not saddle_loop(a, c):
        raise InputError(
            "params.backlash",
            f"the Melnikov criterion needs a > 0 and c > 0 (got a = {a}, c = {c})",
        )
    fm = loop_load(params, mean_load)
    if not saddle_loop(a, c, fm):
        raise InputError(
            "params.mean_force",
            f"F_m = {fm:g} is at or above F_crit = "
            f"{critical_mean_force(a, c):.6g}: no saddle, the Melnikov criterion does not apply "
            "(mean_load: perturbation gives the paper's first-order treatment)",
        )
    if get_alias(params, frequency_parameter) is None:
        raise InputError(
            "frequency_parameter", f"{frequency_parameter}: its excitation is not given"
        )
    omegas = [float(w) for w in np.linspace(start, stop, num)]
    rows = [
        parameter_threshold(
            with_alias(params, frequency_parameter, w), parameter, a, c, mean_load=mean_load
        )
        for w in omegas
    ]
    if any(r.note for r in rows):
        raise InputError("parameter", next(r.note for r in rows if r.note))
    return ThresholdCurve(
        parameter=parameter,
        frequency_parameter=frequency_parameter,
        frequencies=omegas,
        no_chaos=[r.no_chaos for r in rows],
        branches={br: [r.branches[br].no_sign_change for r in rows] for br in BRANCH_SIGN},
        value=get_alias(params, parameter),
        notes=notes,
    )


def curve_of(request: ThresholdsRequest) -> ThresholdCurve:
    """``threshold_curve`` of a /v1/thresholds request document."""
    return threshold_curve(
        request.params,
        request.parameter,
        request.frequency_parameter,
        request.start,
        request.stop,
        request.num,
        request.mean_load,
    )
