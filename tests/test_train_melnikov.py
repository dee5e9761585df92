"""Melnikov for a train (issue 32): the mesh-mode reduction's verdict when that mode holds >= 90 %
of the mesh strain energy, else not applicable with the reason."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from gearengine.homoclinic.train_reduction import mesh_mode, train_melnikov
from gearengine.homoclinic.verdict import melnikov
from gearengine.model.design import Design
from gearengine.model.train import EXAMPLE_TRAIN
from gearengine.systems.gear_train.model import train_of
from gearengine.systems.gear_train.modes import modes
from gearengine.systems.gear_train.system import train_system

ROOT = Path(__file__).resolve().parents[1]
PAIR = json.loads((ROOT / "examples" / "design-direct.json").read_text())["design"]
LIGHT = {**PAIR, "torque": "2 N*m", "transmission_error": {"harmonics": [{"amplitude": "20 um"}]}}
"""A lightly loaded pair whose Melnikov criterion applies (F_m below the critical load)."""


def test_shared_mesh_is_not_reduced() -> None:
    """The worked example's mesh mode holds 57 % of the mesh energy: not applicable, reason."""
    model, pair = train_of(Design.model_validate({**PAIR, "train": EXAMPLE_TRAIN}))
    answer = train_melnikov(train_system(model, pair))
    assert not answer.applicable and answer.melnikov is None
    assert "56.5%" in answer.reason and "90%" in answer.reason


def test_stiff_limit_reduction_is_the_pair() -> None:
    """Shafts and bearings 1e6 times stiffer: the reduction's Eq. (9) is the equivalent pair's
    (its Melnikov cubic), and so is its Melnikov verdict and every threshold."""
    model, pair = train_of(Design.model_validate({**LIGHT, "train": EXAMPLE_TRAIN}))
    answer = train_melnikov(train_system(model.stiffened(1e6), pair))
    assert answer.applicable and answer.mesh_energy_share > 0.9999
    reduced, params = answer.params, pair.params
    assert reduced.damping == pytest.approx(params.damping, rel=1e-4)
    assert reduced.mean_force == pytest.approx(params.mean_force, rel=1e-4)
    for name in ("stiffness", "transmission_error", "torque"):
        mine, theirs = getattr(reduced, name), getattr(params, name)
        assert mine.frequency == pytest.approx(theirs.frequency, rel=1e-4)
        for h, g in zip(mine.harmonics, theirs.harmonics, strict=True):
            assert h.amplitude == pytest.approx(g.amplitude, rel=1e-4)
    expected = melnikov(params)
    got = answer.melnikov
    assert expected.applicable and got.chaos_possible == expected.chaos_possible
    assert got.a == pytest.approx(1 / 6, rel=1e-4)
    assert expected.thresholds and set(got.thresholds) == set(expected.thresholds)
    for name, threshold in expected.thresholds.items():
        mine = got.thresholds[name]
        assert mine.critical_values == pytest.approx(threshold.critical_values, rel=1e-3)
        assert (mine.nearest is None) == (threshold.nearest is None)


def test_reduction_keeps_the_mesh_mode_frequency() -> None:
    """Shafts and bearings 100 times stiffer (share 96 %): the reduction's linear frequency in
    contact, s sqrt(1 + kappa) omega_n, is the train's mesh mode; its a is lowered by kappa."""
    model, pair = train_of(Design.model_validate({**LIGHT, "train": EXAMPLE_TRAIN}))
    stiff = model.stiffened(100.0)
    system = train_system(stiff, pair)
    _, s, share = mesh_mode(system)
    answer = train_melnikov(system)
    assert answer.applicable and 0.9 <= share < 0.99
    kappa = (1 - share) / share
    found = modes(stiff, pair.natural_frequency_hz)
    mesh_hz = found.modes[found.mesh_mode].frequency_hz
    assert s * math.sqrt(1 + kappa) * pair.natural_frequency_hz == pytest.approx(mesh_hz, rel=1e-9)
    assert answer.params.backlash.a == pytest.approx(1 / 6 - kappa, rel=1e-9)
