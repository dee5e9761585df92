"""A sweep's result as documents: the JSON of a ``SweepResult`` assembled from chunks, CSV rows,
and the table of agreement between the numerical and the Melnikov verdicts.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator, Sequence

from pydantic import BaseModel, Field, TypeAdapter

from gearengine.sweeps.axes import display_unit, in_display_unit, is_dimensionless
from gearengine.sweeps.request import SweepAxis
from gearengine.sweeps.results import RESPONSE_UNITS, SweepBifurcation, SweepPoint, SweepResult

_LINE_HEAD = '{"bifurcations":'
_LINE_POINTS = ',"points":['


def chunk_json(
    points: Iterable[SweepPoint],
    bifurcations: list[SweepBifurcation] | None,
    outputs: Sequence[str] | None = None,
) -> str:
    """A chunk's output (what workers exchange): the JSON array of its points, or, for a line
    of a one-axis continuation sweep, ``{"bifurcations": [...], "points": [...]}``. With
    ``outputs`` (``SweepRequest.outputs``) a point holds values, branch and those fields only."""
    keep = None if outputs is None else {"values", "branch", *outputs}
    array = ",".join(p.model_dump_json(include=keep) for p in points)
    if bifurcations is None:
        return "[" + array + "]"
    located = ",".join(b.model_dump_json() for b in bifurcations)
    return _LINE_HEAD + "[" + located + "]" + _LINE_POINTS + array + "]}"


def _chunk_parts(text: str) -> tuple[str, list[dict[str, object]] | None]:
    """The inner text of a chunk's points array and its bifurcations (None if it has none)."""
    text = text.strip()
    if not text.startswith(_LINE_HEAD):
        return text[1:-1], None
    cut = text.index(_LINE_POINTS)
    return text[cut + len(_LINE_POINTS) : -2], json.loads(text[len(_LINE_HEAD) : cut])


def chunk_points(text: str) -> list[dict[str, object]]:
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
    windows (``sweeps.windows``) of a sweep over the driver speed."""
    yield '{"axes":[' + ",".join(a.model_dump_json() for a in axes) + '],"points":['
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


def to_csv(
    result: SweepResult, outputs: Sequence[str] | None = None, design: bool = False
) -> Iterator[str]:
    """CSV rows of a result (see ``csv_rows``)."""
    return csv_rows(result.axes, result.points, outputs, design)


def csv_rows(
    axes: list[SweepAxis],
    points: Iterable[SweepPoint],
    outputs: Sequence[str] | None = None,
    design: bool = False,
) -> Iterator[str]:
    """CSV rows (header first): one column per axis (SI for a design's fields); with a
    ``design`` (a sweep of a design in physical units) the same axes in display units
    (``speed [rpm]``, ``torque [N*m]``) and, unless ``outputs`` leaves ``physical`` out, the
    DTE and the dynamic factor (``dte [um]``, ``dynamic_factor``, from the point's
    ``physical``); then the verdicts, and poincare_x as space-separated numbers. Empty cells are
    nulls; booleans are true/false; every number is written as the JSON result writes it
    (``_json_numbers``), the axis values rounded to the 15 significant digits they were given
    with (``_grid_value``). With ``outputs`` (``SweepRequest.outputs``) only the columns it
    names (and branch) are written. Rows are yielded one by one, so a streamed response never
    holds the whole table."""
    names = [a.parameter for a in axes]
    extra = _physical_columns(names, outputs) if design else []
    fields = [f for f in CSV_FIELDS if outputs is None or f == "branch" or f in outputs]
    header = [*names, *(title for _, title, _ in extra), *fields]
    yield ",".join(_text_cell(c) for c in header) + "\n"
    shown = [(key, axis) for key, _, axis in extra]
    for p in points:
        yield ",".join(_row(p, names, shown, fields)) + "\n"


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


def _physical_columns(
    names: list[str], outputs: Sequence[str] | None
) -> list[tuple[str, str, bool]]:
    """(key, column title, is an axis) of a design's sweep: each physical axis in its display
    unit (from the point's ``values``), then the response entries of ``RESPONSE_UNITS`` (from
    its ``physical``, unless ``outputs`` leaves that out)."""
    axes = [(n, f"{n} [{display_unit(n)[0]}]", True) for n in names if not is_dimensionless(n)]
    if outputs is not None and "physical" not in outputs:
        return axes
    response = [
        (key, key if unit == "1" else f"{key} [{unit}]", False)
        for key, unit in RESPONSE_UNITS.items()
    ]
    return [*axes, *response]


def _physical(p: SweepPoint, key: str, axis: bool) -> float | None:
    """A gear-unit cell: an axis value in its display unit (``in_display_unit``, as
    ``physical`` holds it), or an entry of ``physical``, which points read back from the job
    store unvalidated (``model_construct``) hold as plain dicts."""
    if axis:
        return in_display_unit(key, p.values[key])
    entry = (p.physical or {}).get(key)
    if entry is None:
        return None
    return float(entry["value"] if isinstance(entry, dict) else entry.value)


def _row(
    p: SweepPoint, names: list[str], shown: list[tuple[str, bool]], fields: list[str]
) -> list[str]:
    """The text cells of a point's row: the axis values, the gear-unit values of ``shown``,
    then each field. The floats (with the Poincaré numbers) are formatted in one
    ``_json_numbers`` call, then taken in order."""
    values = [getattr(p, f) for f in fields]
    floats = [_grid_value(p.values[n]) for n in names]
    gear = [_physical(p, key, axis) for key, axis in shown]
    floats.extend(v for v in gear if v is not None)
    for f, value in zip(fields, values, strict=True):
        if f == "poincare_x":
            floats.extend(value or [])
        elif isinstance(value, float):
            floats.append(value)
    numbers = _json_numbers(floats)
    cells = numbers[: len(names)]
    k = len(names)
    for v in gear:
        cells.append("" if v is None else numbers[k])
        k += v is not None
    for f, value in zip(fields, values, strict=True):
        if f == "poincare_x":
            n = len(value or [])
            cells.append(" ".join(numbers[k : k + n]))
            k += n
        elif isinstance(value, float):
            cells.append(numbers[k])
            k += 1
        elif isinstance(value, bool):
            cells.append(str(value).lower())
        else:
            cells.append("" if value is None else _text_cell(str(value)))
    return cells


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
