"""Everyday inputs and outputs (issue 30 item 9): a nominal circumferential backlash j_t and the
TE amplitude from an ISO 1328 accuracy class, each read with a note, in the library, the API and
the CLI's documents alike (one ``Design``); the basins' box in µm and mm/s with the starts used,
in the result and the picture; the LLE in 1/s in the summaries."""

from __future__ import annotations

import copy
import json
import math

import pytest
from pydantic import ValidationError

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.model.design import Design
from gearengine.model.reduction import convert_design
from gearengine.model.standards import iso1328
from gearengine.plots.basins import basins_figure, starts_words
from tests.conftest import ROOT

GEAR = {"module": "2.5 mm", "face_width": "20 mm"}
DESIGN = {
    "driver": {"teeth": 23, **GEAR},
    "driven": {"teeth": 67, **GEAR},
    "speed": "3000 rpm",
    "torque": "10 N*m",
    "mesh": {"stiffness": "iso6336", "damping_ratio": 0.05, "backlash": "100 um"},
    "transmission_error": {"accuracy_class": 7},
}


def design(**changes) -> Design:
    doc = copy.deepcopy(DESIGN)
    for key, value in changes.items():
        section, _, name = key.partition("__")
        doc[section][name] = value
    return Design.model_validate(doc)


def test_circumferential_backlash_is_read_along_the_line_of_action() -> None:
    d = design()
    b = 100e-6 * math.cos(math.radians(20.0)) / 2.0
    assert d.mesh.half_backlash == pytest.approx(b, rel=1e-12)
    assert convert_design(d).half_backlash_m == pytest.approx(b, rel=1e-12)
    notes = convert_design(d).notes
    assert any("j_t = 100 um (circumferential) read as the half backlash b = j_t cos(alpha_wt) "
               "/ 2 = 46.9846 um" in n for n in notes)  # fmt: skip


def test_profile_shifts_change_the_operating_pressure_angle() -> None:
    doc = copy.deepcopy(DESIGN)
    doc["driver"]["profile_shift"] = 0.3
    d = Design.model_validate(doc)
    alpha = d.operating_pressure_angle()
    assert alpha > math.radians(20.0)
    assert d.mesh.half_backlash == pytest.approx(100e-6 * math.cos(alpha) / 2.0, rel=1e-12)


def test_the_design_reads_back_the_same_after_its_dump() -> None:
    d = design()
    again = Design.model_validate(d.model_dump())
    assert again.mesh.half_backlash == d.mesh.half_backlash
    assert again.transmission_error.harmonics == d.transmission_error.harmonics


def test_accuracy_class_gives_the_class_bound_of_the_mesh_harmonic() -> None:
    seven, five = design(), design(transmission_error__accuracy_class=5)
    (h7,), (h5,) = seven.transmission_error.harmonics, five.transmission_error.harmonics
    assert h7.amplitude == iso1328.pair_te_bound(7, seven.driver, seven.driven)
    assert h7.amplitude * 1e6 == pytest.approx(11.31, abs=0.01)
    assert h7.amplitude / h5.amplitude == pytest.approx(2.0, rel=0.02)  # two classes: sqrt(2)^2
    notes = convert_design(seven).notes
    assert any("accuracy_class 7 read as one mesh-frequency harmonic e_1 = 11.31 um" in n
               for n in notes)  # fmt: skip


def test_one_of_each_pair_of_inputs() -> None:
    with pytest.raises(ValidationError, match="exactly one of half_backlash and backlash"):
        design(mesh__half_backlash="50 um")
    with pytest.raises(ValidationError, match="exactly one of harmonics and accuracy_class"):
        design(transmission_error__harmonics=[{"amplitude": "5 um"}])
    doc = copy.deepcopy(DESIGN)
    doc["driver"] = {"teeth": 23, "base_radius": "27 mm", "inertia": "1e-3 kg*m^2"}
    with pytest.raises(ValidationError, match="accuracy_class: an ISO 1328 class needs"):
        Design.model_validate(doc)


BASINS_DOC = json.loads((ROOT / "examples" / "basins-5750rpm.json").read_text())


@pytest.fixture(scope="module")
def basins_analysis():
    """The pair of examples/basins-5750rpm.json with 16 basin starts over +-30 um, +-250 mm/s."""
    basins = {"starts": 16, "box": [["-30 um", "30 um"], ["-250 mm/s", "250 mm/s"]]}
    settings = {**BASINS_DOC["settings"], "basins": basins}
    return analyze(AnalysisRequest.model_validate({**BASINS_DOC, "settings": settings}))


def test_the_basin_box_is_in_um_and_mm_per_s_in_the_result_and_the_picture(basins_analysis):
    counts = basins_analysis.numerics.basins
    assert counts.starts == 16
    assert counts.box_um_mm_s == [[-30.0, 30.0], [-250.0, 250.0]]
    b_um = basins_analysis.engineering.half_backlash_um
    assert counts.box[0][1] * b_um == pytest.approx(30.0, rel=1e-9)
    assert starts_words(counts) == "16 starts (4 x 4 grid) over x -30..30 µm, v -250..250 mm/s"
    assert basins_figure(basins_analysis, "svg").decode().count("-250..250 mm/s") == 1


def test_the_lle_is_in_1_per_s_in_the_summaries(basins_analysis):
    """Both summaries name the worst attractor's LLE in 1/s (lambda / time_scale_s, tau =
    omega_n t) beside its value per unit tau (the recorded run from the settings' start is
    periodic, its LLE negative)."""
    eng = basins_analysis.engineering
    worst = basins_analysis.numerics.attractors[0]
    per_s = worst.lle / eng.time_scale_s
    three = float(f"{per_s:.3g}")  # 3 significant digits, with thousands separators
    assert f"largest Lyapunov exponent {three:+,g} 1/s ({worst.lle:+.3g} per unit tau)" in (
        eng.summary
    )
    line = basins_analysis.summary()
    four = float(f"{per_s:.4g}")
    lle = f"LLE {worst.lle:+.4g} ± {worst.lle_stderr:.2g} per unit tau = {four:+,g} 1/s"
    assert f"({lle}, " in line
    assert "impacts on both flanks" in line and worst.lle > 0 > basins_analysis.numerics.lle
