"""ISO 1328-1:2013 flank tolerances of a cylindrical gear for a flank tolerance class A.

Clause 5.3 gives each tolerance of class A as its class-5 value times the class step
sqrt(2)^(A - 5) (5.2.2: one class is a factor sqrt(2)); d is the reference diameter [mm], m_n
the normal module [mm], b the face width [mm], results in µm:

(5)  f_pT  = (0.001 d + 0.4 m_n + 5) sqrt(2)^(A-5)                  single pitch
(6)  F_pT  = (0.002 d + 0.55 sqrt(d) + 0.7 m_n + 12) sqrt(2)^(A-5)  total cumulative pitch
(7)  f_HaT = (0.4 m_n + 0.001 d + 4) sqrt(2)^(A-5)                  profile slope
(8)  f_faT = (0.55 m_n + 5) sqrt(2)^(A-5)                           profile form
(9)  F_aT  = sqrt(f_HaT^2 + f_faT^2)                                total profile
(10) f_HbT = (0.05 sqrt(d) + 0.35 sqrt(b) + 4) sqrt(2)^(A-5)        helix slope
(11) f_fbT = (0.07 sqrt(d) + 0.45 sqrt(b) + 4) sqrt(2)^(A-5)        helix form
(12) F_bT  = sqrt(f_HbT^2 + f_fbT^2)                                total helix

Rounding (5.2.3): the unrounded values enter (9) and (12); each tolerance is then rounded, above
10 µm to the nearest integer, from 5 µm to 10 µm to the nearest 0.5 µm, below 5 µm to the
nearest 0.1 µm. Range of validity (clause 1): 1 <= A <= 11, 5 <= z <= 1000, 5 mm <= d <= 15 000
mm, 0.5 mm <= m_n <= 70 mm, 4 mm <= b <= 1200 mm, helix angle <= 45 deg (spur gears here: 0).
Outside it the standard says nothing, so ``tolerances`` refuses (``InputError`` naming the
design's field).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Protocol

from pydantic import BeforeValidator

from gearengine.model.errors import InputError

STANDARD = "ISO 1328-1:2013"

RANGES: dict[str, tuple[float, float]] = {
    "class": (1, 11),
    "teeth": (5, 1000),
    "reference_diameter": (5.0, 15_000.0),
    "module": (0.5, 70.0),
    "face_width": (4.0, 1200.0),
}
"""Range of validity of clause 1 (lengths in mm)."""

FIELDS: dict[str, str] = {
    "class": "tolerances.accuracy",
    "teeth": "{gear}.teeth",
    "reference_diameter": "{gear}.module",
    "module": "{gear}.module",
    "face_width": "{gear}.face_width",
}
"""The design's field (under ``design``) each input of clause 1 comes from (d = m_n z)."""


def class_number(value: object) -> int:
    """A flank tolerance class as a whole number of ``RANGES["class"]`` (7.0 read as 7);
    anything else refused saying what is accepted, a string too ("7": a class is written as the
    number, as every count of a request is), where pydantic's words named only the type."""
    low, high = RANGES["class"]
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, int) and not isinstance(value, bool) and low <= value <= high:
        return value
    text = f"not {value!r}"
    if isinstance(value, str) and value.strip().isdigit() and low <= int(value) <= high:
        text = f"write it as the number {int(value)}, not the text {value!r}"
    raise ValueError(f"an {STANDARD} flank tolerance class is a whole number from {low:g} "
                     f"(finest) to {high:g}, e.g. 7; {text}")  # fmt: skip


AccuracyClass = Annotated[int, BeforeValidator(class_number)]
"""An ISO 1328-1:2013 flank tolerance class (``class_number``); a field of it sets ``ge`` and
``le`` from ``RANGES["class"]`` for its JSON Schema (``minimum``, ``maximum``)."""


def class_step(tolerance_class: int) -> float:
    """sqrt(2)^(A - 5): the factor from class 5 to class A (5.2.2)."""
    return math.sqrt(2.0) ** (tolerance_class - 5)


def rounded(value_um: float) -> float:
    """A tolerance rounded as 5.2.3 says: > 10 µm to 1 µm, 5-10 µm to 0.5 µm, < 5 µm to 0.1 µm
    (halves up)."""
    step = 1.0 if value_um > 10.0 else 0.5 if value_um >= 5.0 else 0.1
    return round(math.floor(value_um / step + 0.5 + 1e-9) * step, 1)


@dataclass(frozen=True)
class FlankTolerances:
    """The eight flank tolerances of one gear [µm], rounded (5.2.3), and the unrounded ones."""

    f_pT: float
    F_pT: float
    f_Halpha: float
    f_falpha: float
    F_alpha: float
    f_Hbeta: float
    f_fbeta: float
    F_beta: float
    unrounded: dict[str, float]


FORMULAS: dict[str, str] = {
    "f_pT": "(5) f_pT = (0.001 d + 0.4 m_n + 5) sqrt(2)^(A-5)",
    "F_pT": "(6) F_pT = (0.002 d + 0.55 sqrt(d) + 0.7 m_n + 12) sqrt(2)^(A-5)",
    "f_Halpha": "(7) f_HaT = (0.4 m_n + 0.001 d + 4) sqrt(2)^(A-5)",
    "f_falpha": "(8) f_faT = (0.55 m_n + 5) sqrt(2)^(A-5)",
    "F_alpha": "(9) F_aT = sqrt(f_HaT^2 + f_faT^2)",
    "f_Hbeta": "(10) f_HbT = (0.05 sqrt(d) + 0.35 sqrt(b) + 4) sqrt(2)^(A-5)",
    "f_fbeta": "(11) f_fbT = (0.07 sqrt(d) + 0.45 sqrt(b) + 4) sqrt(2)^(A-5)",
    "F_beta": "(12) F_bT = sqrt(f_HbT^2 + f_fbT^2)",
}
"""Each tolerance's formula (ISO 1328-1:2013, 5.3), for the ``source`` of derived values."""


def check_range(name: str, value: float, gear: str = "driver") -> None:
    """Refuse ``value`` outside clause 1's range for ``name`` of the ``gear`` (driver or driven):
    ``InputError`` at its design field (``FIELDS``)."""
    lo, hi = RANGES[name]
    if not lo <= value <= hi:
        raise InputError(
            "design." + FIELDS[name].format(gear=gear),
            f"{name}: {value:g} is outside the range of {STANDARD} ({lo:g} to {hi:g}"
            f"{' mm' if name not in ('class', 'teeth') else ''}); the standard does not apply",
        )


def tolerances(
    tolerance_class: int, teeth: int, module_mm: float, face_width_mm: float, gear: str = "driver"
):
    """The flank tolerances of a spur gear of class ``tolerance_class`` (1..11).

    Args:
        tolerance_class: flank tolerance class A, 1 (finest) to 11.
        teeth: number of teeth z.
        module_mm: normal module m_n [mm]; the reference diameter is d = m_n z [mm].
        face_width_mm: face width b [mm].
        gear: which gear of the design it is ("driver" or "driven"), for the error's field.

    Returns:
        ``FlankTolerances`` [µm], Eq. (5)-(12) of ISO 1328-1:2013, 5.3, rounded by 5.2.3.

    Raises:
        InputError: an input outside the range of validity (clause 1), at its design field.
    """
    d = module_mm * teeth
    for name, value in (("class", tolerance_class), ("teeth", teeth), ("module", module_mm),
                        ("face_width", face_width_mm), ("reference_diameter", d)):  # fmt: skip
        check_range(name, value, gear)
    s, m, b = class_step(tolerance_class), module_mm, face_width_mm
    raw = {
        "f_pT": (0.001 * d + 0.4 * m + 5.0) * s,
        "F_pT": (0.002 * d + 0.55 * math.sqrt(d) + 0.7 * m + 12.0) * s,
        "f_Halpha": (0.4 * m + 0.001 * d + 4.0) * s,
        "f_falpha": (0.55 * m + 5.0) * s,
        "f_Hbeta": (0.05 * math.sqrt(d) + 0.35 * math.sqrt(b) + 4.0) * s,
        "f_fbeta": (0.07 * math.sqrt(d) + 0.45 * math.sqrt(b) + 4.0) * s,
    }
    raw["F_alpha"] = math.hypot(raw["f_Halpha"], raw["f_falpha"])
    raw["F_beta"] = math.hypot(raw["f_Hbeta"], raw["f_fbeta"])
    return FlankTolerances(**{k: rounded(v) for k, v in raw.items()}, unrounded=raw)


def mesh_error_bound(profile_driver_um: float, profile_driven_um: float) -> float:
    """Largest amplitude [µm] of the mesh-frequency transmission-error harmonic of a pair whose
    gears have total profile tolerances F_aT,1 and F_aT,2 [µm] (the TE model).

    Assumed (and only this): (a) the mesh-frequency harmonic of the static transmission error is
    driven by the profile deviations, which repeat on every tooth; pitch deviations vary from
    tooth to tooth and feed shaft-order sidebands, not modelled (Welbourn 1979, "Fundamental
    knowledge of gear noise: a survey", IMechE C117/79; Smith 2003, "Gear Noise and Vibration",
    2nd ed., ch. 2-3); (b) one gear's transmission error over a mesh cycle spans at most its total
    profile deviation F_a, so its mesh harmonic has an amplitude of at most F_a / 2 (rigid teeth,
    single contact); (c) the two gears' profile errors have unrelated phases and add as a
    root-sum-square, e_max = sqrt(F_aT,1^2 + F_aT,2^2) / 2. Within that bound a gear that passes
    inspection is anywhere: the amplitude is drawn uniformly on [0, e_max].
    """
    return math.hypot(profile_driver_um, profile_driven_um) / 2.0


MM_PER_M = 1e3
"""The standard's formulas take lengths in mm; a design holds them in m."""
M_PER_UM = 1e-6
"""The standard's tolerances are in µm; the engine's transmission error is in m."""


class GearData(Protocol):
    """A gear of a design: teeth, module and face width [m]."""

    teeth: int
    module: float | None
    face_width: float | None


def pair_tolerances(
    tolerance_class: int, driver: GearData, driven: GearData
) -> tuple[FlankTolerances, FlankTolerances]:
    """The flank tolerances [µm] of both gears of a pair at one class; InputError (at the
    gear's field) when a gear has no module or face width or lies outside the standard."""
    out = []
    for role, gear in (("driver", driver), ("driven", driven)):
        if gear.module is None or gear.face_width is None:
            raise InputError(f"design.{role}", "ISO 1328 needs the module and the face width")
        out.append(tolerances(tolerance_class, gear.teeth, gear.module * MM_PER_M,
                              gear.face_width * MM_PER_M, role))  # fmt: skip
    return out[0], out[1]


def pair_te_bound(tolerance_class: int, driver: GearData, driven: GearData) -> float:
    """The bound [m] of the mesh-frequency transmission-error amplitude of a pair at one class
    (``mesh_error_bound`` of both gears' total profile tolerances F_alpha)."""
    a, b = pair_tolerances(tolerance_class, driver, driven)
    return mesh_error_bound(a.F_alpha, b.F_alpha) * M_PER_UM
