"""The Campbell diagram of a train: natural frequencies against driver speed, with the order lines
of the excitations and their crossings.

The train has no gyroscopic or speed-dependent term (torsion and translation along the line of
action), so each mode is a horizontal line f_i. An excitation of order o (multiples of the
driver speed n [rpm]) is the line f = o n / 60; it crosses mode i at n = 60 f_i / o. Orders
drawn: the mesh (teeth z_a) and its second harmonic, the driver shaft (1), the driven shaft
(z_a / z_b), and the torque fluctuation's and transmission error's own orders when the design
gives them. A crossing inside the speed range is a resonance speed; the crossing of the mesh
order with the mesh mode is the mesh resonance.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from gearengine.model.design import EXAMPLE_DESIGN, Design
from gearengine.model.errors import InputError
from gearengine.model.params import request_config
from gearengine.model.reduction import ParamsOrDesign
from gearengine.model.train import EXAMPLE_TRAIN
from gearengine.model.units import RPM, shown
from gearengine.systems.gear_train.model import train_of
from gearengine.systems.gear_train.modes import Modes, modes

RESONANCE_MARGIN = 1.2
"""Without a ``speed_range`` the diagram reaches at least this factor past the mesh resonance."""


class CampbellRequest(ParamsOrDesign):
    """``{"design": {... "train": {...}}}``: the Campbell diagram of a train over the design's
    ``speed_range`` (default 10 rpm to 3x the speed, or to 1.2x the mesh resonance)."""

    model_config = request_config({"design": {**EXAMPLE_DESIGN, "train": EXAMPLE_TRAIN}})
    TRAINS = True  # systems.gear_train answers for it

    ONE_OF = ("design",)


class OrderLine(BaseModel):
    """An excitation line f = order x speed / 60."""

    model_config = ConfigDict(frozen=True)

    name: str = Field(description="mesh, mesh x2, driver shaft, driven shaft, torque, ...")
    order: float = Field(description="Multiples of the driver speed.")


class Crossing(BaseModel):
    """Where an order line meets a natural frequency."""

    model_config = ConfigDict(frozen=True)

    mode: int = Field(description="Index of the mode in ``modes.modes``.")
    line: str = Field(description="Name of the order line.")
    frequency_hz: float = Field(description="The mode's natural frequency [Hz].")
    speed_rpm: float = Field(description="Driver speed of the crossing, 60 f / order [rpm].")
    mesh_mode: bool = Field(description="The mode is the mesh mode.")


class Campbell(BaseModel):
    """The /v1/analyses/campbell contract."""

    model_config = ConfigDict(frozen=True)

    modes: Modes = Field(description="The train's modes linearised in contact.")
    lines: list[OrderLine] = Field(description="The excitation order lines drawn.")
    crossings: list[Crossing] = Field(description="Crossings inside the speed range, by speed.")
    speed_range_rpm: tuple[float, float] = Field(description="Driver speeds of the diagram.")
    speed_rpm: float = Field(description="The design's driver speed [rpm].")
    mesh_resonance_rpm: float = Field(
        description="Speed at which the mesh frequency meets the mesh mode [rpm]."
    )


def order_lines(design: Design) -> list[OrderLine]:
    """The excitation orders of a design (module docstring), without repeats."""
    z_a, z_b = design.driver.teeth, design.driven.teeth
    lines = [("mesh", float(z_a)), ("mesh x2", 2.0 * z_a), ("driver shaft", 1.0),
             ("driven shaft", z_a / z_b)]  # fmt: skip
    if design.torque_fluctuation is not None:
        lines.append(("torque fluctuation", design.torque_fluctuation.order))
    te = design.transmission_error
    if te is not None and te.order is not None:
        lines.append(("transmission error", te.order))
    out: dict[float, str] = {}
    for name, order in lines:
        out.setdefault(order, name)
    return [OrderLine(name=name, order=order) for order, name in out.items()]


def campbell(request: CampbellRequest) -> Campbell:
    """The Campbell diagram of the request's train (module docstring)."""
    design = request.design
    if design is None or design.train is None:
        raise InputError(
            "design.train",
            "a Campbell diagram needs a train (motor, shafts, load): the rigid pair has the one "
            "mesh mode of conversions/design",
        )
    model, pair = train_of(design)
    found = modes(model, pair.natural_frequency_hz)
    mesh_hz = found.modes[found.mesh_mode].frequency_hz
    resonance = 60.0 * mesh_hz / design.driver.teeth
    lo, hi = request.speed_rpm_range()
    if design.speed_range is None:  # the default range reaches past the mesh resonance
        hi = max(hi, RESONANCE_MARGIN * resonance)
    lines = order_lines(design)
    crossings = []
    for k, mode in enumerate(found.modes):
        for line in lines:
            rpm = 60.0 * mode.frequency_hz / line.order
            if lo <= rpm <= hi:
                crossings.append(
                    Crossing(
                        mode=k,
                        line=line.name,
                        frequency_hz=mode.frequency_hz,
                        speed_rpm=shown(rpm),
                        mesh_mode=k == found.mesh_mode,
                    )
                )
    crossings.sort(key=lambda c: c.speed_rpm)
    return Campbell(
        modes=found,
        lines=lines,
        crossings=crossings,
        speed_range_rpm=(shown(lo), shown(hi)),
        speed_rpm=shown(design.speed / RPM),
        mesh_resonance_rpm=shown(resonance),
    )
