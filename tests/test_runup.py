"""Run-ups (gearengine.studies.runup): the kernel on the integrated driver angle against an
independent DOP853 integration of Eq. (7) in SI units with events at the backlash edges, the
quasi-static jump speeds at a slow rate, the lag at a fast one, refusals before any compute,
and the job through a real server equal to the CLI's document."""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace

import httpx
import numpy as np
import pytest
from pydantic import ValidationError
from scipy.integrate import solve_ivp

from gearengine.cli.main import main
from gearengine.gate.rules import Rules
from gearengine.gate.runup import runup_failures
from gearengine.jsonio import dumps, error_lines
from gearengine.model.units import RPM
from gearengine.studies import jobs
from gearengine.studies.runup import run_local
from gearengine.studies.runup.compute import compute_chunk
from gearengine.studies.runup.profile import checked_runup, ramp_forcing, validated_runup
from gearengine.studies.runup.reading import jumps
from gearengine.studies.runup.request import RunupRequest
from gearengine.systems.spur_pair.forcing import packed_forcing
from gearengine.systems.spur_pair.kernels.phase import ramp_forcing_at
from gearengine.systems.spur_pair.kernels.smooth import forcing_at
from tests._polling import poll
from tests.conftest import ROOT, Server

CI_DESIGN = json.loads((ROOT / "examples" / "ci" / "design.json").read_text())["design"]


def _request(**fields: object) -> dict:
    return {"design": CI_DESIGN, **fields}


def test_a_run_up_says_other_responses_can_coexist() -> None:
    """A run-up showed 7.97 um at 6,000 rpm where basins find 18.2 and 73.2 um too, and said
    nothing of them (fourth new-user review): its notes say it follows one response."""
    r = validated_runup(_request(from_speed="3500 rpm", to_speed="3600 rpm", rate="2000 rpm/s",
                                 direction="up", ensemble={"size": 2}))  # fmt: skip
    said = "other responses can coexist at a speed (gearengine basins"
    assert any(said in note for note in run_local(r).notes)


def test_ramp_forcing_without_acceleration_is_the_stationary_forcing() -> None:
    """beta = 0: the phase record reproduces Eq. (9)'s forcing at absolute time exactly."""
    r = validated_runup(_request(from_speed="1500 rpm", to_speed="2000 rpm", rate="1000 rpm/s"))
    conv = r.conversion
    assert conv is not None and r.params is not None
    wn = 1.0 / conv.time_scale_s
    f = ramp_forcing(r.params, 1500 * RPM, wn)
    kc, fm, fc = packed_forcing(r.params)
    record = np.array([fm, 0.0, 1500 * RPM / wn, 0.0, 0.0])
    for t in (0.0, 1.3, 47.9, 1234.5):
        assert ramp_forcing_at(t, f.kc, record, f.fc) == pytest.approx(
            forcing_at(t, kc, fm, fc), rel=1e-12, abs=1e-14
        )


def _dop853_eq7(request: RunupRequest, t_end: float, samples_per_mesh: int = 200):
    """Eq. (7) in SI units for examples/ci/design.json, written from the paper, not from the
    engine: m x'' + c x' + k(t)
    f_h(x) = F_m(t) - m e''(t) + m r_a / I_a T_p(t), every excitation at the driver angle
    phi(t) = w0 t + a t^2 / 2 of the linear ramp, f_h of Eq. (6) with alpha = 0, DOP853
    (rtol 1e-10) restarted at every event x = +-b. Returns a dense sampler x(t) and the event
    times with the region entered."""
    ra, rb, ia, ib = 0.03, 0.05, 2e-3, 8e-3
    za, km, k1, b = 18, 1e8, 1e7, 50e-6
    e1, tp, torque, zeta = 5e-6, 4.0, 40.0, 0.05
    m = ia * ib / (ib * ra**2 + ia * rb**2)
    c = 2.0 * zeta * math.sqrt(km * m)
    knots = request.knots()

    def speed(t: float) -> tuple[float, float, float]:  # (phi, w, dw/dt) of the profile
        phi = 0.0
        for (t0, w0), (t1, w1) in itertools.pairwise(knots):
            a = (w1 - w0) / (t1 - t0)
            if t <= t1 or t1 == knots[-1][0]:
                s = t - t0
                return phi + w0 * s + 0.5 * a * s * s, w0 + a * s, a
            phi += 0.5 * (w0 + w1) * (t1 - t0)
        raise AssertionError

    def rhs(t: float, y: np.ndarray, region: int) -> list[float]:
        phi, w, a = speed(t)
        k = km + k1 * math.cos(za * phi)
        fh = y[0] - b if region > 0 else (y[0] + b if region < 0 else 0.0)
        ee = -e1 * ((za * w) ** 2 * math.cos(za * phi) + za * a * math.sin(za * phi))  # e''
        fm = torque / ra + ib * (a * ra / rb) / rb
        force = fm - m * ee + m * ra / ia * tp * math.cos(phi)
        return [y[1], (force - c * y[1] - k * fh) / m]

    def edge(level: float, direction: int) -> Callable[..., float]:
        def event(t: float, y: np.ndarray, region: int) -> float:
            return y[0] - level

        event.terminal = True
        event.direction = direction
        return event

    leaving = {  # the edges a region is left through, with their crossing direction
        1: [edge(b, -1)],
        0: [edge(b, 1), edge(-b, -1)],
        -1: [edge(-b, 1)],
    }
    y = np.array([b + torque / ra / km, 0.0])  # static contact, as the run-up starts
    t, region = 0.0, 1
    pieces, events = [], []
    while t < t_end:
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-10, atol=1e-16,
                        args=(region,), events=leaving[region], dense_output=True)  # fmt: skip
        pieces.append((t, sol.t[-1], sol.sol))
        y, t = sol.y[:, -1].copy(), sol.t[-1]
        if sol.status == 1:
            y[0] = b if y[0] > 0 else -b
            region = (1 if y[1] > 0 else 0) if y[0] > 0 else (-1 if y[1] < 0 else 0)
            events.append((t, region))
    mesh = za * knots[-1][1] / (2.0 * math.pi)

    def sample(t0: float, t1: float) -> np.ndarray:
        ts = np.linspace(t0, t1, max(2, int((t1 - t0) * mesh * samples_per_mesh)))
        out = np.empty_like(ts)
        for lo, hi, f in pieces:
            inside = (ts >= lo) & (ts <= hi)
            if inside.any():
                out[inside] = f(ts[inside])[0]
        return out

    return sample, events


def test_runup_follows_an_independent_integration_of_eq7() -> None:
    """DTE envelope and contact status of every bin of a fast up-and-down ramp through the
    separating branch (4300-4500 rpm at 4000 rpm/s) against DOP853 of the SI model."""
    r = validated_runup(_request(from_speed="4300 rpm", to_speed="4500 rpm", rate="4000 rpm/s",
                           direction="up_down", settle_periods=0,
                           ensemble={"size": 1}))  # fmt: skip
    result = run_local(r)
    sample, events = _dop853_eq7(r, r.duration_s())
    bins = [*result.up.bins, *result.down.bins]  # type: ignore[union-attr]
    assert len(bins) == 8
    for k, bn in enumerate(bins):
        t0, t1 = bn.time_s
        x = sample(t0, t1)
        dte = (x.max() - x.min()) * 1e6
        assert bn.dte_peak_to_peak_um == pytest.approx(dte, rel=2e-3), (k, bn.speed_rpm)
        # time in the clearance from the exact event times
        marks = [(t0, _region_at(events, t0))] + [(t, g) for t, g in events if t0 < t < t1]
        sep = sum(min(t1, nxt) - t for (t, g), nxt in
                  zip(marks, [m[0] for m in marks[1:]] + [t1], strict=True) if g == 0)  # fmt: skip
        assert bn.separation_fraction == pytest.approx(sep / (t1 - t0), abs=0.01), k
        assert (bn.contact == "separation") == (sep > 0)
        assert bn.back_flank_fraction == 0.0 and not any(g < 0 for _, g in events)
    assert min(b.separation_fraction for b in bins) > 0.2  # the separating branch


def _region_at(events: list[tuple[float, int]], t: float) -> int:
    before = [g for s, g in events if s <= t]
    return before[-1] if before else 1


def test_slow_runup_reproduces_the_quasi_static_jumps() -> None:
    """examples/ci/design.json at 40 N m: at 100 rpm/s the jump up and the jump down agree
    with the continuation sweep (the hysteresis loop) within its grid step."""
    r = validated_runup(_request(from_speed="3700 rpm", to_speed="4400 rpm", rate="100 rpm/s",
                           direction="up_down", ensemble={"size": 1}))  # fmt: skip
    result = run_local(r, workers=2)
    step = result.quasi_static.grid_step_rpm
    for name, sense in (("up", 1), ("down", -1)):
        branch = getattr(result, name)
        (jump,) = [j for j in branch.jumps if (j.to_um - j.from_um) * sense > 0]
        (quasi,) = getattr(result.quasi_static, name).jumps
        assert jump.quasi_static_speed_rpm == quasi.speed_rpm
        assert abs(jump.lag_rpm) <= step, (name, jump)
    up, down = result.up.jumps[0], result.down.jumps[0]  # type: ignore[union-attr]
    assert 3850 <= down.speed_rpm < up.speed_rpm <= 4250  # the loop: up above down


def test_a_fast_ramp_lags_the_quasi_static_jump() -> None:
    """At 20 000 rpm/s the response needs time to move to the new branch: the run-down's
    jump comes later (lower speed) than the quasi-static one, by more than at 1000 rpm/s."""
    lags = {}
    for rate in ("1000 rpm/s", "20000 rpm/s"):
        r = validated_runup(_request(from_speed="3500 rpm", to_speed="4500 rpm", rate=rate,
                               direction="up_down", ensemble={"size": 1}))  # fmt: skip
        result = run_local(r, workers=2)
        (jump,) = [j for j in result.down.jumps if j.to_um < j.from_um]  # type: ignore[union-attr]
        lags[rate] = jump.lag_rpm
    assert lags["20000 rpm/s"] > lags["1000 rpm/s"] >= 0


@pytest.mark.parametrize(
    ("fields", "path", "words"),
    [
        ({"rate": 0}, "rate", "positive"),
        ({"rate": "-500 rpm/s"}, "rate", "positive"),
        ({"rate": "1000 rpm"}, "rate", "dimension"),
        ({"to_speed": "300000 rpm"}, "to_speed", "plausible range"),
        ({"from_speed": "0.01 rpm"}, "from_speed", "plausible range"),
        ({"to_speed": "400 rpm"}, "to_speed", "above from_speed"),
        ({"rate": None, "duration": "3000 s"}, "duration", "budget"),
        ({"direction": "sideways"}, "direction", "up"),
    ],
)
def test_bad_ramps_are_refused_naming_the_field(fields: dict, path: str, words: str) -> None:
    ramp = _request(from_speed="500 rpm", to_speed="6000 rpm", rate="1000 rpm/s")
    body = {k: v for k, v in {**ramp, **fields}.items() if v is not None}
    with pytest.raises(ValidationError) as exc:
        validated_runup(body)
    lines = error_lines(exc.value)
    assert any(line.startswith(f"{path}:") and words in line for line in lines), lines


def test_a_bin_wider_than_a_quarter_of_the_range_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """``runup --bin 10000`` over 1000-6000 rpm ran one bin over the whole range, its FTLE
    averaged over it, and the chaotic bins 50 rpm bins find vanished unsaid (new-user review of
    issue 30): a bin wider than a quarter of the range is refused, naming the field (and the
    option) in the library, the API and the CLI; the default 50 rpm stays allowed on a narrow
    profile (4000-4100 rpm: two bins)."""
    from fastapi.testclient import TestClient

    from service.core.config import Settings
    from service.main import create_app

    ramp = _request(from_speed="1000 rpm", to_speed="6000 rpm", rate="2000 rpm/s")
    with pytest.raises(ValidationError) as exc:
        validated_runup({**ramp, "bin_rpm": 1250.5})
    (line,) = error_lines(exc.value)
    assert line.startswith(
        "bin_rpm: a bin of 1250.5 rpm is wider than a quarter of the profile's 1000-6000 rpm range"
    )
    assert "give at most 1250 rpm" in line
    assert validated_runup({**ramp, "bin_rpm": 1250}).bin_rpm == 1250
    assert validated_runup(_request(from_speed="4000 rpm", to_speed="4100 rpm", rate="5000 rpm/s"))
    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0))) as client:
        r = client.post("/v1/runups", json={**ramp, "bin_rpm": 10000})
    assert r.status_code == 422 and "bin_rpm" in r.text and "quarter" in r.text, r.text
    path = tmp_path / "design.json"
    path.write_text(json.dumps({"design": CI_DESIGN}))
    code = main(["runup", str(path), "--from", "1000", "--to", "6000", "--rate", "2000",
                 "--bin", "10000"])  # fmt: skip
    assert code == 2
    assert "(the CLI's --bin)" in capsys.readouterr().err


def test_a_start_the_quasi_static_loop_would_not_use_is_refused(tmp_path: Path) -> None:
    """The loop starts its first line where the members start and its second where the first
    ended, so a ``quasi_static`` start was silently replaced (stop 40's note): it is refused,
    naming the field, in the library and the API; the default start, which every stored request
    carries when it is read back, stays accepted."""
    from fastapi.testclient import TestClient

    from service.core.config import Settings
    from service.main import create_app

    ramp = _request(from_speed="4000 rpm", to_speed="4100 rpm", rate="5000 rpm/s")
    box = {"count": 4, "box": [[-1, 1], [-1, 1]]}
    given = {"initial_state": [0.5, 0.0], "initial_states": [[0.5, 0.0]],
             "random_initial_states": box}  # fmt: skip
    for name, value in given.items():
        with pytest.raises(ValidationError) as exc:
            validated_runup({**ramp, "quasi_static": {name: value}})
        (line,) = error_lines(exc.value)
        assert line.startswith(f"quasi_static.{name}: the quasi-static loop starts where"), line
    stored = validated_runup(ramp).model_dump_json()  # as the job store keeps it
    reread = checked_runup(jobs.validated_json(jobs.kind("runup"), stored))
    assert reread.quasi_static.initial_state == [0.01, 0.01]
    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0))) as client:
        r = client.post("/v1/runups", json={**ramp, "quasi_static": {"initial_state": [0.5, 0]}})
    assert r.status_code == 422 and "quasi_static" in r.text and "initial_state" in r.text, r.text


def test_a_chunk_is_the_same_bytes_twice() -> None:
    r = validated_runup(_request(from_speed="4000 rpm", to_speed="4100 rpm", rate="5000 rpm/s",
                           ensemble={"size": 2}))  # fmt: skip
    assert compute_chunk(r, 1) == compute_chunk(r, 1)
    assert compute_chunk(r, 0) != compute_chunk(r, 1)  # the perturbed start differs


def test_the_service_job_is_the_cli_document(tmp_path: Path) -> None:
    """POST /v1/runups on a real server (workers, SQLite): 202 + Location, then the result is
    byte for byte what ``gearengine runup --json`` writes; a bad ramp is a 422 naming the field
    before anything is stored."""
    body = _request(from_speed="4000 rpm", to_speed="4300 rpm", rate="6000 rpm/s",
                    direction="up_down", ensemble={"size": 2}, settle_periods=20)  # fmt: skip
    design_file = tmp_path / "runup.json"
    design_file.write_text(json.dumps(body))
    out = tmp_path / "out.json"
    assert main(["runup", str(design_file), "--json", str(out), "--plot",
                 str(tmp_path / "runup.png")]) == 0  # fmt: skip
    assert (tmp_path / "runup.png").read_bytes()[:4] == b"\x89PNG"
    server = Server(tmp_path / "data")
    try:
        with httpx.Client(base_url=server.url, timeout=60) as http:
            bad = http.post("/v1/runups", json={**body, "rate": "0 rpm/s"})
            assert bad.status_code == 422
            assert "rate" in json.dumps(bad.json()["errors"])
            assert http.get("/v1/runups").json()["total"] == 0
            posted = http.post("/v1/runups", json=body)
            assert posted.status_code == 202
            location = posted.headers["location"]
            poll(lambda: http.get(location).json(), timeout=300, interval=0.5)
            result = http.get(f"{location}/result")
            assert result.status_code == 200
            assert result.content == out.read_bytes()
            plot = http.get(f"{location}/plot", params={"format": "png"})
            assert plot.status_code == 200 and plot.content[:4] == b"\x89PNG"
    finally:
        server.stop()
    assert dumps(run_local(validated_runup(body))) == out.read_text()


def test_the_gate_runs_up_and_down_and_names_the_speeds(tmp_path: Path) -> None:
    """check --runup: the run-down holds the separating branch below the run-up's jump, so a
    dynamic-factor limit fails it from a lower speed (the hysteresis), naming both branches."""
    report = tmp_path / "report.json"
    code = main(["check", str(ROOT / "examples" / "ci" / "design.json"), "--speed", "3700:4400",
                 "--speed-points", "8", "--runup", "1000", "--max-dynamic-factor", "2.5",
                 "--json", str(report)])  # fmt: skip
    assert code == 1
    failures = json.loads(report.read_text())["failures"]
    spans = {f["rule"]: f["speeds_rpm"] for f in failures if f["rule"].startswith("run-")}
    up, down = spans["run-up: dynamic factor > 2.5"], spans["run-down: dynamic factor > 2.5"]
    assert down[0] < up[0] <= 4200 and up[1] == down[1] == 4400


def test_a_passing_gate_says_which_run_ups_it_ran(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """``check --speed --torque --runup 2000`` that passed said nothing of its run-ups (no
    rate, levels or result in the text or the JSON), though they took most of its time
    (new-user review of issue 30): a pass says what it ran, in the text and the report."""
    report = tmp_path / "report.json"
    code = main(["check", str(ROOT / "examples" / "ci" / "design.json"), "--speed", "3500:3700",
                 "--speed-points", "5", "--torque", "30:40", "--torque-points", "2",
                 "--runup", "2000", "--json", str(report)])  # fmt: skip
    assert code == 0
    out = capsys.readouterr().out
    assert (
        "  run-ups: run-up and run-down at 2000 rpm/s through 3500-3700 rpm (50 rpm bins, 4 "
        "starts) at each of the 2 levels, torque 30 N*m to torque 40 N*m: no failing window\n"
    ) in out
    ran = json.loads(report.read_text())["runup"]
    assert (ran["rate_rpm_s"], ran["speeds_rpm"], ran["directions"]) == (
        2000.0, [3500.0, 3700.0], ["up", "down"])  # fmt: skip
    assert [lv["torque"]["value"] for lv in ran["levels"]] == [30.0, 40.0]
    assert ran["failing_windows"] == 0


def test_chaos_fails_the_gate_only_when_it_lasts(tmp_path: Path) -> None:
    """A run of chaotic bins fails after CHAOS_SECONDS, not before (the rule over time)."""
    r = validated_runup(_request(from_speed="4000 rpm", to_speed="4400 rpm", rate="4000 rpm/s",
                           ensemble={"size": 2}))  # fmt: skip
    result = run_local(r)
    bins = result.up.bins  # type: ignore[union-attr]
    rules = Rules()
    assert runup_failures(result, rules, {}) == []  # periodic throughout
    for n, fails in ((1, False), (len(bins), True)):  # 0.0125 s of chaos, then 0.1 s
        marked = [b.model_copy(update={"chaotic": True}) if k < n else b
                  for k, b in enumerate(bins)]  # fmt: skip
        chaotic = result.model_copy(update={"up": result.up.model_copy(update={"bins": marked})})
        found = runup_failures(chaotic, rules, {})
        assert bool(found) == fails
        if fails:
            assert found[0].speeds_rpm == [4000.0, 4400.0] and "chaotic" in found[0].rule


def test_a_jump_caught_half_way_by_a_bin_is_one_jump() -> None:
    """Steps in one sense at neighbouring edges join into one jump at the largest step; a step
    back the other way is a jump of its own."""
    found = jumps([100.0, 150.0, 200.0, 250.0], [10.0, 20.0, 50.0, 50.0, 12.0], b_um=50.0)
    assert [(j.speed_rpm, j.from_um, j.to_um) for j in found] == [
        (150.0, 10.0, 50.0),
        (250.0, 50.0, 12.0),
    ]


def test_the_gate_hands_each_level_the_validated_design(monkeypatch: pytest.MonkeyPatch) -> None:
    """check --runup: each torque level's run-up carries the envelope's validated design at
    the level's torque (not a dump of it read again: its own unit readings stay), with the
    same ramp; nothing is re-validated from a document per level."""
    import gearengine.gate.runup as gate
    from gearengine.gate.envelope import EnvelopeReport
    from gearengine.studies.runup.results import RunupResult
    from gearengine.studies.sweep.points import PhysicalValue
    from gearengine.studies.sweep.request import validated as sweep_request

    seen: list[RunupRequest] = []

    def fake_run(request: RunupRequest, workers: int = 1) -> RunupResult:
        seen.append(request)
        return RunupResult.model_construct(up=None, down=None)

    monkeypatch.setattr(gate, "run_local", fake_run)
    doc = json.loads((ROOT / "examples" / "ci" / "design.json").read_text())
    sweep = sweep_request({"design": doc.get("design", doc), "axes": [
        {"parameter": "speed", "start": "3500 rpm", "stop": "4500 rpm", "num": 5},
        {"parameter": "torque", "start": "10 N*m", "stop": "40 N*m", "num": 2}]})  # fmt: skip
    levels = [{"torque": PhysicalValue(value=t, unit="N*m")} for t in (10.0, 40.0)]
    windows = [SimpleNamespace(level=lv) for lv in levels]
    sweep_result = SimpleNamespace(windows=windows)
    report = EnvelopeReport.model_construct(failures=[], rules=Rules(), sweep=sweep_result)
    runups = gate.gate_runups(sweep, 20000.0)  # fast enough that half CHAOS_SECONDS is 500 rpm
    assert runups.levels == levels
    gate.gate_envelope(report, runups)
    assert [r.design.torque for r in seen] == [10.0, 40.0]
    for r in seen:
        assert r.design.readings == sweep.design.readings
        assert r.design.model_copy(update={"torque": sweep.design.torque}) == sweep.design
        assert (r.from_speed, r.to_speed) == (seen[0].from_speed, seen[0].to_speed)
    assert seen[0].bin_rpm == 250.0  # the grid step
    # three grid speeds: a 500 rpm step is over a quarter of the range, the bins a quarter
    coarse = sweep_request({"design": doc.get("design", doc), "axes": [
        {"parameter": "speed", "start": "3500 rpm", "stop": "4500 rpm", "num": 3},
        {"parameter": "torque", "start": "10 N*m", "stop": "40 N*m", "num": 2}]})  # fmt: skip
    ran = gate.gate_envelope(report, gate.gate_runups(coarse, 20000.0)).runup
    assert ran is not None and ran.bin_rpm == 250.0 and ran.failing_windows == 0
    assert seen[-1].bin_rpm == 250.0


def test_the_gate_runs_up_at_the_levels_of_the_envelope_windows() -> None:
    """The run-ups are made (and refused) before the envelope is computed, so their torque
    levels come from the grid, not from the computed speed windows: they are the windows'
    levels, to the last bit, on a grid whose levels are not round (5-60 N*m in 7 points)."""
    from gearengine.gate.runup import gate_runups
    from gearengine.studies.sweep import run_local as sweep_local
    from gearengine.studies.sweep.request import validated as sweep_request

    doc = json.loads((ROOT / "examples" / "ci" / "design.json").read_text())
    sweep = sweep_request({"design": doc.get("design", doc), "axes": [
        {"parameter": "speed", "start": "3500 rpm", "stop": "4500 rpm", "num": 2},
        {"parameter": "torque", "start": "5 N*m", "stop": "60 N*m", "num": 7}],
        "settings": {"transient_periods": 4, "record_periods": 4,
                     "steps_per_period": 32}})  # fmt: skip
    windows = sweep_local(sweep).windows
    assert windows is not None
    assert gate_runups(sweep, 2000.0).levels == [w.level for w in windows]


def test_the_assembly_reads_the_design_converted_with_the_plan(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The plan carries the conversion its system was built with: assembling a run-up converts
    the design once (for its plan), not a second time to read the members."""
    from gearengine.studies.runup.compute import RUNUP_JOB, chunk_counts
    from gearengine.studies.runup.profile import runup_plan

    r = validated_runup(_request(from_speed="4300 rpm", to_speed="4500 rpm", rate="4000 rpm/s",
                           settle_periods=0, ensemble={"size": 1}))  # fmt: skip
    assert runup_plan(r).conversion == r.model()[1]
    chunks = [compute_chunk(r, i) for i in range(len(chunk_counts(r, 1)))]
    calls = []
    model = RunupRequest.model
    monkeypatch.setattr(RunupRequest, "model", lambda self: calls.append(1) or model(self))
    result = RUNUP_JOB.assemble(r, chunks)
    assert len(calls) == 1  # its plan's: reading the members converts no more
    monkeypatch.undo()
    assert result == run_local(r)


def test_a_pair_run_up_converts_its_design_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The members integrate the pair that validation converted: the plan converts no more."""
    import gearengine.systems.designs as designs
    from gearengine.studies.runup.profile import runup_plan

    r = validated_runup(_request(from_speed="4300 rpm", to_speed="4500 rpm", rate="4000 rpm/s"))
    conversions = []
    convert = designs.convert_design
    monkeypatch.setattr(designs, "convert_design", lambda d: conversions.append(d) or convert(d))
    plan = runup_plan(r)
    assert conversions == [] and plan.conversion is r.conversion
    assert plan.system.params == r.params


def test_a_run_up_alone_prints_no_quasi_static_down_jump() -> None:
    """``runup --direction up`` printed the quasi-static loop's "quasi-static down" jump as if a
    run-down had been made (review of issue 30, item 7): only the directions run are printed."""
    from gearengine.cli.runup import quasi_static_lines
    from gearengine.studies.runup.results import RunupResult
    from tests.conftest import ROOT

    both = RunupResult.model_validate_json((ROOT / "tests/golden/runup-ci.json").read_text())
    assert both.quasi_static.down.jumps and both.quasi_static.up.jumps
    assert [line.split(":")[0] for line in quasi_static_lines(both)] == [
        "quasi-static up", "quasi-static down"]  # fmt: skip
    up = quasi_static_lines(both.model_copy(update={"down": None}))
    assert up == ["quasi-static up: jump at 4150 rpm, 25.3 -> 53.7 µm"]


def test_chaos_in_the_ramps_transient_is_said_to_be_transient() -> None:
    """A run-up flagged chaos where the steady state (and ``check``) finds none and neither said
    so (review of issue 30, item 7): chaotic bins over a periodic quasi-static branch are named
    as the ramp's transient, in the gate's failure and by ``transient_chaos`` (the notes)."""
    from gearengine.studies.runup.reading import transient_chaos, transient_note
    from gearengine.studies.runup.results import RunupResult

    golden = RunupResult.model_validate_json((ROOT / "tests/golden/runup-ci.json").read_text())
    assert golden.up is not None
    bins = [b.model_copy(update={"chaotic": True}) if 3600 <= b.speed_rpm[0] < 3800 else b
            for b in golden.up.bins]  # fmt: skip
    up = golden.up.model_copy(update={"bins": bins})
    result = golden.model_copy(update={"up": up, "down": None})
    spans = transient_chaos(up, result.quasi_static.up)
    assert spans == [[3600.0, 3800.0]]
    assert transient_note("up", spans).startswith("run-up: chaotic bins at 3600-3800 rpm where")
    (window,) = runup_failures(result, Rules(), {}, chaos_seconds=0.0)
    assert window.rule.endswith(
        "where the quasi-static continuation (one start followed from speed to speed) is not "
        "chaotic: the ramp's transient, or an attractor it does not follow"
    )  # not "the steady state is not chaotic": check's basin starts may find chaos there

    points = [p.model_copy(update={"classification": "chaotic"})
              for p in result.quasi_static.up.points]  # fmt: skip
    steady = result.quasi_static.up.model_copy(update={"points": points})
    assert transient_chaos(up, steady) == []
    qs = result.quasi_static.model_copy(update={"up": steady})
    (window,) = runup_failures(result.model_copy(update={"quasi_static": qs}), Rules(), {}, 0.0)
    assert "transient" not in window.rule


def test_a_quasi_static_jump_is_lagged_by_one_ramp_jump() -> None:
    """A run-up reported 'jump at 4850 rpm ...; quasi-static at 4050 rpm, lag +800 rpm' for a
    quasi-static jump already paired with the ramp's jump at 4100 rpm (new-user review of issue
    30): each quasi-static jump is the lag of the nearest ramp jump of its sense only."""
    from gearengine.studies.runup.reading import with_lags
    from gearengine.studies.runup.results import RunupJump

    ramp = [RunupJump(speed_rpm=4100.0, from_um=25.0, to_um=50.0),
            RunupJump(speed_rpm=4850.0, from_um=48.6, to_um=61.1)]  # fmt: skip
    quasi = [RunupJump(speed_rpm=4050.0, from_um=25.0, to_um=52.0)]
    first, second = with_lags(ramp, quasi, "up")
    assert (first.quasi_static_speed_rpm, first.lag_rpm) == (4050.0, 50.0)
    assert second.quasi_static_speed_rpm is None and second.lag_rpm is None


@pytest.mark.parametrize("direction", ["up_down", "down"])
def test_the_quasi_static_loop_joins_and_starts_where_the_ramp_does(direction: str) -> None:
    """examples/ci/design.json from 3600 to 4000 rpm ends inside its hysteresis loop: two
    responses coexist in the top bin (19 µm and 57 µm). The quasi-static down line started from
    the sweep's default start in the backlash gap and took the 57 µm one, so the loop did not
    join (18.7 µm up, 57.4 µm down in the top bin) and printed a down jump the ramp's run-down
    never made (new-user review of issue 30, the z = 23/67 example over 1000-6000 rpm): the
    down line continues from where the up line ended and, run down alone, starts from the
    members' start (static contact), as the ramp does."""
    r = validated_runup(_request(from_speed="3600 rpm", to_speed="4000 rpm", rate="2000 rpm/s",
                           direction=direction, ensemble={"size": 1}))  # fmt: skip
    result = run_local(r)
    up, down = result.quasi_static.up.points, result.quasi_static.down.points
    assert down[0].speed_rpm == up[-1].speed_rpm == 3975.0
    assert result.down is not None
    first = result.down.bins[0].dte_peak_to_peak_um
    assert first is not None and down[0].dte_peak_to_peak_um is not None
    assert abs(down[0].dte_peak_to_peak_um - first) < 0.1 * first  # the ramp's response
    if direction == "up_down":
        assert down[0].dte_peak_to_peak_um == pytest.approx(up[-1].dte_peak_to_peak_um, rel=0.01)
    assert result.quasi_static.down.jumps == [] == result.down.jumps
    assert not any("start on different responses" in n for n in result.notes)


def test_a_ramp_and_a_continuation_starting_apart_are_said_to() -> None:
    """Where the ramp's first bin and the continuation at its centre differ as a jump does,
    the notes say they start on different responses (not two silently different answers)."""
    from gearengine.studies.runup.reading import start_note
    from gearengine.studies.runup.results import RunupResult

    golden = RunupResult.model_validate_json((ROOT / "tests/golden/runup-ci.json").read_text())
    assert golden.down is not None
    b_um = 50.0
    assert start_note("down", golden.down, golden.quasi_static.down, b_um) is None
    first = golden.down.bins[0].model_copy(update={"dte_peak_to_peak_um": 19.4})
    apart = golden.down.model_copy(update={"bins": [first, *golden.down.bins[1:]]})
    note = start_note("down", apart, golden.quasi_static.down, b_um)
    assert note is not None and note.startswith(
        "run-down and the quasi-static down start on different responses: 19.4 µm in the "
        "ramp's first bin (4450-4500 rpm)"
    )


def test_the_gates_run_up_bins_resolve_its_chaos_rule(tmp_path: Path) -> None:
    """The gate's run-up bins were the grid step: 227 rpm bins (0.114 s at 2000 rpm/s) on the
    z = 23/67 envelope, longer than the CHAOS_SECONDS a chaotic run may last, and the verdict
    changed with --speed-points (fourth new-user review). Each bin now lasts at most half of
    it: 50 rpm at 2000 rpm/s, as the runup command's own bins."""
    from gearengine.gate.runup import CHAOS_SECONDS

    report = tmp_path / "report.json"
    main(["check", str(ROOT / "examples" / "ci" / "design.json"), "--speed", "3500:4500",
          "--speed-points", "2", "--runup", "2000", "--json", str(report)])  # fmt: skip
    ran = json.loads(report.read_text())["runup"]
    assert ran["bin_rpm"] == 2000 * CHAOS_SECONDS / 2 == 50.0


def test_a_torque_ramp_ends_at_the_design_converted_at_its_end_torque() -> None:
    """A torque ramp's plan ends at the mean force of the design converted at ``to_torque`` (an
    operating point at that torque, as a sweep's grid point reads it: ``point_params``); a
    design whose ISO 6336 stiffness depends on the load is refused, naming to_torque."""
    from gearengine.studies.runup.profile import runup_plan
    from gearengine.studies.sweep.axes import point_params

    ramp = {"from_speed": "4300 rpm", "to_speed": "4500 rpm", "rate": "4000 rpm/s",
            "to_torque": "60 N*m"}  # fmt: skip
    r = validated_runup(_request(**ramp))
    assert r.params is not None and r.to_torque is not None
    f0, f1 = runup_plan(r).mean_force
    end = point_params(r.params, r.design, {"torque": r.to_torque})
    assert (f0, f1) == (r.params.mean_force, end.mean_force)
    assert f1 == pytest.approx(1.5 * f0, rel=1e-12)  # 60 against the design's 40 N*m
    iso = json.loads((ROOT / "examples" / "design-geometry.json").read_text())["design"]
    with pytest.raises(ValidationError, match="to_torque") as refused:
        validated_runup({"design": iso, **ramp, "to_torque": "90 N*m"})
    assert "depends on the load" in str(refused.value)
