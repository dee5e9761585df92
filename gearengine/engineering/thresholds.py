"""Thresholds in gear units: the critical value of each control parameter and its margin to
chaos (``Critical``), and the axes of a threshold figure (``ThresholdUnits``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from pydantic import Field

from gearengine.homoclinic.schemas import ParameterThreshold
from gearengine.model.aliases import get_alias
from gearengine.model.answers import Answer
from gearengine.model.reduction import DesignConversion
from gearengine.model.units import OUTPUTS, Scales, display_label, to_physical


class Critical(Answer):
    """The threshold of one control parameter in its physical unit."""

    unit: str = Field(description="Unit of value, critical_values and margin_to_chaos.")
    value: float | None = Field(description="The design's value.")
    critical_values: list[float] = Field(description="Where the Melnikov verdict flips.")
    nearest: float | None = Field(description="The critical value nearest to the design.")
    margin_to_chaos: float | None = Field(
        description="|value - nearest|, positive on the safe side, negative inside the "
        "chaos-possible region (the threshold's margin in this unit)."
    )
    relative_margin: float | None = Field(description="margin_to_chaos / |nearest|.")


CONTROLS = {
    "F_e1": "transmission_error_amplitude",
    "F_p1": "torque_fluctuation_amplitude",
    "mu": "damping_ratio",
    "k_p1": "stiffness_variation_amplitude",
}
"""Control parameter -> its output quantity (``model.units.OUTPUTS``), the engineering name."""


@dataclass(frozen=True)
class ThresholdUnits:
    """A threshold figure's axes in gear units: every excitation frequency scales with the
    driver speed, so a frequency Omega is the speed ``rpm_per_frequency * Omega``; each control
    parameter is linear in its physical value (``model.units.to_physical``)."""

    rpm_per_frequency: float
    parameter_label: str
    parameter_scale: float


def threshold_units(
    conv: DesignConversion, parameter: str, frequency_parameter: str
) -> ThresholdUnits | None:
    """The gear units of the threshold curves of a design (None: the swept frequency's
    excitation is absent, so the speed of a frequency is not defined)."""
    omega = get_alias(conv.params, frequency_parameter)
    if not omega:
        return None
    output = CONTROLS[parameter]
    label = display_label(output).replace("_", " ").replace("[um]", "[µm]")
    return ThresholdUnits(conv.speed_rpm / omega, label, to_physical(output, 1.0, conv.scales))


def critical(name: str, t: ParameterThreshold, scales: Scales) -> Critical:
    """One threshold in physical units with its signed margin to chaos (the threshold's
    margin, positive on the safe side, in this unit: every map of ``to_physical`` is linear)."""
    output = CONTROLS[name]
    unit = OUTPUTS[output].unit
    crit = [to_physical(output, v, scales) for v in t.critical_values]
    value = None if t.value is None else to_physical(output, t.value, scales)
    nearest = None if t.nearest is None else to_physical(output, t.nearest, scales)
    margin = rel = None
    if value is not None and nearest is not None and t.margin is not None:
        margin = math.copysign(abs(value - nearest), t.margin)
        rel = margin / abs(nearest) if nearest else None
    return Critical(unit=unit, value=value, critical_values=crit, nearest=nearest,
                    margin_to_chaos=margin, relative_margin=rel)  # fmt: skip
