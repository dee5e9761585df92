"""A sweep's result: the whole ``SweepResult`` (the /v1/sweeps/{id}/result contract) and its
views for analysis in Python: the CSV rows, a pandas DataFrame with the CSV's columns
(``SweepResult.to_pandas``, pandas is optional: ``pip install 'gearchaos[pandas]'``), numpy
grids of one field over the axes (``SweepResult.grid``), and a one-line summary."""

from __future__ import annotations

import io
from collections import Counter
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from gearengine.studies.sweep.export import TITLES, csv_rows
from gearengine.studies.sweep.points import SpeedWindows, SweepBifurcation, SweepPoint
from gearengine.studies.sweep.request import SweepAxis
from gearengine.studies.sweep.windows import response_label


class SweepResult(BaseModel):
    """All points of a sweep, in chunk order (first axis fastest; branch up before down)."""

    model_config = ConfigDict(frozen=True)

    axes: list[SweepAxis] = Field(description="The axes of the request.")
    values_units: dict[str, str] | None = Field(
        None,
        description="The unit of each axis' numbers in the points' values: a design field in "
        "SI (speed: rad/s, torque: N*m; each point's physical has it in its display unit, "
        "rpm), a dimensionless alias 1.",
        examples=[{"speed": "rad/s", "torque": "N*m"}],
    )
    notes: list[str] | None = Field(
        None,
        description="How bare numbers on physical axes were read (in the field's SI unit, "
        "speed in rad/s), one sentence each; absent when every end has its unit.",
    )
    points: list[SweepPoint] = Field(description="One entry per point and branch.")
    bifurcations: list[SweepBifurcation] | None = Field(
        None,
        description="One-axis continuation sweeps: the bifurcation points located on each "
        "branch, in sweep order; null for other sweeps.",
    )
    partial: bool = Field(
        False,
        description="True when points are missing: the finished chunks of a job that did not "
        "succeed (cancelled, failed or still running), fetched with ?partial=true.",
    )
    windows: list[SpeedWindows] | None = Field(
        None,
        description="Sweeps over the driver speed: per level of the other axis, the speed "
        "intervals [rpm] of each response, of tooth contact (separation, back_flank) and of "
        "Melnikov chaos; null otherwise.",
    )

    def summary(self) -> str:
        """The result in one line: axes, points, counts of each response, Melnikov."""
        return summary(self)

    def __repr__(self) -> str:
        return f"SweepResult({self.summary()!r})"

    __str__ = summary

    def to_pandas(self) -> Any:
        """A ``pandas.DataFrame`` with the CSV's columns (``results.to_pandas``); pandas
        is an optional extra: ``pip install 'gearchaos[pandas]'``."""
        return to_pandas(self)

    def grid(self, field: str, branch: str | None = None) -> tuple[list[np.ndarray], np.ndarray]:
        """(axis values, values of ``field``) as numpy arrays (``results.grid``)."""
        return grid(self, field, branch)


def to_csv(
    result: SweepResult, outputs: Sequence[str] | None = None, design: bool = False
) -> Iterator[str]:
    """CSV rows of a result (see ``csv_rows``; the basin columns when its points have basins,
    with as many attractors' columns as a point has attractors at most)."""
    basins = any(p.attractors is not None for p in result.points)
    most = max((len(p.attractors or []) for p in result.points), default=0)
    return csv_rows(result.axes, result.points, outputs, design, basins, most)


def to_pandas(result: SweepResult) -> Any:
    """A ``pandas.DataFrame``, one row per point and branch, with exactly the columns of the
    sweep's CSV (``studies.sweep.export.csv_rows``: axes in SI, a design's axes in display units as
    ``speed [rpm]``, ``dte [um]``, ``dynamic_factor``, the verdicts); ``poincare_x [b]`` holds a
    list of floats per row (units of b)."""
    try:
        import pandas as pd
    except ImportError:
        raise ImportError(
            "SweepResult.to_pandas needs pandas: pip install 'gearchaos[pandas]'"
        ) from None
    design = any(p.physical for p in result.points)
    frame = pd.read_csv(io.StringIO("".join(to_csv(result, design=design))))
    column = TITLES["poincare_x"]
    if column in frame:
        frame[column] = [
            [float(v) for v in cell.split()] if isinstance(cell, str) else []
            for cell in frame[column]
        ]
    return frame


def grid(
    result: SweepResult, field: str, branch: str | None = None
) -> tuple[list[np.ndarray], np.ndarray]:
    """One field of the points as a numpy grid over the axes.

    Parameters
    ----------
    result : the sweep result.
    field : a numeric ``SweepPoint`` field (``lle``, ``period``, ``x_peak_to_peak``, ...), or a
        key of the points' ``physical`` (``dte`` in µm, ``dynamic_factor``).
    branch : with continuation, ``"up"`` or ``"down"``; None for other sweeps.

    Returns
    -------
    axes : the grid values of each axis (SI for a design's fields, as the points' ``values``),
        shapes (n0,) and (n1,).
    values : shape (n0,) for one axis, (n1, n0) for a map (row = second axis, column = first
        axis, as ``imshow`` draws it); NaN where the field is null.
    """
    names = [a.parameter for a in result.axes]
    points = [p for p in result.points if p.branch == branch]
    axes = [np.unique([p.values[n] for p in points]) for n in names]
    values = np.full([len(a) for a in reversed(axes)], np.nan)
    pairs = list(zip(axes, names, strict=True))
    for p in points:
        index = tuple(int(np.searchsorted(a, p.values[n])) for a, n in pairs)
        if field in type(p).model_fields:
            value = getattr(p, field)
        else:  # a physical entry: PhysicalValue, or a plain dict read back from the job store
            entry = (p.physical or {}).get(field)
            value = entry["value"] if isinstance(entry, dict) else getattr(entry, "value", None)
        values[index[::-1]] = np.nan if value is None else float(value)
    return axes, values


def summary(result: SweepResult) -> str:
    """The result in one line: "sweep of F_e1 (0.0 to 0.3, 301): 301 points: periodic 1T 180,
    chaotic 121; Melnikov: chaos possible at 150 points"."""
    axes = ", ".join(f"{a.parameter} ({a.start} to {a.stop}, {a.num})" for a in result.axes)
    counts = Counter(response_label(p) for p in result.points if p.classification is not None)
    responses = ", ".join(f"{label} {n}" for label, n in counts.most_common()) or "no verdicts"
    melnikov = sum(bool(p.melnikov_chaos_possible) for p in result.points)
    unjudged = sum(p.melnikov_chaos_possible is None for p in result.points)
    na = f", not applicable at {unjudged}" if unjudged else ""  # above the critical torque
    partial = " (partial)" if result.partial else ""
    return (f"sweep of {axes}: {len(result.points)} points{partial}: {responses}; "
            f"Melnikov: chaos possible at {melnikov} points{na}")  # fmt: skip
