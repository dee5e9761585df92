"""nolds.lyap_r cross-check of the Benettin exponent."""

from __future__ import annotations

import numpy as np

from gearengine.numerics.simulation import SimulationSettings, simulate
from gearengine.signals.nolds_check import first_decorrelation
from tests._gear_cases import paper

NOLDS = SimulationSettings(lyapunov_nolds=True)


def test_nolds_imports() -> None:
    import nolds

    assert callable(nolds.lyap_r)


def test_nolds_agrees_with_benettin_on_chaos() -> None:
    r = simulate(paper(0.25), NOLDS)
    assert r.nolds is not None and r.nolds.lle is not None and r.lle is not None
    assert 0.5 * r.lle < r.nolds.lle < 2.0 * r.lle
    period = r.forcing_period
    assert period is not None  # min_tsep is one forcing period, lag a quarter of it
    assert abs(r.nolds.min_tsep * r.nolds.sample_interval - period) < r.nolds.sample_interval
    assert r.nolds.lag == round(r.nolds.min_tsep / 4)


def test_nolds_on_exact_periodic_orbit_is_null_with_note() -> None:
    r = simulate(paper(0.2), NOLDS)
    assert r.nolds is not None and r.nolds.lle is None
    assert "exact periodic orbit, nolds returned -inf" in r.nolds.notes
    assert "Infinity" not in r.model_dump_json()


def test_decorrelation_lag_of_a_sine_is_a_quarter_period() -> None:
    x = np.sin(2 * np.pi * np.arange(4000) / 40)
    assert first_decorrelation(x) in (10, 11)
