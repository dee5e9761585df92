"""Which tolerance matters: Sobol first-order and total indices, by SALib.

The samples of a sensitivity study are SALib's Saltelli design (``SALib.sample.sobol``, scrambled,
seeded; without second-order terms: N (D + 2) rows for N base samples and D toleranced fields),
on the unit cube, mapped to the fields by ``studies.robustness.tolerances``. Rows 0, D + 2,
2 (D + 2), ... are the base matrix A: N samples of the joint distribution, on which the
probabilities are counted. The indices come from ``SALib.analyze.sobol.analyze`` (Saltelli
2010 / Jansen estimators; intervals by bootstrap), nothing here estimates them:

* first-order S_i: the share of the output's variance explained by field i alone;
* total S_Ti: its share including every interaction with the other fields.

Saltelli, A. et al. (2010), "Variance based sensitivity analysis of model output. Design and
estimator for the total sensitivity index", Comput. Phys. Commun. 181, 259-270.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from SALib.analyze import sobol as sobol_analysis
from SALib.sample import sobol as sobol_sample


def _problem(dimension: int) -> dict[str, object]:
    return {
        "num_vars": dimension,
        "names": [f"u{j}" for j in range(dimension)],
        "bounds": [[0.0, 1.0]] * dimension,
    }


def saltelli_points(dimension: int, n: int, seed: int) -> np.ndarray:
    """The Saltelli design on [0, 1)^dimension for ``n`` base samples, shape
    (n (dimension + 2), dimension)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # SALib warns for n not a power of 2
        return sobol_sample.sample(
            _problem(dimension), n, calc_second_order=False, scramble=True, seed=seed
        )


def base_rows(n_rows: int, dimension: int) -> list[int]:
    """Rows of the base matrix A in a Saltelli design of ``n_rows`` rows."""
    return list(range(0, n_rows, dimension + 2))


MIN_EVENTS = 10
"""Least number of samples with, and without, a yes/no outcome for its indices: with fewer, the
estimators share out the variance of a handful of samples (indices of 0 or 2, meaningless)."""


def bootstrap_seed(seed: int) -> int:
    """The seed SALib's bootstrap intervals get for the request's ``seed``: SALib seeds them
    only when ``if seed:`` holds, so seed 0 left them to numpy's global generator (one seed, two
    error bars: "90 % +- 16 %" then "+- 15 %"); 0 becomes 2**32, a seed no request gives (they
    stop at 2**32 - 1), and every other seed is itself."""
    return seed or 2**32


def indices(names: list[str], y: np.ndarray, seed: int) -> dict[str, dict[str, float]] | None:
    """Sobol first-order and total indices of output ``y`` (one value per Saltelli row) for the
    fields ``names``, with their 95 % bootstrap half-widths; None when ``y`` does not vary, has
    undefined values, or is a yes/no outcome seen (or missed) fewer than ``MIN_EVENTS`` times."""
    y = np.asarray(y, dtype=float)
    if not np.all(np.isfinite(y)) or float(np.var(y)) == 0.0:
        return None
    if np.all((y == 0.0) | (y == 1.0)) and min(y.sum(), (1.0 - y).sum()) < MIN_EVENTS:
        return None
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        s = sobol_analysis.analyze(_problem(len(names)), y, calc_second_order=False,
                                   seed=bootstrap_seed(seed), print_to_console=False)  # fmt: skip

    def clean(x: float) -> float | None:
        return None if not math.isfinite(x) else round(float(x), 4)

    return {
        name: {
            "first": clean(s["S1"][j]),
            "total": clean(s["ST"][j]),
            "first_conf": clean(s["S1_conf"][j]),
            "total_conf": clean(s["ST_conf"][j]),
        }
        for j, name in enumerate(names)
    }


def ranked(output: str, table: dict[str, dict[str, float]] | None, labels: dict[str, str]) -> str:
    """The indices of one output in plain words, largest total index first."""
    if table is None:
        return (
            f"{output}: too few samples differ (fewer than {MIN_EVENTS} either way, or none) "
            "to share out its variance"
        )
    order = sorted(table, key=lambda k: -(table[k]["total"] or 0.0))

    def pct(x: float | None) -> str:
        return f"{100 * min(max(x or 0.0, 0.0), 1.0):.0f} %"

    parts = [
        f"{labels.get(k, k)} explains {pct(table[k]['first'])} (with its interactions "
        f"{pct(table[k]['total'])} +- {pct(table[k]['total_conf'])})"
        for k in order
    ]
    return f"variance of {output}: " + "; ".join(parts)
