"""A sweep's result as documents: the JSON of a ``SweepResult`` assembled from chunks, CSV rows,
and the table of agreement between the numerical and the Melnikov verdicts.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Iterable, Iterator, Sequence

from pydantic import BaseModel, Field

from gearengine.sweeps.request import SweepAxis
from gearengine.sweeps.results import SweepBifurcation, SweepPoint, SweepResult

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
    "poincare_x",
)


def to_csv(result: SweepResult, outputs: Sequence[str] | None = None) -> Iterator[str]:
    """CSV rows of a result (see ``csv_rows``)."""
    return csv_rows(result.axes, result.points, outputs)


def csv_rows(
    axes: list[SweepAxis], points: Iterable[SweepPoint], outputs: Sequence[str] | None = None
) -> Iterator[str]:
    """CSV rows (header first): one column per axis, the verdicts, and poincare_x as
    space-separated numbers. Empty cells are nulls; booleans are true/false. With ``outputs``
    (``SweepRequest.outputs``) only the columns it names (and branch) are written. Rows are
    yielded one by one, so a streamed response never holds the whole table."""
    names = [a.parameter for a in axes]
    fields = [f for f in CSV_FIELDS if outputs is None or f == "branch" or f in outputs]
    buf = io.StringIO()
    yield _csv_row([*names, *fields], buf)
    for p in points:
        cells: list[object] = [_grid_value(p.values[n]) for n in names]
        for f in fields:
            value = getattr(p, f)
            if f == "poincare_x":
                value = " ".join(map(repr, value or []))
            cells.append(value)
        yield _csv_row(cells, buf)


def _grid_value(x: float) -> float:
    """An axis value as the decimal it stands for: ``numpy.linspace`` computes 0.204 as
    0.20400000000000001 (an ulp away); 15 significant digits snap it back, so the cell reads
    0.204 (every float is written in repr's shortest form)."""
    return float(f"{x:.15g}")


def _csv_row(cells: list[object], buf: io.StringIO | None = None) -> str:
    """One CSV line of ``cells``; ``buf`` (emptied first) is reused across rows if given."""
    if buf is None:
        buf = io.StringIO()
    buf.seek(0)
    buf.truncate()
    csv.writer(buf, lineterminator="\n").writerow(
        ["" if c is None else str(c).lower() if isinstance(c, bool) else c for c in cells]
    )
    return buf.getvalue()


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
