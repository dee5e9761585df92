"""Documented example designs (the OpenAPI examples, the README, the tests)."""

from __future__ import annotations

PAPER_SECTION_41 = {
    "damping": 0.07,
    "mean_force": 0.01,
    "backlash": {"model": "cubic", "a": 0.1667, "c": 0.1667},
    "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2, "phase": 0.0}]},
}
"""The paper's section 4.1 design at F~_e1 = 0.2 (Fig. 6), dimensionless parameters of Eq. (9)."""
