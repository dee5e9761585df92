"""``gearengine signal FILE --rate 20kHz [--speed 1500rpm --teeth 18]``: read a recorded series.

FILE is a JSON request (as ``POST /v1/signals``), or the samples as text: one value per line,
or CSV / whitespace columns (the last column is read; with two or more columns and no
``--rate`` the first is the time in seconds and sets the rate). Lines that are not numbers
(a header) are skipped. ``-`` reads standard input. Options override the request's fields; a
bare number of ``--rate`` is Hz, of ``--speed`` rpm. Prints the verdict, its evidence and the
main numbers; ``--json OUT`` writes the API's response body, ``--plot OUT`` the figure.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from gearengine.cli.documents import EXIT_OK, InvalidInputError, validated_input
from gearengine.jsonio import dumps, load_document
from gearengine.model.errors import InputError
from gearengine.model.units import with_unit
from gearengine.rig import read_signal
from gearengine.signals.schema import SignalResult
from gearengine.signals.series import SignalRequest, read_table


def signal_request(args: argparse.Namespace) -> SignalRequest:
    """The request of FILE with the options applied."""
    try:
        text = sys.stdin.read() if args.file == "-" else Path(args.file).read_text()
    except OSError as exc:
        raise InvalidInputError([f"{args.file}: {exc.strerror}"]) from None
    body: dict[str, Any]
    if text.lstrip().startswith("{"):
        try:
            doc = load_document(text)
        except ValueError as exc:
            raise InvalidInputError([f"{args.file}: {exc}"]) from None
        body = dict(doc)
    else:
        try:
            values, rate = read_table(text)
        except InputError as exc:
            raise InvalidInputError([f"{args.file}: {exc.message}"]) from None
        body = {"signal": {"values": values.tolist()}}
        if rate is not None:
            body["signal"]["sample_rate"] = rate
    sig = body.setdefault("signal", {})
    if isinstance(sig, dict):
        if args.rate is not None:
            sig["sample_rate"] = with_unit(args.rate, "Hz")
        for option in ("quantity", "unit"):
            if getattr(args, option) is not None:
                sig[option] = getattr(args, option)
        if "sample_rate" not in sig:
            raise InvalidInputError([f"{args.file}: give the sample rate: --rate 20kHz"])
    if args.speed is not None:
        body["speed"] = with_unit(args.speed, "rpm")
    if args.teeth is not None:
        body["teeth"] = args.teeth
    if args.design is not None:
        body["design"] = json.loads(Path(args.design).read_text()).get("design")
    if args.seed is not None:
        body["seed"] = args.seed
    return validated_input(SignalRequest.model_validate, body, args.file)


def report_lines(result: SignalResult) -> list[str]:
    """The verdict, the evidence and the main numbers, for a terminal."""
    out = [f"verdict: {result.verdict}", result.summary]
    ref = result.reference
    if ref.shaft_rpm is not None:
        mesh = f", {ref.teeth} teeth, mesh {ref.mesh_hz:.6g} Hz" if ref.teeth else ""
        out.append(f"reference: {ref.source}, {ref.shaft_rpm:.6g} rpm{mesh}")
    for line in result.spectrum.lines[:5]:
        where = f"order {line.order:.4g}" if line.order is not None else ""
        out.append(f"  line {line.frequency_hz:10.4g} Hz {where:14s} {line.amplitude:.4g} "
                   f"{result.record.unit}  {line.label}")  # fmt: skip
    if result.zero_one is not None:
        z = result.zero_one
        out.append(f"0-1 test: K = {z.k:.3f} (quartiles {z.k_quartiles[0]:.3f} to "
                   f"{z.k_quartiles[1]:.3f}), {z.points} points, {z.series}")  # fmt: skip
    if result.lyapunov is not None and result.lyapunov.per_second is not None:
        ly = result.lyapunov
        per = "" if ly.per_revolution is None else f", {ly.per_revolution:.4g} per revolution"
        out.append(f"largest Lyapunov exponent: {ly.per_second:.4g} /s{per} ({ly.implementation},"
                   f" m = {ly.dimension}, delay {ly.delay_s:.4g} s, fit {ly.fit_range_s[0]:.4g}-"
                   f"{ly.fit_range_s[1]:.4g} s)")  # fmt: skip
    if result.surrogates is not None:
        s = result.surrogates
        out.append(f"surrogates: p = {s.p_value:.3g} ({s.surrogates} IAAFT), "
                   f"{'rejected' if s.rejected else 'not rejected'}")  # fmt: skip
    if result.model is not None:
        out.append(result.model.summary)
    out.extend(f"note: {n}" for n in result.notes)
    return out


def cmd_signal(args: argparse.Namespace) -> int:
    """Read the series, print the reading, write --json and --plot."""
    result = read_signal(signal_request(args))
    print("\n".join(report_lines(result)))
    if args.json:
        Path(args.json).write_text(dumps(result))
    if args.plot:
        from gearengine.plots.signal import signal_figure

        fmt = "svg" if args.plot.endswith(".svg") else "png"
        Path(args.plot).write_bytes(signal_figure(result, fmt))  # type: ignore[arg-type]
    return EXIT_OK
