"""The gears that will be built: samples of a design's tolerances, their verdicts, and the
probability of each outcome with its interval.

Each tolerance of ``design.tolerances`` (``model.tolerances``) becomes a ``Variable``: a field
path and the inverse CDF of its distribution (scipy.stats: ``uniform``, ``truncnorm`` at the
field's physical bounds, ``triang``). Samples are points of a scrambled Sobol sequence
(scipy.stats.qmc, seeded: the same seed gives the same samples), or with sensitivity the
Saltelli design of SALib built on it (``studies.robustness.sensitivity``), mapped through the
inverse CDFs. Every sample is a full design, re-validated and converted as a single analysis of it
would be (``model.fields.design_with``), at every operating point of the request.

A probability is k of n samples with the Clopper-Pearson 95 % interval
(``scipy.stats.binomtest(...).proportion_ci(method="exact")``): exact for independent samples and
conservative for randomised QMC, whose error is smaller than independent sampling's.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pydantic import ValidationError
from scipy import stats
from scipy.stats import qmc

from gearengine.model.design import ACCURACY_FIELD, BACKLASH_FIELD, Design, TransmissionError
from gearengine.model.errors import InputError
from gearengine.model.fields import design_with, si_value
from gearengine.model.reduction import half_backlash_band
from gearengine.model.standards import iso1328
from gearengine.model.tolerances import Distribution, Normal, Triangular, Uniform

BOUNDS: dict[str, tuple[float, float]] = {
    "damping_ratio": (0.0, 1.0),
    "phase": (-math.inf, math.inf),
    "profile_shift": (-1.0, 2.0),
}
"""Physical bounds of a field by the last name of its path; every other field is >= 0."""


def bounds(path: str) -> tuple[float, float]:
    """(low, high) physical bounds of the field at ``path`` (truncation of a normal)."""
    return BOUNDS.get(path.rsplit(".", 1)[-1], (0.0, math.inf))


@dataclass(frozen=True)
class Variable:
    """One toleranced field: its path, its distribution in words, and u -> value (SI)."""

    path: str
    words: str
    ppf: Callable[[np.ndarray], np.ndarray]
    label: str = ""
    """How sentences name it ("profile accuracy (ISO 1328 class 7)"); default: the path."""

    @property
    def name(self) -> str:
        return self.label or self.path


def tolerance_error(field: str, message: str) -> InputError:
    """A refused tolerance: the field is the path inside ``design.tolerances``."""
    path = f"design.tolerances{'.' if field else ''}{field}"
    return InputError(path, message, ("design", "tolerances", field) if field else None)


def base_design(design: Design) -> Design:
    """The design the samples vary, without its tolerances (each sample is one built design);
    with an accuracy class and no transmission error, a mesh-frequency harmonic is added for
    the class to set."""
    update: dict[str, object] = {"tolerances": None}
    tol = design.tolerances
    if tol is not None and tol.accuracy is not None and design.transmission_error is None:
        update["transmission_error"] = TransmissionError.model_validate(
            {"harmonics": [{"amplitude": 0.0}]}
        )
    return design.model_copy(update=update)


def _value(design: Design, path: str, value: object, what: str) -> float:
    try:
        return si_value(design, path, value)
    except (KeyError, IndexError, TypeError):
        raise tolerance_error(path, "the design has no such field") from None
    except ValidationError as exc:
        reason = "; ".join(e["msg"] for e in exc.errors(include_url=False))
        raise tolerance_error(
            path, f"{what} {value!r} is outside the field's range: {reason}"
        ) from None


def _variable(design: Design, path: str, dist: Distribution) -> Variable:
    lo_b, hi_b = bounds(path)
    if isinstance(dist, Uniform):
        lo, hi = (_value(design, path, v, "the bound") for v in dist.uniform)
        if not lo < hi:
            raise tolerance_error(path, "uniform: give [low, high] with low < high")
        return Variable(path, f"uniform on [{lo:.6g}, {hi:.6g}]", stats.uniform(lo, hi - lo).ppf)
    if isinstance(dist, Triangular):
        lo, mode, hi = (_value(design, path, v, "the value") for v in dist.triangular)
        if not lo <= mode <= hi or not lo < hi:
            raise tolerance_error(path, "triangular: give [low, mode, high], low <= mode <= high")
        shape = stats.triang((mode - lo) / (hi - lo), loc=lo, scale=hi - lo)
        return Variable(path, f"triangular [{lo:.6g}, {mode:.6g}, {hi:.6g}]", shape.ppf)
    assert isinstance(dist, Normal)
    mean = _value(design, path, dist.normal.mean, "the mean")
    if not lo_b <= mean <= hi_b:
        raise tolerance_error(path, f"the mean {mean:g} is outside the physical bounds")
    sd_given = dist.normal.sd
    if isinstance(sd_given, (int, float)) and sd_given <= 0:
        raise tolerance_error(path, "normal: the sd must be > 0")
    try:
        sd = si_value(design, path, sd_given)
    except (ValidationError, KeyError, IndexError, TypeError):
        raise tolerance_error(path, f"normal: the sd {sd_given!r} must be a value > 0") from None
    if not sd > 0:
        raise tolerance_error(path, "normal: the sd must be > 0")
    shape = stats.truncnorm((lo_b - mean) / sd, (hi_b - mean) / sd, loc=mean, scale=sd)
    for end in shape.ppf([1e-9, 1 - 1e-9]):  # the far ends of what is drawn must be designs
        _value(design, path, float(end), "the distribution reaches")
    return Variable(path, f"normal(mean {mean:.6g}, sd {sd:.6g}) truncated to "
                    f"[{lo_b:g}, {hi_b:g}]", shape.ppf)  # fmt: skip


def variables(design: Design) -> list[Variable]:
    """The toleranced fields of ``design`` in order: accuracy, backlash, then by path.

    Raises ``InputError`` (naming the field) for an unknown path, a distribution outside
    the field's physical bounds, sd <= 0, or an ISO 1328 input outside its range; the fields
    by path are read first (on the base design, each through its field's unit), then the
    standards' tolerances.
    """
    tol = design.tolerances
    if tol is None:
        raise tolerance_error("", "the design has no tolerances")
    base, out = base_design(design), []
    fields = [_variable(base, path, dist) for path, dist in tol.fields().items()]
    if tol.accuracy is not None:
        grade = tol.accuracy.tolerance_class
        try:
            e_max = iso1328.pair_te_bound(grade, design.driver, design.driven)
        except InputError as exc:
            raise tolerance_error("accuracy", exc.message) from None
        out.append(Variable(ACCURACY_FIELD, f"ISO 1328 class {grade}: mesh-frequency TE "
                            f"uniform on [0, {e_max * 1e6:.3g} um]",
                            stats.uniform(0.0, e_max).ppf,
                            f"profile accuracy (ISO 1328 class {grade})"))  # fmt: skip
    if tol.backlash is not None:
        lo, hi = half_backlash_band(design, tol.backlash.min, tol.backlash.max)
        band = f"{tol.backlash.min * 1e6:.4g}-{tol.backlash.max * 1e6:.4g} um"
        words = (
            f"backlash band {band}: half backlash uniform on [{lo * 1e6:.4g}, {hi * 1e6:.4g}] um"
        )
        label = f"backlash (band {band})"
        out.append(Variable(BACKLASH_FIELD, words, stats.uniform(lo, hi - lo).ppf, label))
    out += fields
    if not out:
        raise tolerance_error("", "give at least one tolerance")
    return out


def sobol_points(dimension: int, n: int, seed: int) -> np.ndarray:
    """``n`` points of the scrambled Sobol sequence in [0, 1)^dimension (scipy.stats.qmc,
    ``seed``), shape (n, dimension)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # n not a power of 2: balance is lost
        return qmc.Sobol(dimension, scramble=True, seed=seed).random(n)


def sample_values(variables: list[Variable], unit: np.ndarray) -> list[dict[str, float]]:
    """Each row of ``unit`` (shape (n, len(variables))) as field values (SI) by path."""
    columns = [v.ppf(unit[:, j]) for j, v in enumerate(variables)]
    return [
        {v.path: float(columns[j][i]) for j, v in enumerate(variables)} for i in range(len(unit))
    ]


def sample_design(base: Design, values: dict[str, float]) -> Design:
    """The built design of one sample: ``base`` with the sampled values, re-validated."""
    return design_with(base, values)


def probability(k: int, n: int) -> dict[str, object]:
    """k of n with its Clopper-Pearson 95 % interval."""
    if n == 0:
        return {"value": None, "interval": None, "count": 0, "samples": 0}
    return {"value": k / n, "interval": clopper_pearson(k, n), "count": k, "samples": n}


def clopper_pearson(k: int, n: int, confidence: float = 0.95) -> list[float]:
    """The exact (Clopper-Pearson) two-sided interval [low, high] of a proportion, k of n > 0
    samples, at ``confidence`` (``scipy.stats.binomtest(...).proportion_ci``)."""
    ci = stats.binomtest(k, n).proportion_ci(confidence, method="exact")
    return [float(ci.low), float(ci.high)]


def samples_to_prove(limit: float, confidence: float = 0.95) -> int | None:
    """The fewest samples n that can show P <= ``limit``: with 0 events the two-sided
    Clopper-Pearson upper bound is 1 - ((1 - confidence)/2)^(1/n) (``probability``), at or
    below ``limit`` from n = ln((1 - confidence)/2) / ln(1 - limit) on (368 for 1 %, 74 for
    5 %); None for a zero limit, which no count proves."""
    if limit <= 0.0:
        return None
    if limit >= 1.0:
        return 1
    tail = (1.0 - confidence) / 2.0
    n = max(1, math.ceil(math.log(tail) / math.log1p(-limit)))
    while 1.0 - tail ** (1.0 / n) > limit:  # rounding of the logarithms
        n += 1
    return n
