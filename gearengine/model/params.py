"""The dimensionless parameter model of the gear pair, Eq. (9) of the seed paper.

    x'' + 2 mu~ x' + (1 + 2 sum_r k~_pr cos(r Omega_k tau + phi_kr)) f_h(x)
        = F~_m + sum_r F~_pr cos(r Omega_p tau + phi_pr)
               + sum_r (r Omega_e)^2 F~_er cos(r Omega_e tau + phi_er)          (Eq. 9)

x is the dynamic transmission error divided by the half backlash b, tau = omega_n t is
dimensionless time. This module is the single definition of the parameters used by the engine,
the HTTP API and the CLI (it imports nothing but pydantic). Every number is validated to be
finite; bad input raises ``pydantic.ValidationError`` (a ``ValueError``) naming the field.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Annotated, Any, Literal

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, PrivateAttr

MAX_HARMONICS = 32
"""Largest number of harmonics r = 1..R accepted per excitation."""

PAPER_A = 0.1667
"""Cubic backlash coefficients of the paper, f_h(x) = -0.1667 x + 0.1667 x^3 (Eq. 9)."""

MAX_MAGNITUDE = 1.0e6
"""Largest magnitude of an amplitude, force or coefficient; beyond it numbers overflow."""

MIN_FREQUENCY = 1.0e-6
"""Smallest dimensionless frequency (a period of 6e6 time units)."""

Finite = Annotated[float, Field(allow_inf_nan=False)]
"""Any finite number (NaN and +-inf refused)."""
Magnitude = Annotated[float, Field(allow_inf_nan=False, ge=-MAX_MAGNITUDE, le=MAX_MAGNITUDE)]
"""A finite dimensionless amplitude, force or coefficient, |value| <= MAX_MAGNITUDE."""
Phase = Annotated[float, Field(allow_inf_nan=False, ge=-1.0e3, le=1.0e3)]


def request_config(*examples: object) -> ConfigDict:
    """Config of every request model: unknown fields, NaN/inf and lax coercions (a bool or a
    string for a number) are refused; ``examples`` document the model in the OpenAPI schema."""
    config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)
    if examples:
        config["json_schema_extra"] = {"examples": list(examples)}
    return config


WholeNumber = Annotated[
    int, BeforeValidator(lambda v: int(v) if isinstance(v, float) and v.is_integer() else v)
]
"""An integer as JSON Schema counts them: 2.0 is the integer 2 (strict mode refuses floats)."""


def given(name: str) -> dict[str, Any]:
    """JSON schema: the object has the field ``name``, and not as null (an optional field's
    null counts as absent)."""
    return {"required": [name], "properties": {name: {"not": {"type": "null"}}}}


def not_both(a: str, b: str) -> dict[str, Any]:
    """JSON schema: the object does not have both fields ``a`` and ``b`` (``given``)."""
    return {"not": {"allOf": [given(a), given(b)]}}


class StrictModel(BaseModel):
    """Base of every request model of the engine (``request_config``)."""

    model_config = request_config()


class Harmonic(StrictModel):
    """One harmonic r of an excitation: amplitude times cos(r Omega tau + phase)."""

    amplitude: Magnitude = Field(
        0.0,
        description="Dimensionless amplitude of this harmonic (k~_pr, F~_er or F~_pr).",
        examples=[0.2],
    )
    phase: Phase = Field(
        0.0,
        description="Phase angle phi_r of this harmonic, radians (|phi| <= 1000).",
        examples=[0.0],
    )


class Excitation(StrictModel):
    """A periodic excitation: fundamental frequency Omega and harmonics r = 1..R."""

    frequency: Annotated[float, Field(ge=MIN_FREQUENCY, le=1.0e3, allow_inf_nan=False)] = Field(
        description="Dimensionless fundamental frequency Omega = omega / omega_n (1e-6 to 1000).",
        examples=[0.5],
    )
    harmonics: list[Harmonic] = Field(
        default_factory=list,
        max_length=MAX_HARMONICS,
        description=(
            "Harmonics r = 1, 2, ... in order; entry r-1 multiplies cos(r Omega tau + phase). "
            f"At most {MAX_HARMONICS}."
        ),
        examples=[[{"amplitude": 0.2, "phase": 0.0}]],
    )

    def active(self) -> Iterator[tuple[int, Harmonic]]:
        """Yield (r, harmonic) for every harmonic with a nonzero amplitude."""
        for r, h in enumerate(self.harmonics, start=1):
            if h.amplitude != 0.0:
                yield r, h


class CubicBacklash(StrictModel):
    """Cubic approximation of the backlash law, f_h(x) = -a x + c x^3 (Eq. 9)."""

    model_config = request_config()
    model_config["json_schema_extra"] = {"required": ["model"]}  # the union's tag (Backlash)

    model: Literal["cubic"] = Field("cubic", description="Backlash law: cubic polynomial.")
    a: Magnitude = Field(
        PAPER_A,
        description="Linear coefficient a of f_h(x) = -a x + c x^3 (paper: 0.1667).",
        examples=[PAPER_A],
    )
    c: Magnitude = Field(
        PAPER_A,
        description="Cubic coefficient c of f_h(x) = -a x + c x^3 (paper: 0.1667).",
        examples=[PAPER_A],
    )


class PiecewiseBacklash(StrictModel):
    """Exact backlash law of Eq. (8): slope alpha inside the clearance |x| <= 1, 1 outside."""

    model_config = request_config()
    model_config["json_schema_extra"] = {"required": ["model"]}  # the union's tag (Backlash)

    model: Literal["piecewise"] = Field(
        "piecewise", description="Backlash law: piecewise linear, Eq. (8)."
    )
    alpha: Annotated[float, Field(ge=0.0, lt=1.0, allow_inf_nan=False)] = Field(
        0.0,
        description="Stiffness ratio alpha inside the clearance, 0 <= alpha < 1 (paper: 0).",
        examples=[0.0],
    )


Backlash = Annotated[CubicBacklash | PiecewiseBacklash, Field(discriminator="model")]

EXCITATIONS = ("stiffness", "transmission_error", "torque")
"""Names of the three excitations, in the order used by the kernels."""


class GearParams(StrictModel):
    """Dimensionless parameters of Eq. (9); an omitted excitation has zero amplitude."""

    damping: Annotated[float, Field(ge=0.0, le=1.0e3, allow_inf_nan=False)] = Field(
        description="Damping ratio mu~ = c / (2 m omega_n).", examples=[0.07]
    )
    mean_force: Magnitude = Field(
        0.0, description="Mean transmitted force F~_m = F^_m / (b k_m).", examples=[0.01]
    )
    backlash: Backlash = Field(
        default_factory=CubicBacklash,
        description="Backlash law f_h: cubic (default a = c = 0.1667) or piecewise (Eq. 8).",
        examples=[
            {"model": "cubic", "a": 0.1667, "c": 0.1667},
            {"model": "piecewise", "alpha": 0.0},
        ],
    )
    stiffness: Excitation | None = Field(
        None,
        description="Mesh-stiffness variation: amplitudes k~_pr at frequency Omega_k.",
        examples=[{"frequency": 1.0, "harmonics": [{"amplitude": 0.0, "phase": 0.0}]}],
    )
    transmission_error: Excitation | None = Field(
        None,
        description=(
            "Static transmission error: amplitudes F~_er = e_r / b at frequency Omega_e; "
            "the forcing is (r Omega_e)^2 F~_er cos(r Omega_e tau + phi_er)."
        ),
        examples=[{"frequency": 0.5, "harmonics": [{"amplitude": 0.2, "phase": 0.0}]}],
    )
    torque: Excitation | None = Field(
        None,
        description="Torque fluctuation: amplitudes F~_pr at frequency Omega_p.",
        examples=[{"frequency": 0.1, "harmonics": [{"amplitude": 0.0, "phase": 0.0}]}],
    )

    model_config = request_config(
        {
            "damping": 0.07,
            "mean_force": 0.01,
            "backlash": {"model": "cubic", "a": 0.1667, "c": 0.1667},
            "transmission_error": {
                "frequency": 0.5,
                "harmonics": [{"amplitude": 0.2, "phase": 0.0}],
            },
        }
    )

    _shaft_orders: dict[str, float] | None = PrivateAttr(None)

    @property
    def shaft_orders(self) -> dict[str, float] | None:
        """For the parameters of a design: each excitation's fundamental as a multiple of the
        driver speed (stiffness: the teeth z; transmission error and torque: their orders),
        from which ``model.frequencies`` takes the Poincare period exactly; None for
        parameters given dimensionless. Not part of the JSON: it travels with the object."""
        return None if self._shaft_orders is None else dict(self._shaft_orders)

    def with_shaft_orders(self, orders: dict[str, float] | None) -> GearParams:
        """A copy recording ``orders`` (see ``shaft_orders``)."""
        copy = self.model_copy()
        copy._shaft_orders = None if orders is None else dict(orders)
        return copy

    def same_parameters(self, other: GearParams) -> bool:
        """Equal parameters of Eq. (9) (``==`` also compares ``shaft_orders``)."""
        return self.model_dump() == other.model_dump()

    def excitations(self) -> Iterator[tuple[str, Excitation]]:
        """Yield (name, excitation) for each excitation that is given."""
        for name in EXCITATIONS:
            exc = getattr(self, name)
            if exc is not None:
                yield name, exc

    def active_frequencies(self) -> list[float]:
        """Frequencies r Omega of every harmonic with nonzero amplitude (1/time units)."""
        return [r * exc.frequency for _, exc in self.excitations() for r, _ in exc.active()]
