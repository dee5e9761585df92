"""Verdict on one response: periodic, chaotic, quasi-periodic or diverged.

* ``diverged``: |x| or |v| left ``DIVERGENCE_BOUND`` (or became non-finite).
* ``periodic``: a stroboscopic period n <= 64 was found.
* ``chaotic``: no period and the LLE is clearly positive: lle > 3 stderr and lle > LLE_FLOOR.
* ``quasi_periodic``: no period and the LLE is not clearly positive (~0, or negative when the
  period is longer than 64 or the transient is unfinished).
"""

from __future__ import annotations

from typing import Literal

DIVERGENCE_BOUND = 1.0e6
"""Bound on |x| and |v| beyond which the run stops as diverged."""
LLE_FLOOR = 1.0e-3
"""Smallest LLE (per unit time) called positive."""

Classification = Literal["periodic", "chaotic", "quasi_periodic", "diverged"]
SEVERITY: dict[str, int] = {"periodic": 0, "quasi_periodic": 1, "chaotic": 2, "diverged": 3}
"""Order of worst cases: diverged > chaotic > quasi_periodic > periodic."""


def classify(
    diverged: bool, period: int | None, lle: float | None, stderr: float | None
) -> Classification:
    """Classification of one run from its divergence flag, period and LLE (+ stderr)."""
    if diverged:
        return "diverged"
    if period is not None:
        return "periodic"
    if lle is not None and lle > LLE_FLOOR and (stderr is None or lle > 3.0 * stderr):
        return "chaotic"
    return "quasi_periodic"


def severity(classification: str, period: int | None) -> tuple[int, int]:
    """Sort key of a verdict: larger is worse (longer periods are worse among periodic)."""
    return SEVERITY[classification], period or 0
