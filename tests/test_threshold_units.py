"""Threshold curves of a design in gear units (issue 26, item 11): the parameter in its unit
over the driver speed, as the rest of a physical page."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from gearengine.engineering.thresholds import threshold_units
from gearengine.homoclinic.schemas import ThresholdsRequest
from gearengine.model.aliases import get_alias
from gearengine.model.design import EXAMPLE_DESIGN
from tests.conftest import PAPER_PARAMS


def test_units_put_the_design_at_its_speed_and_amplitude() -> None:
    req = ThresholdsRequest.model_validate({"design": EXAMPLE_DESIGN, "parameter": "F_e1"})
    conv = req.conversion
    units = threshold_units(conv, "F_e1", "Omega_e")
    omega = get_alias(conv.params, "Omega_e")
    assert units.rpm_per_frequency * omega == pytest.approx(1500.0)
    assert units.parameter_scale * get_alias(conv.params, "F_e1") == pytest.approx(5.0)  # µm
    assert units.parameter_label == "transmission error amplitude [µm]"
    assert threshold_units(conv, "mu", "Omega_e").parameter_scale == 1.0  # zeta = mu~
    ripple = threshold_units(conv, "F_p1", "Omega_p")  # order 1: the shaft speed itself
    assert ripple.rpm_per_frequency * get_alias(conv.params, "Omega_p") == pytest.approx(1500.0)
    assert ripple.parameter_scale * get_alias(conv.params, "F_p1") == pytest.approx(4.0)  # N m


def test_the_figure_of_a_design_is_drawn_in_gear_units(client: TestClient) -> None:
    body = {"design": EXAMPLE_DESIGN, "mean_load": "perturbation"}  # F_m above F_crit
    svg = client.post("/v1/thresholds/plot?format=svg", json=body).text
    assert "driver speed [rpm]" in svg and "transmission error amplitude [µm]" in svg
    assert "dimensionless frequency" not in svg
    svg = client.post("/v1/thresholds/plot?format=svg", json={"params": PAPER_PARAMS}).text
    assert "dimensionless frequency" in svg and "driver speed" not in svg
