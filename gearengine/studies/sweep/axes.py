"""What a sweep axis moves, and the parameters of each grid point.

An axis names one of:

* a dimensionless alias of Eq. (9) (``F_e1``, ``mu``, ``Omega_e``, ...; ``model.aliases``), set on
  the request's ``params`` (for a design: on its conversion);
* ``Omega``: every excitation frequency scaled together, as a change of running speed; its value
  is the fundamental of the fastest excitation, the others keep their ratios to it;
* with a ``design``, a physical field by its path: ``speed`` (every excitation frequency moves
  with it), ``torque``, ``mesh.half_backlash``, ``mesh.damping_ratio``,
  ``transmission_error.harmonics.0.amplitude``, ... with start and stop as unit strings
  ("500 rpm") or SI numbers. The design is re-validated and converted at every point, so each
  point is exactly the design a single ``/v1/analyses`` call at that value would analyse.
"""

from __future__ import annotations

from pydantic import ValidationError

from gearengine.model.aliases import ALIASES, fastest_frequency, with_aliases, with_speed_factor
from gearengine.model.design import Design
from gearengine.model.fields import design_with, si_value
from gearengine.model.params import GearParams
from gearengine.model.units import Scales, field_unit
from gearengine.systems.base import System
from gearengine.systems.designs import design_model, params_of
from gearengine.systems.spur_pair.forcing import packed_forcing

OMEGA = "Omega"
"""The axis that scales every excitation frequency together (dimensionless)."""


def is_dimensionless(parameter: str) -> bool:
    """True for an alias of Eq. (9) or ``Omega``; False for a field of a design."""
    return parameter in ALIASES or parameter == OMEGA


def axis_unit(parameter: str) -> str:
    """The unit of an axis' values in a point's ``values``: a design field's SI unit (speed
    rad/s), "1" for a dimensionless alias."""
    return "1" if is_dimensionless(parameter) else field_unit(parameter).si


def bare_reading(parameter: str, where: str, value: object) -> str | None:
    """How a bare number at one end of a physical axis was read: in the field's SI unit
    (``axis_unit``: speed in rad/s), said in words as a design's own bare numbers are
    (``model.units``); None for a unit string, a dimensionless alias or a unitless field."""
    unit = field_unit(parameter)
    bare = isinstance(value, (int, float)) and not isinstance(value, bool)
    if not bare or is_dimensionless(parameter) or unit.si in ("1", "SI"):
        return None
    text = f"{where} ({parameter}): the bare number {value:g} read as {value:g} {unit.si}"
    if unit.display != unit.si:
        shown = float(value) * unit.factor
        text += (f" = {shown:,.6g} {unit.display}; write '{value:g} {unit.display}' if "
                 f"{unit.display} was meant")  # fmt: skip
    return text


def point_params(params: GearParams, design: Design | None, values: dict[str, float]) -> GearParams:
    """The dimensionless parameters of one grid point (``scaled_point``; of a train, those of
    its equivalent pair)."""
    return params_of(scaled_point(params, design, None, values)[0])


def point_model(
    params: GearParams, design: Design | None, values: dict[str, float]
) -> GearParams | System:
    """What the numerics run at one grid point (``scaled_point``)."""
    return scaled_point(params, design, None, values)[0]


def scaled_point(
    params: GearParams, design: Design | None, scales: Scales | None, values: dict[str, float]
) -> tuple[GearParams | System, Scales | None]:
    """What the numerics run at one grid point and, for a design (whose ``scales`` are given),
    the scales that map its answers back to gear data.

    Physical fields are set on the design first (then converted: its scales), aliases and
    ``Omega`` on the resulting parameters (the static force follows an ``F_m`` axis). A design
    with a ``train`` is its ``System`` at every point (``systems.designs.design_model``), moved
    by physical fields only: its dimensionless aliases are not free parameters (ValueError).
    """
    physical = {k: v for k, v in values.items() if not is_dimensionless(k)}
    model: GearParams | System = params
    if physical or (design is not None and design.train is not None):
        assert design is not None
        model, conversion = design_model(design_with(design, physical))
        params, scales = params_of(model), conversion.scales
    aliases = {k: v for k, v in values.items() if k in ALIASES}
    if OMEGA in values:
        aliases[OMEGA] = values[OMEGA]
    if aliases and isinstance(model, System):
        raise ValueError(
            f"{', '.join(aliases)} is a parameter of Eq. (9), not of a gear train: sweep the "
            "train's design fields (speed, torque, train.input_shaft.torsional_stiffness, ...)"
        )
    aliases.pop(OMEGA, None)
    if aliases:
        params = with_aliases(params, aliases)
    if OMEGA in values:
        ref = fastest_frequency(params)
        assert ref is not None
        params = with_speed_factor(params, values[OMEGA] / ref)
    if not isinstance(model, System):
        model = params
    return model, None if scales is None else scales.at(params.mean_force)


def dynamics_key(params: GearParams | System) -> tuple | None:
    """What Eq. (9) (or a ``System``) actually integrates: two designs with equal keys have
    equal dynamics; None when a system cannot tell."""
    if isinstance(params, System):
        return params.dynamics_key()
    kc, fm, fc = packed_forcing(params)
    return (params.damping, params.backlash, fm, kc.tobytes(), fc.tobytes())


def axis_problem(params: GearParams, design: Design | None, parameter: str, start: object,
                 stop: object, base: dict[str, float]) -> tuple[str, str] | None:  # fmt: skip
    """Why an axis cannot be swept, as (field, message), or None when it can."""
    if not is_dimensionless(parameter):
        if design is None:
            return "parameter", (
                f"{parameter} is not an alias of Eq. (9) ({', '.join(sorted(ALIASES))}, Omega); "
                "physical axes (speed, torque, mesh.half_backlash, ...) need a design"
            )
        for end, value in (("start", start), ("stop", stop)):
            try:
                si_value(design, parameter, value)
            except (KeyError, IndexError, TypeError):
                return "parameter", f"the design has no field {parameter}"
            except ValidationError as exc:
                return end, "; ".join(e["msg"] for e in exc.errors(include_url=False))
    elif not all(isinstance(v, (int, float)) for v in (start, stop)):
        return "start", f"{parameter} is dimensionless: give start and stop as numbers"
    if parameter == OMEGA and fastest_frequency(params) is None:
        return "parameter", "Omega scales the excitation frequencies, and no excitation is given"
    return None


def changes_nothing(
    params: GearParams, design: Design | None, parameter: str, lo: float, hi: float,
    base: dict[str, float],
) -> bool:  # fmt: skip
    """True when moving ``parameter`` from ``lo`` to ``hi`` leaves Eq. (9) unchanged (an
    ``Omega_e`` axis with no transmission-error harmonic, say)."""
    ends = [dynamics_key(point_model(params, design, {**base, parameter: v})) for v in (lo, hi)]
    return ends[0] is not None and ends[0] == ends[1]
