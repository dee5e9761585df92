"""Everyday inputs (issue 30 item 9): a nominal circumferential backlash j_t and the TE
amplitude from an ISO 1328 accuracy class, each read with a note, in the library, the API and
the CLI's documents alike (one ``Design``)."""

from __future__ import annotations

import copy
import math

import pytest
from pydantic import ValidationError

from gearengine.model.design import Design
from gearengine.model.reduction import convert_design
from gearengine.model.standards import iso1328

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
