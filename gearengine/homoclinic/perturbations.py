"""How far first-order Melnikov theory is stretched: each perturbation's size against the
unperturbed system's force scale.

The Melnikov function is the first term of an expansion in the size of the perturbation
(Guckenheimer & Holmes 1983, section 4.5); its zeros predict a transverse intersection only
while the perturbing forces are small against the forces of the unperturbed system. The force
scale used here is F_crit = (2a/3) sqrt(a/(3c)), the cubic's peak restoring force between the
saddle and a well (the largest mean load the unperturbed system can balance with a saddle).
Each perturbation's size is its largest force along the loops over F_crit:

    damping             2 mu max |y_h|
    stiffness           2 sum_r |k_pr| max |a x_h - c x_h^3|
    torque              sum_r |F_pr|
    transmission_error  sum_r (r Omega_e)^2 |F_er|
    mean_force          |F_m|   (only when treated as a perturbation)

Sizes above ``SMALL`` get a plain-words caveat in the verdict's notes.
"""

from __future__ import annotations

from gearengine.homoclinic.loops import sampled_extremes
from gearengine.model.params import GearParams

SMALL = 0.3
"""Largest size (over F_crit) read as a small perturbation; a rule of thumb, not a theorem."""
SAMPLES = 4001
"""Points per loop on t in [-40/k, 40/k] for the largest velocity and force along it."""


def loop_extremes(a: float, c: float, fm: float) -> tuple[float, float]:
    """(max |y_h|, max |a x_h - c x_h^3|) over both homoclinic loops of x'' = a x - c x^3 + F_m,
    sampled at SAMPLES times (``loops.sampled_extremes``: only the samples next to the peaks
    are evaluated)."""
    speed, force = sampled_extremes(a, c, fm, SAMPLES)
    return float(speed), float(force)


def perturbation_sizes(
    params: GearParams, extremes: tuple[float, float], fm: float, scale: float
) -> dict[str, float]:
    """Each given perturbation's size over the force scale ``scale`` (F_crit), by name;
    ``extremes`` are the loops' ``loop_extremes`` and ``fm`` the load they carry."""
    speed, force = extremes
    sizes = {"damping": 2.0 * params.damping * speed / scale}
    for name, exc in params.excitations():
        amps = [(r * exc.frequency, h.amplitude) for r, h in exc.active()]
        if name == "stiffness":
            size = 2.0 * sum(abs(v) for _, v in amps) * force
        elif name == "torque":
            size = sum(abs(v) for _, v in amps)
        else:
            size = sum(w * w * abs(v) for w, v in amps)
        sizes[name] = size / scale
    if fm == 0.0 and params.mean_force != 0.0:
        sizes["mean_force"] = abs(params.mean_force) / scale
    return sizes


def force_per_unit(
    params: GearParams, parameter: str, extremes: tuple[float, float]
) -> float | None:
    """The largest force along the loops per unit of a control parameter (the weights of the
    module docstring); None for a frequency. ``extremes`` are ``loop_extremes``."""
    speed, force = extremes
    if parameter == "F_e1":
        exc = params.transmission_error
        return None if exc is None else exc.frequency**2
    return {"mu": 2.0 * speed, "k_p1": 2.0 * force, "F_p1": 1.0}.get(parameter)


def caveat(sizes: dict[str, float], scale: float) -> str | None:
    """The plain-words note when some perturbation is not small (None when all are)."""
    big = {k: v for k, v in sizes.items() if v > SMALL}
    if not big:
        return None
    listed = ", ".join(f"{k.replace('_', ' ')} {v:.2g}" for k, v in sorted(big.items()))
    return (
        f"first-order theory is stretched: against the force scale F_crit = {scale:.4g} of the "
        f"unperturbed system the perturbations are not small ({listed}; small means below "
        f"{SMALL:g}); read the thresholds as estimates and let the simulated response decide"
    )
