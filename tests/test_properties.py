"""Property tests on the engine: no NaN or inf ever escapes, and the verdicts are coherent."""

from __future__ import annotations

import json
import math

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.homoclinic.verdict import melnikov
from gearengine.jsonio import dumps
from gearengine.model.params import GearParams
from gearengine.numerics.simulation import SimulationSettings
from gearengine.signals.classify import severity


def strict_json(text: str) -> object:
    """json.loads that refuses NaN and Infinity (which Python's json would accept)."""

    def refuse(token: str) -> None:
        raise AssertionError(f"non-finite number {token} in output")

    return json.loads(text, parse_constant=refuse)


excitation = st.one_of(
    st.none(),
    st.builds(
        lambda f, amps: {
            "frequency": f,
            "harmonics": [{"amplitude": a, "phase": p} for a, p in amps],
        },
        st.sampled_from([0.1, 0.25, 0.5, 0.7, 1.0, 2.0, math.sqrt(2)]),
        st.lists(st.tuples(st.floats(-2.0, 2.0), st.floats(-3.2, 3.2)), min_size=0, max_size=3),
    ),
)
backlash = st.one_of(
    st.builds(lambda a, c: {"model": "cubic", "a": a, "c": c}, st.floats(-1, 1), st.floats(-1, 1)),
    st.builds(lambda al: {"model": "piecewise", "alpha": al}, st.floats(0.0, 0.9)),
)
designs = st.builds(
    lambda mu, fm, bl, k, e, p: GearParams.model_validate(
        {
            "damping": mu,
            "mean_force": fm,
            "backlash": bl,
            "stiffness": k,
            "transmission_error": e,
            "torque": p,
        }
    ),
    st.floats(0.0, 1.0),
    st.floats(-1.0, 1.0),
    backlash,
    excitation,
    excitation,
    excitation,
)
SHORT = SimulationSettings(transient_periods=20, record_periods=40, steps_per_period=32)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(designs)
def test_melnikov_output_is_finite_and_coherent(p: GearParams) -> None:
    r = melnikov(p, omega_scan=(0.2, 2.0, 8))
    strict_json(dumps(r))
    if not r.applicable:
        assert r.chaos_possible is None and r.branches is None
        return
    assert r.chaos_possible == any(b.sign_change for b in r.branches.values())
    for b in r.branches.values():
        assert b.min <= b.max
        assert b.sign_change == (b.min < 0.0 < b.max)
    for name, t in r.thresholds.items():
        if t.nearest is not None:  # |value - nearest|, positive on the safe side
            assert abs(t.margin) == abs(t.value - t.nearest)
            safe = any((lo is None or t.value >= lo) and (hi is None or t.value <= hi)
                       for lo, hi in t.no_chaos)  # fmt: skip
            assert t.margin == 0.0 or (t.margin > 0.0) == safe
            own = [v for v in t.critical_values if (v > 0.0) == (t.value > 0.0)]
            amplitude = name in ("F_e1", "k_p1", "F_p1") and t.value != 0.0 and own
            pool = own if amplitude else t.critical_values  # an amplitude keeps its sign
            assert min(abs(t.value - v) for v in pool) == abs(t.margin)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(designs, st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)))
def test_numerics_output_is_finite_and_coherent(p: GearParams, start: tuple) -> None:
    cfg = SHORT.model_copy(update={"initial_state": list(start)})
    r = analyze(AnalysisRequest(params=p, settings=cfg))
    strict_json(dumps(r))
    num = r.numerics
    assert num.classification in {"periodic", "chaotic", "quasi_periodic", "diverged"}
    if num.classification == "periodic":
        assert num.period is not None and 1 <= num.period <= 64
    else:
        assert num.period is None
    if num.classification == "chaotic":
        assert num.lle is not None and num.lle > 0.0
    if num.forcing_period is None:
        assert num.classification != "periodic"
    worst = max(num.starts, key=lambda s: severity(s.classification, s.period))
    assert severity(num.worst_case.classification, num.worst_case.period) == severity(
        worst.classification, worst.period
    )
    assert r.verdict.consistent == (r.verdict.agreement != "numerics_only")
