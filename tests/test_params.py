"""The parameter model: validation, aliases, commensurability."""

from __future__ import annotations

import math

import pytest
from pydantic import ValidationError

from gearengine.model.aliases import ALIASES, get_alias, with_alias, with_aliases
from gearengine.model.frequencies import common_frequency, forcing_period
from gearengine.model.params import GearParams
from tests.conftest import PAPER_PARAMS

PAPER = {
    **PAPER_PARAMS,
    "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.0, "phase": 0.0}]},
    "torque": {"frequency": 0.1, "harmonics": [{"amplitude": 0.0, "phase": 0.0}]},
}
"""The paper's design with its zero stiffness and torque excitations written out."""


def test_public_json_contract_round_trips() -> None:
    p = GearParams.model_validate(PAPER)
    assert GearParams.model_validate(p.model_dump(mode="json")) == p
    assert p.active_frequencies() == [0.5]


@pytest.mark.parametrize(
    ("patch", "field"),
    [
        ({"damping": float("nan")}, "damping"),
        ({"damping": -0.1}, "damping"),
        ({"mean_force": float("inf")}, "mean_force"),
        ({"transmission_error": {"frequency": 0.0}}, "frequency"),
        ({"backlash": {"model": "piecewise", "alpha": 1.0}}, "alpha"),
        ({"backlash": {"model": "quartic"}}, "backlash"),
        ({"torque": {"frequency": 1.0, "harmonics": [{"amplitude": 0.0}] * 33}}, "harmonics"),
        ({"speed": 3}, "speed"),
    ],
)
def test_bad_input_is_refused_naming_the_field(patch: dict, field: str) -> None:
    with pytest.raises(ValidationError) as err:
        GearParams.model_validate({**PAPER, **patch})
    locs = [".".join(str(p) for p in e["loc"]) for e in err.value.errors()]
    assert any(field in loc for loc in locs), locs


def test_aliases_read_and_write_first_harmonics() -> None:
    p = GearParams.model_validate(PAPER)
    assert {k: get_alias(p, k) for k in ALIASES} == {
        "mu": 0.07,
        "F_m": 0.01,
        "k_p1": 0.0,
        "F_e1": 0.2,
        "F_p1": 0.0,
        "Omega_k": 1.0,
        "Omega_e": 0.5,
        "Omega_p": 0.1,
    }
    q = with_aliases(p, {"F_e1": 0.25, "Omega_e": 0.7, "mu": 0.12})
    assert (get_alias(q, "F_e1"), get_alias(q, "Omega_e"), get_alias(q, "mu")) == (0.25, 0.7, 0.12)
    assert get_alias(p, "F_e1") == 0.2  # the original is untouched


def test_alias_on_absent_excitation() -> None:
    p = GearParams(damping=0.1)
    assert get_alias(p, "F_p1") == 0.0 and get_alias(p, "Omega_p") is None
    with pytest.raises(ValueError, match="Omega_p"):
        with_alias(p, "F_p1", 0.3)
    q = with_aliases(p, {"F_p1": 0.3, "Omega_p": 0.2})
    assert q.active_frequencies() == [0.2]
    with pytest.raises(ValueError, match="unknown parameter"):
        with_alias(p, "F_x9", 1.0)
    with pytest.raises(ValidationError):
        with_alias(p, "mu", -1.0)


@pytest.mark.parametrize(
    ("freqs", "omega0"),
    [
        ([0.5], 0.5),
        ([1.0, 0.5], 0.5),
        ([1.0, 0.1], 0.1),
        ([0.6, 0.4], 0.2),
        ([1.0, 1.0 / 3.0], 1.0 / 3.0),
        ([3.0, 2.0, 0.5], 0.5),
        ([1.0, 7.0 / 64.0], 1.0 / 64.0),
        ([1.0, 0.7 / 64.0], None),
        ([1.0, math.sqrt(2)], None),
        ([1.0, 1.0 / 67.0], None),
        ([], None),
    ],
)
def test_common_frequency(freqs: list[float], omega0: float | None) -> None:
    got = common_frequency(freqs)
    if omega0 is None:
        assert got is None
    else:
        assert got == pytest.approx(omega0, rel=1e-12)
        for f in freqs:
            assert f / got == pytest.approx(round(f / got), abs=1e-9)


def test_forcing_period() -> None:
    assert forcing_period([0.5]) == pytest.approx(4 * math.pi)
    assert forcing_period([]) is None
