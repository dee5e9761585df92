"""Short aliases of the parameters swept and thresholded: first harmonics, frequencies, mu, F_m.

``F_e1`` is the first transmission-error harmonic F~_e1, ``Omega_e`` its fundamental frequency,
and so on (the paper's symbols of Eq. 9). Sweeps, thresholds and the CLI name parameters this way.
"""

from __future__ import annotations

from typing import Literal

from gearengine.model.params import Excitation, GearParams

ALIASES: dict[str, tuple[str, str]] = {
    "mu": ("damping", ""),
    "F_m": ("mean_force", ""),
    "k_p1": ("stiffness", "amplitude"),
    "F_e1": ("transmission_error", "amplitude"),
    "F_p1": ("torque", "amplitude"),
    "Omega_k": ("stiffness", "frequency"),
    "Omega_e": ("transmission_error", "frequency"),
    "Omega_p": ("torque", "frequency"),
}
"""alias -> (field, what): what is '' for a scalar field, else the excitation's item."""

Alias = Literal["mu", "F_m", "k_p1", "F_e1", "F_p1", "Omega_k", "Omega_e", "Omega_p"]


def get_alias(params: GearParams, name: str) -> float | None:
    """Value of a short alias (first-harmonic amplitude, frequency, mu or F_m).

    An absent excitation has amplitude 0 and frequency ``None``.
    """
    field, what = _alias(name)
    if not what:
        return float(getattr(params, field))
    exc: Excitation | None = getattr(params, field)
    if exc is None:
        return 0.0 if what == "amplitude" else None
    if what == "frequency":
        return exc.frequency
    return exc.harmonics[0].amplitude if exc.harmonics else 0.0


def with_alias(params: GearParams, name: str, value: float) -> GearParams:
    """A copy of ``params`` with the alias set to ``value``, validated.

    Raises ``ValueError`` when an amplitude is set on an excitation whose frequency is unknown.
    """
    return with_aliases(params, {name: value})


def with_aliases(params: GearParams, values: dict[str, float]) -> GearParams:
    """A copy of ``params`` with several aliases set at once, validated (see ``with_alias``).
    A design's shaft orders (``GearParams.shaft_orders``) stay while no frequency is set."""
    copy = GearParams.model_validate(aliased_data(params.model_dump(), values))
    if any(_alias(name)[1] == "frequency" for name in values):
        return copy
    return copy.with_shaft_orders(params.shaft_orders)


def aliased_data(data: dict, values: dict[str, float]) -> dict:
    """The dumped parameters ``data`` with aliases set, not validated (a copy: ``data`` and its
    excitations are left as they were). Raises ``ValueError`` like ``with_alias``."""
    data = dict(data)
    for name, value in values.items():
        field, what = _alias(name)
        if not what:
            data[field] = value
            continue
        exc = data.get(field)
        if exc is not None:
            exc = data[field] = {**exc, "harmonics": [dict(h) for h in exc["harmonics"]]}
        else:
            if what == "amplitude" and value == 0.0:
                continue
            freq_alias = next(k for k, v in ALIASES.items() if v == (field, "frequency"))
            if what == "amplitude" and freq_alias not in values:
                raise ValueError(
                    f"cannot set {name}: {field} has no frequency; give {field}.frequency "
                    f"or {freq_alias}"
                )
            exc = data[field] = {"frequency": values.get(freq_alias, 1.0), "harmonics": []}
        if what == "frequency":
            exc["frequency"] = value
        else:
            if not exc["harmonics"]:
                exc["harmonics"].append({"amplitude": 0.0, "phase": 0.0})
            exc["harmonics"][0]["amplitude"] = value
    return data


def _alias(name: str) -> tuple[str, str]:
    try:
        return ALIASES[name]
    except KeyError:
        raise ValueError(f"unknown parameter {name!r}; expected one of {sorted(ALIASES)}") from None


def fastest_frequency(params: GearParams) -> float | None:
    """The largest fundamental frequency among the given excitations: the value of a sweep's
    ``Omega`` axis, whose points ``with_speed_factor`` makes."""
    freqs = [exc.frequency for _, exc in params.excitations()]
    return max(freqs) if freqs else None


def with_speed_factor(params: GearParams, factor: float) -> GearParams:
    """A copy of ``params`` with every excitation frequency times ``factor`` (> 0): a change of
    running speed, which moves the mesh, transmission-error and torque frequencies together and
    leaves the dimensionless amplitudes unchanged (F~_er = e_r / b; the forcing (r Omega)^2 F~_er
    grows with speed by itself)."""
    data = params.model_dump()
    for name, _ in params.excitations():
        data[name]["frequency"] *= factor
    return GearParams.model_validate(data).with_shaft_orders(params.shaft_orders)
