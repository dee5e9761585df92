"""The Melnikov verdict: sign change of each branch, thresholds and margins (paper 3.2, 4.1-4.3).

A branch has a simple zero (transverse homoclinic intersection) iff min M < 0 < max M over tau0.
Chaos is possible when either branch does. For each control parameter p in (F_e1, mu, k_p1,
F_p1) M is affine in p, so the set of p where a branch does *not* change sign is a union of at
most two closed intervals (max M <= 0 or min M >= 0); its finite ends are the critical values
(the paper's Eqs. 23, 24, 28-30, generalised to every term by root finding).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field
from scipy import optimize

from gearengine.extrema import Extrema, Interval, TrigSum, extrema, sublevel_interval
from gearengine.frequencies import forcing_period
from gearengine.melnikov import (
    BRANCH_SIGN,
    Branch,
    MelnikovCoefficients,
    Method,
    coefficients,
    cubic_coefficients,
)
from gearengine.params import GearParams, get_alias

CONTROL_PARAMETERS = ("F_e1", "mu", "k_p1", "F_p1")
"""Control parameters with thresholds; the amplitudes are first harmonics."""

_TERM_OF = {"F_e1": "transmission_error", "k_p1": "stiffness", "F_p1": "torque"}

DOMAIN = {"mu": Interval(0.0, None)}
"""Admissible range of a control parameter (damping is non-negative); others are unbounded."""

OMEGA_SCAN = (0.05, 3.0, 60)
"""Default Omega_e scan for critical frequencies: start, stop, number of points."""


class _Result(BaseModel):
    model_config = ConfigDict(frozen=True)


class BranchVerdict(_Result):
    """Extrema of M over tau0 on one homoclinic branch."""

    sign_change: bool = Field(description="min M < 0 < max M: M has a simple zero.")
    min: float = Field(
        description="Minimum of M(tau0) (infimum if the frequencies are incommensurate)."
    )
    max: float = Field(description="Maximum of M(tau0) (supremum if incommensurate).")
    tau0_min: float | None = Field(
        description="tau0 of the minimum within one period, if attained."
    )
    tau0_max: float | None = Field(
        description="tau0 of the maximum within one period, if attained."
    )
    extrema: Literal["exact", "supremum", "constant"] = Field(
        description="exact: commensurate frequencies, extrema over the common period; "
        "supremum: incommensurate, sum of amplitudes; constant: no excitation."
    )


class TermOut(_Result):
    """One sinusoid B sin(Omega tau0 + phi) of M."""

    excitation: str = Field(description="stiffness, transmission_error or torque.")
    r: int = Field(description="Harmonic number.")
    frequency: float = Field(description="r Omega (dimensionless).")
    phase: float = Field(description="Phase phi_r, radians.")
    coefficient: float = Field(description="B, same units as M.")


class CoefficientsOut(_Result):
    """M(tau0) = damping + sum(terms) on one branch."""

    damping: float = Field(description="Constant part A = -(8/3) mu a^(3/2) / c.")
    terms: list[TermOut]


class BranchThreshold(_Result):
    """Where one branch stops changing sign as the parameter varies."""

    critical_values: list[float] = Field(description="Ends of the no-sign-change intervals.")
    no_sign_change: list[tuple[float | None, float | None]] = Field(
        description="Closed intervals [lo, hi] of the parameter where this branch has no simple "
        "zero; null is an unbounded end."
    )


class ParameterThreshold(_Result):
    """Thresholds of one control parameter, the others fixed, and the design's margin."""

    value: float | None = Field(description="The parameter's value in the given design.")
    critical_values: list[float] = Field(
        description="Values where the overall verdict (either branch changes sign) flips."
    )
    nearest: float | None = Field(description="The critical value nearest to the design.")
    margin: float | None = Field(
        description="value - nearest: signed distance to the nearest critical value."
    )
    relative_margin: float | None = Field(description="margin / |nearest| (null if nearest = 0).")
    no_chaos: list[tuple[float | None, float | None]] = Field(
        description="Intervals of the parameter where neither branch changes sign."
    )
    branches: dict[Branch, BranchThreshold] | None = Field(
        None, description="Per-branch thresholds (null for the frequency scan)."
    )
    scan: tuple[float, float, int] | None = Field(
        None, description="For a frequency: the scanned range (start, stop, points)."
    )
    note: str | None = Field(None, description="Why a threshold is missing, if it is.")


class MelnikovResult(_Result):
    """The Melnikov verdict of a design (the /v1/melnikov contract)."""

    applicable: bool = Field(description="False when the unperturbed system has no saddle loop.")
    chaos_possible: bool | None = Field(
        description="Either branch changes sign: transverse homoclinic orbits, chaos possible. "
        "null when not applicable."
    )
    branches: dict[Branch, BranchVerdict] | None = Field(
        description="plus: x_h > 0 (Eq. 15), minus: x_h < 0."
    )
    thresholds: dict[str, ParameterThreshold] = Field(
        description="Per control parameter (F_e1, mu, k_p1, F_p1, Omega_e)."
    )
    coefficients: dict[Branch, CoefficientsOut] | None = Field(
        description="The sinusoids of M on each branch."
    )
    a: float | None = Field(description="Cubic coefficient a used (f_h = -a x + c x^3).")
    c: float | None = Field(description="Cubic coefficient c used.")
    forcing_period: float | None = Field(
        description="Common period 2 pi / Omega_0 of the active excitations (null if none or "
        "incommensurate)."
    )
    method: Method = Field(description="closed_form (corrected Eq. 19) or quadrature (Eq. 18).")
    notes: list[str] = Field(description="Caveats and explanations, in plain words.")


# --- Verdict ------------------------------------------------------------------------------------


def _trig_sum(coef: MelnikovCoefficients) -> TrigSum:
    return TrigSum(
        coef.damping,
        np.array([t.coefficient for t in coef.terms]),
        np.array([t.frequency for t in coef.terms]),
        np.array([t.phase for t in coef.terms]),
    )


def branch_verdict(ext: Extrema) -> BranchVerdict:
    """Sign-change decision of one branch from its extrema."""
    return BranchVerdict(
        sign_change=ext.minimum.value < 0.0 < ext.maximum.value,
        min=ext.minimum.value,
        max=ext.maximum.value,
        tau0_min=ext.minimum.tau0,
        tau0_max=ext.maximum.tau0,
        extrema=ext.method,
    )


def sign_change_strength(params: GearParams, a: float, c: float) -> float:
    """max over branches of min(max M, -min M): > 0 iff some branch changes sign.

    Continuous in the parameters (for a fixed set of commensurate frequencies), so its roots
    are the critical values of any parameter.
    """
    strengths = []
    for br in BRANCH_SIGN:
        ext = extrema(_trig_sum(coefficients(params, a, c, br)))
        strengths.append(min(ext.maximum.value, -ext.minimum.value))
    return max(strengths)


def melnikov(
    params: GearParams, method: Method = "closed_form", omega_scan: tuple = OMEGA_SCAN
) -> MelnikovResult:
    """The Melnikov verdict of ``params`` with thresholds of every control parameter.

    Args:
        params: dimensionless parameters of Eq. (9), evaluated with epsilon = 1.
        method: ``closed_form`` or ``quadrature`` for the coefficients of M.
        omega_scan: (start, stop, num) of the Omega_e scan for critical frequencies.
    """
    a, c, notes = cubic_coefficients(params)
    if not (a > 0.0 and c > 0.0):
        return MelnikovResult(
            applicable=False,
            chaos_possible=None,
            branches=None,
            thresholds={},
            coefficients=None,
            a=a,
            c=c,
            forcing_period=None,
            method=method,
            notes=[
                *notes,
                f"not applicable: the homoclinic orbit of x'' = a x - c x^3 needs a > 0 and "
                f"c > 0 (got a = {a:g}, c = {c:g}); without a saddle loop there is no "
                "Melnikov criterion",
            ],
        )
    coefs = {br: coefficients(params, a, c, br, method) for br in BRANCH_SIGN}
    branches = {br: branch_verdict(extrema(_trig_sum(coefs[br]))) for br in BRANCH_SIGN}
    period = forcing_period(params.active_frequencies())
    if any(b.extrema == "supremum" for b in branches.values()):
        notes.append(
            "the active frequencies are incommensurate (no ratio p/q with q <= 64): min and max "
            "of M are the infimum and supremum A -/+ sum |B_i|, approached but not attained"
        )
    if params.mean_force != 0.0:
        notes.append("the mean force F_m does not enter M: the integral of y_h over the orbit is 0")
    thresholds = {p: parameter_threshold(params, p, a, c) for p in CONTROL_PARAMETERS}
    thresholds["Omega_e"] = frequency_threshold(params, a, c, omega_scan)
    return MelnikovResult(
        applicable=True,
        chaos_possible=any(b.sign_change for b in branches.values()),
        branches=branches,
        thresholds=thresholds,
        coefficients={
            br: CoefficientsOut(
                damping=coef.damping,
                terms=[
                    TermOut(
                        excitation=t.excitation,
                        r=t.r,
                        frequency=t.frequency,
                        phase=t.phase,
                        coefficient=t.coefficient,
                    )
                    for t in coef.terms
                ],
            )
            for br, coef in coefs.items()
        },
        a=a,
        c=c,
        forcing_period=period,
        method=method,
        notes=notes,
    )


# --- Thresholds ---------------------------------------------------------------------------------


def _family(coef: MelnikovCoefficients, parameter: str) -> tuple[TrigSum, TrigSum] | None:
    """Split M = m0 + p g for the control parameter p (None if p's excitation is absent)."""
    m = _trig_sum(coef)
    zeros = np.zeros_like(m.amplitudes)
    if parameter == "mu":
        return (
            TrigSum(0.0, m.amplitudes, m.frequencies, m.phases),
            TrigSum(coef.damping_per_unit, zeros, m.frequencies, m.phases),
        )
    name = _TERM_OF[parameter]
    j = next((i for i, t in enumerate(coef.terms) if t.excitation == name and t.r == 1), None)
    if j is None:
        return None
    rest = m.amplitudes.copy()
    rest[j] = 0.0
    unit = zeros.copy()
    unit[j] = coef.terms[j].per_unit
    return (
        TrigSum(m.offset, rest, m.frequencies, m.phases),
        TrigSum(0.0, unit, m.frequencies, m.phases),
    )


def _negate(m: TrigSum) -> TrigSum:
    return TrigSum(-m.offset, -m.amplitudes, m.frequencies, m.phases)


def no_sign_change(m0: TrigSum, g: TrigSum) -> list[Interval]:
    """Intervals of p where m0 + p g keeps one sign: max <= 0 or min >= 0."""
    sets = (sublevel_interval(m0, g), sublevel_interval(_negate(m0), _negate(g)))
    return [s for s in sets if s is not None]


def _intersect(xs: list[Interval], ys: list[Interval]) -> list[Interval]:
    out = []
    for x in xs:
        for y in ys:
            lo = _max_end(x.lo, y.lo)
            hi = _min_end(x.hi, y.hi)
            if lo is None or hi is None or lo <= hi:
                out.append(Interval(lo, hi))
    return sorted(out, key=lambda i: -np.inf if i.lo is None else i.lo)


def _max_end(p: float | None, q: float | None) -> float | None:
    return q if p is None else p if q is None else max(p, q)


def _min_end(p: float | None, q: float | None) -> float | None:
    return q if p is None else p if q is None else min(p, q)


def _ends(intervals: list[Interval], domain: Interval) -> list[float]:
    """Finite interval ends that are not ends of the parameter's domain."""
    bounds = {domain.lo, domain.hi}
    return sorted({e for i in intervals for e in (i.lo, i.hi) if e is not None and e not in bounds})


def _margin(value: float | None, critical: list[float]) -> tuple:
    if value is None or not critical:
        return None, None, None
    nearest = min(critical, key=lambda v: abs(value - v))
    margin = value - nearest
    return nearest, margin, (margin / abs(nearest) if nearest != 0.0 else None)


def parameter_threshold(
    params: GearParams, parameter: str, a: float, c: float
) -> ParameterThreshold:
    """Critical values of one control parameter (others fixed) and the design's margin."""
    value = get_alias(params, parameter)
    domain = DOMAIN.get(parameter, Interval(None, None))
    branches: dict[Branch, BranchThreshold] = {}
    sets: dict[Branch, list[Interval]] = {}
    for br in BRANCH_SIGN:
        family = _family(coefficients(params, a, c, br, include_inactive=True), parameter)
        if family is None:
            exc = _TERM_OF[parameter]
            return ParameterThreshold(
                value=value,
                critical_values=[],
                nearest=None,
                margin=None,
                relative_margin=None,
                no_chaos=[],
                note=f"{exc} is not given: no frequency for {parameter}",
            )
        sets[br] = _intersect(no_sign_change(*family), [domain])
        branches[br] = BranchThreshold(
            critical_values=_ends(sets[br], domain),
            no_sign_change=[(i.lo, i.hi) for i in sets[br]],
        )
    overall = _intersect(sets["plus"], sets["minus"])
    critical = _ends(overall, domain)
    nearest, margin, rel = _margin(value, critical)
    return ParameterThreshold(
        value=value,
        critical_values=critical,
        nearest=nearest,
        margin=margin,
        relative_margin=rel,
        no_chaos=[(i.lo, i.hi) for i in overall],
        branches=branches,
    )


def frequency_threshold(
    params: GearParams, a: float, c: float, scan: tuple = OMEGA_SCAN
) -> ParameterThreshold:
    """Critical Omega_e in a scan: where the verdict flips, located by bisection."""
    value = get_alias(params, "Omega_e")
    base = dict(value=value, branches=None, scan=scan)
    if value is None:
        return ParameterThreshold(
            **base,
            critical_values=[],
            nearest=None,
            margin=None,
            relative_margin=None,
            no_chaos=[],
            note="transmission_error is not given: no Omega_e to scan",
        )
    start, stop, num = scan
    exc = params.transmission_error

    def strength(om: float) -> float:
        moved = exc.model_copy(update={"frequency": float(om)})
        return sign_change_strength(params.model_copy(update={"transmission_error": moved}), a, c)

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
    nearest, margin, rel = _margin(value, critical)
    return ParameterThreshold(
        **base,
        critical_values=critical,
        nearest=nearest,
        margin=margin,
        relative_margin=rel,
        no_chaos=no_chaos,
        note="critical frequencies found by scanning; flips between scan points closer than "
        "the grid step may be missed",
    )
