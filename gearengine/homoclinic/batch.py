"""Melnikov verdicts and threshold margins of many designs at once (for optimisers).

``melnikov_batch(designs)`` gives, per design, what an optimiser needs from ``melnikov``:
``chaos_possible`` and the margin of each control parameter (F_e1, mu, k_p1, F_p1) to its
nearest critical value, the same numbers as the full verdict's thresholds (no Omega_e scan).

Designs with one excitation and at most its first harmonic (the paper's section 4.1 case) are
evaluated together on arrays (``_simple``): with one sinusoid M = A + B sin(Omega tau0 + phi), the
thresholds are the closed forms of Eqs. (23)-(24),

    F_1 critical  = -/+ (-A / |B_unit|)                      (Eq. 23, any excitation's amplitude)
    mu critical   = -|B| / A_unit,  A_unit = -(8/3) a^(3/2) / c          (Eq. 24)

computed with the same operations as the single verdict (``extrema._one_sinusoid_interval``), so
the numbers are the same to the last bit. Every other design (several excitations or harmonics,
no saddle loop, zero damping, coefficients at the edge of the float range) takes the per-design
path, ``melnikov``'s thresholds without the scan.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numba
import numpy as np
from pydantic import BaseModel, ConfigDict, Field
from typing_extensions import TypedDict  # pydantic needs it on Python < 3.12

from gearengine.homoclinic.coefficients import (
    BRANCH_SIGN,
    MeanLoad,
    active_only,
    loop_load,
    saddle_loop,
)
from gearengine.homoclinic.extrema import NEGLIGIBLE
from gearengine.homoclinic.kernels import (
    AMPLITUDE,
    FUNDAMENTAL,
    HARMONIC,
    KIND_ROW,
    MU,
    damping_unit,
    unit_coefficient,
)
from gearengine.homoclinic.margins import signed_margin
from gearengine.homoclinic.terms import packed_terms
from gearengine.homoclinic.thresholds import CONTROL_PARAMETERS, parameter_threshold
from gearengine.homoclinic.verdict import applicability
from gearengine.model.aliases import get_alias
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.frequencies import poincare_period
from gearengine.model.params import GearParams, request_config
from gearengine.systems.spur_pair.laws import melnikov_cubic

MAX_DESIGNS = 10_000
"""Largest number of designs in one POST /v1/melnikov/batch."""

_PARAMETER_OF = {"transmission_error": "F_e1", "stiffness": "k_p1", "torque": "F_p1"}


class Margin(TypedDict):
    """Signed distance of a control parameter to its nearest critical value (null if none)."""

    margin: float | None
    relative_margin: float | None


class BatchVerdict(TypedDict):
    """One design's verdict: chaos possible (null: criterion not applicable) and margins."""

    chaos_possible: bool | None
    margins: dict[str, Margin]


class MelnikovBatchRequest(BaseModel):
    """``{"designs": [params, ...]}``: verdicts and margins of up to MAX_DESIGNS designs."""

    model_config = request_config({"designs": [PAPER_SECTION_41]})

    designs: list[GearParams] = Field(
        min_length=1,
        max_length=MAX_DESIGNS,
        description=f"Dimensionless parameters of Eq. (9), one per design (1 to {MAX_DESIGNS}).",
        examples=[[PAPER_SECTION_41]],
    )
    mean_load: MeanLoad = Field(
        "unperturbed",
        description="Where the mean force goes, as in POST /v1/melnikov (unperturbed: null "
        "verdicts where |F_m| >= F_crit).",
    )


class MelnikovBatchResult(BaseModel):
    """Per design, in request order: chaos possible and the margin of F_e1, mu, k_p1, F_p1."""

    model_config = ConfigDict(frozen=True)

    results: list[BatchVerdict] = Field(
        description="chaos_possible (null: criterion not applicable) and margins[parameter] = "
        "{margin, relative_margin} as in the thresholds of POST /v1/melnikov (null: no critical "
        "value)."
    )


def _margin(
    parameter: str, value: float, critical: Sequence[float], no_chaos: Sequence[Sequence]
) -> Margin:
    """``margins.signed_margin``: positive on the safe side (null without critical value)."""
    _, margin, rel = signed_margin(parameter, value, critical, no_chaos)
    return {"margin": margin, "relative_margin": rel}


NO_MARGIN: Margin = {"margin": None, "relative_margin": None}


@numba.njit(cache=True, nogil=True)
def _one_loop(kind, freq, amp, system, s):  # pragma: no cover - compiled
    """(status, chaos, H, R) of ``_simple`` on homoclinic branch s alone."""
    au = damping_unit(system, s)
    bu = unit_coefficient(kind, freq, system, s)
    if not (math.isfinite(au) and abs(au) < 1e150 and math.isfinite(bu) and abs(bu) < 1e150):
        return 1, False, np.nan, np.nan
    big_a, big_b = au * system[MU], bu * amp
    chaos = big_a - abs(big_b) < 0.0 < big_a + abs(big_b)
    if abs(big_a) < NEGLIGIBLE or abs(au) < NEGLIGIBLE or abs(bu) < NEGLIGIBLE:
        return 2, chaos, np.nan, np.nan
    h = -big_a / abs(bu)
    if not (math.isfinite(h) and h != 0.0):
        return 2, chaos, np.nan, np.nan
    r = np.nan
    if abs(big_b) >= NEGLIGIBLE:
        rj = -(0.0 + abs(big_b)) / au
        if not math.isfinite(rj):
            return 2, chaos, h, np.nan
        if rj != 0.0:
            r = rj
    return 0, chaos, h, r


@numba.njit(cache=True, nogil=True)
def _simple(terms, systems):  # pragma: no cover - compiled
    """Per design j: (status, chaos, amplitude critical H, mu critical R) of the one-term
    packed form (``homoclinic.terms``) column ``terms[:, j]`` on ``systems[j]``.

    Branch s keeps one sign for |F_1| <= H_s and for mu >= R_s; neither branch changes sign on
    the intersection, so H = min_s H_s and R = max_s R_s (the branches are alike for F_m = 0).
    status 0: closed forms valid (critical F_1 = -/+H unless H is NaN, mu critical R unless NaN);
    1: not applicable (M overflows, as ``verdict.applicability``); 2: take the per-design path.
    """
    n = terms.shape[1]
    status = np.zeros(n, dtype=np.int8)
    chaos = np.zeros(n, dtype=np.bool_)
    h, r = np.full(n, np.nan), np.full(n, np.nan)
    for j in range(n):
        kind = int(terms[KIND_ROW, j])
        freq = terms[HARMONIC, j] * terms[FUNDAMENTAL, j]
        worst = 0
        for s in (1.0, -1.0):
            st, ch, hs, rs = _one_loop(kind, freq, terms[AMPLITUDE, j], systems[j], s)
            worst = 1 if st == 1 or worst == 1 else max(worst, st)
            chaos[j] = chaos[j] or ch
            if not math.isnan(hs):
                h[j] = hs if math.isnan(h[j]) else min(h[j], hs)
            if not math.isnan(rs):
                r[j] = rs if math.isnan(r[j]) else max(r[j], rs)
        status[j] = worst
    return status, chaos, h, r


def _simple_row(p: GearParams) -> str | None:
    """The excitation's name when ``p`` has one excitation with at most one harmonic."""
    given = [(name, exc) for name, exc in p.excitations()]
    if len(given) != 1 or len(given[0][1].harmonics) > 1 or p.damping == 0.0:
        return None
    return given[0][0]


def design_verdict(p: GearParams, mean_load: MeanLoad = "unperturbed") -> BatchVerdict:
    """One design on the full path: ``melnikov``'s verdict and parameter thresholds."""
    a, c, _, units = applicability(p, mean_load=mean_load)
    if units is None:
        return {
            "chaos_possible": None,
            "margins": {q: NO_MARGIN for q in CONTROL_PARAMETERS},
        }
    chaos, period = False, poincare_period(p)
    for br in BRANCH_SIGN:
        ext = active_only(units[br], p).extrema(period)
        chaos = chaos or ext.minimum.value < 0.0 < ext.maximum.value
    margins: dict[str, Margin] = {}
    for q in CONTROL_PARAMETERS:
        t = parameter_threshold(p, q, a, c, coefs=units)
        margins[q] = {"margin": t.margin, "relative_margin": t.relative_margin}
    return {"chaos_possible": chaos, "margins": margins}


def melnikov_batch(
    designs: Sequence[GearParams], mean_load: MeanLoad = "unperturbed"
) -> list[BatchVerdict]:
    """Verdict and control-parameter margins of every design, in order.

    Equal to ``melnikov(p).chaos_possible`` and ``melnikov(p).thresholds[q].margin`` /
    ``relative_margin`` for q in F_e1, mu, k_p1, F_p1 (closed-form coefficients). Single-excitation
    designs run together in one compiled pass; the others one by one (see the module docstring).
    """
    out: list[BatchVerdict | None] = [None] * len(designs)
    packs, where = [], []
    for i, p in enumerate(designs):
        simple = _simple_row(p)
        a, c, _ = melnikov_cubic(p.backlash)
        fm = loop_load(p, mean_load)
        if simple is None or not saddle_loop(a, c, fm):
            out[i] = design_verdict(p, mean_load)
            continue
        packs.append(packed_terms(p, a, c, fm, inactive=True))
        where.append((i, _PARAMETER_OF[simple]))
    if packs:
        terms = np.concatenate([q.terms for q in packs], axis=1)
        systems = np.stack([q.system for q in packs])
        status, chaos, h, r = _simple(terms, systems)
        for k, (i, own) in enumerate(where):
            verdict = _simple_verdict(designs[i], own, status[k], chaos[k], h[k], r[k])
            out[i] = design_verdict(designs[i], mean_load) if verdict is None else verdict
    return out  # type: ignore[return-value]


def _simple_verdict(p, own, status, chaos, h, r) -> BatchVerdict | None:
    """The verdict of a one-excitation design from the compiled closed forms; None to take the
    per-design path."""
    if status == 2:
        return None
    if status == 1:
        return {
            "chaos_possible": None,
            "margins": {q: NO_MARGIN for q in CONTROL_PARAMETERS},
        }
    amplitude = float(get_alias(p, own))
    mu = float(p.damping)
    margins: dict[str, Margin] = {q: NO_MARGIN for q in CONTROL_PARAMETERS}
    if not math.isnan(h):  # neither branch changes sign for |F_1| <= H (Eq. 23)
        margins[own] = _margin(own, amplitude, [-float(h), float(h)], [(-float(h), float(h))])
    if not math.isnan(r):  # nor for mu >= R (Eq. 24)
        margins["mu"] = _margin("mu", mu, [float(r)], [(float(r), None)])
    return {"chaos_possible": bool(chaos), "margins": margins}


def warm_up() -> None:
    """Load (or compile) every Melnikov kernel once: a two-excitation verdict and a batch."""
    from gearengine.homoclinic.verdict import melnikov

    two = GearParams.model_validate(
        {
            **PAPER_SECTION_41,
            "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.1}]},
        }
    )
    melnikov(two)
    melnikov_batch([GearParams.model_validate(PAPER_SECTION_41), two])
