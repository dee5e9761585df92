"""Physical quantities as engineers type them: "1500 rpm", "50 um", "40 N*m", parsed with pint.

A field of a physical design takes a string with a unit, or a bare number in SI units. Each
kind of quantity (``QUANTITIES``) names its pint dimension, its SI unit and the range an actual
spur-gear pair can have; a value outside that range is refused, and when reading the number in
a neighbouring unit would put it inside ("100 m" for a backlash), the refusal says what was
probably meant ("did you mean 100 µm?"). Errors are ``ValueError`` whose message pydantic puts
after the field's path, so a 422 names the field, the unit given and the dimension expected.

Reference: H. E. Grecco et al., pint (https://pint.readthedocs.io), the registry used here.
"""

from __future__ import annotations

import math
import re
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from functools import cache
from typing import TYPE_CHECKING, Any

from pydantic import BeforeValidator

if TYPE_CHECKING:
    import pint


@cache
def registry() -> pint.UnitRegistry:
    """The one pint registry of the engine (rpm = rev/min = revolution per minute, µm and um
    alike),
    made when a quantity is first read: importing pint costs ~0.15 s, which every command and
    the service's start-up would otherwise pay for designs given as plain numbers."""
    import pint

    ureg = pint.UnitRegistry()
    ureg.define("rev = revolution")  # "3000 rev/min", "50 rev/s" as engineers write them
    return ureg


@dataclass(frozen=True)
class QuantityKind:
    """A kind of physical quantity: its dimension, SI unit, plausible range and the units a
    slip of the keyboard most likely meant (tried, in order, when a value is out of range)."""

    name: str
    unit: str
    low: float
    high: float
    slips: tuple[str, ...]
    example: str
    spellings: dict[str, str] = field(default_factory=dict)
    """Units as engineers type them that pint reads otherwise (``Nm``: pint's N is Avogadro's
    number), and the unit meant; the whole unit text must match."""
    negative: str | None = None
    """Why a negative value is refused, for a kind whose range starts at 0 (which otherwise
    takes either sign: a displacement, a harmonic's amplitude)."""

    @property
    def a_name(self) -> str:
        """The name with its article: "a shaft speed", "an angle" (it read "a angle")."""
        return f"{'an' if self.name[0] in 'aeiou' else 'a'} {self.name}"

    @property
    def signed(self) -> bool:
        """Negative values are read (their magnitude checked against the range)."""
        return self.low == 0.0 and self.negative is None

    @property
    def dimensionality(self) -> Any:
        return registry().Quantity(1.0, self.unit).dimensionality

    def describe(self, si: float) -> str:
        """``si`` in the kind's unit, 6 significant digits."""
        return f"{si:.6g} {self.unit}"

    def span(self) -> str:
        """The plausible range in the SI unit, and in the example's unit when it differs
        ("0.10472 rad/s to 10472 rad/s (1 to 100,000 rpm)")."""
        text = f"{self.describe(self.low)} to {self.describe(self.high)}"
        shown = self.example.split(maxsplit=1)[-1]
        if shown == self.unit:
            return text
        low, high = (registry().Quantity(v, self.unit).to(shown).magnitude
                     for v in (self.low, self.high))  # fmt: skip
        return f"{text} ({low:,.6g} to {high:,.6g} {shown})"


TORQUE_SPELLINGS = {"Nm": "N*m", "kNm": "kN*m", "MNm": "MN*m", "Nmm": "N*mm"}
"""Torque units as typed on drawings and in spreadsheets, read as newton metres (pint reads
``Nm`` as a number-metre, ``N`` being Avogadro's number there; ``N.m`` and ``N m`` it reads
right)."""

_READINGS: ContextVar[list[str] | None] = ContextVar("readings", default=None)


@contextmanager
def readings() -> Iterator[list[str]]:
    """Collect, while validating inside this block, what ``parse_quantity`` understood from a
    spelling of ``QuantityKind.spellings`` (one sentence each, for the notes of a design)."""
    found: list[str] = []
    token = _READINGS.set(found)
    try:
        yield found
    finally:
        _READINGS.reset(token)


def note(text: str) -> None:
    """Add ``text`` to the current ``readings`` (a value the design derived from another one
    the user gave, said in words); nothing outside a ``readings`` block."""
    found = _READINGS.get()
    if found is not None:
        found.append(text)


_SI_NUMBERS: ContextVar[bool] = ContextVar("si_numbers", default=False)


@contextmanager
def si_numbers() -> Iterator[None]:
    """Inside this block bare numbers are the engine's own SI values (a validated design
    dumped and read again with a field changed), read without a note."""
    token = _SI_NUMBERS.set(True)
    try:
        yield
    finally:
        _SI_NUMBERS.reset(token)


_NUMBER_AND_UNIT = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*?)\s*")


def _respelled(text: str, kind: QuantityKind) -> str:
    """``text`` with an engineer's spelling of the unit (``40 Nm``) written as pint reads it
    (``40 N*m``), noted in the current ``readings``; other text unchanged."""
    match = _NUMBER_AND_UNIT.fullmatch(text)
    if match is None or match.group(2) not in kind.spellings:
        return text
    meant = f"{match.group(1)} {kind.spellings[match.group(2)]}"
    found = _READINGS.get()
    if found is not None:
        found.append(f"{kind.name} {text.strip()!r} read as {meant!r}")
    return meant


QUANTITIES: dict[str, QuantityKind] = {
    "length": QuantityKind("length", "m", 1e-9, 10.0, ("um", "mm"), "30 mm"),
    "module": QuantityKind("module", "m", 1e-5, 0.1, ("mm",), "3 mm"),
    "half_backlash": QuantityKind("half backlash", "m", 1e-7, 5e-3, ("um", "mm"), "50 um"),
    "backlash": QuantityKind("circumferential backlash", "m", 2e-7, 1e-2, ("um", "mm"), "100 um"),
    "error": QuantityKind("transmission error", "m", 0.0, 1e-3, ("um", "mm"), "5 um"),
    "speed": QuantityKind(
        "shaft speed", "rad/s", 2 * math.pi / 60, 1e5 * 2 * math.pi / 60, ("rpm",), "1500 rpm"
    ),  # 1 to 100,000 rpm: a bare 20000 (rad/s, 191,000 rpm) is refused, not read silently
    "torque": QuantityKind("torque", "N*m", 0.0, 1e6, (), "40 N*m", TORQUE_SPELLINGS),
    "mean_torque": QuantityKind(
        "torque",
        "N*m",
        0.0,
        1e6,
        (),
        "40 N*m",
        TORQUE_SPELLINGS,
        "a mean torque is a magnitude, 0 to 1e6 N*m: the model's backlash is symmetric, so a "
        "reversed torque mirrors the response (x -> -x); give its magnitude",
    ),  # "-20 N*m" was read and answered as +20 N*m's mirror, unsaid
    "stiffness": QuantityKind("mesh stiffness", "N/m", 1e6, 1e11, ("N/um", "N/mm"), "1e8 N/m"),
    "stiffness_variation": QuantityKind(
        "stiffness variation", "N/m", 0.0, 1e11, ("N/um", "N/mm"), "1e7 N/m"
    ),
    "inertia": QuantityKind("inertia", "kg*m^2", 1e-9, 1e4, ("kg*cm^2", "kg*mm^2"), "2e-3 kg*m^2"),
    "damping": QuantityKind("damping", "N*s/m", 0.0, 1e7, (), "1100 N*s/m"),
    "angle": QuantityKind("angle", "rad", math.radians(10), math.radians(35), ("deg",), "20 deg"),
    "displacement": QuantityKind("displacement", "m", 0.0, 1e-2, ("um", "mm"), "-30 um"),
    "velocity": QuantityKind("velocity", "m/s", 0.0, 100.0, ("mm/s",), "200 mm/s"),
    "speed_rate": QuantityKind(
        "rate of change of shaft speed",
        "rad/s^2",
        2 * math.pi / 60,
        1e6 * 2 * math.pi / 60,
        ("rpm/s",),
        "1000 rpm/s",
    ),
    "duration": QuantityKind("duration", "s", 1e-3, 3600.0, ("ms", "min"), "5 s"),
    "torsional_stiffness": QuantityKind(
        "torsional stiffness",
        "N*m/rad",
        10.0,
        1e9,
        ("kN*m/rad", "MN*m/rad"),
        "3e4 N*m/rad",
        {f"{t}/rad": f"{m}/rad" for t, m in TORQUE_SPELLINGS.items()},
    ),
    "bearing_stiffness": QuantityKind(
        "bearing stiffness", "N/m", 1e5, 1e12, ("N/um", "N/mm"), "2e8 N/m"
    ),
    "mass": QuantityKind("mass", "kg", 1e-3, 1e5, ("g", "t"), "1.2 kg"),
    "shear_modulus": QuantityKind("shear modulus", "Pa", 1e9, 5e11, ("GPa", "MPa"), "79.3 GPa"),
    "sample_rate": QuantityKind("sample rate", "Hz", 1e-3, 1e8, ("kHz", "MHz"), "20 kHz"),
}
"""Kinds of quantity by key; ``low``/``high`` bound plausible magnitudes in SI units."""

# Lengths of gear bodies (radius, module, face width, bore) may be zero only for a bore.
POSITIVE_KINDS = frozenset(
    {"length", "module", "half_backlash", "speed", "stiffness", "inertia", "angle"}
)


def parse_quantity(
    value: object,
    kind: QuantityKind,
    allow_zero: bool = False,
    field: str | None = None,
    unit_required: bool = False,
) -> float:
    """``value`` (a string with a unit, or a number in SI units) in the kind's SI unit.

    Raises ValueError naming the unit given and the dimension expected, or the plausible range
    with a guess at the intended unit. A bare number is read in SI units with a note naming
    ``field`` (``_bare``), or, ``unit_required``, refused naming the units meant (a field whose
    answer has no place for the note), except inside ``si_numbers``.
    """
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise ValueError(f"give a number in {kind.unit} or a string with a unit, e.g. "
                         f"{kind.example!r}")  # fmt: skip
    if isinstance(value, str):
        if SEPARATED.search(value):
            raise ValueError(
                f"{value!r}: write the number with a decimal point and no "
                f"separators, e.g. {kind.example!r} (digits split by a comma or a "
                "space are read as neither a decimal nor a thousands mark)"
            )
        value = _respelled(value, kind)  # noted in the readings each time it is read
        key = (value, kind.unit)
        got = _text_readings.get(key)
        if got is None:
            got = _text_reading(value, kind)
            with _text_readings_lock:  # threads of one process read designs at once
                if len(_text_readings) >= TEXT_READINGS:
                    _text_readings.pop(next(iter(_text_readings)), None)
                _text_readings[key] = got
        bare, magnitude, text = got
        if bare:
            return _bare(magnitude, text, kind, allow_zero, field, unit_required)
        return _plausible(magnitude, text, kind, allow_zero)
    return _bare(float(value), value, kind, allow_zero, field, unit_required)


TEXT_READINGS = 4096
"""Quantity texts whose reading this process keeps (``parse_quantity``): ``design_with``
validates a whole design again for every envelope point and lever value, its texts ("2.5
mm", "20 N*m") the same each time, and pint's parse of one costs ~10-50 us (~4 s of the CPU
of a remedies search over every default lever). A text that is refused is never kept."""
_text_readings: dict[tuple, tuple[bool, float, str]] = {}
_text_readings_lock = threading.Lock()


def _text_reading(value: str, kind: QuantityKind) -> tuple[bool, float, str]:
    """(bare, magnitude, text) of the quantity text ``value`` (respelled: ``_respelled``) for
    ``kind``: a number with no unit (bare: its magnitude, to be noted by ``_bare``), else its
    value in the kind's SI unit (to be range-checked by ``_plausible``). Raises ValueError
    naming the unit given and the dimension expected."""
    ureg = registry()
    try:
        quantity = ureg.Quantity(value.strip())
    except Exception as exc:
        raise ValueError(f"cannot read {value!r} as a quantity ({exc}); write e.g. "
                         f"{kind.example!r}") from None  # fmt: skip
    if isinstance(quantity, ureg.Quantity) and str(quantity.units) in SHARES:
        raise ValueError(
            f"{value!r} is a share, not {kind.a_name}: give a unit of dimension "
            f"{kind.dimensionality}, e.g. {kind.example!r} (a share of a nominal value is "
            "read only where one is meant: a torque fluctuation amplitude in % of the mean "
            "torque)"
        )
    if not isinstance(quantity, ureg.Quantity) or str(quantity.units) == "dimensionless":
        return True, float(getattr(quantity, "magnitude", quantity)), value
    if quantity.dimensionless and kind.unit not in ("rad",):
        quantity = ureg.Quantity(quantity.magnitude, kind.unit)
    if quantity.dimensionality != kind.dimensionality:
        raise ValueError(
            f"{value!r} has the unit {quantity.units:~} ({quantity.dimensionality}); "
            f"{kind.a_name} needs a unit of dimension {kind.dimensionality}, e.g. "
            f"{kind.example!r}"
        )
    _angle_given(quantity, value, kind)
    return False, float(quantity.to(kind.unit).magnitude), value


ANGULAR_RATES = frozenset({"rad/s", "rad/s^2"})
"""SI units of the kinds that are an angle per time (a shaft speed, its rate of change)."""


def _angle_given(quantity: Any, value: str, kind: QuantityKind) -> None:
    """Refuse a frequency with no angle (Hz, kHz, 1/s, 1/min) for an angle per time: pint
    treats the radian as dimensionless and reads "50 Hz" as 50 rad/s (477 rpm) where a shaft's
    50 Hz means 50 rev/s (3000 rpm). The message gives both readings in units with an angle."""
    if kind.unit not in ANGULAR_RATES or "radian" in dict(quantity.to_root_units().unit_items()):
        return
    ureg, shown = registry(), kind.example.split(maxsplit=1)[-1]
    turns = (quantity * ureg.revolution).to(shown).magnitude
    radians = (quantity * ureg.radian).to(kind.unit).magnitude
    per = kind.unit.removeprefix("rad")
    raise ValueError(
        f"{value!r} has no angle (pint would read Hz and 1/s as rad/s): {kind.a_name} needs "
        f"one; write "
        f"'{turns:.6g} {shown}' or '{quantity.to('1' + per).magnitude:.6g} rev{per}' for "
        f"revolutions, '{radians:.6g} {kind.unit}' for radians"
    )


SHARES = frozenset({"percent", "permille", "ppm"})
"""Dimensionless units of a share: refused in a dimensional field (pint would read "3 %" as
0.03, and a dimensionless magnitude here as the SI unit)."""


def _bare(
    si: float,
    given: object,
    kind: QuantityKind,
    allow_zero: bool,
    field: str | None,
    unit_required: bool = False,
) -> float:
    """A bare number (no unit) read in the kind's SI unit, noted in the current ``readings``
    with the value in the example's unit ("shaft speed: the bare number 6000 read as 6000
    rad/s = 57,295.8 rpm; write '6000 rpm' if rpm was meant"), the same reading as every other
    door (API, library; the CLI's options name their unit); ``unit_required``, refused saying
    both readings (outside ``si_numbers``: the engine's own SI values read back pass)."""
    shown = kind.example.split(maxsplit=1)[-1]
    if unit_required and not _SI_NUMBERS.get():
        raise ValueError(
            f"the bare number {si:g} has no unit: {kind.a_name} needs one, e.g. "
            f"'{si:g} {shown}' or '{si:g} {kind.unit}' (no note can say how a bare number "
            "was read here)"
        )
    si = _plausible(si, given, kind, allow_zero)
    found = _READINGS.get()
    if found is not None and si != 0.0 and not _SI_NUMBERS.get():
        text = f"{field or kind.name}: the bare number {si:g} read as {kind.describe(si)}"
        if shown != kind.unit:
            other = float(registry().Quantity(si, kind.unit).to(shown).magnitude)
            text += f" = {other:,.6g} {shown}; write '{si:g} {shown}' if {shown} was meant"
        found.append(text)
    return si


def _plausible(si: float, given: object, kind: QuantityKind, allow_zero: bool) -> float:
    """``si`` if finite and in the kind's range; else a refusal with the likely slip."""
    if not math.isfinite(si):
        raise ValueError(f"{given!r} is not a finite {kind.name}")
    if si == 0.0 and allow_zero:
        return si
    shown = given if isinstance(given, str) else kind.describe(si)
    if si < 0.0 and kind.negative is not None:
        raise ValueError(f"{shown} is negative; {kind.negative}, e.g. '{-si:.6g} {kind.unit}'")
    if kind.low <= abs(si) <= kind.high and (si > 0.0 or kind.low == 0.0):
        return si
    ureg = registry()
    if si < 0.0 and kind.low > 0.0:  # no slip of the unit makes it positive
        raise ValueError(f"{shown} is negative; {kind.a_name} is a positive magnitude, e.g. "
                         f"{kind.example!r}")  # fmt: skip
    message = f"{shown} is outside the plausible range of {kind.a_name}, {kind.span()}"
    magnitude = ureg.Quantity(given.strip()).magnitude if isinstance(given, str) else si
    for slip in kind.slips:
        meant = float(ureg.Quantity(abs(float(magnitude)), slip).to(kind.unit).magnitude)
        if kind.low <= meant <= kind.high and meant > 0.0:
            message += f": did you mean {magnitude:g} {ureg.Unit(slip):~P}?"
            break
    raise ValueError(message)


SEPARATED = re.compile(r"\d,\d|\d\s+\d{3}(?![\d/])")
"""Digits split by a comma ("2,5 mm") or a thousands space ("1 500 rpm"): pint reads "2,5" as
25 and "1 500" as 500, where a user means 2.5 and 1500 (a unit that begins with a digit,
"3000 1/min", is not a split number)."""

NUMBER = r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?"
"""A decimal number as pint reads it."""


SHARE = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*%\s*")
"""A share in percent, "3 %"."""


def plain_number(name: str) -> Any:
    """A pydantic validator of a dimensionless field (a damping ratio): a share in percent
    ("5 %") is refused naming the plain number meant (0.05), since "%" is read only where a
    share of a nominal value is meant (a torque ripple of the mean torque); other input goes
    on to the field's own type."""

    def refuse_share(value: object) -> object:
        if isinstance(value, str) and (match := SHARE.fullmatch(value)):
            percent = float(match.group(1))
            raise ValueError(
                f"{value.strip()!r}: a {name} is a plain number: write {percent / 100:g} for "
                f"{percent:g} % (a share in % is read only where one of a nominal value is "
                "meant: a torque fluctuation amplitude, of the mean torque)"
            )
        return value

    return BeforeValidator(refuse_share)


def with_unit(text: str, unit: str) -> str:
    """A command-line quantity: a bare number ("500", "1e3") in the option's ``unit`` ("500
    rpm"); any other text ("52 rad/s", "5%") as written, for ``parse_quantity`` to read or
    refuse. A share is no bare number: "5%" stays a share, refused in a dimensional field,
    where "5%" with the unit appended read as "5% N*m" = 0.05 N*m, and "1e3" (a letter)
    kept no unit and was read in SI units."""
    try:
        float(text)
    except ValueError:
        return text.strip()
    return f"{text.strip()} {unit}"
