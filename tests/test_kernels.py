"""Kernels: forcing tables, step plan, 4th-order convergence, batch = single, gear_ref.c."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from gearengine.model.params import GearParams
from gearengine.numerics.simulation import SimulationSettings, simulate, simulate_batch
from gearengine.systems.spur_pair import kernels
from gearengine.systems.spur_pair.forcing import packed_forcing, step_plan
from gearengine.systems.spur_pair.laws import LAWS
from tests._gear_cases import gear_ref_binary, gear_ref_summary, paper

CUBIC = LAWS["cubic"].kernel_code

MULTI = GearParams.model_validate(
    {
        "damping": 0.1,
        "mean_force": 0.02,
        "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.05, "phase": 0.3}]},
        "transmission_error": {
            "frequency": 0.5,
            "harmonics": [
                {"amplitude": 0.1},
                {"amplitude": 0.0},
                {"amplitude": 0.02, "phase": 1.0},
            ],
        },
        "torque": {"frequency": 0.25, "harmonics": [{"amplitude": 0.03, "phase": -0.5}]},
    }
)


def _run(params: GearParams, N: int, n_trans: int, n_rec: int, table: bool = True) -> tuple:
    kc, fm, fc = packed_forcing(params)
    T = step_plan(params, 200).period
    return kernels.run_rk4(
        CUBIC, 0.1667, 0.1667, 0.0, params.damping, 0.01, 0.01, kc, fm, fc, table, T, N,
        n_trans, n_rec, 1, 1e6,
    )  # fmt: skip


def test_forcing_table_is_eq9_at_stage_times() -> None:
    plan = step_plan(MULTI, 50)
    assert plan.omega0 == pytest.approx(0.25)
    assert plan.steps == 200  # 50 per period of the fastest excitation (Omega_k = 1), 4 per T0
    Kt, Ft = kernels.forcing_table(plan.period, plan.steps, *packed_forcing(MULTI))
    t = np.arange(2 * plan.steps + 1) * plan.h / 2
    K = 1.0 + 2 * 0.05 * np.cos(t + 0.3)
    F = (
        0.02
        + 0.03 * np.cos(0.25 * t - 0.5)
        + 0.25 * 0.1 * np.cos(0.5 * t)
        + 2.25 * 0.02 * np.cos(1.5 * t + 1.0)
    )
    np.testing.assert_allclose(Kt, K, rtol=0, atol=1e-15)
    np.testing.assert_allclose(Ft, F, rtol=0, atol=1e-15)
    assert Kt[0] == pytest.approx(Kt[-1]) and Ft[0] == pytest.approx(Ft[-1])  # T0-periodic


def test_table_and_absolute_time_forcing_agree() -> None:
    a = _run(MULTI, 800, 0, 20, table=True)
    b = _run(MULTI, 800, 0, 20, table=False)
    np.testing.assert_allclose(a[0], b[0], rtol=0, atol=1e-10)
    np.testing.assert_allclose(a[2], b[2], rtol=0, atol=1e-9)


def test_rk4_state_and_lyapunov_converge_at_fourth_order() -> None:
    ref = _run(paper(0.2), 12800, 0, 8)
    errs_x, errs_l = [], []
    for N in (200, 400, 800):
        out = _run(paper(0.2), N, 0, 8)
        errs_x.append(math.hypot(out[8] - ref[8], out[9] - ref[9]))
        errs_l.append(abs(out[2].sum() - ref[2].sum()))
    for errs in (errs_x, errs_l):
        orders = [math.log2(errs[i] / errs[i + 1]) for i in range(2)]
        assert all(3.6 < q < 4.4 for q in orders), (errs, orders)


def test_batch_equals_single_kernel() -> None:
    settings = SimulationSettings(
        transient_periods=100, record_periods=100, initial_states=[[0.01, 0.01], [1.5, -0.2]]
    )
    points = [paper(fe) for fe in (0.1, 0.22, 0.25)] + [paper(0.3, mu=0.12, we=0.7), MULTI]
    torque = {"frequency": 0.3, "harmonics": [{"amplitude": 0.01}]}
    incommensurate = GearParams.model_validate({**paper(0.1).model_dump(), "torque": torque})
    points += [paper(0.1, model="piecewise"), incommensurate]
    batch = simulate_batch(points, settings)
    for p, b in zip(points, batch, strict=True):
        single = simulate(p, settings)
        assert b.classification == single.classification
        assert b.period == single.period
        assert b.lle == single.lle  # identical arithmetic: bit-for-bit
        assert b.final_state == single.worst_case.final_state
        assert b.poincare[-1] == single.poincare[-1]


def test_batch_marks_diverged_lane_and_keeps_others() -> None:
    bad = GearParams.model_validate(
        {
            "damping": 0.01,
            "backlash": {"model": "cubic", "a": -1.0, "c": -1.0},
            "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 20.0}]},
        }
    )
    settings = SimulationSettings(transient_periods=20, record_periods=20)
    out = simulate_batch([paper(0.1), bad, paper(0.2)], settings)
    assert [o.classification for o in out] == ["periodic", "diverged", "periodic"]
    assert out[1].lle is None and out[1].final_state is None
    assert out[2].lle == simulate(paper(0.2), settings).lle


@pytest.fixture(scope="module")
def gear_ref(tmp_path_factory: pytest.TempPathFactory) -> Path:
    exe = gear_ref_binary(tmp_path_factory.mktemp("gear_ref"))
    if exe is None:
        pytest.skip("gcc or gear_ref.c not available")
    return exe


@pytest.mark.parametrize(("fe", "table"), [(0.2, True), (0.25, True), (0.25, False)])
def test_matches_gear_ref_bit_for_bit(gear_ref: Path, fe: float, table: bool) -> None:
    opts = [] if table else ["--direct"]
    args = ["0.07", str(fe), "0.5", "0.01", "0", "1", "0", "1", "cubic", "200", "300", "300"]
    period, lle, x, v = gear_ref_summary(gear_ref, opts + args)
    out = _run(paper(fe), 200, 300, 300, table=table)
    assert np.cumsum(out[2])[-1] / (300 * 4 * math.pi) == pytest.approx(lle, rel=1e-9)
    assert (out[8], out[9]) == pytest.approx((x, v), rel=1e-11)
    r = simulate(paper(fe), SimulationSettings(transient_periods=300, record_periods=300))
    assert (r.period or 0) == period
