"""Request and result documents of the Melnikov analysis (the /v1/melnikov and /v1/thresholds
contracts, and the CLI's ``melnikov`` command)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from gearengine.homoclinic.coefficients import (
    BranchCoefficients,
    HomoclinicBranch,
    MeanLoad,
    Method,
)
from gearengine.model.answers import Answer
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.params import MIN_FREQUENCY, WholeNumber, request_config
from gearengine.model.reduction import ParamsOrDesign

Bounds = Annotated[list[float | None], Field(min_length=2, max_length=2)]
"""A closed interval [lo, hi] of a parameter; null marks an unbounded end. (A list, not a tuple:
nested tuples give an invalid OpenAPI schema.)"""


class BranchVerdict(Answer):
    """Extrema of M over tau0 on one homoclinic branch."""

    sign_change: bool = Field(description="min M < 0 < max M: M has a simple zero.")
    min: float = Field(
        description="Minimum of M(tau0) (infimum if the frequencies are incommensurate)."
    )
    max: float = Field(description="Maximum of M(tau0) (supremum if incommensurate).")
    tau0_min: float | None = Field(
        description="tau0 of the minimum within one period, if attained."
    )
    tau0_max: float | None = Field(
        description="tau0 of the maximum within one period, if attained."
    )
    extrema: Literal["exact", "supremum", "constant"] = Field(
        description="exact: commensurate frequencies, extrema over the common period; "
        "supremum: incommensurate, sum of amplitudes; constant: no excitation."
    )


class BranchThreshold(Answer):
    """Where one branch stops changing sign as the parameter varies."""

    critical_values: list[float] = Field(description="Ends of the no-sign-change intervals.")
    no_sign_change: list[Bounds] = Field(
        description="Closed intervals [lo, hi] of the parameter where this branch has no simple "
        "zero; null is an unbounded end."
    )


class ParameterThreshold(Answer):
    """Thresholds of one control parameter, the others fixed, and the design's margin."""

    value: float | None = Field(description="The parameter's value in the given design.")
    critical_values: list[float] = Field(
        description="Values where the overall verdict (either branch changes sign) flips."
    )
    nearest: float | None = Field(
        description="The critical value nearest to the design (for an amplitude, of its sign)."
    )
    margin: float | None = Field(
        description="|value - nearest|, positive on the safe side (neither branch changes sign "
        "at the design's value), negative inside the chaos-possible region. For an amplitude the "
        "nearest critical value of the design's own sign is taken (a negative amplitude is a "
        "phase shift by pi)."
    )
    relative_margin: float | None = Field(description="margin / |nearest| (null if nearest = 0).")
    margin_in_force_scale: float | None = Field(
        None,
        description="The margin as the largest force it makes along the loops, over the force "
        "scale F_crit of the unperturbed system (as perturbation_sizes): how far first-order "
        "theory carries the threshold (null for Omega_e).",
    )
    no_chaos: list[Bounds] = Field(
        description="Intervals of the parameter where neither branch changes sign."
    )
    branches: dict[HomoclinicBranch, BranchThreshold] | None = Field(
        None, description="Per-branch thresholds (null for the frequency scan)."
    )
    scan: list[float] | None = Field(
        None, description="For a frequency: the scanned range (start, stop, points)."
    )
    note: str | None = Field(None, description="Why a threshold is missing, if it is.")


class MelnikovResult(Answer):
    """The Melnikov verdict of a design (the /v1/melnikov contract)."""

    applicable: bool = Field(
        description="False when the unperturbed system has no saddle loop (with the mean load "
        "in it: |F_m| >= F_crit)."
    )
    chaos_possible: bool | None = Field(
        description="Either branch changes sign: transverse homoclinic orbits, chaos possible. "
        "null when not applicable."
    )
    branches: dict[HomoclinicBranch, BranchVerdict] | None = Field(
        description="plus: x_h > 0 (Eq. 15), minus: x_h < 0."
    )
    thresholds: dict[str, ParameterThreshold] = Field(
        description="Per control parameter (F_e1, mu, k_p1, F_p1, Omega_e)."
    )
    coefficients: dict[HomoclinicBranch, BranchCoefficients] | None = Field(
        description="The sinusoids of M on each branch."
    )
    a: float | None = Field(description="Cubic coefficient a used (f_h = -a x + c x^3).")
    c: float | None = Field(description="Cubic coefficient c used.")
    forcing_period: float | None = Field(
        description="Common period 2 pi / Omega_0 of the active excitations (null if none or "
        "incommensurate)."
    )
    method: Method = Field(description="closed_form (corrected Eq. 19) or quadrature (Eq. 18).")
    notes: list[str] = Field(description="Caveats and explanations, in plain words.")
    mean_load: MeanLoad = Field(
        "unperturbed",
        description="unperturbed: F_m in the unperturbed system x'' = a x - c x^3 + F_m (its "
        "saddle and asymmetric loops); perturbation: the paper's first-order treatment, where "
        "F_m drops out of M.",
    )
    critical_mean_force: float | None = Field(
        None,
        description="F_crit = (2a/3) sqrt(a/(3c)): the largest |F_m| for which the unperturbed "
        "system has a saddle (null without a cubic with a, c > 0).",
    )
    saddle: float | None = Field(
        None, description="x_s, the saddle of the unperturbed system (0 without mean load)."
    )
    perturbation_sizes: dict[str, float] | None = Field(
        None,
        description="Each perturbation's largest force along the loops over the force scale "
        "F_crit (the cubic's peak restoring force): damping, stiffness, torque, "
        "transmission_error, and mean_force when it is treated as a perturbation. First-order "
        "theory assumes them small; a note says when they are not.",
    )


class ThresholdCurve(Answer):
    """Critical values of a control parameter over a frequency range (paper Figs. 5, 12, 18)."""

    parameter: str = Field(description="The control parameter: F_e1, mu, k_p1 or F_p1.")
    frequency_parameter: str = Field(
        description="The swept frequency: Omega_e, Omega_k or Omega_p."
    )
    frequencies: list[float] = Field(description="The frequency values.")
    no_chaos: list[list[Bounds]] = Field(
        description="Per frequency: intervals of the parameter where neither branch changes sign "
        "(chaos is possible outside them)."
    )
    branches: dict[HomoclinicBranch, list[list[Bounds]]] = Field(
        description="Per branch and frequency: intervals where that branch has no simple zero."
    )
    value: float | None = Field(description="The design's value of the parameter.")
    notes: list[str] = Field(description="Caveats.")


# --- requests ---------------------------------------------------------------------------


class MelnikovRequest(ParamsOrDesign):
    """``{"params": {...}}``: the Melnikov verdict of one design."""

    model_config = request_config({"params": PAPER_SECTION_41})

    method: Method = Field(
        "closed_form",
        description="closed_form: corrected Eq. (19); quadrature: Eq. (18) integrated numerically.",
    )
    mean_load: MeanLoad = Field(
        "unperturbed",
        description="unperturbed (default): the mean force F_m belongs to the unperturbed system "
        "(saddle and loops under load; not applicable for |F_m| >= F_crit); perturbation: the "
        "paper's treatment (section 3.1), F_m small and absent from M.",
    )


class ThresholdsRequest(ParamsOrDesign):
    """Threshold curves of ``parameter`` while ``frequency_parameter`` runs over a range."""

    model_config = request_config()

    parameter: Literal["F_e1", "mu", "k_p1", "F_p1"] = Field(
        "F_e1", description="Control parameter whose critical values are traced."
    )
    frequency_parameter: Literal["Omega_e", "Omega_k", "Omega_p"] = Field(
        "Omega_e",
        description="Frequency swept along the horizontal axis; its excitation (Omega_e: "
        "transmission_error, Omega_k: stiffness, Omega_p: torque) must be given in params.",
    )
    start: float = Field(
        0.05,
        ge=MIN_FREQUENCY,
        le=1e3,
        description="First frequency (dimensionless, 1e-6 to 1000).",
        examples=[0.05],
    )
    stop: float = Field(
        2.5,
        ge=MIN_FREQUENCY,
        le=1e3,
        description="Last frequency (dimensionless, 1e-6 to 1000); below start the "
        "frequencies run downwards.",
        examples=[2.5],
    )
    mean_load: MeanLoad = Field(
        "unperturbed",
        description="Where the mean force goes, as in POST /v1/melnikov.",
    )
    num: WholeNumber = Field(
        100,
        ge=2,
        le=100_000,
        description="Number of frequencies, start and stop included (the service caps it at "
        "max_curve_points, default 2000).",
        examples=[100],
    )
    # No rule joins start and stop (JSON Schema could not state it): the grid is
    # numpy.linspace(start, stop, num) in either direction, as a sweep axis is.
