"""The Melnikov verdict of a design: sign change of each branch, thresholds and margins.

A branch has a simple zero (transverse homoclinic intersection) iff min M < 0 < max M over tau0
(paper section 3.2). Chaos is possible when either branch does. Guckenheimer & Holmes 1983,
Theorem 4.5.3; Farshidianfar & Saghafi 2014, Eqs. (20)-(24).
"""

from __future__ import annotations

import math

from gearengine.homoclinic.coefficients import (
    BRANCH_SIGN,
    MeanLoad,
    Method,
    active_only,
    critical_mean_force,
    loop_load,
    melnikov_coefficients,
    saddle_loop,
)
from gearengine.homoclinic.extrema import Extrema
from gearengine.homoclinic.loops import saddle
from gearengine.homoclinic.perturbations import (
    caveat,
    force_per_unit,
    loop_extremes,
    perturbation_sizes,
)
from gearengine.homoclinic.schemas import MelnikovResult
from gearengine.homoclinic.thresholds import (
    CONTROL_PARAMETERS,
    OMEGA_SCAN,
    Coefficients,
    frequency_threshold,
    parameter_thresholds,
)
from gearengine.model.aliases import get_alias
from gearengine.model.frequencies import poincare_period
from gearengine.model.params import GearParams
from gearengine.systems.spur_pair.laws import melnikov_cubic


def branch_verdict(ext: Extrema) -> dict:
    """Sign-change decision of one branch from its extrema: a ``BranchVerdict``'s fields,
    validated with the result in one pass."""
    return {
        "sign_change": ext.minimum.value < 0.0 < ext.maximum.value,
        "min": ext.minimum.value,
        "max": ext.maximum.value,
        "tau0_min": ext.minimum.tau0,
        "tau0_max": ext.maximum.tau0,
        "extrema": ext.method,
    }


def not_applicable(
    a: float, c: float, method: Method, notes: list[str], mean_load: MeanLoad = "unperturbed"
) -> MelnikovResult:
    """A result without numbers: the criterion does not apply, and the notes say why."""
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
        notes=notes,
        mean_load=mean_load,
        critical_mean_force=critical_mean_force(a, c) if a > 0.0 and c > 0.0 else None,
    )


def applicability(
    params: GearParams, method: Method = "closed_form", mean_load: MeanLoad = "unperturbed"
) -> tuple[float, float, list[str], Coefficients | None]:
    """(a, c, notes, units) of a design: the cubic law, its notes, and the per-unit coefficients
    of both branches (``unit_coefficients``); units is None when the criterion does not apply
    (no saddle loop, |F_m| >= F_crit with the mean load in the unperturbed system, or M
    overflows), and the last note says why."""
    a, c, notes = melnikov_cubic(params.backlash)
    if not saddle_loop(a, c):
        notes.append(
            f"not applicable: the homoclinic orbit of x'' = a x - c x^3 needs a > 0 and "
            f"c > 0 (got a = {a:g}, c = {c:g}); without a saddle loop there is no "
            "Melnikov criterion"
        )
        return a, c, notes, None
    fm, f_crit = loop_load(params, mean_load), critical_mean_force(a, c)
    if not saddle_loop(a, c, fm):
        notes.append(
            f"not applicable: the mean load F~_m = {fm:.4g} is at or above F_crit = "
            f"(2a/3) sqrt(a/(3c)) = {f_crit:.4g}, the largest force the backlash nonlinearity "
            "can balance with a saddle: the teeth sit in one potential well of x'' = a x - "
            "c x^3 + F_m, there is no saddle and no homoclinic orbit, so the homoclinic "
            "mechanism of chaos does not exist at this load; the numerical verdict still "
            "applies"
        )
        return a, c, notes, None
    # every per-unit coefficient the thresholds will use, inactive first harmonics included
    units = {
        br: melnikov_coefficients(params, a, c, br, method, include_inactive=True, fm=fm)
        for br in BRANCH_SIGN
    }
    scale = [units["plus"].damping_per_unit, *(t.per_unit for t in units["plus"].terms)]
    if not all(math.isfinite(v) and abs(v) < 1e150 for v in scale):
        notes.append(
            f"not applicable: with a = {a:g}, c = {c:g} the orbit's scale sqrt(2a/c) makes "
            "M overflow; the Melnikov function is numerically meaningless here"
        )
        return a, c, notes, None
    return a, c, notes, units


def melnikov(
    params: GearParams,
    method: Method = "closed_form",
    omega_scan: tuple = OMEGA_SCAN,
    mean_load: MeanLoad = "unperturbed",
) -> MelnikovResult:
    """The Melnikov verdict of ``params`` with thresholds of every control parameter.

    Args:
        params: dimensionless parameters of Eq. (9), evaluated with epsilon = 1.
        method: ``closed_form`` or ``quadrature`` for the coefficients of M, used everywhere:
            the branch extrema, the thresholds and the Omega_e scan.
        omega_scan: (start, stop, num) of the Omega_e scan for critical frequencies.
        mean_load: ``unperturbed`` (F_m in the unperturbed system, its saddle and loops) or
            ``perturbation`` (the paper's first-order treatment, F_m absent from M).
    """
    period = poincare_period(params)  # the model room's answers first: T0 and the aliases
    values = {p: get_alias(params, p) for p in (*CONTROL_PARAMETERS, "Omega_e")}
    a, c, notes, units = applicability(params, method, mean_load)
    if units is None:
        return not_applicable(a, c, method, notes, mean_load)
    fm, f_crit = loop_load(params, mean_load), critical_mean_force(a, c)
    coefs = {br: active_only(units[br], params) for br in BRANCH_SIGN}
    branches = {br: branch_verdict(coefs[br].extrema(period)) for br in BRANCH_SIGN}
    if any(b["extrema"] == "supremum" for b in branches.values()):
        notes.append(
            "the active frequencies are incommensurate (no ratio p/q with q <= 64): min and max "
            "of M are the infimum and supremum A -/+ sum |B_i|, approached but not attained"
        )
    if params.mean_force != 0.0 and mean_load == "perturbation":
        notes.append(
            "mean_load perturbation: the mean force F_m is taken as small (the paper's "
            "F~_m = eps f_m) and does not enter M, the integral of y_h over the orbit being 0"
            + (
                ""
                if saddle_loop(a, c, params.mean_force)
                else f"; at F~_m = {params.mean_force:.4g} >= F_crit = {f_crit:.4g} the loaded "
                "system has no saddle at all, so this first-order answer is outside its domain"
            )
        )
    elif fm != 0.0:
        notes.append(
            f"the mean force F~_m = {fm:.4g} is in the unperturbed system (F_crit = "
            f"{f_crit:.4g}): the saddle sits at x_s = {saddle(a, c, fm):.6g} and the two "
            "homoclinic loops differ, so each has its own M and thresholds"
        )
    extremes = loop_extremes(a, c, fm)
    sizes = perturbation_sizes(params, extremes, fm, f_crit)
    stretched = caveat(sizes, f_crit)
    if stretched:
        notes.append(stretched)
    if method != "closed_form":
        notes.append(
            f"method {method}: the verdict, the thresholds and the Omega_e scan all use "
            f"{method} coefficients"
        )
    forces = {p: force_per_unit(params, p, extremes) for p in CONTROL_PARAMETERS}
    thresholds = parameter_thresholds(units, values, forces, f_crit)
    thresholds["Omega_e"] = frequency_threshold(
        params, values["Omega_e"], a, c, fm, omega_scan, method
    )
    return MelnikovResult(
        applicable=True,
        chaos_possible=any(b["sign_change"] for b in branches.values()),
        branches=branches,
        thresholds=thresholds,
        coefficients=coefs,
        a=a,
        c=c,
        forcing_period=period,
        method=method,
        notes=notes,
        mean_load=mean_load,
        critical_mean_force=f_crit,
        saddle=float(saddle(a, c, fm)),
        perturbation_sizes=sizes,
    )
