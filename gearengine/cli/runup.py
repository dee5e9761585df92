"""``gearengine runup FILE --from 500 --to 6000 --rate 1000``: a run-up in this process.

FILE holds ``{"design": {...}}`` (and any other field of ``POST /v1/runups``; the options
override them). Bare numbers of ``--from``/``--to`` are rpm, of ``--rate`` rpm/s, of
``--duration`` seconds, of ``--to-torque`` N m. Prints a table per branch (bins, contact, FTLE,
the quasi-static DTE beside it) and the jumps with their lag behind the quasi-static loop;
``--json OUT`` writes the API's document, ``--plot OUT.png|OUT.svg`` the figure.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from gearengine.cli.documents import EXIT_OK, InvalidInputError, read_document, validated_input
from gearengine.cli.sweep import progress_bar
from gearengine.jsonio import dumps
from gearengine.model.units import with_unit
from gearengine.studies.runup.compute import run_local
from gearengine.studies.runup.profile import validated_runup
from gearengine.studies.runup.request import RunupRequest
from gearengine.studies.runup.results import RunupBranch, RunupResult

OPTIONS = {  # attribute -> (request field, unit of a bare number, option)
    "from_speed": ("from_speed", "rpm", "--from"),
    "to_speed": ("to_speed", "rpm", "--to"),
    "rate": ("rate", "rpm/s", "--rate"),
    "duration": ("duration", "s", "--duration"),
    "to_torque": ("to_torque", "N*m", "--to-torque"),
}


def runup_request(args: argparse.Namespace) -> RunupRequest:
    """The request of FILE with the options applied."""
    doc = read_document(args.file)
    if not isinstance(doc, dict) or "design" not in doc:
        raise InvalidInputError([f'{args.file}: a run-up needs {{"design": {{...}}}}'])
    body, options = dict(doc), {}
    for attribute, (field, unit, option) in OPTIONS.items():
        value = getattr(args, attribute, None)
        if value is not None:
            body[field], options[field] = with_unit(value, unit), option
    if args.direction is not None:
        body["direction"] = args.direction
    if args.bin is not None:
        body["bin_rpm"], options["bin_rpm"] = args.bin, "--bin"
    if args.ensemble is not None:
        body["ensemble"] = {**body.get("ensemble", {}), "size": args.ensemble}
    return validated_input(validated_runup, body, args.file, options)


def _number(value: float | None, fmt: str) -> str:
    return "-" if value is None else format(value, fmt)


def _percent(share: float | None) -> str:
    """A share of the time in %, two significant digits: '0.2' beside a bin labelled
    separation, where '0.00' (a fraction to two decimals) read as never apart."""
    return "-" if share is None else "0" if share == 0 else f"{100 * share:.2g}"


def branch_table(name: str, branch: RunupBranch, result: RunupResult) -> list[str]:
    """One line per bin: speed, DTE (and the quasi-static one), factor, contact (shares of time
    apart and on the back flank in %, entries onto the drive and the back flank), FTLE."""
    quasi = {round(p.speed_rpm, 6): p for p in getattr(result.quasi_static, name).points}
    lines = [
        f"run-{name}:",
        "  speed [rpm]    time [s]   DTE [µm]  QS DTE  dyn.f.  contact      sep %  back % "
        "impacts drive/back  FTLE/tau",
    ]
    for b in branch.bins:
        lo, hi = b.speed_rpm
        q = quasi.get(round(0.5 * (lo + hi), 6))
        impacts = "/".join(  # entries onto each flank, as the JSON's two counts
            "-" if n is None else str(n) for n in (b.drive_flank_impacts, b.back_flank_impacts)
        )
        lines.append(
            f"  {lo:6.0f}-{hi:<6.0f} {b.time_s[0]:6.2f}-{b.time_s[1]:<5.2f} "
            f"{_number(b.dte_peak_to_peak_um, '8.2f')} "
            f"{_number(None if q is None else q.dte_peak_to_peak_um, '7.2f')} "
            f"{_number(b.dynamic_factor, '6.2f')}  {b.contact or '-':12s} "
            f"{_percent(b.separation_fraction):>5s}  {_percent(b.back_flank_fraction):>6s} "
            f"{impacts:>18s}  {_number(b.lle, '+8.4f')}{' chaotic' if b.chaotic else ''}"
        )
    for j in branch.jumps:
        lag = ""
        if j.lag_rpm is not None:
            lag = f"; quasi-static at {j.quasi_static_speed_rpm:.0f} rpm, lag {j.lag_rpm:+.0f} rpm"
        lines.append(f"  jump at {j.speed_rpm:.0f} rpm: {j.from_um:.1f} -> {j.to_um:.1f} µm{lag}")
    return lines


def quasi_static_lines(result: RunupResult) -> list[str]:
    """The quasi-static jumps of the directions run ("quasi-static up: jump at 4150 rpm, 25.3
    -> 53.7 µm"): a run-up alone has no down branch, so the loop's down jump is not its own."""
    return [f"quasi-static {name}: jump at {j.speed_rpm:.0f} rpm, "
            f"{j.from_um:.1f} -> {j.to_um:.1f} µm"
            for name in ("up", "down") if getattr(result, name) is not None
            for j in getattr(result.quasi_static, name).jumps]  # fmt: skip


def cmd_runup(args: argparse.Namespace) -> int:
    """Run the run-up, print the tables, write --json and --plot."""
    request = runup_request(args)
    result = run_local(request, progress_bar(time.monotonic()), workers=os.cpu_count() or 1)
    for name in ("up", "down"):
        branch = getattr(result, name)
        if branch is not None:
            print("\n".join(branch_table(name, branch, result)))
    for line in quasi_static_lines(result):
        print(line)
    for note in [*result.notes, *request.design.readings]:  # the design's bare numbers too
        print(f"note: {note}")
    if args.json:
        Path(args.json).write_text(dumps(result))
    if args.plot:
        from gearengine.plots.runup import runup_figure

        fmt = "svg" if args.plot.endswith(".svg") else "png"
        Path(args.plot).write_bytes(runup_figure(result, fmt))  # type: ignore[arg-type]
    return EXIT_OK
