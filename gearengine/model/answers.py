"""The bases of every answer's documents (results, not requests): one definition for the rooms
that answer (``homoclinic``, ``signals``, ``numerics``, ``studies``)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict


class Answer(BaseModel):
    """A computed answer: frozen, never edited after it is made (``model_copy`` makes another)."""

    model_config = ConfigDict(frozen=True)


class FiniteAnswer(Answer):
    """An answer whose every number is finite: a NaN or an infinity is refused (the numerical
    verdicts, whose non-finite values are reported as null and said why)."""

    model_config = ConfigDict(allow_inf_nan=False)
