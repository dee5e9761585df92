"""The method is honoured everywhere (issue #14 item 8), and the compiled Omega_e scan equals the
scan on the documents it replaces."""

from __future__ import annotations

import random

import pytest

from gearengine.homoclinic import coefficients as mk
from gearengine.homoclinic import thresholds as th
from gearengine.homoclinic.verdict import melnikov
from gearengine.model.params import GearParams
from tests.conftest import PAPER_PARAMS

PAPER = GearParams.model_validate({**PAPER_PARAMS, "mean_force": 0.0})
"""The paper's design without mean force."""


def test_quadrature_thresholds_use_quadrature_coefficients(monkeypatch: pytest.MonkeyPatch) -> None:
    """A stand-in 'quadrature' that doubles every sinusoid halves the F_e1 threshold and moves
    the critical frequencies: the thresholds and the scan follow the method."""
    closed = melnikov(PAPER)

    def doubled(*args: object) -> float:
        return 2.0 * mk.closed_form_coefficient(*args)

    fake = mk.CoefficientMethod(mk.damping_coefficient, doubled)
    monkeypatch.setitem(mk.METHODS, "quadrature", fake)
    quad = melnikov(PAPER, method="quadrature")
    assert quad.thresholds["F_e1"].critical_values == pytest.approx(
        [0.5 * v for v in closed.thresholds["F_e1"].critical_values], rel=1e-12
    )
    assert quad.thresholds["mu"].nearest == pytest.approx(2 * closed.thresholds["mu"].nearest)
    assert quad.thresholds["Omega_e"].critical_values != pytest.approx(
        closed.thresholds["Omega_e"].critical_values, rel=1e-3
    )
    assert any("quadrature" in n for n in quad.notes)


def test_quadrature_method_agrees_with_the_closed_form_everywhere() -> None:
    closed = melnikov(PAPER, omega_scan=(0.3, 1.5, 7))
    quad = melnikov(PAPER, method="quadrature", omega_scan=(0.3, 1.5, 7))
    assert quad.method == "quadrature"
    for name, t in closed.thresholds.items():
        assert quad.thresholds[name].critical_values == pytest.approx(t.critical_values, rel=1e-8)


def random_design(rng: random.Random) -> GearParams:
    names = rng.sample(["stiffness", "transmission_error", "torque"], rng.randint(1, 3))
    if "transmission_error" not in names:
        names.append("transmission_error")
    base = rng.choice([0.25, 0.5, 1.0])
    # a mean load below F_crit = 0.0642 of the paper's cubic: the loops are loaded and differ
    data: dict = {"damping": rng.uniform(0.0, 0.2), "mean_force": rng.uniform(-0.06, 0.06)}
    for name in names:
        harmonics = [
            {"amplitude": rng.uniform(-0.5, 0.5), "phase": rng.uniform(-3, 3)}
            for _ in range(rng.randint(1, 2))
        ]
        data[name] = {"frequency": base * rng.choice([1, 2, 3]), "harmonics": harmonics}
    if rng.random() < 0.2:
        data["torque"] = {"frequency": 0.1 * 2**0.5, "harmonics": [{"amplitude": 0.05}]}
    return GearParams.model_validate(data)


def test_compiled_scan_equals_the_scan_on_documents() -> None:
    rng = random.Random(7)
    a = c = 0.1667
    for _ in range(40):
        p = random_design(rng)
        value = p.transmission_error.frequency
        fm = p.mean_force
        fast = th._scan_compiled(p, a, c, fm, (0.05, 3.0, 30), value)
        slow = th._scan_python(p, a, c, (0.05, 3.0, 30), value, "closed_form", fm)
        assert fast is not None
        assert fast[0] == pytest.approx(slow[0], rel=1e-9, abs=1e-9), p
        assert len(fast[1]) == len(slow[1]), p


def test_single_sinusoid_scan_is_bit_for_bit_the_same() -> None:
    value = 0.5
    fast = th._scan_compiled(PAPER, 0.1667, 0.1667, 0.0, th.OMEGA_SCAN, value)
    slow = th._scan_python(
        PAPER, 0.1667, 0.1667, th.OMEGA_SCAN, value, "closed_form", PAPER.mean_force
    )
    assert fast == slow
