"""The input of a signal reading: a recorded series in physical units, and what is known of
the shaft that made it (speed or tachometer, teeth), refused before any compute when unusable.

``SignalRequest`` is the body of ``POST /v1/signals`` and of ``gearengine signal FILE``:

    {"signal": {"values": [...], "sample_rate": "20 kHz", "quantity": "transmission_error",
     "unit": "um"}, "speed": "1500 rpm", "teeth": 18, "seed": 0}

or a ``tach`` (pulse times in seconds, pulses per revolution) instead of ``speed``, and an
optional ``design`` (the model is then run at the same speed and torque). Refusals are
``InputError``s naming the field: NaN or infinite values (pydantic: ``signal.values[i]``), a
constant series, fewer than ``MIN_SAMPLES`` samples or more than ``MAX_SAMPLES``, a sample rate
below twice the mesh frequency, a tach that is not increasing or covers fewer than
``MIN_REVOLUTIONS`` turns of the record.
"""

from __future__ import annotations

import math
import re
from functools import cached_property
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from gearengine.model.design import Design
from gearengine.model.errors import InputError
from gearengine.model.params import StrictModel, WholeNumber, given, not_both, request_config
from gearengine.model.units import SampleRate, Speed, registry

MIN_SAMPLES = 512
"""Shortest series read: the embedding and the 0-1 test need a few hundred points."""
EXAMPLE_VALUES = [round(math.sin(0.7 * k), 3) for k in range(MIN_SAMPLES)]
"""A series the reading accepts (the shortest, not constant): the schema's example."""
EXAMPLE_MESH_TONE = [round(math.sin(0.9 * math.pi * k), 3) for k in range(800)]
"""The request's example: 0.8 s at 1 kHz of an 18-tooth mesh at 1500 rpm (450 Hz), 20
revolutions, enough for an order reading (``MIN_REVOLUTIONS``); an example the service accepts
as it stands (an elided one, "...", was refused)."""
MAX_SAMPLES = 10_000_000
"""Longest series read (80 MB as float64); the service's synchronous budget is lower
(``SYNC_SAMPLES``)."""
SYNC_SAMPLES = 1 << 17
"""Longest series a synchronous request reads (the API): longer ones run with the CLI."""
MAX_PULSES = 1_000_000
MIN_REVOLUTIONS = 16
"""Fewest shaft revolutions a speed or tach must put in the record for an order reading."""

Quantity = Literal["transmission_error", "acceleration", "displacement", "velocity", "other"]
DIMENSIONS: dict[str, tuple[str, ...]] = {
    "transmission_error": ("m", "rad"),
    "displacement": ("m",),
    "velocity": ("m/s",),
    "acceleration": ("m/s^2",),
}
"""Units each quantity may be given in (their dimensions); ``other`` takes any unit."""
UNIT_SPELLINGS = {"g": "standard_gravity", "um": "micrometer", "µm": "micrometer"}
"""Units of vibration data that pint reads otherwise ("g" is a gram there)."""

Finite = Annotated[float, Field(allow_inf_nan=False)]


def read_unit(unit: str, quantity: str) -> str:
    """``unit`` if pint reads it with a dimension ``quantity`` allows; raises InputError."""
    ureg = registry()
    try:
        parsed = ureg.Unit(UNIT_SPELLINGS.get(unit.strip(), unit.strip()) or "dimensionless")
    except Exception:
        raise InputError("unit", f"cannot read {unit!r} as a unit") from None
    allowed = DIMENSIONS.get(quantity)
    if allowed is not None and not any(
        parsed.dimensionality == ureg.Unit(a).dimensionality for a in allowed
    ):
        dims = " or ".join(str(ureg.Unit(a).dimensionality) for a in allowed)
        raise InputError(
            "unit",
            f"{unit!r} has the dimension {parsed.dimensionality}; a {quantity.replace('_', ' ')}"
            f" needs {dims}",
        )
    return unit


class Signal(StrictModel):
    """The recorded series."""

    values: list[Finite] = Field(
        min_length=MIN_SAMPLES, max_length=MAX_SAMPLES,
        description=f"Samples, equally spaced in time, {MIN_SAMPLES} to {MAX_SAMPLES}.",
        examples=[EXAMPLE_VALUES],
    )  # fmt: skip
    sample_rate: SampleRate = Field(description="Samples per second, e.g. '20 kHz'.")
    quantity: Quantity = Field("other", description="What was measured.")
    unit: str = Field(
        "1", max_length=40, description="Unit of the values, e.g. 'um', 'm/s^2', 'g', 'urad'."
    )

    @model_validator(mode="after")
    def _usable(self) -> Signal:
        read_unit(self.unit, self.quantity)
        lo, hi = min(self.values), max(self.values)
        if not hi > lo:
            raise InputError("values", f"the series is constant ({lo:g}): nothing to read")
        return self

    @cached_property
    def array(self) -> np.ndarray:
        """The values as float64, shape (n,)."""
        return np.asarray(self.values, dtype=np.float64)

    @property
    def duration(self) -> float:
        """Length of the record, s."""
        return len(self.values) / self.sample_rate


class Tach(StrictModel):
    """Tachometer pulses: their times and how many make a revolution."""

    times: list[Finite] = Field(
        min_length=2, max_length=MAX_PULSES,
        description="Pulse times in seconds from the first sample, increasing.",
    )  # fmt: skip
    per_revolution: WholeNumber = Field(1, ge=1, le=10000, description="Pulses per revolution.")

    @model_validator(mode="after")
    def _increasing(self) -> Tach:
        steps = np.diff(np.asarray(self.times))
        if not np.all(steps > 0.0):
            k = int(np.argmax(steps <= 0.0)) + 1
            raise InputError(f"times.{k}", "pulse times must increase")
        return self

    def revolutions(self) -> tuple[np.ndarray, np.ndarray]:
        """(pulse times [s], shaft revolutions at them)."""
        t = np.asarray(self.times, dtype=float)
        return t, np.arange(t.size) / self.per_revolution


class SignalRequest(StrictModel):
    """``{"signal": {...}, "speed" or "tach", "teeth", "design", "seed"}``: read a series."""

    model_config = request_config(
        {
            "signal": {"values": EXAMPLE_MESH_TONE, "sample_rate": "1 kHz",
                       "quantity": "transmission_error", "unit": "um"},
            "speed": "1500 rpm",
            "teeth": 18,
        }
    )  # fmt: skip
    model_config["json_schema_extra"] |= {  # as _consistent checks
        "allOf": [
            not_both("speed", "tach"),
            {"if": given("teeth"),
             "then": {"anyOf": [given("speed"), given("tach"), given("design")]}},
        ]
    }  # fmt: skip

    signal: Signal
    speed: Speed | None = Field(None, description="Shaft speed, constant, e.g. '1500 rpm'.")
    tach: Tach | None = Field(None, description="Tachometer pulses, instead of a speed.")
    teeth: WholeNumber | None = Field(
        None, ge=1, le=1000, description="Teeth of the gear on that shaft: mesh orders, strobes "
        "once per mesh period."
    )  # fmt: skip
    design: Design | None = Field(
        None, description="The pair in physical units: the model's verdict at the same speed "
        "(the signal's, when given) beside the signal's."
    )  # fmt: skip
    seed: WholeNumber = Field(0, ge=0, le=2**32 - 1, description="Seed of the 0-1 test's "
                              "frequencies and of the surrogates.")  # fmt: skip

    @model_validator(mode="after")
    def _consistent(self) -> SignalRequest:
        if self.speed is not None and self.tach is not None:
            raise InputError("tach", "give speed or tach, not both")
        if self.teeth is not None and self.shaft_hz is None:
            raise InputError("teeth", "teeth need a speed or a tach (or a design)")
        shaft = self.shaft_hz
        if shaft is None:
            return self
        source = "tach" if self.tach is not None else "speed"
        revs = self.signal.duration * shaft
        if revs < MIN_REVOLUTIONS:
            raise InputError(source, f"the record holds {revs:.3g} revolutions at "
                             f"{shaft * 60:.6g} rpm; an order reading needs at least "
                             f"{MIN_REVOLUTIONS}")  # fmt: skip
        mesh = shaft * (self.mesh_teeth or 1)
        if self.signal.sample_rate < 2.0 * mesh:
            what = "mesh" if self.mesh_teeth else "shaft"
            raise InputError(
                "signal.sample_rate",
                f"{self.signal.sample_rate:.6g} Hz is below twice the {what} frequency "
                f"({mesh:.6g} Hz at {shaft * 60:.6g} rpm): the {what} order is aliased",
            )
        return self

    @property
    def mesh_teeth(self) -> int | None:
        """The teeth given, else the design's driver teeth (with a design), else None."""
        if self.teeth is not None:
            return self.teeth
        return None if self.design is None else self.design.driver.teeth

    @property
    def shaft_hz(self) -> float | None:
        """Mean shaft speed [rev/s]: the speed, the tach's mean, the design's speed, or None."""
        if self.speed is not None:
            return self.speed / (2.0 * math.pi)
        if self.tach is not None:
            t, revs = self.tach.revolutions()
            return float((revs[-1] - revs[0]) / (t[-1] - t[0]))
        if self.design is not None:
            return self.design.speed / (2.0 * math.pi)
        return None


_SPLIT = re.compile(r"[,;\s]+")


def read_table(text: str) -> tuple[np.ndarray, float | None]:
    """(values, sample rate [Hz] from a time column, or None) of a text or CSV table: one value
    per line, or columns split by commas, semicolons or blanks (the last column is read; with
    two or more, a first column that increases is the time in seconds). Lines before the
    numbers that are not numbers (a header) are skipped; raises InputError("signal.values")."""
    rows = []
    for number, line in enumerate(text.splitlines(), start=1):
        fields = [f for f in _SPLIT.split(line.strip()) if f]
        if not fields:
            continue
        try:
            rows.append([float(f) for f in fields])
        except ValueError:
            if rows:  # a header comes first; text after the numbers is an error
                raise InputError("signal.values", f"line {number}: not a number: "
                                 f"{line.strip()[:60]!r}") from None  # fmt: skip
    if not rows:
        raise InputError("signal.values", "no numbers found")
    width = len(rows[0])
    if any(len(r) != width for r in rows):
        raise InputError("signal.values", "rows have different numbers of columns")
    table = np.asarray(rows, dtype=float)
    rate = None
    if width >= 2:
        step = np.diff(table[:, 0])
        if step.size and np.all(step > 0.0):
            rate = 1.0 / float(np.median(step))
    return table[:, -1], rate
