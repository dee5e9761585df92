"""``gearengine sweep FILE [--out DIR|-] [--format json|csv]``: run a sweep in this process,
without a server.

Writes ``STEM.json`` (the API's result document), ``STEM.csv`` and ``STEM.png`` into DIR, STEM
being FILE's name without extension; ``--out -`` writes only the JSON document (or with
``--format csv`` the CSV) to standard output. Progress goes to standard error: a bar on a
terminal, plain lines otherwise.
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from gearengine.cli.documents import EXIT_OK, InvalidInputError, read_document, validated_input
from gearengine.jsonio import dumps
from gearengine.studies.sweep.compute import run_local
from gearengine.studies.sweep.request import SweepRequest, validated
from gearengine.studies.sweep.results import to_csv

BAR = 30
"""Width of the progress bar, characters."""

GC_GEN0_THRESHOLD = 50_000
"""Allocations between young-generation collections while a sweep runs (Python's default 700)."""


@contextmanager
def quiet_gc() -> Iterator[None]:
    """Stop the cyclic collector from rescanning what the sweep keeps alive.

    A map builds a few objects per point (points, Poincaré lists) and no reference cycles; with
    the default thresholds the full collections rescan every imported module and every point
    built so far, about a quarter of a 100 x 100 map's wall time. ``gc.freeze`` moves what
    exists now (imports, request) out of the collector's sight and a larger young generation
    makes collections rare. Both are undone on exit (the command may run inside a test process).
    """
    old = gc.get_threshold()
    gc.freeze()
    gc.set_threshold(GC_GEN0_THRESHOLD, 50, 100)
    try:
        yield
    finally:
        gc.set_threshold(*old)
        gc.unfreeze()


def read_sweep(path: str) -> SweepRequest:
    """The validated sweep request of a file (``-``: stdin); raises InvalidInputError."""
    return validated_input(validated, read_document(path), path)


def progress(start: float, label: str, unit: str = "points") -> Callable[[int, int], None]:
    """Progress on standard error: a bar on a terminal, plain lines (every 10 %) when stderr is
    a file or a CI log, which a carriage return would litter; counted in ``unit``."""
    if sys.stderr.isatty():
        return progress_bar(start, unit)
    shown = [-1]

    def line(done: int, total: int) -> None:
        tenth = 10 * done // max(total, 1)
        if tenth > shown[0]:
            shown[0] = tenth
            elapsed = time.monotonic() - start
            print(f"{label}: {done}/{total} {unit}, {elapsed:.1f} s", file=sys.stderr)

    return line


def progress_bar(start: float, unit: str = "points") -> Callable[[int, int], None]:
    """A callback drawing ``[#####     ] done/total points, seconds`` on a terminal's stderr."""

    def draw(done: int, total: int) -> None:
        filled = BAR * done // max(total, 1)
        elapsed = time.monotonic() - start
        bar = "#" * filled + " " * (BAR - filled)
        end = "\n" if done >= total else ""
        print(f"\r[{bar}] {done}/{total} {unit}, {elapsed:.1f} s", end=end, file=sys.stderr)

    return draw


def cmd_sweep(args: argparse.Namespace) -> int:
    with quiet_gc():
        return _sweep(args)


def _sweep(args: argparse.Namespace) -> int:
    request = read_sweep(args.file)
    stem = "sweep" if args.file == "-" else Path(args.file).stem
    if args.out != "-" and args.file != "-":
        written = [Path(args.out) / f"{stem}.{ext}" for ext in ("json", "csv", "png")]
        if any(w.resolve() == Path(args.file).resolve() for w in written):
            why = f"the result {stem}.json would overwrite the input {args.file}"
            raise InvalidInputError([f"--out {args.out}: {why}; give another --out directory"])
    result = run_local(request, progress(time.monotonic(), stem), workers=os.cpu_count() or 1)
    for text in result.notes or []:  # a bare number on a physical axis, read in SI
        print(f"note: {text}", file=sys.stderr)
    if request.settings.basins is None:  # say what one or a few starts cannot see
        n = len(request.settings.starts())
        print(f"note: each point from {n} start{'s' if n > 1 else ''} of the settings: other "
              "attractors are not searched (settings.basins searches them, as the gate "
              "does)", file=sys.stderr)  # fmt: skip
    csv = to_csv(result, request.outputs, design=request.design is not None)
    if args.out == "-":  # stream one document to standard output, no files
        sys.stdout.write("".join(csv) if args.format == "csv" else dumps(result) + "\n")
        return EXIT_OK
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{stem}.json").write_text(dumps(result))
    (out / f"{stem}.csv").write_text("".join(csv))
    from gearengine.plots.sweep import sweep_figure  # matplotlib: only when a figure is made

    (out / f"{stem}.png").write_bytes(
        sweep_figure(request, result.points, "png", result.bifurcations)
    )
    for ext in ("json", "csv", "png"):
        print(out / f"{stem}.{ext}")
    return EXIT_OK
