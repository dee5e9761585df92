"""``gearengine sweep FILE [--out DIR]``: run a sweep in this process, without a server.

Writes ``STEM.json`` (the API's result document), ``STEM.csv`` and ``STEM.png`` into DIR, STEM
being FILE's name without extension; a progress bar goes to standard error.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path

from gearengine.cli.documents import EXIT_OK, read_document, validated_input
from gearengine.jsonio import dumps
from gearengine.plots.sweep import sweep_figure
from gearengine.sweeps.compute import run_local
from gearengine.sweeps.export import to_csv
from gearengine.sweeps.request import SweepRequest, validated

BAR = 30
"""Width of the progress bar, characters."""


def read_sweep(path: str) -> SweepRequest:
    """The validated sweep request of a file (``-``: stdin); raises InvalidInputError."""
    return validated_input(validated, read_document(path), path)


def progress_bar(start: float) -> Callable[[int, int], None]:
    """A callback drawing ``[#####     ] done/total points, seconds`` on stderr."""

    def draw(done: int, total: int) -> None:
        filled = BAR * done // max(total, 1)
        elapsed = time.monotonic() - start
        bar = "#" * filled + " " * (BAR - filled)
        end = "\n" if done >= total else ""
        print(f"\r[{bar}] {done}/{total} points, {elapsed:.1f} s", end=end, file=sys.stderr)

    return draw


def cmd_sweep(args: argparse.Namespace) -> int:
    request = read_sweep(args.file)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    stem = "sweep" if args.file == "-" else Path(args.file).stem
    result = run_local(request, progress_bar(time.monotonic()))
    (out / f"{stem}.json").write_text(dumps(result))
    (out / f"{stem}.csv").write_text("".join(to_csv(result, request.outputs)))
    (out / f"{stem}.png").write_bytes(
        sweep_figure(request, result.points, "png", result.bifurcations)
    )
    for ext in ("json", "csv", "png"):
        print(out / f"{stem}.{ext}")
    return EXIT_OK
