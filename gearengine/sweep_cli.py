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

from pydantic import ValidationError

from gearengine.jsonio import dumps, error_lines, load_document
from gearengine.sweep_plots import render
from gearengine.sweeps import SweepRequest, run_local, to_csv, validated

BAR = 30
"""Width of the progress bar, characters."""


def read_sweep(path: str) -> SweepRequest:
    """The validated sweep request of a file (``-``: stdin); raises InvalidInputError."""
    from gearengine.cli import InvalidInputError

    try:
        text = sys.stdin.read() if path == "-" else Path(path).read_text()
        return validated(load_document(text))
    except OSError as exc:
        raise InvalidInputError([f"{path}: {exc.strerror}"]) from None
    except ValidationError as exc:
        raise InvalidInputError(error_lines(exc)) from None
    except ValueError as exc:
        raise InvalidInputError([f"{path}: {exc}"]) from None


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
    (out / f"{stem}.csv").write_text("".join(to_csv(result)))
    (out / f"{stem}.png").write_bytes(render(request, result.points, "png"))
    for ext in ("json", "csv", "png"):
        print(out / f"{stem}.{ext}")
    return 0
