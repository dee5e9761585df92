"""melnikov_batch against the full verdict, and POST /v1/melnikov/batch with its cap."""

from __future__ import annotations

import math
import random

import pytest
from fastapi.testclient import TestClient

from gearengine.homoclinic import melnikov, melnikov_batch
from gearengine.homoclinic.batch import MAX_DESIGNS
from gearengine.model.params import GearParams

PARAMETERS = ("F_e1", "mu", "k_p1", "F_p1")
KINDS = ("stiffness", "transmission_error", "torque")


def random_design(rng: random.Random) -> GearParams:
    """Mostly one-excitation designs (the compiled path), with every kind of exception mixed in:
    several excitations and harmonics, zero damping or amplitude, no saddle loop, piecewise law,
    a huge frequency (coefficients underflow)."""
    names = [rng.choice(KINDS)] if rng.random() < 0.7 else rng.sample(KINDS, rng.randint(1, 3))
    data: dict = {"damping": rng.choice([0.0, rng.uniform(0.001, 0.3)]) if rng.random() < 0.1
                  else rng.uniform(0.001, 0.3)}  # fmt: skip
    kind = rng.random()
    if kind < 0.05:
        data["backlash"] = {"model": "cubic", "a": -0.1, "c": 0.2}
    elif kind < 0.1:
        data["backlash"] = {"model": "piecewise", "alpha": rng.uniform(0.0, 0.5)}
    else:
        data["backlash"] = {
            "model": "cubic",
            "a": rng.uniform(0.05, 1.0),
            "c": rng.uniform(0.05, 1),
        }
    base = rng.choice([0.25, 0.5, 1.0])
    for name in names:
        n = 1 if rng.random() < 0.8 else rng.randint(0, 3)
        harmonics = [
            {"amplitude": 0.0 if rng.random() < 0.05 else rng.uniform(-1, 1),
             "phase": rng.uniform(-3, 3)}
            for _ in range(n)
        ]  # fmt: skip
        freq = base * rng.choice([1, 2]) if len(names) > 1 else rng.uniform(0.05, 2.5)
        if rng.random() < 0.01:
            freq = 900.0
        data[name] = {"frequency": freq, "harmonics": harmonics}
    return GearParams.model_validate(data)


def test_batch_equals_the_single_verdict() -> None:
    rng = random.Random(20240613)
    designs = [random_design(rng) for _ in range(400)]
    for p, got in zip(designs, melnikov_batch(designs), strict=True):
        full = melnikov(p, omega_scan=(0.5, 1.0, 2))
        assert got["chaos_possible"] == full.chaos_possible, p
        for q in PARAMETERS:
            t = full.thresholds.get(q)
            want = (None, None) if t is None else (t.margin, t.relative_margin)
            m = got["margins"][q]
            assert (m["margin"], m["relative_margin"]) == want, (p, q)


def test_batch_of_ten_thousand_single_excitation_designs_is_finite() -> None:
    rng = random.Random(1)
    designs = [
        GearParams.model_validate(
            {
                "damping": rng.uniform(0.01, 0.2),
                "transmission_error": {
                    "frequency": rng.uniform(0.1, 2.0),
                    "harmonics": [{"amplitude": rng.uniform(0.0, 0.5)}],
                },
            }
        )
        for _ in range(MAX_DESIGNS)
    ]
    results = melnikov_batch(designs)
    assert len(results) == MAX_DESIGNS
    for r in results[::97]:
        assert isinstance(r["chaos_possible"], bool)
        for m in r["margins"].values():
            assert m["margin"] is None or math.isfinite(m["margin"])


def test_batch_route_answers_in_order(client: TestClient) -> None:
    designs = [
        {"damping": 0.07, "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": f}]}}
        for f in (0.1, 0.3)
    ]
    r = client.post("/v1/melnikov/batch", json={"designs": designs})
    assert r.status_code == 200, r.text
    results = r.json()["results"]
    assert [x["chaos_possible"] for x in results] == [False, True]
    single = melnikov(GearParams.model_validate(designs[1])).thresholds["F_e1"]
    assert results[1]["margins"]["F_e1"]["margin"] == single.margin
    assert results[1]["margins"]["k_p1"] == {"margin": None, "relative_margin": None}


@pytest.mark.parametrize("count", [0, MAX_DESIGNS + 1])
def test_batch_route_refuses_beyond_the_cap_naming_the_field(
    client: TestClient, count: int
) -> None:
    r = client.post("/v1/melnikov/batch", json={"designs": [{"damping": 0.1}] * count})
    assert r.status_code == 422
    assert r.headers["content-type"] == "application/problem+json"
    assert "designs" in [e["path"] for e in r.json()["errors"]], r.json()
