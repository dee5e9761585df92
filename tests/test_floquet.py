"""Floquet multipliers, stability margins and located period doublings (numerics.floquet,
numerics.bifurcations), and their wiring through the analysis, sweeps, HTTP queue and CLI gate.

The paper's cascade (Sec. 4.1: Omega_e = 0.5, mu~ = 0.07, F_m = 0.01, cubic a = c = 0.1667)
with RK4 at 200 steps per T0, checked against an independent computation: scipy DOP853
(rtol 1e-11, atol 1e-12) of Eq. (9) and its variational equations, written out again below
without gearengine, with periodic orbits from scipy.optimize.root (hybr) and period-doubling
points from brentq. Numbers are printed (pytest -s) for docs/floquet.md.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, root

from gearengine.cli import main
from gearengine.model.params import GearParams
from gearengine.numerics.bifurcations import feigenbaum_ratios, locate_bifurcations
from gearengine.numerics.floquet import NEWTON_MAX_STEPS, floquet, floquet_of, liouville_words
from gearengine.numerics.runs import as_system
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import simulate
from gearengine.plots.sweep import bifurcation_label, sweep_figure
from gearengine.studies.sweep import run_local, validated
from gearengine.systems.spur_pair import kernels
from gearengine.systems.spur_pair.forcing import packed_forcing
from gearengine.systems.spur_pair.kernels import monodromy
from service.core.config import Settings
from service.main import create_app
from tests._gear_cases import paper
from tests._polling import poll
from tests.conftest import PAPER_PARAMS, ROOT, started

MU, FM, WE, A, C = 0.07, 0.01, 0.5, 0.1667, 0.1667
CUBIC, PIECEWISE = 0, 1  # kernel codes of systems.spur_pair.laws.LAWS
T0 = 2.0 * math.pi / WE
FEIGENBAUM = 4.669201609
GRID = np.linspace(0.2, 0.235, 141)  # F_e1 step 2.5e-4
Flow = Callable[[np.ndarray, int], tuple[np.ndarray, np.ndarray]]


# --- independent reference: DOP853 of Eq. (9) + variational equations ----------------------


def dop853_cubic(fe: float, rtol: float = 1e-11, atol: float = 1e-12) -> Flow:
    """(X, n) -> (phi_{n T0}(X), Phi) for the paper's cubic case at F_e1 = fe."""
    amp = WE * WE * fe

    def rhs(t: float, y: np.ndarray) -> list[float]:
        x, v, p1, q1, p2, q2 = y
        k = 3.0 * C * x * x - A
        acc = -2.0 * MU * v - x * (C * x * x - A) + FM + amp * math.cos(WE * t)
        return [v, acc, q1, -2.0 * MU * q1 - k * p1, q2, -2.0 * MU * q2 - k * p2]

    def flow(X: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
        y0 = [X[0], X[1], 1.0, 0.0, 0.0, 1.0]
        y = solve_ivp(rhs, (0.0, n * T0), y0, method="DOP853", rtol=rtol, atol=atol).y[:, -1]
        return y[:2], np.array([[y[2], y[4]], [y[3], y[5]]])

    return flow


def dop853_piecewise(fe: float, mu: float, rtol: float = 1e-12, atol: float = 1e-13) -> Flow:
    """As ``dop853_cubic`` for the piecewise law of Eq. (8) with alpha = 0: each region's linear
    field is integrated up to a terminal event at |x| = 1, then the next region starts there
    (no saltation: the field is continuous across |x| = 1)."""
    amp = WE * WE * fe

    def rhs(t: float, y: np.ndarray, reg: int) -> list[float]:
        x, v, p1, q1, p2, q2 = y
        fh, k = (x - reg, 1.0) if reg else (0.0, 0.0)
        acc = -2.0 * mu * v - fh + FM + amp * math.cos(WE * t)
        return [v, acc, q1, -2.0 * mu * q1 - k * p1, q2, -2.0 * mu * q2 - k * p2]

    def event(b: float, direction: int):
        def g(t: float, y: np.ndarray, reg: int) -> float:
            return y[0] - b

        g.terminal, g.direction = True, direction
        return g

    leave = {1: [event(1.0, -1)], -1: [event(-1.0, 1)], 0: [event(1.0, 1), event(-1.0, -1)]}

    def flow(X: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
        y, t = np.array([X[0], X[1], 1.0, 0.0, 0.0, 1.0]), 0.0
        reg = 1 if y[0] > 1.0 else (-1 if y[0] < -1.0 else 0)
        while t < n * T0:
            sol = solve_ivp(
                rhs, (t, n * T0), y, method="DOP853", rtol=rtol, atol=atol,
                events=leave[reg], args=(reg,),
            )  # fmt: skip
            y, t = sol.y[:, -1].copy(), sol.t[-1]
            if sol.status == 1:  # on |x| = 1: the direction of motion picks the new region
                y[0] = math.copysign(1.0, y[0])
                reg = (1 if y[1] > 0.0 else 0) if y[0] > 0.0 else (-1 if y[1] < 0.0 else 0)
        return y[:2], np.array([[y[2], y[4]], [y[3], y[5]]])

    return flow


def reference_orbit(flow: Flow, X: np.ndarray, n: int) -> tuple[np.ndarray, list[complex]]:
    """Period-n orbit by scipy.optimize.root (hybr, Jacobian Phi - I) and its multipliers."""

    def fun(Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        end, phi = flow(Y, n)
        return end - Y, phi - np.eye(2)

    sol = root(fun, X, jac=True, method="hybr", tol=1e-14)
    lam = np.linalg.eigvals(flow(sol.x, n)[1]).astype(complex)
    return sol.x, sorted(lam.tolist(), key=abs, reverse=True)


def reference_pd(bracket: tuple[float, float], X: np.ndarray, n: int) -> float:
    """F_e1 where the period-n orbit's largest |multiplier| crosses 1 (DOP853 + brentq)."""
    warm = {"X": X}

    def margin(fe: float) -> float:
        warm["X"], lam = reference_orbit(dop853_cubic(fe), warm["X"], n)
        return 1.0 - abs(lam[0])

    return brentq(margin, *bracket, xtol=1e-13)


# --- fixtures -------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def cascade() -> list[dict]:
    """Events of the paper's F_e1 sweep 0.2 .. 0.235 (141 points, RK4 200 steps per T0)."""
    return locate_bifurcations(paper(0.2), "F_e1", GRID, SimulationSettings())


@pytest.fixture(scope="module")
def pd_reference(cascade: list[dict]) -> list[float]:
    """DOP853 period-doubling points 1T->2T, 2T->4T, 4T->8T (brackets from the RK4 sweep)."""
    out = []
    for ev in cascade[:3]:
        lo, hi = ev["bracket"]
        r = simulate(paper(lo))
        fl = floquet(paper(lo), SimulationSettings(), r.poincare[-1], ev["period_before"])
        out.append(reference_pd((lo, hi), np.array(fl.orbit_state), ev["period_before"]))
    return out


def _orbit(fe: float, steps: int = 200):
    r = simulate(paper(fe))
    assert r.classification == "periodic" and r.period is not None
    return floquet(paper(fe), SimulationSettings(steps_per_period=steps), r.poincare[-1], r.period)


def _lams(fl) -> list[complex]:
    return [complex(re, im) for re, im in fl.multipliers]


# --- the kernel -----------------------------------------------------------------------------


def test_state_path_and_tangent_equal_run_rk4() -> None:
    p = paper(0.2)
    kc, fm, fc = packed_forcing(p)
    x, v, phi = monodromy(CUBIC, A, C, 0.0, MU, 0.3, -0.1, kc, fm, fc, T0, 200, 3)
    out = kernels.run_rk4(CUBIC, A, C, 0.0, MU, 0.3, -0.1, kc, fm, fc, False, T0, 200, 0, 3, 1, 1e6)
    assert (x, v) == (out[8], out[9])  # same arithmetic, bit for bit
    growth = np.linalg.norm(phi @ np.array([kernels.SQRT1_2, kernels.SQRT1_2]))
    assert math.log(growth) == pytest.approx(out[2].sum(), rel=1e-13)


@pytest.mark.parametrize(
    ("law", "alpha", "fe", "mu"), [(CUBIC, 0.0, 0.2, 0.07), (PIECEWISE, 0.0, 0.15, 0.1),
                                   (PIECEWISE, 0.3, 0.15, 0.1)]
)  # fmt: skip
def test_monodromy_is_the_jacobian_of_the_flow(
    law: int, alpha: float, fe: float, mu: float
) -> None:
    """Phi against central differences of the end state; for the piecewise law the orbit
    crosses the kinks, so this checks that no saltation jump is missing."""
    p = paper(fe, mu=mu)
    kc, fm, fc = packed_forcing(p)

    def end(X: np.ndarray) -> np.ndarray:
        return np.array(monodromy(law, A, C, alpha, mu, X[0], X[1], kc, fm, fc, T0, 400, 2)[:2])

    X = np.array([1.5, 0.0])  # in contact: the piecewise path leaves and re-enters x > 1
    xs = kernels.run_kink(alpha, mu, X[0], X[1], kc, fm, fc, T0, 400, 0, 2, 1, 1e6)
    assert law == CUBIC or xs[5] < 1.0 < xs[6]  # the piecewise path crosses x = 1
    phi = monodromy(law, A, C, alpha, mu, X[0], X[1], kc, fm, fc, T0, 400, 2)[2]
    d = 1e-6
    fd = np.column_stack([(end(X + d * e) - end(X - d * e)) / (2 * d) for e in np.eye(2)])
    assert np.max(np.abs(phi - fd)) < 1e-6 * np.max(np.abs(phi))


# --- Floquet multipliers of the paper's 1T and 2T orbits ------------------------------------


@pytest.mark.parametrize(
    ("fe", "period", "kind"), [(0.2, 1, "period_doubling"), (0.215, 2, "fold")]
)
def test_multipliers_agree_with_dop853(fe: float, period: int, kind: str) -> None:
    fl = _orbit(fe)
    X_ref, lam_ref = reference_orbit(dop853_cubic(fe), np.array(fl.orbit_state), period)
    lam = _lams(fl)
    print(f"\nF_e1={fe} {period}T: RK4 N=200 {lam}, DOP853 {lam_ref}, orbit {fl.orbit_state}")
    assert fl.period == period and fl.converged
    assert fl.orbit_residual < 1e-11 and fl.newton_steps <= NEWTON_MAX_STEPS
    assert max(abs(a - b) for a, b in zip(lam, lam_ref, strict=True)) < 1e-6
    assert np.hypot(*(np.array(fl.orbit_state) - X_ref)) < 1e-6
    assert fl.stability_margin == pytest.approx(1.0 - abs(lam[0])) and fl.stability_margin > 0.0
    assert abs(lam[0]) >= abs(lam[1]) and fl.nearest_bifurcation == kind


@pytest.mark.parametrize(("fe", "period"), [(0.2, 1), (0.215, 2)])
def test_multipliers_converge_at_fourth_order(fe: float, period: int) -> None:
    _, lam_ref = reference_orbit(dop853_cubic(fe), np.array(_orbit(fe).orbit_state), period)
    errors = []
    for N in (200, 400, 800):
        lam = _lams(_orbit(fe, N))
        errors.append(max(abs(a - b) for a, b in zip(lam, lam_ref, strict=True)))
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    print(f"\nF_e1={fe}: multiplier error at N=200, 400, 800: {errors}, ratios {ratios}")
    assert errors[0] < 1e-6
    assert all(10.0 < q < 22.0 for q in ratios)  # 2^4 = 16: O(h^4)


@pytest.mark.parametrize("fe", [0.2, 0.215])
def test_liouville_identity(fe: float) -> None:
    """det Phi = exp(-2 mu n T0): met to the RK4 truncation error, which falls as h^4."""
    errors = [_orbit(fe, N).liouville_error for N in (200, 400, 800, 1600)]
    print(f"\nF_e1={fe}: Liouville error at N=200..1600: {errors}")
    assert errors[0] < 1e-6 and errors[2] < 2e-9 and errors[3] < 1e-10
    assert all(12.0 < errors[i] / errors[i + 1] < 20.0 for i in range(3))


def test_complex_pair_has_the_liouville_modulus() -> None:
    fl = _orbit(0.1)
    lam = _lams(fl)
    assert lam[0] == lam[1].conjugate() and lam[0].imag != 0.0
    assert abs(lam[0]) == pytest.approx(math.exp(-MU * T0), abs=1e-6)
    assert fl.nearest_bifurcation == "neimark_sacker"
    assert any("cannot reach the unit circle" in n for n in fl.notes)


def test_piecewise_law_against_dop853_with_events_and_4x_steps() -> None:
    p = paper(0.15, mu=0.1, model="piecewise", alpha=0.0)
    r = simulate(p)
    assert r.period == 2 and r.impact_regime == "single_sided"
    coarse, fine = (
        floquet(p, SimulationSettings(steps_per_period=N), r.poincare[-1], 2) for N in (200, 800)
    )
    _, lam_ref = reference_orbit(dop853_piecewise(0.15, 0.1), np.array(fine.orbit_state), 2)
    err_coarse = max(abs(a - b) for a, b in zip(_lams(coarse), lam_ref, strict=True))
    err_fine = max(abs(a - b) for a, b in zip(_lams(fine), lam_ref, strict=True))
    print(f"\npiecewise 2T: {_lams(coarse)}, DOP853+events {lam_ref}, err {err_coarse} {err_fine}")
    assert coarse.converged and fine.converged
    assert err_coarse < 1e-6 and err_fine < 1e-8
    assert coarse.liouville_error < 1e-6 and fine.liouville_error < 1e-8


# --- the cascade ----------------------------------------------------------------------------


def test_cascade_points(cascade: list[dict]) -> None:
    for ev in cascade:
        print(f"\n{ev}", end="")
    assert [e["type"] for e in cascade] == ["period_doubling"] * 5
    assert [(e["period_before"], e["period_after"]) for e in cascade] == [
        (1, 2), (2, 4), (4, 8), (8, 16), (16, None),
    ]  # fmt: skip
    pd = [e["value"] for e in cascade]
    assert 0.21 < pd[0] < 0.2125 and 0.22 < pd[1] < 0.23 and 0.23 < pd[2] < 0.2325 < pd[3]
    for e in cascade:
        assert e["parameter"] == "F_e1" and e["branch"] == "up"
        assert e["bracket"][0] < e["value"] < e["bracket"][1]
        assert e["critical_multiplier"] == pytest.approx([-1.0, 0.0], abs=1e-6)


def test_feigenbaum_ratios(cascade: list[dict]) -> None:
    ratios = feigenbaum_ratios([e["value"] for e in cascade])
    print(f"\nFeigenbaum ratios {ratios} (delta = {FEIGENBAUM})")
    assert len(ratios) == 3
    assert all(3.0 < r < 7.0 and abs(r - FEIGENBAUM) < 0.2 for r in ratios)


def test_deep_cascade_ratios_approach_feigenbaum(cascade: list[dict]) -> None:
    """A 2.5e-6 grid below the accumulation point (~0.232812) resolves the cascade down to
    64T -> 128T; the interval ratios creep towards delta."""
    deep = locate_bifurcations(paper(0.2325), "F_e1", np.linspace(0.2325, 0.2328125, 126))
    assert [(e["period_before"], e["period_after"]) for e in deep[:3]] == [
        (8, 16),
        (16, 32),
        (32, 64),
    ]
    assert deep[3]["period_before"] == 64 and all(e["type"] == "period_doubling" for e in deep)
    assert deep[0]["value"] == pytest.approx(cascade[3]["value"], abs=1e-9)
    points = [e["value"] for e in cascade[:3] + deep]
    ratios = feigenbaum_ratios(points)
    print(f"\nPD points {points}\nFeigenbaum ratios {ratios}")
    assert len(ratios) == 5 and all(3.0 < r < 7.0 for r in ratios)
    assert abs(ratios[-1] - FEIGENBAUM) < 0.01


def test_pd_points_agree_with_dop853(cascade: list[dict], pd_reference: list[float]) -> None:
    diffs = [e["value"] - ref for e, ref in zip(cascade, pd_reference, strict=False)]
    print(f"\nDOP853 PD points {pd_reference}, RK4 N=200 minus DOP853: {diffs}")
    assert all(abs(d) < 1e-8 for d in diffs)


def test_pd_point_converges_at_fourth_order(pd_reference: list[float]) -> None:
    """Step halving h, 2h, 4h = T0/800, T0/400, T0/200 (at N = 100 the error changes sign:
    higher-order terms still compete, so the table starts at 200)."""
    errors = []
    for N in (200, 400, 800):
        s = SimulationSettings(steps_per_period=N)
        (ev,) = locate_bifurcations(paper(0.2), "F_e1", [0.2115, 0.212], s, xtol=1e-14)
        errors.append(abs(ev["value"] - pd_reference[0]))
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    print(f"\nPD 1T->2T error at N=200, 400, 800: {errors}, ratios {ratios}")
    assert errors[0] < 1e-8
    assert all(10.0 < q < 22.0 for q in ratios)


def test_down_sweep_and_coarse_grid_find_the_same_points(cascade: list[dict]) -> None:
    """A decreasing sweep meets each doubling from the doubled side (the orbit merges into its
    parent); a coarse grid makes young doubled orbits collapse onto their parents unless they
    are deflated. Both must reproduce the fine upward sweep."""
    up = [e["value"] for e in cascade[:3]]
    down = locate_bifurcations(paper(0.2), "F_e1", np.linspace(0.2325, 0.21, 46))
    assert [(e["period_before"], e["period_after"]) for e in down] == [(8, 4), (4, 2), (2, 1)]
    assert all(e["branch"] == "down" and e["type"] == "period_doubling" for e in down)
    assert [e["value"] for e in down] == pytest.approx(up[::-1], abs=1e-9)
    coarse = locate_bifurcations(paper(0.2), "F_e1", np.linspace(0.2, 0.232, 33))
    assert [(e["period_before"], e["period_after"]) for e in coarse] == [(1, 2), (2, 4), (4, 8)]
    assert [e["value"] for e in coarse] == pytest.approx(up, abs=1e-9)


# --- API contract ---------------------------------------------------------------------------


def test_analysis_field_is_null_with_a_reason_when_not_periodic() -> None:
    chaotic = simulate(paper(0.25))
    assert chaotic.floquet is None and "chaotic" in chaotic.floquet_note
    assert floquet_of(as_system(paper(0.25)), SimulationSettings(), chaotic) == (
        None,
        chaotic.floquet_note,
    )
    periodic = simulate(paper(0.2))
    assert periodic.floquet is not None and periodic.floquet_note is None
    assert periodic.floquet.period == 1 and periodic.floquet.converged
    direct = floquet(paper(0.2), SimulationSettings(), periodic.poincare[-1], 1)
    assert periodic.floquet == direct
    doc = json.loads(periodic.model_dump_json())["floquet"]
    assert doc["multipliers"] == periodic.floquet.multipliers


def test_incommensurate_forcing_and_bad_grids_are_refused() -> None:
    quasi = GearParams.model_validate(
        {
            **paper(0.1).model_dump(),
            "torque": {"frequency": math.sqrt(2.0), "harmonics": [{"amplitude": 0.01}]},
        }
    )
    with pytest.raises(ValueError, match="incommensurate"):
        floquet(quasi, SimulationSettings(), [0.5, 0.1], 1)
    with pytest.raises(ValueError, match="monotone"):
        locate_bifurcations(paper(0.2), "F_e1", [0.2, 0.21, 0.205])
    with pytest.raises(ValueError, match="monotone"):
        locate_bifurcations(paper(0.2), "F_e1", [0.2])


# --- wiring: analysis API, continuation sweeps (local and over the queue), CLI gate ---------

PD_REFERENCE = (0.2119437390, 0.2282815460)
"""1T->2T and 2T->4T by DOP853 + brentq (docs/floquet.md; ``pd_reference`` recomputes them)."""


def test_analysis_api_returns_multipliers_and_margin(client) -> None:
    r = client.post("/v1/analyses", json={"params": PAPER_PARAMS})
    assert r.status_code == 200
    num = r.json()["numerics"]
    fl = num["floquet"]
    assert num["classification"] == "periodic" and num["floquet_note"] is None
    flat = [part for lam in fl["multipliers"] for part in lam]
    assert flat == pytest.approx([-0.5240356, 0.0, -0.3285401, 0.0], abs=1e-6)  # DOP853
    assert fl["stability_margin"] == pytest.approx(1.0 - 0.5240356, abs=1e-6)
    assert fl["nearest_bifurcation"] == "period_doubling" and fl["orbit_residual"] < 1e-11
    chaotic = {"params": {**PAPER_PARAMS, "transmission_error": {
        "frequency": 0.5, "harmonics": [{"amplitude": 0.28}]}}}  # fmt: skip
    num = client.post("/v1/analyses", json=chaotic).json()["numerics"]
    assert num["floquet"] is None and "chaotic" in num["floquet_note"]


def _line_sweep(num: int, **extra) -> dict:
    axis = {"parameter": "F_e1", "start": 0.2, "stop": 0.235, "num": num}
    return {"params": PAPER_PARAMS, "axes": [axis], "continuation": True, **extra}


def test_continuation_sweep_locates_the_cascade() -> None:
    result = run_local(validated(_line_sweep(15, direction="both")))
    located = [b for b in result.bifurcations if b.type == "period_doubling"]
    up = [b for b in located if b.branch == "up"]
    down = [b for b in located if b.branch == "down"]
    assert [(b.period_before, b.period_after) for b in up[:3]] == [(1, 2), (2, 4), (4, 8)]
    assert [(b.period_before, b.period_after) for b in down] == [(8, 4), (4, 2), (2, 1)]
    for b, ref in zip(up, PD_REFERENCE, strict=False):
        assert b.parameter == "F_e1" and abs(b.value - ref) < 1e-5
        assert b.bracket[0] < b.value < b.bracket[1]
    assert [b.value for b in down[::-1]] == pytest.approx([b.value for b in up[:3]], abs=1e-8)
    plain = run_local(validated({**_line_sweep(4), "continuation": False}))
    assert plain.bifurcations is None


@pytest.fixture(scope="module")
def working(tmp_path_factory: pytest.TempPathFactory):
    """An app with an embedded dispatcher and one worker process (as test_sweeps_api)."""
    settings = Settings(data_dir=tmp_path_factory.mktemp("jobs"), workers=1)
    with started(create_app(settings)) as c:
        yield c


def test_continuation_sweep_over_the_queue_carries_the_bifurcations(working) -> None:
    doc = _line_sweep(15)
    job_id = working.post("/v1/sweeps", json=doc).json()["id"]
    poll(lambda: working.get(f"/v1/sweeps/{job_id}").json())
    body = working.get(f"/v1/sweeps/{job_id}/result").json()
    local = run_local(validated(doc)).model_dump(mode="json")
    assert body == local
    first, second = body["bifurcations"][:2]
    assert (first["period_before"], first["period_after"], first["branch"]) == (1, 2, "up")
    assert abs(first["value"] - PD_REFERENCE[0]) < 1e-5
    assert abs(second["value"] - PD_REFERENCE[1]) < 1e-5
    csv_text = working.get(f"/v1/sweeps/{job_id}/result", params={"format": "csv"}).text
    assert len(csv_text.splitlines()) == 16
    plot = working.get(f"/v1/sweeps/{job_id}/plot")
    assert plot.status_code == 200 and plot.content.startswith(b"\x89PNG")


def test_bifurcation_labels_on_the_diagram() -> None:
    req = validated(_line_sweep(8))
    result = run_local(req)
    svg = sweep_figure(req, result.points, "svg", result.bifurcations).decode()
    assert bifurcation_label(result.bifurcations[0]) == "1T→2T at F_e1 = 0.21194"
    assert "1T→2T at F_e1 = 0.21194" in svg


def test_check_gate_on_the_stability_margin(tmp_path, capsys) -> None:
    periodic = tmp_path / "periodic.json"
    periodic.write_text(json.dumps({"params": PAPER_PARAMS}))
    assert main(["check", str(periodic), "--min-stability-margin", "0.4"]) == 0
    assert "PASS" in capsys.readouterr().out
    assert main(["check", str(periodic), "--min-stability-margin", "0.5"]) == 1
    out = capsys.readouterr().out
    assert out.startswith("FAIL") and "--min-stability-margin 0.5: margin 0.476" in out
    chaotic = tmp_path / "chaotic.json"
    te = {"frequency": 0.5, "harmonics": [{"amplitude": 0.28}]}
    chaotic.write_text(json.dumps({"params": {**PAPER_PARAMS, "transmission_error": te}}))
    argv = ["check", str(chaotic), "--fail-on", "diverged", "--min-stability-margin", "0.5"]
    assert main(argv) == 0  # the margin applies to periodic responses only
    assert main(["analyze", str(periodic)]) == 0
    assert "stability margin 0.476" in capsys.readouterr().out


def test_the_text_says_why_a_complex_pair_cannot_bifurcate(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``analyze`` printed "stability margin 1 (nearest bifurcation: neimark_sacker)" for
    multipliers of modulus 4e-10 (third new-user review): the JSON's note says a complex pair
    of this planar system cannot reach the unit circle, and now the text says it too."""
    assert main(["analyze", str(ROOT / "examples" / "design-geometry.json")]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if "Floquet" in s)
    # the generic label (the JSON's) is not offered as a bifurcation near (fourth review)
    assert "(no bifurcation while they are a complex pair); " in line and "neimark" not in line
    assert "so the pair cannot reach the unit circle" in line


def test_a_missed_liouville_check_is_weighed_against_the_margin() -> None:
    """The note says how large the multipliers' error is against the stability margin it could
    move: 2.2e-4 beside a margin of 0.88 (the analyze-geometry golden) is small, not
    "Phi is inaccurate"; the same error beside a margin of 1e-4 leaves the margin uncertain."""
    small = liouville_words(2.2e-4, 0.88, 2)
    assert "exp(-2 mu n T0)" in small and "small against the stability margin 0.88" in small
    assert "inaccurate" not in small
    near = liouville_words(2.2e-4, 1e-4, 2)
    assert "not small against the stability margin" in near and "uncertain" in near
    assert "exp(tr J n T0)" in liouville_words(2.2e-4, 0.5, 6)
