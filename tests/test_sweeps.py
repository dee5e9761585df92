"""Sweeps in the engine: enumeration, chunking, validation, determinism, CSV, figures."""

from __future__ import annotations

import csv
import gc
import io
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from pydantic import ValidationError

from gearengine.cli import main
from gearengine.homoclinic.thresholds import chaos_possible
from gearengine.homoclinic.verdict import melnikov
from gearengine.jsonio import error_lines
from gearengine.model.aliases import with_aliases
from gearengine.numerics.runs import work
from gearengine.numerics.simulation import SimulationSettings, simulate_batch
from gearengine.plots.sweep import sweep_figure
from gearengine.studies.jobs import cyclic_gc_paused
from gearengine.studies.sweep import (
    SweepPlan,
    SweepResult,
    agreement_table,
    balanced_chunk_points,
    compute_chunk,
    compute_chunk_json,
    export,
    run_local,
    sweep_work,
    to_csv,
    validated,
)
from tests.conftest import PAPER_PARAMS

SHORT = {"transient_periods": 50, "record_periods": 50, "steps_per_period": 64}


def sweep(*axes: tuple[str, float, float, int], **extra: Any) -> dict[str, Any]:
    """A request document with short settings."""
    return {
        "params": PAPER_PARAMS,
        "settings": SHORT,
        "axes": [{"parameter": p, "start": a, "stop": b, "num": n} for p, a, b, n in axes],
        **extra,
    }


def test_grid_is_enumerated_first_axis_fastest_and_chunked_without_gaps() -> None:
    req = validated(sweep(("F_e1", 0.0, 0.3, 5), ("Omega_e", 0.4, 0.6, 3)))
    plan = SweepPlan(req, chunk_points=4)
    assert plan.n_chunks() == 4 and plan.point_counts() == [4, 4, 4, 3]
    order = [ix for i in range(plan.n_chunks()) for ix in plan.chunk(i).points]
    assert order == [(i0, i1) for i1 in range(3) for i0 in range(5)]
    with pytest.raises(IndexError):
        plan.chunk(4)


def test_continuation_chunks_are_lines_with_branches() -> None:
    req = validated(
        sweep(("F_e1", 0.0, 0.3, 4), ("Omega_e", 0.4, 0.6, 2), continuation=True, direction="both")
    )
    plan = SweepPlan(req, chunk_points=3)
    assert plan.n_chunks() == 4 and req.n_points() == 16
    up, down = plan.chunk(1), plan.chunk(3)
    assert up.branch == "up" and up.points == [(0, 1), (1, 1), (2, 1), (3, 1)]
    assert down.branch == "down" and down.points == [(3, 1), (2, 1), (1, 1), (0, 1)]


@pytest.mark.parametrize(
    ("doc", "path"),
    [
        (sweep(("F_e1", 0.0, 0.3, 0)), "axes[0].num"),
        (sweep(("F_e1", 0.0, 0.3, 3), ("F_e1", 0.1, 0.2, 3)), "axes[1].parameter"),
        (sweep(("Fe1", 0.0, 0.3, 3)), "axes[0].parameter"),
        (sweep(("k_p1", 0.0, 0.3, 3)), "axes[0].parameter"),
        (sweep(("mu", 0.1, -0.1, 3)), "axes[0].stop"),
        (sweep(("Omega_e", 0.0, 1.0, 3)), "axes[0].start"),
        (sweep(("F_e1", 0.2, 0.2, 3)), "axes[0].stop"),
        (sweep(("F_e1", 0.0, 0.3, 3), direction="both"), "direction"),
        (sweep(("F_e1", 0.0, float("nan"), 3)), "axes[0].stop"),
        (sweep(("F_e1", 0.0, 0.3, 3), extra=1), "extra"),
        (sweep(), "axes"),
    ],
)
def test_invalid_sweeps_name_the_field(doc: dict[str, Any], path: str) -> None:
    with pytest.raises(ValidationError) as info:
        validated(doc)
    assert any(line.startswith(path + ":") for line in error_lines(info.value)), info.value


def test_point_cap_names_the_axes() -> None:
    with pytest.raises(ValidationError) as info:
        validated(sweep(("F_e1", 0.0, 0.3, 300), ("mu", 0.05, 0.1, 300)), max_points=40_000)
    assert error_lines(info.value)[0].startswith("axes: 90000 points")


def test_a_chunk_depends_only_on_request_and_index() -> None:
    """Same bytes when computed twice and whatever the neighbours in the SIMD batch."""
    req = validated(sweep(("F_e1", 0.15, 0.3, 12)))
    text = req.model_dump_json()
    assert compute_chunk_json(text, 1, 4) == compute_chunk_json(text, 1, 4)
    by_four = [p for i in range(3) for p in compute_chunk(req, i, 4)]
    by_five = [p for i in range(3) for p in compute_chunk(req, i, 5)]
    assert by_four == by_five
    assert run_local(req, chunk_points=4).points == by_four


def test_continuation_carries_the_final_state() -> None:
    req = validated(sweep(("F_e1", 0.2, 0.25, 3), continuation=True))
    points = compute_chunk(req, 0)
    settings = SimulationSettings(**SHORT)
    (first,) = simulate_batch([with_aliases(req.params, {"F_e1": 0.2})], settings)
    carried = settings.model_copy(update={"initial_state": first.final_state})
    (second,) = simulate_batch([with_aliases(req.params, {"F_e1": 0.225})], carried)
    assert points[0].lle == first.lle and points[1].lle == second.lle
    assert points[1].poincare_x == [s[0] for s in second.poincare]
    assert [p.branch for p in points] == ["up"] * 3


def test_backward_branch_runs_from_stop_to_start() -> None:
    req = validated(sweep(("F_e1", 0.2, 0.25, 3), continuation=True, direction="both"))
    result = run_local(req)
    assert [(p.branch, p.values["F_e1"]) for p in result.points] == [
        ("up", 0.2), ("up", 0.225), ("up", 0.25), ("down", 0.25), ("down", 0.225), ("down", 0.2)
    ]  # fmt: skip
    assert result.points[2].poincare_x != result.points[3].poincare_x  # other initial state


def test_melnikov_flag_equals_the_full_verdict() -> None:
    for fe in (0.0, 0.1, 0.19, 0.2, 0.3):
        params = with_aliases(validated(sweep(("F_e1", 0, 1, 2))).params, {"F_e1": fe})
        assert chaos_possible(params) == melnikov(params).chaos_possible


def test_paper_fig6_period_doubling() -> None:
    """Reference: 1T up to F_e1 = 0.21, 2T from 0.2125, 4T at 0.23 (500 + 500 periods)."""
    doc = sweep(("F_e1", 0.20, 0.23, 4))
    doc["settings"] = {"transient_periods": 500, "record_periods": 500, "steps_per_period": 200}
    points = run_local(validated(doc)).points
    assert [p.period for p in points] == [1, 1, 2, 4]
    assert [p.melnikov_chaos_possible for p in points] == [True] * 4
    assert {p.impact_regime for p in points} == {"single_sided"}


def test_csv_has_a_row_per_point_and_axis_columns() -> None:
    req = validated(sweep(("F_e1", 0.0, 0.3, 3), ("Omega_e", 0.4, 0.6, 2)))
    result = run_local(req)
    rows = list(csv.DictReader(io.StringIO("".join(to_csv(result)))))
    assert len(rows) == 6 and float(rows[4]["Omega_e"]) == 0.6 and float(rows[4]["F_e1"]) == 0.15
    assert rows[0]["melnikov_chaos_possible"] in ("true", "false")
    assert [float(x) for x in rows[1]["poincare_x [b]"].split()] == result.points[1].poincare_x
    counts = agreement_table(result.points)
    assert sum(counts.model_dump().values()) == 6


def test_csv_numbers_read_as_the_json_writes_them() -> None:
    """Every number of a CSV row is, verbatim, a number of the JSON result (so a cell reads as
    the JSON value, e.g. 0.00001 rather than 1e-05) and parses back to the same float."""
    req = validated(sweep(("F_e1", 0.0, 0.3, 3), ("Omega_e", 0.4, 0.6, 2)))
    result = run_local(req)
    small = result.points[0].model_copy(update={"lle": 1e-05, "poincare_x": [1e-07, 0.25]})
    result.points.append(small)  # numbers that repr writes in another form (1e-05, 1e-07)
    rows = list(csv.reader(io.StringIO("".join(to_csv(result)))))
    header = rows[0]
    assert rows[-1][header.index("lle [1/tau]")] == "0.00001"
    assert rows[-1][header.index("poincare_x [b]")] == "1e-7 0.25"
    for row, point in zip(rows[1:], result.points, strict=True):
        doc = point.model_dump_json()
        cells = dict(zip(header, row, strict=True))
        for name in ("lle", "lle_stderr"):
            if getattr(point, name) is not None:
                cell = cells[f"{name} [1/tau]"]
                assert f'"{name}":{cell},' in doc
                assert float(cell) == getattr(point, name)
        tokens = cells["poincare_x [b]"].split()
        assert "[" + ",".join(tokens) + "]" in doc
        assert [float(t) for t in tokens] == point.poincare_x


@pytest.mark.parametrize("text", ["upper", 'say "x"', "a,b", "two\nlines"])
def test_csv_text_cells_are_quoted_only_when_they_must_be(text: str) -> None:
    cell = export._text_cell(text)
    assert next(csv.reader(io.StringIO(cell + ",1\n"))) == [text, "1"]
    assert (cell == text) == (text == "upper")


def test_progress_reaches_the_total() -> None:
    seen: list[tuple[int, int]] = []
    req = validated(sweep(("F_e1", 0.0, 0.3, 5)))
    run_local(req, lambda done, total: seen.append((done, total)), chunk_points=2)
    assert seen == [(2, 5), (4, 5), (5, 5)]


def test_melnikov_threshold_of_fig6() -> None:
    """The F_e1 threshold at Omega_e = 0.5, mu = 0.07 with F~_m = 0.01 in the unperturbed
    system is 0.17795, the smaller loop's (the paper's first-order 0.19588 is README's
    ``mean_load: perturbation``)."""
    req = validated(sweep(("F_e1", 0.0, 0.3, 2)))
    critical = melnikov(req.params).thresholds["F_e1"].critical_values
    (v,) = [f for f in critical if 0.0 <= f <= 0.3]
    assert v == pytest.approx(0.177953, abs=1e-5)
    assert [chaos_possible(with_aliases(req.params, {"F_e1": f})) for f in (0.177, 0.179)] == [
        False,
        True,
    ]


def test_figures_render_as_png_and_svg() -> None:
    one = validated(sweep(("F_e1", 0.18, 0.3, 6)))
    two = validated(sweep(("F_e1", 0.0, 0.3, 4), ("Omega_e", 0.4, 0.8, 3)))
    for req in (one, two):
        points = run_local(req).points
        assert sweep_figure(req, points, "png").startswith(b"\x89PNG")
        assert b"<svg" in sweep_figure(req, points, "svg")[:500]


def test_cli_sweep_writes_json_csv_png_with_a_progress_bar(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    doc = tmp_path / "small.json"
    doc.write_text(json.dumps(sweep(("F_e1", 0.18, 0.3, 5))))
    assert main(["sweep", str(doc), "--out", str(tmp_path / "out")]) == 0
    out = tmp_path / "out"
    result = SweepResult.model_validate_json((out / "small.json").read_text())
    assert len(result.points) == 5
    assert (out / "small.csv").read_text().count("\n") == 6
    assert (out / "small.png").read_bytes().startswith(b"\x89PNG")
    assert "5/5 points" in capsys.readouterr().err


def test_cli_sweep_names_the_bad_field(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    doc = tmp_path / "bad.json"
    doc.write_text(json.dumps(sweep(("F_e1", 0.0, 0.3, 0))))
    assert main(["sweep", str(doc), "--out", str(tmp_path)]) == 2
    assert capsys.readouterr().err.startswith("axes[0].num:")


def test_sweep_work_costs_every_frequency_combination() -> None:
    """Found in review: the corners of an Omega_e axis cost 400k and 200k steps per point, but
    interior ratios to Omega_k = 1 need up to 12.8M; the budget must see the real total."""
    doc = {
        "params": {
            **PAPER_PARAMS,
            "stiffness": {"frequency": 1.0, "harmonics": [{"amplitude": 0.1}]},
        },
        "axes": [{"parameter": "Omega_e", "start": 0.5, "stop": 1.0, "num": 65}],
    }
    req = validated(doc)
    per_point = [
        work(with_aliases(req.params, {"Omega_e": v}), req.settings) for v in req.axes[0].values()
    ]
    assert sweep_work(req) == sum(per_point) == 279_800_000
    amplitude = validated(sweep(("F_e1", 0.0, 0.3, 31)))
    assert sweep_work(amplitude) == 31 * work(amplitude.params, amplitude.settings)


def test_csv_of_a_design_sweep_has_its_values_in_gear_units() -> None:
    """A design's sweep: the axes titled with their SI units and, where the display unit
    differs, also in it (rpm), the DTE in µm and the dynamic factor, equal to each point's
    ``physical``; axis cells as plain decimals; a sweep of params has no such columns."""
    doc = json.loads((Path(__file__).parents[1] / "examples" / "envelope-map.json").read_text())
    doc["settings"] = SHORT
    doc["axes"][0]["num"], doc["axes"][1]["num"] = 3, 2
    req = validated(doc)
    result = run_local(req)
    rows = list(csv.DictReader(io.StringIO("".join(to_csv(result, design=True)))))
    assert list(rows[0])[:5] == [
        "speed [rad/s]", "torque [N*m]", "speed [rpm]", "dte [um]", "dynamic_factor"
    ]  # fmt: skip
    assert [r["speed [rpm]"] for r in rows[:3]] == ["500", "3250", "6000"]
    assert all("e" not in r["speed [rad/s]"] and not r["torque [N*m]"].endswith(".0")
               for r in rows)  # fmt: skip
    for row, point in zip(rows, result.points, strict=True):
        assert point.physical is not None
        for key, title in (("torque", "torque [N*m]"), ("dte", "dte [um]")):
            assert float(row[title]) == point.physical[key].value
        assert int(row["periods_run"]) == point.periods_run
    plain = validated(sweep(("F_e1", 0.0, 0.3, 2)))
    header = next(csv.reader(io.StringIO("".join(to_csv(run_local(plain))))))
    assert header[:2] == ["F_e1", "branch"]


WORKQUEUE_RUN = """
import json, sys
from gearengine.studies.sweep import run_local, validated
doc = json.loads(sys.argv[1])
result = run_local(validated(doc), chunk_points=4, workers=2)
print(len(result.points))
"""


def test_threads_under_numbas_workqueue_layer_take_turns() -> None:
    """Where numba has neither OpenMP nor TBB it falls back to the workqueue threading layer,
    which aborts the process when two threads run a parallel kernel at once; run_local then
    runs the chunks one after the other (same result)."""
    doc = sweep(("F_e1", 0.0, 0.3, 4), ("Omega_e", 0.4, 0.6, 3))
    env = {**os.environ, "NUMBA_THREADING_LAYER": "workqueue"}
    run = subprocess.run(
        [sys.executable, "-c", WORKQUEUE_RUN, json.dumps(doc)],
        env=env, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split() == ["12"]


@pytest.mark.parametrize(
    ("n", "workers", "smallest", "size"),
    [(200, 2, 64, 64), (4000, 2, 64, 500), (20000, 1, 64, 1024), (115, 2, 1, 15), (3, 0, 1, 1)],
)
def test_balanced_chunks_are_about_four_per_worker_within_bounds(
    n: int, workers: int, smallest: int, size: int
) -> None:
    assert balanced_chunk_points(n, workers, smallest) == size


def test_the_cyclic_collector_is_paused_while_chunks_compute_and_restored_after() -> None:
    """Concurrent chunks (threads) share the pause: on again only after the last one."""
    assert gc.isenabled()
    first, second = cyclic_gc_paused(), cyclic_gc_paused()
    with first:
        assert not gc.isenabled()
        second.__enter__()
    assert not gc.isenabled()  # the second chunk still computes
    second.__exit__(None, None, None)
    assert gc.isenabled()
    gc.disable()
    try:
        with cyclic_gc_paused():
            pass
        assert not gc.isenabled()  # off before: left off
    finally:
        gc.enable()
