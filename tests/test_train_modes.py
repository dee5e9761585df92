"""Modes of a gear train (issue 32): the worked example, scipy's eigen-solution of the physical
M and K, the stiff limit, and ROSS's torsional modes of a shaft-gear-shaft train."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from gearengine.model.design import Design
from gearengine.model.train import EXAMPLE_TRAIN
from gearengine.systems.gear_train.model import train_of
from gearengine.systems.gear_train.modes import eigen, mesh_energy_shares, modes
from tests._ross import import_ross

ROOT = Path(__file__).resolve().parents[1]
PAIR = json.loads((ROOT / "examples" / "design-direct.json").read_text())["design"]


def train_design(**changes: object) -> Design:
    """The example pair with the issue's train (``changes`` replace top-level train entries;
    None removes one)."""
    train = {**EXAMPLE_TRAIN, **changes}
    return Design.model_validate({**PAIR, "train": {k: v for k, v in train.items() if v}})


def test_worked_example_frequencies() -> None:
    """Issue 32: 298.5, 652.6, 1100.3, 1722.5, 2799.9 Hz in contact; stiff limit 739.3 Hz."""
    model, pair = train_of(train_design())
    found = modes(model, pair.natural_frequency_hz)
    got = [m.frequency_hz for m in found.modes]
    assert np.round(got, 1).tolist() == [298.5, 652.6, 1100.3, 1722.5, 2799.9]
    assert round(found.stiff_limit_hz, 1) == 739.3
    assert found.mesh_mode == 4  # the 2799.9 Hz mode holds the most mesh strain energy
    assert 0.5 < found.modes[4].mesh_energy_share < 0.6


@pytest.mark.parametrize("bearings", [True, False])
def test_frequencies_equal_scipy_eig_of_physical_matrices(bearings: bool) -> None:
    """The reduced eigenproblem equals scipy.linalg.eig(K, M) of the physical coordinates
    (angles and displacements, the free rotation as its zero eigenvalue) to 1e-6."""
    design = train_design() if bearings else train_design(bearings=None)
    model, _ = train_of(design)
    values = scipy.linalg.eig(model.stiffness(), model.mass, right=False)
    assert np.max(np.abs(values.imag)) == 0.0
    physical = np.sort(np.sqrt(np.abs(values.real)))
    assert physical[0] < 1e-6 * physical[1]  # the free rotation
    omega, shapes = eigen(model)
    assert omega.size == model.size - 1
    np.testing.assert_allclose(omega, physical[1:], rtol=1e-6)
    # each shape solves K phi = omega^2 M phi in the physical coordinates
    residual = model.stiffness() @ shapes - model.mass @ shapes * omega**2
    assert np.max(np.abs(residual)) < 1e-8 * np.max(np.abs(model.stiffness() @ shapes))


def test_stiff_limit_is_the_equivalent_pair() -> None:
    """Shafts and bearings 1e6 times stiffer: the lowest mode is the pair with I_a = I_m + I_p,
    I_b = I_g + I_l (739.3 Hz) and holds all the mesh strain energy."""
    model, pair = train_of(train_design())
    stiff = modes(model.stiffened(1e6), pair.natural_frequency_hz)
    first = stiff.modes[0]
    assert first.frequency_hz == pytest.approx(pair.natural_frequency_hz, rel=1e-5)
    assert stiff.mesh_mode == 0 and first.mesh_energy_share > 0.9999
    ia, ib, ra, rb = 6e-3, 3.8e-2, 0.03, 0.05
    m = ia * ib / (ib * ra**2 + ia * rb**2)
    assert pair.natural_frequency_hz == pytest.approx(math.sqrt(1e8 / m) / (2 * math.pi))


def test_mesh_energy_shares_and_damping() -> None:
    """Shares lie in [0, 1]; an undamped train has zero damping ratios; the shape of the
    mesh share is the strain energy k_m (w . phi)^2 / phi^T K phi."""
    design = train_design()
    model, _ = train_of(design)
    _, shapes = eigen(model)
    shares = mesh_energy_shares(model, shapes)
    assert np.all((shares >= 0.0) & (shares <= 1.0))
    train = json.loads(json.dumps(EXAMPLE_TRAIN))
    for part in (train["input_shaft"], train["output_shaft"], *train["bearings"].values()):
        part["damping_ratio"] = 0.0
    mesh = {**PAIR["mesh"], "damping_ratio": 0.0}
    undamped = Design.model_validate({**PAIR, "mesh": mesh, "train": train})
    m0, p0 = train_of(undamped)
    assert all(abs(m.damping_ratio) < 1e-9 for m in modes(m0, p0.natural_frequency_hz).modes)
    assert all(0.0 < m.damping_ratio < 0.2 for m in modes(model, 1.0).modes)


def test_torsional_modes_agree_with_ross() -> None:
    """ROSS (ross-rotordynamics) MultiRotor of two rotors, each one ShaftElement (Timoshenko
    beam, density 1e-3 kg/m^3: its own mass negligible) between a DiskElement (motor / load)
    and a GearElement (pinion / gear), coupled by the mesh stiffness, every node on a
    BearingElement of 1e13 N/m (lateral motion rigid). Its torsional frequencies equal the
    torsional train's (no bearings) within 1 %."""
    rs = import_ross()
    g = 79.3e9
    light = rs.Material(name="light_steel", rho=1e-3, E=2.6 * g, G_s=g)

    def shaft(k: float, length: float = 0.1):
        d = (32.0 * length * k / (g * math.pi)) ** 0.25  # k = G pi d^4 / (32 L)
        return rs.ShaftElement(L=length, idl=0.0, odl=d, material=light)

    def rotor(k, first, second):
        bearings = [rs.BearingElement(n=i, kxx=1e13, kyy=1e13, cxx=0.0) for i in (0, 1)]
        return rs.Rotor([shaft(k)], [first, second], bearings)

    im, ip, ig, il = 4e-3, 2e-3, 8e-3, 3e-2
    driving = rotor(
        3e4,
        rs.DiskElement(n=0, m=1.0, Id=im / 2, Ip=im),
        rs.GearElement(n=1, m=1.2, Id=ip / 2, Ip=ip, n_teeth=18, base_diameter=0.06),
    )
    driven = rotor(
        8e4,
        rs.GearElement(n=0, m=3.0, Id=ig / 2, Ip=ig, n_teeth=30, base_diameter=0.10),
        rs.DiskElement(n=1, m=1.0, Id=il / 2, Ip=il),
    )
    multi = rs.MultiRotor(driving, driven, coupled_nodes=(1, 0), gear_mesh_stiffness=1e8)
    ross_hz = np.sort(multi.run_modal(speed=0, num_modes=40).wn) / (2 * math.pi)
    model, pair = train_of(train_design(bearings=None))
    ours = [m.frequency_hz for m in modes(model, pair.natural_frequency_hz).modes]
    for f in ours:
        nearest = ross_hz[np.argmin(np.abs(ross_hz - f))]
        assert nearest == pytest.approx(f, rel=0.01), (f, ross_hz)
