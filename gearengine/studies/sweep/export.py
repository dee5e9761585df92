"""A sweep's result as documents: the JSON of a ``SweepResult`` assembled from chunks, CSV rows,
and the table of agreement between the numerical and the Melnikov verdicts.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator, Mapping, Sequence
from functools import lru_cache
from typing import Any

import numpy as np
from pydantic import BaseModel, Field, TypeAdapter

from gearengine.model.units import (
    POINT_OUTPUTS,
    RECORD_FORCES,
    display_label,
    field_unit,
    in_display_unit,
)
from gearengine.numerics.headline import of_starts
from gearengine.numerics.magnitudes import ADVERSE
from gearengine.studies.sweep.axes import axis_unit, bare_reading, is_dimensionless
from gearengine.studies.sweep.points import SweepBifurcation, SweepPoint
from gearengine.studies.sweep.request import SweepAxis


def chunk_json(
    points: Iterable[SweepPoint],
    bifurcations: list[SweepBifurcation] | None,
    outputs: Sequence[str] | None = None,
) -> str:
    """A chunk's output (what workers exchange), JSON lines: the JSON array of its points and,
    for a line of a one-axis continuation sweep, a second line with the JSON array of its
    bifurcations. Compact JSON holds no raw newline (strings escape it), so each line is one
    whole document. With ``outputs`` (``SweepRequest.outputs``) a point holds values, branch
    and those fields only, with the names of whose they are (``NAMED_WITH``)."""
    keep = None if outputs is None else {"values", "branch", *outputs}
    if keep is not None:
        keep |= {name for field in outputs or () for name in NAMED_WITH.get(field, ())}
    array = "[" + ",".join(p.model_dump_json(include=keep) for p in points) + "]"
    if bifurcations is None:
        return array
    return array + "\n[" + ",".join(b.model_dump_json() for b in bifurcations) + "]"


NAMED_WITH = {
    "classification": ("decided_by", "decided_fraction"),
    "physical": ("magnitudes_from",),
}
"""Fields kept with an output a sweep keeps (with basins): who decided the verdict fields, and
which attractor each magnitude of ``physical`` comes from."""


def _chunk_parts(text: str) -> tuple[str, list[dict[str, object]] | None]:
    """The inner text of a chunk's points array (its elements, streamed as they are) and its
    bifurcations (None if it has none), one JSON document per line (``chunk_json``)."""
    points, *located = text.strip().split("\n")
    inner = points.strip().removeprefix("[").removesuffix("]")
    return inner, json.loads(located[0]) if located else None


def points_of_chunk(text: str) -> list[dict[str, object]]:
    """The points of a chunk's output, as JSON objects."""
    return json.loads("[" + _chunk_parts(text)[0] + "]")


def chunk_bifurcations(chunk_outputs: Iterable[str]) -> list[SweepBifurcation] | None:
    """The bifurcations of all chunks, in chunk order; None when no chunk located any."""
    found = [_chunk_parts(text)[1] for text in chunk_outputs]
    if all(f is None for f in found):
        return None
    return [SweepBifurcation.model_validate(b) for f in found for b in f or []]


def result_json(
    axes: list[SweepAxis],
    chunk_arrays: Iterable[str],
    partial: bool = False,
    windows: list[BaseModel] | None = None,
) -> Iterator[str]:
    """The JSON text of a ``SweepResult`` from the chunks' outputs (``chunk_json``, in chunk
    order): the points streamed as they are, the lines' bifurcations gathered at the end.
    ``partial``: some chunks are missing (a job that did not succeed); ``windows``: the speed
    windows (``studies.sweep.windows``) of a sweep over the driver speed."""
    units = {a.parameter: axis_unit(a.parameter) for a in axes}
    ends = [(a.parameter, f"axes[{i}].{end}", getattr(a, end))
            for i, a in enumerate(axes) for end in ("start", "stop")]  # fmt: skip
    notes = [text for end in ends if (text := bare_reading(*end))]
    yield (
        '{"axes":[' + ",".join(a.model_dump_json() for a in axes) + '],"values_units":'
        + json.dumps(units) + ',"notes":' + json.dumps(notes or None) + ',"points":['
    )  # fmt: skip
    first = True
    located: list[dict[str, object]] | None = None
    for array in chunk_arrays:
        inner, bifurcations = _chunk_parts(array)
        if bifurcations is not None:
            located = (located or []) + bifurcations
        if inner:
            yield ("" if first else ",") + inner
            first = False
    shown = (
        "null" if windows is None else "[" + ",".join(w.model_dump_json() for w in windows) + "]"
    )
    yield (
        '],"bifurcations":' + json.dumps(located) + ',"partial":' + json.dumps(partial)
        + ',"windows":' + shown + "}"
    )  # fmt: skip


CSV_FIELDS = (
    "branch",
    "classification",
    "period",
    "lle",
    "lle_stderr",
    "impact_regime",
    "melnikov_chaos_possible",
    "periods_run",
    "x_peak_to_peak",
    "force_max",
    "force_min",
    "poincare_x",
)
"""The CSV's columns after the axes, the long Poincaré column last."""

LLE_UNIT = "1/tau"
"""The unit of an LLE: per unit of the dimensionless time tau = omega_n t (docs/units.md)."""
X_UNIT = "b"
"""The unit of x: half backlashes (dimensionless, docs/units.md)."""
TITLES = {
    "lle": f"lle [{LLE_UNIT}]",
    "lle_stderr": f"lle_stderr [{LLE_UNIT}]",
    "x_peak_to_peak": f"x_peak_to_peak [{X_UNIT}]",
    "poincare_x": f"poincare_x [{X_UNIT}]",
}
"""The CSV titles of the ``CSV_FIELDS`` that have a unit."""
BASIN_COLUMNS = ("decided_by", "decided_fraction", "basin_starts", "record_from")
"""The CSV's columns with settings.basins, before the ``attractor_columns``: who decided the
verdict columns (the worst attractor above basins.min_fraction), its fraction, the starts run,
and whose run the record columns (x_peak_to_peak, poincare_x, the unitless forces) are
(``RECORD_FROM``): not the verdict's attractor, which may differ (chaotic beside a constant
poincare_x)."""
RECORD_FROM = "worst of the settings' own starts"
"""The ``record_from`` cell of a point with basins (``SweepPoint.attractors``' description)."""
ATTRACTOR_COLUMNS = ("class", "period", "impact_regime", "fraction", "fraction_low",
                     "fraction_high", f"lle [{LLE_UNIT}]")  # fmt: skip
"""Each attractor's columns with settings.basins (``attractor_columns``): its class, period (in
T0), contact regime, basin fraction with its 95 % Wilson interval, and LLE."""
FROM_COLUMNS = tuple(f"{key}_from" for key in POINT_OUTPUTS)
"""With settings.basins and a design's magnitude columns, before ``BASIN_COLUMNS``: the
attractor each magnitude column comes from (``SweepPoint.magnitudes_from``, 'periodic 1T, ...
from 69 % of starts'): the largest over the attractors above basins.min_fraction (force_min the
smallest), which need not be the one that decided the verdict."""


def csv_rows(
    axes: list[SweepAxis],
    points: Iterable[SweepPoint | PointFields],
    outputs: Sequence[str] | None = None,
    design: bool = False,
    basins: bool = False,
    attractors: int = 0,
) -> Iterator[str]:
    """CSV rows (header first): one column per axis, a design's field in SI units and titled
    with its unit (``speed [rad/s]``, ``torque [N*m]``); with a ``design`` (a sweep of a design
    in physical units) the axes whose display unit differs also in that unit (``speed [rpm]``)
    and, unless ``outputs`` leaves ``physical`` out, the DTE, the dynamic factor and the mesh
    forces in N (``dte [um]``, ``dynamic_factor``, ``force_max [N]``, ``force_min [N]``, from the
    point's ``physical``; the unitless ``force_max`` and ``force_min`` in units of b k_m are
    then left out: with basins they would be another start's); then the verdicts (the LLE per
    unit tau: ``lle [1/tau]``), and poincare_x as space-separated numbers. Empty cells are
    nulls; booleans are true/false. Axis cells are plain decimals (``_axis_cell``: 500,
    0.000001, never 500.0 beside 1e-6), rounded to the 15 significant digits they were given
    with (``_grid_value``); every other number is written as the JSON result writes it
    (``_json_numbers``). With ``outputs`` (``SweepRequest.outputs``) only the columns it names
    (and branch) are written. Rows are yielded one by one, so a streamed response never holds
    the whole table. With ``basins`` (a sweep with settings.basins, whose verdict columns are
    the worst attractor's) the ``FROM_COLUMNS`` (with the magnitude columns) and the
    ``BASIN_COLUMNS`` follow, then the columns of ``attractors`` attractors, worst first
    (``attractor_columns``; the most any point has), empty where a point has fewer."""
    names = [a.parameter for a in axes]
    extra = _physical_columns(names, outputs) if design else []
    magnitudes = [key for key, _, axis in extra if not axis]
    fields = [f for f in CSV_FIELDS if (outputs is None or f == "branch" or f in outputs)
              and not (f in RECORD_FORCES and f in magnitudes)]  # fmt: skip
    header = [*map(_axis_title, names), *(title for _, title, _ in extra),
              *(TITLES.get(f, f) for f in fields)]  # fmt: skip
    named = basins and bool(magnitudes)
    found = attractors if basins else 0
    if basins:
        header += [*(FROM_COLUMNS if named else ()), *BASIN_COLUMNS,
                   *attractor_columns(found, named)]  # fmt: skip
    yield ",".join(_text_cell(c) for c in header) + "\n"
    shown = [(key, axis) for key, _, axis in extra]
    for p in points:
        cells = _row(p, names, shown, fields)
        if basins:
            fields_of = p.__dict__ if isinstance(p, SweepPoint) else p
            cells += _from_cells(fields_of) if named else []
            cells += _basin_cells(fields_of)
            cells += _attractor_cells(fields_of, found, named)
        yield ",".join(cells) + "\n"


def attractor_columns(count: int, magnitudes: bool) -> list[str]:
    """The titles of ``count`` attractors' columns, ``attractor_0_class``, ...,
    ``attractor_0_lle [1/tau]``, then ``attractor_1_class``, ...: numbered as the JSON indexes
    a point's ``attractors`` (0 the worst; ``magnitudes_from``'s ``attractor`` is that index):
    the ``ATTRACTOR_COLUMNS``, with ``magnitudes`` (a design's sweep) also its ``dte [um]``,
    ``dynamic_factor``, ``force_max [N]``, ``force_min [N]``."""
    names = [*ATTRACTOR_COLUMNS, *(display_label(key) for key in ADVERSE if magnitudes)]
    return [f"attractor_{k}_{name}" for k in range(count) for name in names]


def _attractor_cells(p: PointFields, count: int, magnitudes: bool) -> list[str]:
    """The cells of ``attractor_columns`` of a point (empty past its own attractors)."""
    found = p.get("attractors") or []
    width = len(attractor_columns(1, magnitudes))
    cells: list[str] = []
    for k in range(count):
        if k >= len(found):
            cells += [""] * width
            continue
        a = found[k] if isinstance(found[k], Mapping) else found[k].__dict__
        low, high = a["interval"]
        shown = [a[key] for key, _, _ in ADVERSE.values()] if magnitudes else []
        values = [a["classification"], a["period"], a["impact_regime"], a["fraction"], low,
                  high, a["lle"], *shown]  # fmt: skip
        cells += [_value_cell(v) for v in values]
    return cells


def _value_cell(value: object) -> str:
    """A cell of one value: empty for null, a text or a whole number as it is, a float as the
    JSON writes it."""
    if value is None:
        return ""
    if isinstance(value, str):
        return _text_cell(value)
    if isinstance(value, int):
        return str(value)
    return _json_numbers([float(value)])[0]  # type: ignore[arg-type]


def _from_cells(p: PointFields) -> list[str]:
    """The ``FROM_COLUMNS`` cells of a point: each magnitude's attractor named with its basin
    fraction (empty where the point has none)."""
    named = p.get("magnitudes_from") or {}
    out = []
    for key in POINT_OUTPUTS:
        a = named.get(key)
        if a is None:
            out.append("")
            continue
        label, fraction = (a["label"], a["fraction"]) if isinstance(a, Mapping) else \
            (a.label, a.fraction)  # fmt: skip
        out.append(_text_cell(of_starts(label, fraction)))
    return out


def _basin_cells(p: PointFields) -> list[str]:
    """The ``BASIN_COLUMNS`` cells of a point (empty where it has no basins)."""
    counts = p.get("basins")
    fraction = p.get("decided_fraction")
    starts = None if counts is None else (
        counts["starts"] if isinstance(counts, Mapping) else counts.starts)  # fmt: skip
    return [
        "" if p.get("decided_by") is None else _text_cell(str(p["decided_by"])),
        "" if fraction is None else _json_numbers([float(fraction)])[0],
        "" if starts is None else str(starts),
        "" if counts is None else _text_cell(RECORD_FROM),
    ]


STREAM_BLOCK = 1 << 16
"""Characters per piece of a streamed document (``text_blocks``)."""


def text_blocks(parts: Iterable[str], size: int = STREAM_BLOCK) -> Iterator[str]:
    """``parts`` joined into pieces of about ``size`` characters (the last one shorter). A
    streamed response hands each piece of a synchronous iterator to a thread of its pool: one
    row per hand-over (~0.1 ms each) held a million-row CSV at 0.5 MB/s."""
    block: list[str] = []
    count = 0
    for part in parts:
        block.append(part)
        count += len(part)
        if count >= size:
            yield "".join(block)
            block, count = [], 0
    if block:
        yield "".join(block)


PointFields = Mapping[str, Any]
"""A point's fields by name: a ``SweepPoint``'s ``__dict__``, or a point of a stored chunk as
its JSON object (``points_of_chunk``), whose nested documents are plain dicts."""


def _physical_columns(
    names: list[str], outputs: Sequence[str] | None
) -> list[tuple[str, str, bool]]:
    """(key, column title, is an axis) of a design's sweep: each physical axis in its display
    unit (from the point's ``values``), then the responses and the record's mesh forces of
    ``model.units.POINT_OUTPUTS`` (``dte [um]``, ``dynamic_factor``, ``force_max [N]``,
    ``force_min [N]``, from its ``physical``, unless ``outputs`` leaves that out)."""
    axes = [
        (n, f"{n} [{field_unit(n).display}]", True)
        for n in names
        if not is_dimensionless(n) and field_unit(n).display != field_unit(n).si
    ]
    if outputs is not None and "physical" not in outputs:
        return axes
    response = [(key, display_label(key), False) for key in POINT_OUTPUTS]
    return [*axes, *response]


def _axis_title(name: str) -> str:
    """An axis column's title: the alias, or a design field with its SI unit."""
    if axis_unit(name) == "1":
        return name
    return f"{name} [{axis_unit(name)}]"


@lru_cache(maxsize=1 << 16)
def _axis_cell(x: float) -> str:
    """An axis value as a plain decimal (shortest that reads back to the same float), cached:
    the values of an axis repeat on every line of a map."""
    return np.format_float_positional(x, trim="-")


def _physical(p: PointFields, key: str, axis: bool) -> float | None:
    """A gear-unit cell: an axis value in its display unit (``in_display_unit``, as
    ``physical`` holds it), or an entry of ``physical`` (a document, or a plain dict)."""
    if axis:
        return in_display_unit(key, p["values"][key])
    entry = (p.get("physical") or {}).get(key)
    if entry is None:
        return None
    return float(entry["value"] if isinstance(entry, dict) else entry.value)


def _row(
    point: SweepPoint | PointFields,
    names: list[str],
    shown: list[tuple[str, bool]],
    fields: list[str],
) -> list[str]:
    """The text cells of a point's row: the axis values, the gear-unit values of ``shown``,
    then each field (a field the point lacks is empty). The floats (with the Poincaré
    numbers) are formatted in one ``_json_numbers`` call, then put in their cells."""
    p = point.__dict__ if isinstance(point, SweepPoint) else point
    cells = [_axis_cell(_grid_value(p["values"][n])) for n in names]
    floats: list[float] = []
    later: list[tuple[int, int]] = []  # (cell, count of numbers) filled after formatting
    for key, axis in shown:
        value = _physical(p, key, axis)
        if axis:
            cells.append(_axis_cell(value))
            continue
        if value is not None:
            later.append((len(cells), 1))
            floats.append(value)
        cells.append("")
    for f in fields:
        value = p.get(f)
        if f == "poincare_x":
            later.append((len(cells), len(value or [])))
            cells.append("")
            floats.extend(value or [])
        elif value is None:
            cells.append("")
        elif type(value) is float:
            later.append((len(cells), 1))
            cells.append("")
            floats.append(value)
        elif type(value) is bool:
            cells.append("true" if value else "false")
        else:
            cells.append(_text_cell(str(value)))
    if floats:
        numbers = _json_numbers(floats)
        k = 0
        for cell, count in later:
            cells[cell] = numbers[k] if count == 1 else " ".join(numbers[k : k + count])
            k += count
    return cells


@lru_cache(maxsize=1024)
def _text_cell(text: str) -> str:
    """A text cell quoted as the csv module quotes it (RFC 4180), only when it must be. Numbers
    never need it, so the rows are joined without scanning their long Poincaré cells."""
    if any(ch in text for ch in ',"\r\n'):
        return '"' + text.replace('"', '""') + '"'
    return text


_FLOATS = TypeAdapter(list[float])


def _json_numbers(values: list[float]) -> list[str]:
    """Each float as the JSON result writes it (pydantic-core's shortest round-trip form, e.g.
    0.00001 and 1e-7): a cell reads exactly as the JSON value, and a map's 64 Poincaré numbers
    per point take about a tenth of the time of ``repr`` (the CSV's largest cost)."""
    return _FLOATS.dump_json(values).decode()[1:-1].split(",") if values else []


@lru_cache(maxsize=1 << 16)
def _grid_value(x: float) -> float:
    """An axis value as the decimal it stands for: ``numpy.linspace`` computes 0.204 as
    0.20400000000000001 (an ulp away); 15 significant digits snap it back, so the cell reads
    0.204."""
    return float(f"{x:.15g}")


class AgreementTable(BaseModel):
    """How the numerical classification agrees with the Melnikov region (counts of points)."""

    chaotic_inside: int = Field(description="Numerically chaotic, Melnikov: chaos possible.")
    chaotic_outside: int = Field(description="Numerically chaotic, Melnikov: no chaos.")
    regular_inside: int = Field(description="Not chaotic, Melnikov: chaos possible.")
    regular_outside: int = Field(description="Not chaotic, Melnikov: no chaos.")
    not_applicable: int = Field(description="Points without a Melnikov verdict.")


def agreement_table(points: Iterable[SweepPoint]) -> AgreementTable:
    """Count points by numerical chaos (classification chaotic) and Melnikov region."""
    counts = dict.fromkeys(AgreementTable.model_fields, 0)
    for p in points:
        if p.melnikov_chaos_possible is None:
            counts["not_applicable"] += 1
            continue
        kind = "chaotic" if p.classification == "chaotic" else "regular"
        counts[f"{kind}_{'inside' if p.melnikov_chaos_possible else 'outside'}"] += 1
    return AgreementTable(**counts)
