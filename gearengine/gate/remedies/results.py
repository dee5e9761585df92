"""The documents of a remedies job: each lever's samples, its remedy or why it is
unreachable, the combination of two levers, and the ranked answer."""

from __future__ import annotations

from typing import Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
)

from gearengine.gate.envelope import (
    EnvelopeReport,
)


class Sample(BaseModel):
    """One value tried: whether the envelope passed (numerical) or chaos was ruled out."""

    model_config = ConfigDict(frozen=True)

    value: float = Field(description="In the remedy's unit.")
    passed: bool
    failing_points: int = Field(
        description="Numerical: the failing points of the check at this value, of ``points``. "
        "The design's own value is checked in full (refined, as gearengine check); any other "
        "failing value's grid is not refined (the search needs pass or fail only), so a full "
        "check there finds at least as many. Melnikov: the grid points where the criterion "
        "allows chaos."
    )  # fmt: skip
    points: int = Field(description="The points that check looked at (the grid's, with the "
                        "refined ones where it refined).")  # fmt: skip


class Remedy(BaseModel):
    """The smallest change of one lever found to make the envelope pass."""

    model_config = ConfigDict(frozen=True, serialize_by_alias=True, validate_by_name=True)

    lever: str = Field(description="Design field path.")
    from_: float = Field(alias="from", description="The design's value, in unit.")
    to: float = Field(description="The remedy's value, in unit.")
    unit: str
    bound: Literal["numerical", "melnikov"]
    monotone: bool = Field(description="The bracket samples switch from fail to pass once; "
                           "else the value found is one switch, not unique.")  # fmt: skip
    bracket: list[float] = Field(description="[last failing value tried, to], in unit.")
    samples: list[Sample] = Field(description="The bracket samples, from the design's value.")
    not_applicable_points: int | None = Field(
        None, description="Melnikov: envelope points at ``to`` where the criterion does not "
        "apply (not judged; not failures).",
    )  # fmt: skip
    melnikov_points: int | None = Field(
        None, description="Melnikov: envelope grid points judged at ``to``; the guarantee holds "
        "at melnikov_points - not_applicable_points of them (none: no guarantee).",
    )  # fmt: skip
    melnikov_between: list[int] | None = Field(
        None, description="Melnikov: [points where the criterion still allows chaos at ``to``, "
        "points] on the envelope's 2x finer grid, between the search's grid points; a guarantee "
        "is offered only when the first is 0.",
    )  # fmt: skip
    contact_ratio: float | None = Field(
        None, description="With gear geometry: the transverse contact ratio at ``to`` (a "
        "profile-shift lever moves it, and with it the stiffness variation)."
    )  # fmt: skip
    iso1328_class: list[int | None] | None = Field(
        None, description="A transmission-error lever of a design with gear geometry: [class at "
        "from, class at to], the coarsest ISO 1328-1:2013 flank tolerance class whose profile "
        "tolerances bound the mesh harmonic below the amplitude, within 0.5 % for the standard's "
        "rounding (11.3 µm meets a class bound of 11.31 µm; null: none of 1-11 does)."
    )  # fmt: skip
    summary: str
    check: EnvelopeReport = Field(description="The envelope report of a run at ``to``.")


class Unreachable(BaseModel):
    """A lever with no value in its range that clears the envelope (by one bound)."""

    model_config = ConfigDict(frozen=True)

    lever: str
    bound: Literal["numerical", "melnikov"]
    searched: list[str] = Field(description="[from, far end] with units.")
    samples: list[Sample]
    why: str


class LeverSetting(BaseModel):
    """One lever's value in a combination."""

    model_config = ConfigDict(frozen=True, serialize_by_alias=True, validate_by_name=True)

    lever: str
    from_: float = Field(alias="from")
    to: float
    unit: str


class Combination(BaseModel):
    """Two levers changed together, when no single lever clears the envelope."""

    model_config = ConfigDict(frozen=True)

    levers: list[LeverSetting]
    how: str = Field(description="How it was found.")
    summary: str
    check: EnvelopeReport


class ChunkOutcome(BaseModel):
    """A chunk's result: a lever's remedies and unreachable bounds, or the combination."""

    model_config = ConfigDict(frozen=True)

    baseline: EnvelopeReport | None = Field(description="The design's own report (chunk 0).")
    passed_already: bool
    remedies: list[Remedy] = []
    unreachable: list[Unreachable] = []
    combination: Combination | None = None


class RemediesResult(BaseModel):
    """What to change, by how much, and the runs that prove it."""

    model_config = ConfigDict(frozen=True)

    passed_already: bool = Field(description="The design passes its envelope as it is.")
    answer: str = Field(description="The ranked answer in words.")
    remedies: list[Remedy] = Field(description="Ranked: smallest relative change first.")
    unreachable: list[Unreachable]
    combination: Combination | None = Field(
        description="Two levers together, only when no single lever clears the envelope."
    )
    check: EnvelopeReport | None = Field(
        description="The design's own envelope report (null only in a partial result without "
        "the first chunk)."
    )


# --- levers ---------------------------------------------------------------------------------
