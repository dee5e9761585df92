"""The project's own simulated gear responses, read as recordings (issue 33): the paper's
periodic 1T (F_e = 0.1), periodic 4T (0.23) and chaotic (0.25) cases, with and without 25 dB of
sensor noise; the chaotic exponent within 30 % of the simulation's Benettin LLE."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearengine.numerics.runs import history_stride, integrate
from gearengine.numerics.settings import SimulationSettings
from gearengine.rig import signal
from gearengine.signals.lyapunov import benettin
from gearengine.systems.spur_pair.forcing import step_plan
from tests._gear_cases import paper

RATE = 20000.0
"""Sample rate [Hz] the simulated record is read at: one kept sample per 1/RATE s sets the
time scale, 50 samples per forcing period (the mesh period: 400 Hz)."""
TEETH = 18


def recording(fe: float, snr_db: float | None) -> tuple[np.ndarray, float, float, float]:
    """(x samples, mesh frequency [Hz], Benettin LLE [1/s], omega_n [rad/s]) of the paper's
    case at ``fe``, 500 + 500 periods, with white sensor noise at ``snr_db`` (None: none)."""
    params, settings = paper(fe), SimulationSettings()
    run = integrate(params, settings, settings.starts()[0])
    plan = step_plan(params, settings.steps_per_period)
    stride = history_stride(settings, plan.steps)
    omega_n = stride * plan.h * RATE  # tau per second
    mesh_hz = RATE / (plan.steps / stride)
    lle = benettin(run.logs, plan.period).lle * omega_n
    x = run.hx.copy()
    if snr_db is not None:
        rng = np.random.default_rng(25)
        x += rng.normal(size=x.size) * x.std() * 10.0 ** (-snr_db / 20.0)
    return x, mesh_hz, lle, omega_n


def read(x: np.ndarray, mesh_hz: float):  # type: ignore[no-untyped-def]
    return signal(x, RATE, speed=2.0 * math.pi * mesh_hz / TEETH, teeth=TEETH,
                  quantity="displacement", unit="um")  # fmt: skip


@pytest.mark.parametrize("snr", [None, 25.0])
@pytest.mark.parametrize(("fe", "period"), [(0.1, 1), (0.23, 4)])
def test_periodic_gear_responses_are_periodic(fe: float, period: int, snr: float | None) -> None:
    x, mesh_hz, lle, _ = recording(fe, snr)
    assert lle < 0.0
    r = read(x, mesh_hz)
    assert r.verdict == "periodic", r.summary
    assert r.periodicity is not None and r.periodicity.cycles == period
    assert r.periodicity.seconds == pytest.approx(period / mesh_hz)
    assert r.spectrum.lines[0].label == "mesh harmonic 1" or period > 1


@pytest.mark.parametrize("snr", [None, 25.0])
def test_chaotic_gear_response_is_chaotic_with_the_simulations_exponent(
    snr: float | None,
) -> None:
    x, mesh_hz, lle, _ = recording(0.25, snr)
    assert lle > 0.0
    r = read(x, mesh_hz)
    assert r.verdict == "chaotic", r.summary
    assert r.zero_one is not None and r.zero_one.k > 0.9
    assert r.zero_one.series == "one sample per mesh period"
    ly = r.lyapunov
    assert ly is not None and ly.per_second is not None
    assert ly.per_second == pytest.approx(lle, rel=0.30)
    assert ly.per_mesh_period == pytest.approx(ly.per_second / mesh_hz)
    assert ly.per_revolution == pytest.approx(ly.per_second * TEETH / mesh_hz)


def test_a_model_that_disagrees_with_the_rig_is_swept_over_its_uncertain_quantities() -> None:
    """The README's design (periodic at this speed) beside the chaotic recording: the model
    disagrees, and each uncertain quantity is tried halved and doubled."""
    from gearengine.model.design import EXAMPLE_DESIGN

    x, mesh_hz, _, _ = recording(0.25, None)
    r = signal(x, RATE, speed=2.0 * math.pi * mesh_hz / TEETH, design=EXAMPLE_DESIGN)
    assert r.verdict == "chaotic" and r.model is not None
    assert r.model.classification == "periodic" and r.model.agrees is False
    tried = {(t.quantity, t.factor): t for t in r.model.sweep}
    assert set(tried) == {(q, f) for q in ("damping", "half_backlash", "transmission_error")
                          for f in (0.5, 2.0)}  # fmt: skip
    assert tried[("damping", 0.5)].value == "0.025"
    assert tried[("half_backlash", 2.0)].value == "100 um"
    assert tried[("transmission_error", 0.5)].value == "2.5 um"
    assert all(t.matches_signal == (t.classification == "chaotic") for t in r.model.sweep)
    assert "disagrees with the signal (chaotic)" in r.model.summary
