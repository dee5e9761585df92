"""A sweep's result as documents: the JSON of a ``SweepResult`` assembled from chunks, CSV rows,
and the table of agreement between the numerical and the Melnikov verdicts.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Iterator

from pydantic import BaseModel, Field

from gearengine.sweeps.request import SweepAxis
from gearengine.sweeps.results import SweepPoint, SweepResult


def result_json(axes: list[SweepAxis], chunk_arrays: Iterable[str]) -> Iterator[str]:
    """The JSON text of a ``SweepResult`` from the chunks' JSON arrays (in chunk order)."""
    yield '{"axes":[' + ",".join(a.model_dump_json() for a in axes) + '],"points":['
    first = True
    for array in chunk_arrays:
        inner = array.strip()[1:-1]
        if inner:
            yield ("" if first else ",") + inner
            first = False
    yield "]}"


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


def to_csv(result: SweepResult) -> Iterator[str]:
    """CSV rows of a result (see ``csv_rows``)."""
    return csv_rows(result.axes, result.points)


def csv_rows(axes: list[SweepAxis], points: Iterable[SweepPoint]) -> Iterator[str]:
    """CSV rows (header first): one column per axis, the verdicts, and poincare_x as
    space-separated numbers. Empty cells are nulls; booleans are true/false."""
    names = [a.parameter for a in axes]
    yield _csv_row([*names, *CSV_FIELDS])
    for p in points:
        cells = [p.values[n] for n in names]
        cells += [getattr(p, f) for f in CSV_FIELDS[:-1]]
        cells.append(" ".join(repr(x) for x in p.poincare_x))
        yield _csv_row(cells)


def _csv_row(cells: list[object]) -> str:
    buf = io.StringIO()
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
