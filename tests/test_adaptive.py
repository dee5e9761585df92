"""Adaptive stopping (``systems.spur_pair.kernels.adaptive``, lengths counted in T0:
``physical_time`` false; the physical-time lengths are tests/test_physical.py's) against the
fixed-length run on a 40 x 40 subsample of the chaos map, the mesh-force extremes of the three
kernels, and the gate's --max-dynamic-factor rule."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gearengine.gate.envelope import envelope_report
from gearengine.gate.rules import Rules
from gearengine.model.params import GearParams
from gearengine.numerics.batch import simulate_batch
from gearengine.numerics.settings import SimulationSettings
from gearengine.studies.sweep import run_local, validated
from gearengine.studies.sweep.request import SweepRequest
from gearengine.systems.spur_pair import kernels
from gearengine.systems.spur_pair.forcing import packed_forcing, step_plan
from gearengine.systems.spur_pair.kernels.adaptive import (
    ADAPT_LLE_MIN_RECORD,
    ADAPT_SETTLE,
    ADAPT_WINDOW,
)
from gearengine.systems.spur_pair.laws import law
from tests.conftest import ROOT

LIGHT = {"transient_periods": 60, "record_periods": 60, "steps_per_period": 128}


def chaos_map(num: int) -> list[GearParams]:
    """The designs of examples/chaos-map.json on a num x num grid (first axis fastest)."""
    doc = json.loads((ROOT / "examples" / "chaos-map.json").read_text())
    doc.pop("settings")
    for axis in doc["axes"]:
        axis["num"] = num
    req = SweepRequest.model_validate(doc)
    g0, g1 = req.grids()
    a0, a1 = (a.parameter for a in req.axes)
    return [req.point({a0: x, a1: y}) for y in g1 for x in g0]


@pytest.fixture(scope="module")
def map_40() -> tuple[list, list]:
    points = chaos_map(40)
    adaptive = simulate_batch(points, SimulationSettings(physical_time=False))
    fixed = simulate_batch(points, SimulationSettings(adaptive=False))
    return adaptive, fixed


def test_adaptive_verdicts_agree_with_the_fixed_length_run(map_40: tuple[list, list]) -> None:
    adaptive, fixed = map_40
    same = sum((a.classification, a.period) == (f.classification, f.period)
               for a, f in zip(adaptive, fixed, strict=True))  # fmt: skip
    assert same >= 0.995 * len(fixed)
    assert all(f.periods_run == 1000 for f in fixed)
    stopped = [a for a in adaptive if a.periods_run < 1000]
    assert len(stopped) > len(adaptive) // 2  # most points settle early
    assert min(a.periods_run for a in stopped) >= ADAPT_SETTLE + ADAPT_WINDOW
    assert all(a.classification == "periodic" for a in stopped if a.periods_run <= 500)


def test_chaotic_points_stop_once_their_lle_is_known(map_40: tuple[list, list]) -> None:
    adaptive, fixed = map_40
    settings = SimulationSettings()
    chaotic = [(a, f) for a, f in zip(adaptive, fixed, strict=True)
               if f.classification == "chaotic"]  # fmt: skip
    assert len(chaotic) > 100
    early = [(a, f) for a, f in chaotic if a.periods_run < 1000]
    assert len(early) > len(chaotic) // 2
    within = 0
    for a, f in chaotic:
        if a.periods_run == 1000:  # not known before the end: the fixed-length run's numbers
            assert a.lle == f.lle and a.lle_stderr == f.lle_stderr and a.poincare == f.poincare
            continue
        assert a.classification == "chaotic" and a.periods_run >= 500 + ADAPT_LLE_MIN_RECORD
        assert a.lle_stderr <= max(settings.lle_stderr_abs, settings.lle_stderr_rel * a.lle)
        within += abs(a.lle - f.lle) <= 3.0 * a.lle_stderr
    assert within >= 0.99 * len(early)


def test_early_stopped_record_is_the_settled_window(map_40: tuple[list, list]) -> None:
    adaptive, fixed = map_40
    for a, f in zip(adaptive, fixed, strict=True):
        if a.periods_run <= 500:  # stopped in the transient by the periodic rule
            assert a.lle < 0 and a.lle == pytest.approx(f.lle, abs=0.02)
            assert len(a.poincare) == 64
            assert a.force_max == pytest.approx(f.force_max, rel=1e-3, abs=1e-6)
            assert a.force_min == pytest.approx(f.force_min, rel=1e-3, abs=1e-6)


def test_adaptive_needs_a_window_of_record() -> None:
    points = chaos_map(4)
    out = simulate_batch(
        points, SimulationSettings(transient_periods=100, record_periods=60, physical_time=False)
    )
    assert all(p.periods_run == 160 for p in out)


def test_mesh_force_extremes() -> None:
    (rest,) = simulate_batch(chaos_map(2)[:1], SimulationSettings())  # F_e1 = 0: at rest
    assert rest.force_max == pytest.approx(0.01, abs=1e-9)  # K f_h(x) = F_m
    assert rest.force_min == pytest.approx(0.01, abs=1e-9)
    p = chaos_map(5)[12]
    settings = SimulationSettings(transient_periods=50, record_periods=50, adaptive=False)
    (bp,) = simulate_batch([p], settings)
    plan = step_plan(p, settings.steps_per_period)
    lw = law(p)
    forcing = packed_forcing(p)
    out = kernels.run_rk4(lw.code, lw.a, lw.c, lw.alpha, p.damping, 0.01, 0.01, *forcing,
                          True, plan.period, plan.steps, 50, 50, 1, 1e6)  # fmt: skip
    assert (out[10], out[11]) == (bp.force_min, bp.force_max)  # same arithmetic, same steps
    # brute force from the recorded path: K(t) f_h(x) + 2 mu v at the step ends
    t = plan.period / plan.steps * np.arange(1, 50 * plan.steps + 1)
    kc = forcing[0]
    K = 1.0 + sum(kc[0, i] * np.cos(kc[1, i] * t + kc[2, i]) for i in range(kc.shape[1]))
    x, v = out[3], out[4]
    force = K * x * (lw.c * x * x - lw.a) + 2 * p.damping * v
    assert force.max() == pytest.approx(bp.force_max, rel=1e-12)
    assert force.min() == pytest.approx(bp.force_min, rel=1e-12)


def test_kink_kernel_mesh_force() -> None:
    p = GearParams.model_validate(
        {"damping": 0.05, "mean_force": 0.1, "backlash": {"model": "piecewise", "alpha": 0.0},
         "transmission_error": {"frequency": 0.8, "harmonics": [{"amplitude": 0.3}]}}
    )  # fmt: skip
    settings = SimulationSettings(transient_periods=30, record_periods=20, physical_time=False)
    (bp,) = simulate_batch([p], settings)
    assert bp.force_min is not None and bp.force_max > 0.1  # the mean force, exceeded
    lw = law(p)
    plan = step_plan(p, settings.steps_per_period)
    out = kernels.run_kink(lw.alpha, p.damping, 0.01, 0.01, *packed_forcing(p), plan.period,
                           plan.steps, 30, 20, 1, 1e6, True)  # fmt: skip
    assert (out[10], out[11]) == (bp.force_min, bp.force_max)
    x, v = out[3], out[4]  # brute force: K = 1 (no stiffness harmonics), f_h of Eq. (8)
    fh = np.where(x > 1, x - 1, np.where(x < -1, x + 1, 0.0))
    force = fh + 2 * p.damping * v
    assert force.max() == pytest.approx(bp.force_max, rel=1e-9, abs=1e-12)
    assert force.min() == pytest.approx(bp.force_min, rel=1e-9, abs=1e-12)


def design_sweep() -> dict:
    from gearengine.model.design import EXAMPLE_DESIGN

    axes = [{"parameter": "speed", "start": "500 rpm", "stop": "6000 rpm", "num": 3}]
    return {"design": EXAMPLE_DESIGN, "settings": LIGHT, "axes": axes}


def test_dynamic_factor_and_its_gate() -> None:
    result = run_local(validated(design_sweep()))
    for p in result.points:
        factor = p.physical["dynamic_factor"]
        assert factor.unit == "1"
        assert factor.value == pytest.approx(p.force_max / p.dimensionless["F_m"], rel=1e-9)
        assert factor.value >= 1.0 - 1e-9  # the mean force is reached or exceeded
    top = max(p.physical["dynamic_factor"].value for p in result.points)
    assert envelope_report(result, Rules(max_dynamic_factor=top)).passed
    report = envelope_report(result, Rules(max_dynamic_factor=top * 0.999))
    assert not report.passed
    assert {f.rule for f in report.failures} == {f"dynamic factor > {top * 0.999:g}"}
    assert all("dynamic_factor" not in w.level for w in report.windows)


def test_gate_option_max_dynamic_factor(tmp_path: Path) -> None:
    from gearengine.model.design import EXAMPLE_DESIGN

    good = tmp_path / "design.json"
    good.write_text(json.dumps({"design": EXAMPLE_DESIGN, "settings": LIGHT}))
    run = [sys.executable, "-m", "gearengine.cli", "check", str(good), "--speed", "500:6000",
           "--speed-points", "3"]  # fmt: skip
    out = subprocess.run([*run, "--max-dynamic-factor", "1.001"], cwd=ROOT, capture_output=True,
                         text=True, timeout=600)  # fmt: skip
    assert out.returncode == 1 and "dynamic factor > 1.001" in out.stdout, out.stdout + out.stderr
    assert "--max-dynamic-factor 1.001" in out.stdout
    out = subprocess.run([*run, "--max-dynamic-factor", "1e6"], cwd=ROOT, capture_output=True,
                         text=True, timeout=600)  # fmt: skip
    assert out.returncode == 0 and out.stdout.startswith("PASS"), out.stdout + out.stderr
