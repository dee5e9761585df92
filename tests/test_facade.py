"""The library as a user types it (issue 26, item 9): a design type on the facade, short
summaries and reprs of results, and a sweep as a DataFrame or numpy grids."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gearengine
from gearengine import Design, SimulationSettings, SweepRequest, analyze, run_sweep
from gearengine.model import design as design_module
from gearengine.studies.sweep.results import to_csv
from tests.conftest import ROOT

LIGHT = SimulationSettings(transient_periods=40, record_periods=40, steps_per_period=128)


@pytest.fixture(scope="module")
def design() -> dict:
    return json.loads((ROOT / "examples" / "design-geometry.json").read_text())["design"]


def test_dir_shows_the_public_names_only() -> None:
    shown = {n for n in dir(gearengine) if not n.startswith("__")}
    assert shown == set(gearengine.__all__)
    assert gearengine.Design is design_module.Design


def test_an_analysis_of_a_design_has_a_one_line_summary(design: dict) -> None:
    result = analyze(Design.model_validate(design), LIGHT)
    assert result.settings == LIGHT and result.engineering is not None
    line = result.summary()
    assert line.startswith("periodic 1T") and "dynamic factor" in line and "\n" not in line
    assert repr(result) == f"AnalysisResult({line!r})" and str(result) == line
    assert len(repr(result)) < 400 < len(result.model_dump_json())
    with pytest.raises(TypeError, match="carries its settings"):
        analyze(gearengine.AnalysisRequest(design=design), LIGHT)


def test_a_sweep_as_a_dataframe_and_numpy_grids(design: dict) -> None:
    pd = pytest.importorskip("pandas")
    axes = [{"parameter": "speed", "start": "1000 rpm", "stop": "3000 rpm", "num": 3},
            {"parameter": "torque", "start": "20 N*m", "stop": "60 N*m", "num": 2}]  # fmt: skip
    request = SweepRequest.model_validate(
        {"design": design, "settings": LIGHT.model_dump(), "axes": axes}
    )
    result = run_sweep(request)
    assert result.summary().startswith("sweep of speed (1000 rpm to 3000 rpm, 3), torque")
    assert len(repr(result)) < 400
    frame = result.to_pandas()
    assert isinstance(frame, pd.DataFrame) and len(frame) == 6
    assert list(frame.columns) == next(to_csv(result, design=True)).rstrip("\n").split(",")
    assert frame["poincare_x [b]"][0] == result.points[0].poincare_x
    axes, dte = result.grid("dte")
    assert [a.shape for a in axes] == [(3,), (2,)] and dte.shape == (2, 3)
    assert axes[0][-1] == pytest.approx(3000 * 2 * np.pi / 60)
    for p in result.points:
        i, j = list(axes[0]).index(p.values["speed"]), list(axes[1]).index(p.values["torque"])
        assert dte[j, i] == p.physical["dte"].value
    assert np.array_equal(result.grid("lle")[1].ravel(), [p.lle for p in result.points])


@pytest.mark.parametrize("source", ["design", "params"])
def test_a_dumped_analysis_loads_back_equal(design: dict, source: str) -> None:
    """model_dump_json -> model_validate_json -> the same JSON: the per-unit Melnikov
    coefficients the thresholds use are not serialised, and read back as None."""
    doc = {"design": design} if source == "design" else {"params": PAPER}
    result = analyze(gearengine.AnalysisRequest.model_validate({**doc, "settings": LIGHT}))
    text = result.model_dump_json()
    back = gearengine.AnalysisResult.model_validate_json(text)
    assert back.model_dump_json() == text
    if source == "params":
        assert back.melnikov is not None and back.melnikov.coefficients is not None
        assert back.melnikov.coefficients["plus"].damping_per_unit is None


PAPER = {
    "damping": 0.07,
    "mean_force": 0.01,
    "transmission_error": {"frequency": 0.5, "harmonics": [{"amplitude": 0.2}]},
}
