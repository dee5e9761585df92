"""Piecewise backlash law (Eq. 8): kink-splitting RK4 against step halving, scipy and gear_ref.c."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearengine.model.params import GearParams
from gearengine.numerics.simulation import SimulationSettings, simulate
from gearengine.signals.lyapunov import benettin
from gearengine.systems.spur_pair import kernels
from gearengine.systems.spur_pair.forcing import packed_forcing, step_plan
from gearengine.systems.spur_pair.laws import LAWS
from tests._gear_cases import gear_ref_binary, gear_ref_summary, paper, scipy_run

PIECEWISE = LAWS["piecewise"].kernel_code


def _kink(params: GearParams, N: int, n_trans: int, n_rec: int, x0: float = 0.01) -> tuple:
    kc, fm, fc = packed_forcing(params)
    T = step_plan(params, 200).period
    alpha = params.backlash.alpha
    return kernels.run_kink(
        alpha, params.damping, x0, 0.01, kc, fm, fc, T, N, n_trans, n_rec, 1, 1e6
    )  # fmt: skip


def _plain(params: GearParams, N: int, n_trans: int, n_rec: int, x0: float = 0.01) -> tuple:
    kc, fm, fc = packed_forcing(params)
    T = step_plan(params, 200).period
    alpha = params.backlash.alpha
    return kernels.run_rk4(
        PIECEWISE, 0.0, 0.0, alpha, params.damping, x0, 0.01, kc, fm, fc, True, T, N,
        n_trans, n_rec, 1, 1e6,
    )  # fmt: skip


def _errors(run, params: GearParams, Ns: tuple[int, ...]) -> tuple[list[float], list[float]]:
    """Errors of final state and log-growth sum after 10 T0 from x0 = 1.5 (starts in contact)."""
    ref = _kink(params, 12800, 0, 10, 1.5)
    ex, el = [], []
    for N in Ns:
        out = run(params, N, 0, 10, 1.5)
        ex.append(math.hypot(out[8] - ref[8], out[9] - ref[9]))
        el.append(abs(out[2].sum() - ref[2].sum()))
    return ex, el


@pytest.mark.parametrize("alpha", [0.0, 0.3])
def test_kink_scheme_converges_at_fourth_order(alpha: float) -> None:
    params = paper(0.25, model="piecewise", alpha=alpha)
    out = _kink(params, 200, 0, 10, 1.5)
    assert out[5] < 1.0 < out[6]  # the record crosses the kink at x = 1
    ex, el = _errors(_kink, params, (200, 400, 800))
    for errs in (ex, el):
        orders = [math.log2(errs[i] / errs[i + 1]) for i in range(2)]
        assert all(3.5 < q < 4.5 for q in orders), (errs, orders)


def test_plain_rk4_across_kinks_is_much_worse() -> None:
    params = paper(0.25, model="piecewise")
    ex_kink, el_kink = _errors(_kink, params, (200,))
    ex_plain, el_plain = _errors(_plain, params, (200,))
    assert ex_plain[0] > 30.0 * ex_kink[0]
    assert el_plain[0] > 30.0 * el_kink[0]


@pytest.mark.parametrize(("fe", "alpha"), [(0.05, 0.0), (0.1, 0.5)])
def test_kink_scheme_agrees_with_dop853(fe: float, alpha: float) -> None:
    params = paper(fe, mu=0.1, model="piecewise", alpha=alpha)
    period, lle, _ = scipy_run(params, 200, 100)
    r = simulate(params, SimulationSettings(transient_periods=200, record_periods=100))
    assert r.method.startswith("rk4 split at the kinks")
    assert r.period == period == 1
    assert r.lle == pytest.approx(lle, abs=1e-3)
    assert r.lle < 0.0


def test_piecewise_verdicts_are_stable_under_step_halving() -> None:
    a, b = (
        simulate(paper(0.25, model="piecewise"), SimulationSettings(steps_per_period=n))
        for n in (200, 400)
    )
    assert a.period == b.period == 6
    assert a.lle == pytest.approx(b.lle, abs=1e-6)
    assert a.poincare[-1] == pytest.approx(b.poincare[-1], abs=1e-6)
    c, d = (
        simulate(paper(0.1, model="piecewise"), SimulationSettings(steps_per_period=n))
        for n in (200, 400)
    )
    assert c.classification == d.classification == "chaotic"
    assert c.lle == pytest.approx(d.lle, abs=0.01)


@pytest.mark.parametrize(("fe", "chaotic"), [(0.26, False), (0.1, True)])
def test_matches_gear_ref_kink_mode(
    tmp_path_factory: pytest.TempPathFactory, fe: float, chaotic: bool
) -> None:
    """gear_ref.c --kink splits each step at the kinks as the kernel does; it finds the
    crossing time by regula falsi, the kernel by Newton from the Hermite interpolant's root,
    both to 1e-13 of a step. On a periodic orbit the two runs agree to rounding; on the
    chaotic one (LLE > 0) they part after a few hundred periods, as any two runs 1e-13 apart
    do, and their LLEs over 200 periods are two estimates of one exponent: within 3 standard
    errors of their difference (0.0372 +- 0.0017 against gear_ref's 0.0418)."""
    exe = gear_ref_binary(tmp_path_factory.mktemp("gear_ref"))
    if exe is None:
        pytest.skip("gcc or gear_ref.c not available")
    args = ["--kink", "0.07", repr(fe), "0.5", "0.01", "0", "1", "0", "1", "pw", "200", "200",
            "200"]  # fmt: skip
    _, lle, x, v = gear_ref_summary(exe, args)
    out = _kink(paper(fe, model="piecewise"), 200, 200, 200)
    mine = np.cumsum(out[2])[-1] / (200 * 4 * math.pi)
    assert (mine > 0.01) == (lle > 0.01) == chaotic
    if chaotic:
        stderr = benettin(out[2], 4 * math.pi).stderr  # each run's, the same record length
        assert stderr is not None and abs(mine - lle) <= 3.0 * math.sqrt(2.0) * stderr
    else:
        assert mine == pytest.approx(lle, rel=1e-8)
        assert (out[8], out[9]) == pytest.approx((x, v), rel=1e-9)


def test_a_point_the_regula_falsi_lost_is_dop853s_periodic_orbit() -> None:
    """The z = 23/67 pair of examples/remedies-z23-67.json with TE 3.928 um at 5,843.75 rpm and
    45.39 N m (a point of its 45 x 9 gate): with the crossing located by regula falsi alone,
    the kernel reported every start quasi-periodic, x spanning 25,608 half backlashes (1.2 m).
    DOP853 (rtol 1e-10) settles on a periodic 1T orbit with tooth separation (x from 0.98 to
    1.25, peak to peak 0.2640 after 80 T0 from rest); the kernel finds that orbit."""
    import json

    from gearengine.gate.envelope import ENVELOPE_SETTINGS
    from gearengine.model.design import Design
    from gearengine.model.fields import design_with
    from gearengine.numerics.batch import simulate_batch
    from gearengine.systems.designs import design_model
    from tests.conftest import ROOT

    doc = json.loads((ROOT / "examples" / "remedies-z23-67.json").read_text())
    design = design_with(Design.model_validate(doc["design"]), {
        "transmission_error.harmonics.0.amplitude": 3.928e-6, "speed": 611.9560689805118,
        "torque": 45.390625})  # fmt: skip
    point = design_model(design)[0]
    (b,) = simulate_batch([point], SimulationSettings.model_validate(ENVELOPE_SETTINGS))
    assert (b.classification, b.period, b.impact_regime) == ("periodic", 1, "single_sided")
    assert b.x_peak_to_peak == pytest.approx(0.264, rel=2e-3)
    period, _, final = scipy_run(point, 2, 4, tuple(b.poincare[-1]))  # on from its strobe
    assert period == 1  # DOP853 stays on it: the orbit, to RK4's error at 128 steps a mesh period
    assert list(final[:2]) == pytest.approx(b.poincare[-1], abs=1e-4)


@pytest.mark.parametrize(("x", "v", "reg"), [(0.995, 0.8, 0), (1.004, -0.6, 1), (-0.99, -1.1, 0)])
def test_the_regula_falsi_fallback_finds_newtons_crossing(x: float, v: float, reg: int) -> None:
    """A step across a kink, split by Newton from the Hermite root (the compiled kernel) and by
    the bracketing regula falsi alone (``NEWTON_SUBSTEPS`` 0, the fallback a grazing excursion
    or a Newton iterate out of its bracket takes; run as Python): the same crossing, the same
    state and tangent after it, in the region the motion enters."""
    from gearengine.systems.spur_pair.kernels import kink
    from gearengine.systems.spur_pair.kernels.phase import excitation_at

    params = paper(0.25, model="piecewise", alpha=0.3)
    kc, fm, fc = packed_forcing(params)
    alpha, twomu, t, h = params.backlash.alpha, 2.0 * params.damping, 0.7, 0.05
    newton = kink.kink_step(reg, alpha, twomu, kc, fm, fc, t, h, x, v, 1.0, 0.0)
    assert newton[4] != reg  # the step crossed
    K0, F0 = excitation_at(t, kc, fm, fc)
    first = kink._rk4_region(reg, alpha, twomu, kc, fm, fc, K0, F0, t, h, x, v, 1.0, 0.0)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(kink, "NEWTON_SUBSTEPS", 0)
        falsi = kink.kink_split.py_func(reg, alpha, twomu, kc, fm, fc, t, K0, F0, h, x, v, 1.0,
                                        0.0, *first)  # fmt: skip
    assert abs(newton[3] - first[3]) > 1e-3  # the unsplit step's tangent is another
    assert falsi[4] == newton[4]
    assert falsi[:4] == pytest.approx(newton[:4], rel=1e-10, abs=1e-12)
