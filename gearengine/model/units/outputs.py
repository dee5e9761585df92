"""Answers back in gear data: the scales of Eq. (8) that map a dimensionless answer to SI
(``Scales``), the one table of output quantities (``OUTPUTS``) with ``to_physical`` / ``in_si``
and the response values (DTE, dynamic factor), and the display unit of every design field
(``DISPLAY_UNITS``: rpm, µm, N*m) with its label."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    pass


RPM = 2.0 * math.pi / 60.0
"""One revolution per minute in rad/s."""

# Tolerances of the units boundary: one meaning per name.
RADIUS_RATIO_TOLERANCE = 0.01
"""Relative mismatch of the base-radius ratio r_a / r_b and the teeth ratio n_a / n_b beyond
which the data are inconsistent: a design is refused, the SI record of
/v1/conversions/physical (no teeth check of its own) gets a note."""
TORQUE_BALANCE_TOLERANCE = 1e-3
"""Relative mismatch of the braking torque with the balancing one, T_mb = T_ma r_b / r_a, beyond
which a note says the pair would speed up or slow down (rounding such as 66.667 for 200/3 N m
stays below it)."""


def shown(value: float) -> float:
    """A value in display units rounded to 12 significant digits (6000 rpm, not
    6000.000000000001): how every physical number of a sweep point, of its CSV row and of an
    analysis's response is given."""
    return float(f"{value:.12g}")


@dataclass(frozen=True)
class Scales:
    """What maps a dimensionless answer of Eq. (9) back to gear data (Eq. 8: x = x~ / b,
    tau = omega_n t, forces in units of b k_m)."""

    half_backlash: float
    """b [m]: x = 1 is one half backlash."""
    mesh_stiffness: float
    """k_m [N/m]: a dimensionless force times b k_m is in N."""
    natural_frequency: float
    """omega_n = sqrt(k_m / m) [rad/s]: t = tau / omega_n."""
    static_force: float
    """Mean mesh force F^_m = F~_m b k_m [N] (Eq. 7)."""
    mesh_frequency: float
    """omega_k = n_a omega_a [rad/s]."""
    speed: float
    """Driver speed omega_a [rad/s]."""
    torque_gain: float
    """F~_p per N m of driver-torque fluctuation, m r_a / (I_a b k_m) [1/(N m)]."""

    def at(self, mean_force: float) -> Scales:
        """These scales for a point whose dimensionless mean force F~_m was set (an ``F_m``
        axis): the static force is F~_m b k_m."""
        return replace(self, static_force=mean_force * (self.half_backlash * self.mesh_stiffness))


@dataclass(frozen=True)
class OutputKind:
    """A dimensionless result as a physical quantity: ``to_si(value, scales)`` inverts Eq. (8)
    for it, ``display`` is the factor from its SI unit to the unit it is shown in."""

    label: str
    si_unit: str
    unit: str
    to_si: Callable[[float, Scales], float]
    display: float = 1.0


OUTPUTS: dict[str, OutputKind] = {
    "dte": OutputKind(
        "dynamic transmission error (peak to peak)", "m", "um", lambda x, s: x * s.half_backlash,
        1e6,
    ),
    "dynamic_factor": OutputKind(
        "dynamic factor (largest mesh force / static force)", "1", "1",
        lambda f, s: f * s.half_backlash * s.mesh_stiffness / s.static_force,
    ),
    "mesh_force": OutputKind(
        "dynamic mesh force", "N", "N", lambda f, s: f * s.half_backlash * s.mesh_stiffness
    ),
    "force_max": OutputKind(
        "largest mesh force of the model over the record, k_m b (K(t) f_h(x) + 2 mu x')", "N",
        "N", lambda f, s: f * s.half_backlash * s.mesh_stiffness,
    ),
    "force_min": OutputKind(
        "smallest mesh force of the model over the record (its damping term acts in the "
        "clearance too: negative while apart or on the back flank)", "N", "N",
        lambda f, s: f * s.half_backlash * s.mesh_stiffness,
    ),
    "transmission_error_amplitude": OutputKind(
        "transmission-error amplitude e_1 = F~_e1 b", "m", "um",
        lambda v, s: v * s.half_backlash, 1e6,
    ),
    "torque_fluctuation_amplitude": OutputKind(
        "torque-fluctuation amplitude T_p1 = F~_p1 / (m r_a / (I_a b k_m))", "N*m", "N*m",
        lambda v, s: v / s.torque_gain,
    ),
    "stiffness_variation_amplitude": OutputKind(
        "stiffness-variation amplitude k_1 = 2 k_m k~_p1", "N/m", "N/m",
        lambda v, s: 2.0 * v * s.mesh_stiffness,
    ),
    "damping_ratio": OutputKind("damping ratio zeta = mu~", "1", "1", lambda v, s: v),
    "displacement": OutputKind(
        "displacement x~ = x b", "m", "um", lambda x, s: x * s.half_backlash, 1e6
    ),
    "time": OutputKind("time t = tau / omega_n", "s", "ms", lambda t, s: t / s.natural_frequency,
                       1e3),
    "frequency": OutputKind(
        "frequency f = Omega omega_n / (2 pi)", "Hz", "Hz",
        lambda w, s: w * s.natural_frequency / (2 * math.pi),
    ),
}  # fmt: skip
"""Output quantities by name: the physical meaning of a dimensionless result (beside the inputs'
``QUANTITIES``); the engineering block, sweep points, CSV columns, gate rules and plots read it."""

RESPONSES = ("dte", "dynamic_factor")
"""The response quantities of a design's simulated point (a sweep point's ``physical`` entries
beside its axes, the CSV's response columns, the gate's limits)."""
RECORD_FORCES = ("force_max", "force_min")
"""A design's sweep point's mesh forces in N (``physical`` entries after ``RESPONSES``, the CSV's
``force_max [N]``, ``force_min [N]``): the record's ``force_max`` and ``force_min`` x b k_m."""
POINT_OUTPUTS = (*RESPONSES, *RECORD_FORCES)
"""Every ``physical`` entry of a sweep point that is an output, not an axis."""


IMPACTS_REFUSED = (
    "'impacts' is no longer read (it meant back-flank impacts in --fail-on and any separation "
    "in P(...)): write back_flank (back-flank impacts) or separation (the teeth apart at some "
    "time)"
)
"""Why the old word ``impacts`` is refused wherever a contact outcome is named (one vocabulary,
docs/units.md): a gate's fail_on (API, library, ``--fail-on``) and ``--max-probability``."""


def in_si(name: str, value: float, scales: Scales) -> float:
    """The dimensionless ``value`` of output ``name`` in its SI unit (``OUTPUTS``)."""
    return OUTPUTS[name].to_si(value, scales)


def to_physical(name: str, value: float, scales: Scales) -> float:
    """The dimensionless ``value`` of output ``name`` in its display unit (``OUTPUTS``): the one
    crossing from a dimensionless result to a physical value."""
    kind = OUTPUTS[name]
    si = in_si(name, value, scales)
    return si if kind.display == 1.0 else si * kind.display


def response_values(
    x_peak_to_peak: float | None, force_max: float | None, scales: Scales
) -> dict[str, float | None]:
    """DTE [µm peak to peak] and dynamic factor of a simulated response, ``shown``: the one
    definition used by an analysis's engineering block and by every sweep point.

    ``x_peak_to_peak`` (units of b) and ``force_max`` (units of b k_m) come from the kernel's
    per-step extremes over the record; the dynamic factor is None without a positive static
    force."""
    dte = None if x_peak_to_peak is None else shown(to_physical("dte", x_peak_to_peak, scales))
    factor = None
    if force_max is not None and scales.static_force > 0.0:
        factor = shown(to_physical("dynamic_factor", force_max, scales))
    return {"dte": dte, "dynamic_factor": factor}


def display_label(name: str) -> str:
    """An output's name with its display unit, as a CSV column title or a plot's axis label
    ("dte [um]"; a dimensionless one bare)."""
    unit = OUTPUTS[name].unit
    return name if unit == "1" else f"{name} [{unit}]"


@dataclass(frozen=True)
class FieldUnit:
    """How a design field (a sweep axis) is shown: its SI unit, its display unit and the factor
    from the one to the other."""

    si: str
    display: str
    factor: float = 1.0


DISPLAY_UNITS: dict[str, FieldUnit] = {
    "speed": FieldUnit("rad/s", "rpm", 1.0 / RPM),
    "torque": FieldUnit("N*m", "N*m"),
    "braking_torque": FieldUnit("N*m", "N*m"),
    "half_backlash": FieldUnit("m", "um", 1e6),
    "transmission_error": FieldUnit("m", "um", 1e6),
    "torque_fluctuation": FieldUnit("N*m", "N*m"),
    "stiffness_harmonics": FieldUnit("N/m", "N/m"),
    "stiffness": FieldUnit("N/m", "N/m"),
    "damping_ratio": FieldUnit("1", "1"),
    "damping": FieldUnit("N*s/m", "N*s/m"),
    "inertia": FieldUnit("kg*m^2", "kg*m^2"),
    "base_radius": FieldUnit("m", "mm", 1e3),
    "module": FieldUnit("m", "mm", 1e3),
    "face_width": FieldUnit("m", "mm", 1e3),
    "bore": FieldUnit("m", "mm", 1e3),
    "pressure_angle": FieldUnit("rad", "deg", 180.0 / math.pi),
    "order": FieldUnit("1", "1"),
    "profile_shift": FieldUnit("1", "1"),
    "teeth": FieldUnit("1", "1"),
    "phase": FieldUnit("rad", "rad"),
}
"""Units of a design's fields by the most specific name in their path
(``transmission_error.harmonics.0.amplitude`` is shown in µm)."""

FIELD_NAMES = {
    "speed": "driver speed",
    "torque": "mean driver torque",
    "braking_torque": "braking torque",
    "half_backlash": "half backlash",
    "damping_ratio": "damping ratio",
    "damping": "mesh damping",
    "stiffness": "mean mesh stiffness",
    "stiffness_harmonics": "mesh-stiffness variation",
    "transmission_error": "transmission error",
    "torque_fluctuation": "torque fluctuation",
    "base_radius": "base radius",
    "face_width": "face width",
    "pressure_angle": "pressure angle",
    "profile_shift": "profile shift",
}
"""Readable names of the parts of a field path (others are shown as they are)."""


def field_unit(path: str) -> FieldUnit:
    """The units of a design field path (``DISPLAY_UNITS``; SI shown as it is when unknown)."""
    for part in (path, *reversed(path.split("."))):
        if part in DISPLAY_UNITS:
            return DISPLAY_UNITS[part]
    return FieldUnit("SI", "SI")


def display_unit(path: str) -> tuple[str, float]:
    """(display unit, factor from SI) of a design field path."""
    unit = field_unit(path)
    return unit.display, unit.factor


def in_display_unit(path: str, si: float) -> float:
    """A design field's SI value in its display unit, ``shown``: the number of a sweep point's
    ``physical`` entry and of its CSV column."""
    return shown(si * field_unit(path).factor)


def pretty_unit(unit: str) -> str:
    """A unit as printed on a figure: µm for um, a middle dot for a product."""
    return unit.replace("um", "µm").replace("*", "·").replace("^2", "²")


def field_label(path: str) -> str:
    """A readable axis label of a design field path: "driver speed [rpm]",
    "transmission error, harmonic 1 amplitude [µm]", "driver module [mm]"."""
    parts = [p for p in path.split(".") if p != "mesh"]
    words = []
    for k, part in enumerate(parts):
        if part.isdigit():
            words[-1] += f", harmonic {int(part) + 1}"
        elif part != "harmonics" or k == 0:
            words.append(FIELD_NAMES.get(part, part.replace("_", " ")))
    unit = field_unit(path).display
    text = " ".join(words)
    return text if unit == "1" else f"{text} [{pretty_unit(unit)}]"
