"""Transient and record in physical time (``numerics.physical``) against the fixed-length run:
the same verdict at a periodic, a quasi-periodic and a chaotic point, ``adaptive`` false as
before, the single kernels and the lock-step lanes alike, and the lengths the result reports."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.gate.envelope import ENVELOPE_SETTINGS
from gearengine.model.params import GearParams
from gearengine.numerics import physical
from gearengine.numerics.batch import run_lanes, simulate_batch
from gearengine.numerics.physical import DAMPING_TIMES, RECORD_MESH
from gearengine.numerics.runs import integrate
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import simulate
from gearengine.signals.lyapunov import BLOCKS
from tests._gear_cases import paper
from tests.conftest import ROOT

FIXED = SimulationSettings(adaptive=False)

QUASI_PERIODIC = GearParams.model_validate(
    {"damping": 0.07, "mean_force": 0.01,
     "transmission_error": {"frequency": 1.2, "harmonics": [{"amplitude": 0.41739130434782606}]}}
)  # fmt: skip
"""A point of the chaos map (examples/chaos-map.json, 24 x 24 grid) whose fixed-length run
finds no period and an LLE within its error of zero."""


def ci_request(rpm: float, **settings: object) -> AnalysisRequest:
    """The README CI design (examples/ci/design.json, torque ripple at shaft order 1) at
    ``rpm``; T0 is one driver revolution, 18 mesh periods."""
    doc = json.loads((ROOT / "examples" / "ci" / "design.json").read_text())
    doc = copy.deepcopy(doc)
    doc["design"]["speed"] = f"{rpm} rpm"
    doc["settings"] = settings
    return AnalysisRequest.model_validate(doc)


def test_periodic_design_agrees_and_says_how_long_it_ran() -> None:
    adaptive = analyze(ci_request(4000))
    fixed = analyze(ci_request(4000, adaptive=False))
    a, f = adaptive.numerics, fixed.numerics
    assert (a.classification, a.period, a.impact_regime) == ("periodic", 1, "single_sided")
    assert (a.classification, a.period, a.impact_regime) == (
        f.classification, f.period, f.impact_regime)  # fmt: skip
    resp_a, resp_f = adaptive.engineering.response, fixed.engineering.response
    assert resp_a is not None and resp_f is not None
    assert resp_a.dte_peak_to_peak_um == pytest.approx(resp_f.dte_peak_to_peak_um, rel=5e-3)
    assert resp_a.contact.regime == resp_f.contact.regime
    t, r = a.transient, a.record
    assert t is not None and r is not None
    assert (t.reason, r.reason) == ("settled", "period")
    mu, T0 = adaptive.params.damping, a.forcing_period
    assert T0 is not None
    assert t.periods >= math.ceil(DAMPING_TIMES / (mu * T0))
    assert t.mesh_periods == 18 * t.periods and r.mesh_periods == 18 * r.periods
    assert r.periods % BLOCKS == 0 and r.mesh_periods >= RECORD_MESH
    assert t.tau == pytest.approx(t.periods * T0)
    conversion = ci_request(4000).conversion
    assert conversion is not None
    assert t.seconds == pytest.approx(t.tau * conversion.time_scale_s)
    assert t.periods + r.periods < 100  # a few hundred mesh periods, not 18,000
    assert (f.transient.periods, f.transient.reason) == (500, "fixed")
    assert (f.record.periods, f.record.reason) == (500, "fixed")


@pytest.mark.parametrize(
    ("point", "verdict"),
    [(paper(0.22), "periodic"), (QUASI_PERIODIC, "quasi_periodic"), (paper(0.25), "chaotic"),
     (paper(0.2, model="piecewise"), "chaotic")],
    ids=["periodic-2T", "quasi-periodic", "chaotic-cubic", "chaotic-piecewise"],
)  # fmt: skip
def test_verdict_agrees_with_the_fixed_length_run(point: GearParams, verdict: str) -> None:
    a, f = simulate(point), simulate(point, FIXED)
    assert (a.classification, a.period, a.impact_regime) == (
        f.classification, f.period, f.impact_regime)  # fmt: skip
    assert a.classification == verdict
    assert a.x_peak_to_peak == pytest.approx(f.x_peak_to_peak, rel=5e-3)
    assert a.transient is not None and a.record is not None
    assert a.transient.periods + a.record.periods <= 1000
    if verdict == "chaotic":
        assert (a.transient.reason, a.record.reason) == ("cap", "lle_stderr")
        assert a.transient.periods == 500  # chaos keeps the whole transient
        settings = SimulationSettings()
        assert a.lle_stderr <= max(settings.lle_stderr_abs, settings.lle_stderr_rel * a.lle)
        assert abs(a.lle - f.lle) <= 3.0 * math.hypot(a.lle_stderr, f.lle_stderr)


def test_adaptive_false_is_the_fixed_length_run() -> None:
    point = paper(0.22)
    before = SimulationSettings(physical_time=False)  # simulate() ran the full length before
    f, g = simulate(point, FIXED), simulate(point, before)
    assert f.model_dump() == g.model_dump()
    run = integrate(point, FIXED, (0.01, 0.01))
    assert f.poincare[-1] == [float(run.xs[-1]), float(run.vs[-1])]
    assert f.time_history.t[-1] == pytest.approx(1000 * f.forcing_period)
    (b,) = simulate_batch([point], FIXED)
    assert (b.lle, b.periods_run) == (f.lle, 1000)


def test_lanes_give_the_single_kernels_numbers() -> None:
    settings = SimulationSettings(initial_states=[[0.01, 0.01], [1.5, -0.2]])
    points = [paper(0.1), paper(0.22), paper(0.25), paper(0.2, model="piecewise"),
              ci_request(3000).params, ci_request(4000).params]  # fmt: skip
    for p, b in zip(points, simulate_batch(points, settings), strict=True):
        single = simulate(p, settings)
        assert (b.classification, b.period, b.lle) == (
            single.classification, single.period, single.lle)  # fmt: skip
        assert b.poincare[-1] == single.poincare[-1]
        assert b.periods_run <= 1000


def test_caps_are_the_settings_lengths() -> None:
    r = simulate(paper(0.25), SimulationSettings(transient_periods=7, record_periods=30))
    assert (r.transient.periods, r.transient.reason) == (7, "cap")
    assert r.record.periods <= 30
    no_transient = SimulationSettings(transient_periods=0)
    r = simulate(paper(0.1), no_transient)
    assert (r.transient.periods, r.transient.reason) == (0, "cap")
    f = simulate(paper(0.1), no_transient.model_copy(update={"adaptive": False}))
    assert (r.classification, r.period) == (f.classification, f.period)


def test_ensembles_inherit_it_through_their_settings() -> None:
    """The envelope gate's light settings (60 + 60 T0) become upper bounds: a point of the
    CI design runs a few hundred mesh periods, not 2,160."""
    settings = SimulationSettings.model_validate(ENVELOPE_SETTINGS)
    point = ci_request(4000).params
    (a,) = simulate_batch([point], settings)
    (f,) = simulate_batch([point], settings.model_copy(update={"adaptive": False}))
    assert (a.classification, a.period) == (f.classification, f.period)
    assert f.periods_run == 120 and a.periods_run < 40


DIVERGING = GearParams.model_validate(
    {"damping": 0.01, "backlash": {"model": "cubic", "a": -1.0, "c": -1.0},
     "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 20.0}]}}
)  # fmt: skip
"""A softening law driven hard: leaves the divergence bound in its transient."""


def test_diverging_run_stops_where_it_leaves_the_bound() -> None:
    bad = DIVERGING
    r = simulate(bad)
    assert r.classification == "diverged" and r.transient.reason == "diverged"
    (b,) = simulate_batch([bad], SimulationSettings())
    assert b.classification == "diverged" and b.periods_run < r.transient.periods + 1


@pytest.mark.parametrize(
    "point",
    [paper(0.2, we=1.0), paper(0.32, we=0.55, model="piecewise")],
    ids=["cubic", "piecewise"],
)
def test_a_record_run_on_is_the_longer_record_run_at_once(
    point: GearParams, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A chaotic point whose first record (400 T0) leaves the LLE's error unmet runs on to 500
    from where it ended (state, tangent vector, region of Eq. (8) carried by the lanes), not
    again from the record's start: the same bits as running the 500 at once, 100 more T0."""
    lengths, ran_on = physical.lengths, []

    def counted(*args: object) -> list:
        def extend(idx: np.ndarray, keeps: list, n: int) -> physical.Chunk:
            ran_on.append(n)
            return args[7](idx, keeps, n)  # type: ignore[operator]

        return lengths(*args[:7], extend)  # type: ignore[arg-type]

    monkeypatch.setattr(physical, "lengths", counted)
    (b,) = simulate_batch([point])
    assert ran_on == [100] and (b.classification, b.periods_run) == ("chaotic", 1000)
    monkeypatch.setattr(physical, "lengths", lambda *args: lengths(*args[:7]))  # run again
    (again,) = simulate_batch([point])
    assert again.model_dump() == b.model_dump()


@pytest.mark.parametrize("settings", [SimulationSettings(), FIXED], ids=["physical", "fixed"])
def test_x_only_strobes_are_the_strobes_x(settings: SimulationSettings) -> None:
    """``simulate_batch(x_only=True)`` (a map's points) gives the same verdicts with the x of
    the last strobes in ``poincare_x`` instead of the [x, v] pairs (a diverging point too)."""
    points = [paper(0.1), paper(0.5), QUASI_PERIODIC, DIVERGING]
    full = simulate_batch(points, settings)
    short = simulate_batch(points, settings, x_only=True)
    assert full[-1].classification == "diverged"
    for f, s in zip(full, short, strict=True):
        assert s.poincare == [] and f.poincare_x is None
        assert s.poincare_x == [x for x, _ in f.poincare]
        keep = set(type(f).model_fields) - {"poincare", "poincare_x"}
        assert s.model_dump(include=keep) == f.model_dump(include=keep)


def test_starts_of_one_point_on_one_cycle_share_one_record() -> None:
    """The README CI design at 4,000 rpm has two coexisting cycles (tooth separation and full
    contact). Of six starts, the ones that settle on a cycle another start settled on take its
    record instead of recording it again (two records, not six), and every start's class,
    period, contact, DTE and forces are those of six records of their own (to the convergence
    tolerance); starts in sets of their own never share."""
    settings = SimulationSettings.model_validate(ENVELOPE_SETTINGS)
    point = ci_request(4000).params
    lanes = [(0, (x, v)) for x in (-1.5, 0.0, 1.5) for v in (-0.5, 0.5)]
    shared = run_lanes([point], lanes, settings, sets=[0] * len(lanes))
    own = run_lanes([point], lanes, settings)  # no sets: every start records its own
    assert len({b._record for b in shared}) == 2 and len({b._record for b in own}) == 6
    assert {b.impact_regime for b in shared} == {"single_sided", "no_impact"}
    for s, o in zip(shared, own, strict=True):
        assert (s.classification, s.period, s.impact_regime) == (o.classification, o.period,
                                                                 o.impact_regime)  # fmt: skip
        for name in ("x_peak_to_peak", "force_max", "force_min"):
            assert getattr(s, name) == pytest.approx(getattr(o, name), rel=1e-6)
    for s in shared:  # a start that shares a record has its numbers
        first = next(b for b in shared if b._record == s._record)
        assert (s.lle, s.lle_stderr, s.poincare) == (first.lle, first.lle_stderr, first.poincare)


def test_a_record_that_misses_its_cycle_leaves_the_starts_joined_to_it_their_own(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A start is joined to the first one that settled on its cycle only if that start's
    record finds the period back: otherwise (here: every record told to find none at first)
    the joined starts record their own."""
    settings = SimulationSettings.model_validate(ENVELOPE_SETTINGS)
    point = ci_request(3000).params
    lanes = [(0, (x, 0.0)) for x in (-1.0, 0.0, 1.0)]
    assert len({b._record for b in run_lanes([point], lanes, settings, sets=[0, 0, 0])}) == 1
    missed: list[int] = []
    detect = physical.detect_period

    def once_missing(xs: np.ndarray, vs: np.ndarray, size: float, **kw: object) -> int | None:
        if kw or missed:  # the transient's test, or a record after the first
            return detect(xs, vs, size, **kw)  # type: ignore[arg-type]
        missed.append(1)
        return None

    monkeypatch.setattr(physical, "detect_period", once_missing)
    got = run_lanes([point], lanes, settings, sets=[0, 0, 0])
    assert missed and len({b._record for b in got}) == 3
    assert {(b.classification, b.period) for b in got[1:]} == {("periodic", 1)}


def test_starts_that_share_a_record_are_one_estimate_of_the_attractors_lle() -> None:
    """Three starts on one cycle share one record: the attractor's LLE is that record's, with
    its standard error (not the error of a mean of three independent estimates, 1/sqrt 3 of
    it); starts with records of their own are averaged as before."""
    from gearengine.numerics.attractors import _attractor

    settings = SimulationSettings.model_validate(ENVELOPE_SETTINGS)
    point = ci_request(3000).params
    lanes = [(0, (x, 0.0)) for x in (-1.0, 0.0, 1.0)]
    shared = run_lanes([point], lanes, settings, sets=[0] * len(lanes))
    a = _attractor([(s, b) for (_, s), b in zip(lanes, shared, strict=True)], 3, None)
    assert (a.lle, a.lle_stderr, a.count) == (shared[0].lle, shared[0].lle_stderr, 3)
    own = run_lanes([point], lanes, settings)
    b = _attractor([(s, p) for (_, s), p in zip(lanes, own, strict=True)], 3, None)
    errs = [p.lle_stderr for p in own]
    assert b.lle_stderr == pytest.approx(math.sqrt(sum(e * e for e in errs)) / 3)
