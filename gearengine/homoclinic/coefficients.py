"""Melnikov function of the gear model about its two homoclinic orbits (paper section 3).

Unperturbed system (Eq. 11): x' = y, y' = a x - c x^3, with a > 0, c > 0. The saddle (0, 0) is
joined to itself by two homoclinic orbits (Eq. 15), branch s = +1 (``plus``, x_h > 0) and
s = -1 (``minus``):

    x_h(t) = s sqrt(2a/c) sech(sqrt(a) t),   y_h(t) = -s sqrt(2/c) a sech(sqrt(a) t) tanh(sqrt(a) t)

The Melnikov function (Eq. 17-18) is evaluated with the parameters as given (epsilon = 1, so M
has the units of the inputs). Every term is a sinusoid in tau0 (derivation in
``docs/melnikov-erratum.md``); with sigma = pi Omega / (2 sqrt(a)):

    M(tau0) = A + sum_i B_i sin(Omega_i tau0 + phi_i)
    A            = -(8/3) mu a^(3/2) / c                                    damping
    B (stiffness) = k_pr pi Omega^2 (2a - Omega^2) / (3c) csch(sigma)       Omega = r Omega_k
    B (torque)    = s sqrt(2/c) pi Omega sech(sigma) F_pr                   Omega = r Omega_p
    B (trans. err)= s sqrt(2/c) pi Omega^3 sech(sigma) F_er                 Omega = r Omega_e

Treated as a perturbation (the paper's F~_m = eps f_m, ``mean_load="perturbation"``), the mean
force F_m contributes nothing (the integral of y_h vanishes). By default it belongs to the
unperturbed system, x'' = a x - c x^3 + F_m (``mean_load="unperturbed"``): the saddle moves to
x_s, the two loops become asymmetric (``loops``) and each coefficient is the same Eq. (18)
integral along the loaded loop; |F_m| >= F_crit leaves no saddle (``docs/melnikov-under-load.md``).
The stiffness term differs
from the paper's printed Eq. (19), which is wrong unless a = 1: quadrature of Eq. (18) agrees with
the form above (tests/test_melnikov.py).

Two methods give the coefficients (``METHODS``): ``closed_form`` (the corrected Eq. 19) and
``quadrature`` (QUADPACK on Eq. 18, the check). References: Guckenheimer & Holmes, *Nonlinear
Oscillations, Dynamical Systems, and Bifurcations of Vector Fields*, Springer 1983, section 4.5
(the Melnikov function); Farshidianfar & Saghafi, Nonlinear Dyn. 75 (2014), Eqs. (11)-(19).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from gearengine.homoclinic import kernels, loops
from gearengine.homoclinic.extrema import Extrema, TrigSum, extrema, single_extrema
from gearengine.homoclinic.terms import system_array
from gearengine.model.params import GearParams

HomoclinicBranch = Literal["plus", "minus"]
"""The two homoclinic orbits of Eq. (15): plus (x_h > 0) and minus (x_h < 0)."""
BRANCH_SIGN: dict[HomoclinicBranch, float] = {"plus": 1.0, "minus": -1.0}
Method = Literal["closed_form", "quadrature"]
MeanLoad = Literal["unperturbed", "perturbation"]
"""Where the mean force F_m goes: in the unperturbed system x'' = a x - c x^3 + F_m (default), or
a first-order perturbation that drops out of M (the paper's treatment, section 3.1)."""


def loop_load(params: GearParams | dict, mean_load: MeanLoad) -> float:
    """The mean force carried by the unperturbed system: F_m, or 0 as a perturbation (of
    ``params`` or of their dumped, unvalidated data)."""
    if mean_load == "perturbation":
        return 0.0
    return float(params["mean_force"] if isinstance(params, dict) else params.mean_force)


def critical_mean_force(a: float, c: float) -> float:
    """F_crit = (2a/3) sqrt(a/(3c)) (``loops.critical_load``), for a > 0 and c > 0."""
    return float(loops.critical_load(a, c))


T_CRIT_WHY = (
    "T_crit = F_crit b k_m r_a is the torque whose mean mesh force T / r_a reaches the barrier "
    "between the backlash law's two wells, F_crit = (2a/3) sqrt(a/(3c)) in units of b k_m; above "
    "it the saddle disappears, and with it the homoclinic loop the criterion needs, so T_crit "
    "grows with the half backlash b, the mesh stiffness k_m and the base radius r_a "
    "(docs/melnikov-under-load.md)"
)
"""Why the critical torque depends on the design, said where an answer gives it."""


def saddle_loop(a: float, c: float, fm: float = 0.0) -> bool:
    """True when x'' = a x - c x^3 + F_m has a saddle with homoclinic loops: a > 0, c > 0 and
    |F_m| < F_crit.

    The one domain check of the Melnikov criterion; without a saddle loop it does not apply.
    """
    return a > 0.0 and c > 0.0 and abs(fm) < critical_mean_force(a, c)


class Term(BaseModel):
    """One sinusoid B sin(Omega tau0 + phase) of the Melnikov function (Eq. 19)."""

    model_config = ConfigDict(frozen=True)

    excitation: str = Field(description="stiffness, transmission_error or torque.")
    r: int = Field(description="Harmonic number.")
    frequency: float = Field(description="r Omega (dimensionless).")
    phase: float = Field(description="Phase phi_r, radians.")
    coefficient: float = Field(description="B, same units as M.")
    per_unit: float | None = Field(
        None,
        exclude=True,
        description="B per unit amplitude of the harmonic (for thresholds); not serialised, so "
        "None on a result read back from JSON.",
    )


class BranchCoefficients(BaseModel):
    """M(tau0) = damping + sum(term.coefficient * sin(term.frequency tau0 + term.phase)) on one
    homoclinic branch."""

    model_config = ConfigDict(frozen=True)

    damping: float = Field(description="Constant part A = -(8/3) mu a^(3/2) / c.")
    damping_per_unit: float | None = Field(
        None,
        exclude=True,
        description="A per unit mu: -(8/3) a^(3/2) / c (for thresholds); not serialised, so "
        "None on a result read back from JSON.",
    )
    terms: list[Term]

    def trig_sum(self) -> TrigSum:
        """The same sum as arrays, for extrema and threshold search."""
        return TrigSum(
            self.damping,
            np.array([t.coefficient for t in self.terms]),
            np.array([t.frequency for t in self.terms]),
            np.array([t.phase for t in self.terms]),
        )

    def extrema(self, period: float | None = None) -> Extrema:
        """``extrema.extrema`` of ``trig_sum()`` (``period``: a common period known beforehand);
        one sinusoid on the floats of its term (``single_extrema``), without arrays."""
        if len(self.terms) == 1 and self.terms[0].coefficient != 0.0:
            term = self.terms[0]
            return single_extrema(self.damping, term.coefficient, term.frequency, term.phase)
        return extrema(self.trig_sum(), period)

    def __call__(self, tau0: np.ndarray | float) -> np.ndarray | float:
        """Evaluate M at tau0 (array or scalar, dimensionless time)."""
        t = np.asarray(tau0, dtype=float)
        m = np.full(t.shape, self.damping)
        for term in self.terms:
            m = m + term.coefficient * np.sin(term.frequency * t + term.phase)
        return m if m.ndim else float(m)


# --- Homoclinic orbit, Eq. (15) ---------------------------------------------------------------


def homoclinic_orbit(
    t: np.ndarray | float, a: float, c: float, branch: HomoclinicBranch, fm: float = 0.0
) -> tuple:
    """(x_h, y_h) at dimensionless time t (array or scalar) on the given loop: Eq. (15) for
    F_m = 0, else the loaded loop x_s + u_s(t) of ``loops`` (u_s = s P / (cosh(k t) +
    cos theta_s)); compiled (``loops.orbit``)."""
    times = np.asarray(t, dtype=float)
    x, y = loops.orbit(times.ravel(), a, c, fm, BRANCH_SIGN[branch])
    if times.ndim == 0:
        return float(x[0]), float(y[0])
    return x.reshape(times.shape), y.reshape(times.shape)


# --- Closed form, corrected Eq. (19), compiled in ``kernels`` ------------------------------------


@functools.lru_cache(maxsize=1024)
def _system(a: float, c: float, fm: float = 0.0) -> np.ndarray:
    """The unperturbed system (a, c, F_m) in the kernels' packed ``system`` form, read-only and
    kept: every coefficient of a verdict asks for the same one."""
    system = system_array(0.0, a, c, fm, 0.0, 1.0)
    system.flags.writeable = False
    return system


def damping_coefficient(
    a: float, c: float, fm: float = 0.0, branch: HomoclinicBranch = "plus"
) -> float:
    """dA/dmu = -(8/3) a^(3/2) / c, from -2 mu * integral of y_h^2 (Eq. 19, first term); on the
    given loaded loop for F_m != 0."""
    return float(kernels.damping_unit(_system(a, c, fm), BRANCH_SIGN[branch]))


# --- Quadrature of Eq. (18), term by term -------------------------------------------------------


def _weight(
    excitation: str, a: float, c: float, branch: HomoclinicBranch, fm: float = 0.0
) -> Callable[[float], float]:
    """The odd function w(t) with term(tau0) = amplitude * integral w(t) cos(Omega(t+tau0)+phi).

    Eq. (18): y_h * 2 (a x_h - c x_h^3) for stiffness, y_h for torque and transmission error
    (whose Omega^2 factor is applied by the caller).
    """

    def w(t: float) -> float:
        x, y = homoclinic_orbit(t, a, c, branch, fm)
        if excitation == "stiffness":
            return float(2.0 * y * (a * x - c * x**3))
        return float(y)

    return w


def _quad(f: Callable[[float], float], t_max: float, **weight: object) -> float:
    """integral_0^t_max f(t) dt by QUADPACK to ~1e-11 relative (QAWO with a sine weight).

    Raises ArithmeticError when QUADPACK's error estimate exceeds 1e-9 relative (1e-12 absolute).
    """
    from scipy import integrate  # scipy loads in ~0.2 s; only the quadrature check needs it

    value, abserr, *_ = integrate.quad(
        f, 0.0, t_max, epsabs=1e-14, epsrel=1e-11, limit=1000, full_output=1, **weight
    )
    if abserr > max(1e-9 * abs(value), 1e-12):
        raise ArithmeticError(f"quadrature did not converge: {value} +- {abserr}")
    return value


def quadrature_coefficient(
    excitation: str, omega: float, a: float, c: float, branch: HomoclinicBranch, fm: float = 0.0
) -> float:
    """B per unit amplitude by numerical quadrature of Eq. (18) (QUADPACK QAWO).

    w(t) is odd, so integral w(t) cos(Omega(t + tau0) + phi) dt = -sin(Omega tau0 + phi) *
    2 integral_0^inf w(t) sin(Omega t) dt; B is the factor of sin(Omega tau0 + phi).
    """
    w = _weight(excitation, a, c, branch, fm)
    t_max = _t_max(a, c, fm)
    value = _quad(w, t_max, weight="sin", wvar=omega)
    scale = omega**2 if excitation == "transmission_error" else 1.0
    return -2.0 * value * scale


def _t_max(a: float, c: float, fm: float) -> float:
    """80 / k, k = sqrt(alpha) the saddle's rate: w decays like exp(-k t), the tail is < 1e-34."""
    return 80.0 / math.sqrt(a - 3.0 * c * loops.saddle(a, c, fm) ** 2)


def quadrature_damping(
    a: float, c: float, fm: float = 0.0, branch: HomoclinicBranch = "plus"
) -> float:
    """dA/dmu = -2 * integral y_h^2 dt by quadrature (Eq. 18) on the given loop (both loops
    give the same value for F_m = 0 only)."""
    w = _weight("torque", a, c, branch, fm)
    value = _quad(lambda t: w(t) ** 2, _t_max(a, c, fm))
    return -4.0 * value


def closed_form_coefficient(
    excitation: str, omega: float, a: float, c: float, branch: HomoclinicBranch, fm: float = 0.0
) -> float:
    """B per unit amplitude from the corrected closed form of Eq. (19) (loaded: ``loops``)."""
    kind, s = kernels.KIND[excitation], BRANCH_SIGN[branch]
    return float(kernels.unit_coefficient(kind, omega, _system(a, c, fm), s))


@dataclass(frozen=True)
class CoefficientMethod:
    """How the coefficients of M are obtained: the damping part (a, c, F_m) and each sinusoid
    per unit (excitation, Omega, a, c, branch, F_m); F_m is the load of the unperturbed system."""

    damping: Callable[[float, float, float, HomoclinicBranch], float]
    term: Callable[[str, float, float, float, HomoclinicBranch, float], float]


METHODS: dict[Method, CoefficientMethod] = {
    "closed_form": CoefficientMethod(damping_coefficient, closed_form_coefficient),
    "quadrature": CoefficientMethod(quadrature_damping, quadrature_coefficient),
}
"""Coefficient methods by name, as scipy's ``METHODS`` of solve_ivp."""


def melnikov_coefficients(
    params: GearParams,
    a: float,
    c: float,
    branch: HomoclinicBranch,
    method: Method = "closed_form",
    include_inactive: bool = False,
    fm: float = 0.0,
) -> BranchCoefficients:
    """Coefficients of M(tau0) (Eq. 19) of ``params`` on one branch for the cubic law (a, c).

    Args:
        params: the dimensionless parameters (epsilon = 1).
        a, c: cubic backlash coefficients, both > 0 (``saddle_loop``).
        branch: ``plus`` (x_h > 0) or ``minus``.
        method: a key of ``METHODS``: ``closed_form`` or ``quadrature``.
        include_inactive: keep zero-amplitude first harmonics as terms (for threshold search).
        fm: the mean force in the unperturbed system (``loop_load``; 0: a perturbation).
    """
    how = METHODS[method]
    per_unit_damping = how.damping(a, c, fm, branch)
    terms = []
    for name, exc in params.excitations():
        harmonics = list(enumerate(exc.harmonics, start=1)) or [(1, None)]
        for r, h in harmonics:
            amplitude = 0.0 if h is None else h.amplitude
            if amplitude == 0.0 and not (include_inactive and r == 1):
                continue
            omega = r * exc.frequency
            unit = how.term(name, omega, a, c, branch, fm)
            phase = 0.0 if h is None else h.phase
            terms.append(  # validated: pydantic-core does it in half model_construct's time
                Term(
                    excitation=name,
                    r=r,
                    frequency=omega,
                    phase=phase,
                    coefficient=unit * amplitude,
                    per_unit=unit,
                )
            )
    return BranchCoefficients(
        damping=per_unit_damping * params.damping, damping_per_unit=per_unit_damping, terms=terms
    )


def active_only(coef: BranchCoefficients, params: GearParams) -> BranchCoefficients:
    """``melnikov_coefficients(params, ...)`` from the same call with ``include_inactive``: the
    zero-amplitude first harmonics dropped, so one evaluation per branch (one quadrature per
    term with ``method="quadrature"``) serves both the verdict and the thresholds."""
    amplitudes = [
        0.0 if h is None else h.amplitude
        for _, exc in params.excitations()
        for r, h in (list(enumerate(exc.harmonics, start=1)) or [(1, None)])
        if r == 1 or h.amplitude != 0.0
    ]
    if all(amp != 0.0 for amp in amplitudes):
        return coef  # no inactive harmonic to drop
    return BranchCoefficients(
        damping=coef.damping,
        damping_per_unit=coef.damping_per_unit,
        terms=[t for t, amp in zip(coef.terms, amplitudes, strict=True) if amp != 0.0],
    )
