"""The ``gearengine`` command line.

    gearengine melnikov FILE [--json] [--method closed_form|quadrature] [--mean-load ...]
    gearengine analyze FILE [--json]
    gearengine check FILE [--fail-on chaotic|quasi_periodic|diverged|melnikov|back_flank|separation]
        [--max-lle V] [--max-dte E] [--max-dynamic-factor F]
        [--min-stability-margin X]
    gearengine remedies FILE --speed A:B [--torque A:B] [check's rules] [--lever PATH=LO:HI]
    gearengine sweep FILE [--out DIR|-] [--format json|csv]
    gearengine runup FILE --from 500 --to 6000 --rate 1000 [--direction up|down|up_down]
        [--bin 50] [--json OUT] [--plot OUT.png]
    gearengine basins FILE [--starts N] [--json] [--plot FILE]
    gearengine campbell FILE [--json] [--plot FILE]
    gearengine convert FILE [--json]
    gearengine signal FILE --rate 20kHz [--speed 1500rpm --teeth 18] [--json OUT] [--plot OUT]

FILE holds ``{"params": {...}}`` or ``{"design": {...}}`` (physical units), and ``"settings"``
for analyze/check; ``-`` reads standard input. ``--json`` prints exactly the body the HTTP API
returns. Exit codes: 0 success (check: pass), 1 check failed, 2 invalid input (one line per
problem, naming the field), 141 the reader of standard output went away (``| head``): no
traceback, and the shell's code of a process that SIGPIPE stopped (128 + 13), so a closed pipe
is never mistaken for a failed check.

More commands come from installed plugins: every entry point of the group ``gearengine.commands``
is a function ``register(subparsers)``; the service registers ``serve`` and ``worker`` this way,
so the engine's commands work without the web stack installed.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import logging
import math
import os
import re
import sys
import traceback
from collections.abc import Callable, Sequence
from importlib.metadata import entry_points
from typing import NoReturn

from gearengine.cli.documents import (
    EXIT_INTERNAL,
    EXIT_INVALID,
    EXIT_PIPE,
    GATED,
    InvalidInputError,
)
from gearengine.model.units import IMPACTS_REFUSED, QUANTITIES, parse_quantity

PLUGIN_GROUP = "gearengine.commands"
"""Entry-point group of command plugins: each is a ``register(subparsers)`` function."""

Command = Callable[[argparse.Namespace], int]


def lazy(module: str, name: str) -> Command:
    """The command ``name`` of ``module``, imported when it runs: each command pays only for
    the rooms it uses (``convert`` and ``melnikov`` never load matplotlib), and ``--help`` or
    a usage error for none."""

    def run(args: argparse.Namespace) -> int:
        command: Command = getattr(importlib.import_module(module), name)
        return command(args)

    run.__qualname__ = run.__name__ = name
    return run


def lever_range(text: str) -> dict[str, object]:
    """``mesh.half_backlash=5um:200um`` as a lever range (bare numbers are SI units)."""
    path, _, bounds = text.partition("=")
    ends = [e.strip() for e in bounds.split(":")]
    if not path.strip() or len(ends) != 2 or not all(ends):
        raise argparse.ArgumentTypeError(f"{text!r}: give PATH=LOW:HIGH, e.g. "
                                         "mesh.half_backlash=5um:200um")  # fmt: skip
    return {"lever": path.strip(), "bounds": [_number_or_text(e) for e in ends]}


def _number_or_text(text: str) -> float | str:
    try:
        return float(text)
    except ValueError:
        return text


def finite(text: str) -> float:
    """A number option (a limit, a rate): nan and inf are refused, argparse naming the option
    (``--max-dynamic-factor nan`` passed every point: no comparison with nan is true)."""
    try:
        return _finite(float(text), text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None


def rate(text: str) -> float:
    """``--runup``: a positive rate [rpm/s] (``finite``); 0 or below is refused naming the
    option, where the run-up request refused it as "rate" and "bin_rpm", fields the command
    line never shows."""
    value = finite(text)
    if value <= 0.0:
        raise argparse.ArgumentTypeError(
            f"{text!r}: give a positive rate in rpm/s (the run-down runs at the same rate)"
        )
    return value


def per_tau(text: str) -> float:
    """``--max-lle``: a plain number per unit tau (``finite``); a value with a unit ("1/s") is
    refused saying so, where it read "'1/s' is not a number" beside a help saying check prints
    the LLE in 1/s too."""
    try:
        float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: the LLE limit is per unit tau (tau = omega_n t), a plain number; check "
            "prints the 1/s equivalent beside it"
        ) from None
    return finite(text)


def micrometres(text: str) -> float:
    """A length option in µm: a bare number is µm, "0.02 mm" is read with its unit; nan and
    inf refused (``finite``)."""
    try:
        value = float(text)
    except ValueError:
        try:
            value = parse_quantity(text, QUANTITIES["error"]) * 1e6
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    return _finite(value, text)


def _finite(value: float, text: str) -> float:
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r}: give a finite number")
    return value


def samples_count(text: str) -> int | str:
    """``--samples`` of the probability gate: a whole number of at least 1, or ``auto``
    (``--samples 0`` divided by zero in ``samples_needed``)."""
    if text == "auto":
        return text
    try:
        count = int(text)
    except ValueError:
        count = 0
    if count < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: give a whole number of at least 1 (a power "
                                         "of 2) or auto")  # fmt: skip
    return count


def fail_on_word(text: str) -> str:
    """A --fail-on word; the old word impacts refused saying which two to write
    (``gate.envelope.IMPACTS_REFUSED``), as the API and the library refuse it."""
    if text == "impacts":
        raise argparse.ArgumentTypeError(IMPACTS_REFUSED)
    return text


def grid_options(p: argparse.ArgumentParser) -> None:
    """--speed-points and --torque-points, left None when not given, so that a command they
    do not apply to can refuse them (``gate.resolution.GRID_POINTS`` fills them in)."""
    p.add_argument("--speed-points", type=int, default=None, metavar="N", help="default 23")
    p.add_argument("--torque-points", type=int, default=None, metavar="N", help="default 5")


def envelope_options(p: argparse.ArgumentParser, speed_required: bool = False) -> None:
    """The gate's rules and envelope options, shared by ``check`` and ``remedies``."""
    p.add_argument(
        "--fail-on",
        action="append",
        type=fail_on_word,
        choices=["chaotic", "quasi_periodic", "diverged", "melnikov", "back_flank", "separation"],
        help="repeatable; back_flank: back-flank impacts, separation: the teeth apart at some "
        "time (the old word impacts is refused: it meant two things)",
    )
    p.add_argument("--speed", metavar="LOW:HIGH", required=speed_required,
                   help="driver speeds: rpm, or with units")  # fmt: skip
    p.add_argument("--torque", metavar="LOW:HIGH", help="mean driver torques: N m, or with units")
    grid_options(p)
    p.add_argument("--max-dte", type=micrometres, default=None, metavar="E",
                   help="fail where the dynamic transmission error (peak to peak) exceeds E "
                   "(µm, or with a unit: 20um, 0.02mm)")  # fmt: skip
    p.add_argument("--max-dynamic-factor", type=finite, default=None, metavar="F",
                   help="fail where the largest dynamic mesh force exceeds F times the static "
                   "force")  # fmt: skip
    p.add_argument(
        "--max-lle",
        type=per_tau,
        default=None,
        help="fail when the LLE exceeds V per unit tau (tau = omega_n t; "
        "check prints it in 1/s too)",
    )
    p.add_argument("--starts", type=int, default=None, metavar="N",
                   help="envelope checks: basin starts per operating point (default 16; 1: "
                   "the settings' own start only)")  # fmt: skip
    p.add_argument("--min-basin", type=finite, default=None, metavar="F",
                   help="envelope checks: check only attractors whose basin fraction is above "
                   "F (default: every attractor found)")  # fmt: skip
    p.add_argument("--refine", type=int, default=None, metavar="N", choices=range(5),
                   help="envelope checks: halve the grid spacing up to N times where neighbouring "
                   "points differ (verdict or attractor set) or a point is near a limit "
                   "(default 2: down to a 4x finer grid's points there; 0: the grid "
                   "only)")  # fmt: skip


def build_parser() -> argparse.ArgumentParser:
    """The engine's commands and those of every installed plugin."""
    parser = argparse.ArgumentParser(
        prog="gearengine",
        description="Periodic or chaotic? Melnikov and numerical verdicts for spur-gear pairs.",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("melnikov", help="Melnikov verdict, thresholds and margins of a design")
    p.add_argument("file", help='JSON file holding {"params": {...}} or {"design": {...}}, or -')
    p.add_argument("--json", action="store_true", help="print the API's JSON response")
    p.add_argument("--method", choices=["closed_form", "quadrature"], default=None)
    p.add_argument(
        "--mean-load",
        choices=["unperturbed", "perturbation"],
        default=None,
        help="where the mean force goes (default unperturbed; perturbation: the paper's)",
    )
    p.set_defaults(func=lazy("gearengine.cli.melnikov", "cmd_melnikov"))

    p = sub.add_parser("analyze", help="Melnikov and numerical verdicts of a design")
    p.add_argument(
        "file", help='JSON file holding {"params" or "design": {...}, "settings": {...}}, or -'
    )
    p.add_argument("--json", action="store_true", help="print the API's JSON response")
    p.set_defaults(func=lazy("gearengine.cli.analyze", "cmd_analyze"))

    p = sub.add_parser(
        "check",
        help="CI gate: exit 1 when the design fails (0 pass, 2 invalid input)",
        description="--fail-on X fails on X or anything worse "
        "(periodic < quasi_periodic < chaotic < diverged); melnikov fails when a transverse "
        "homoclinic tangle is possible; back_flank on back-flank impacts; separation when the "
        "teeth separate (drive-flank impacts, or impacts on both flanks). Default: --fail-on "
        "chaotic; the limits (--max-lle, --max-dte, --max-dynamic-factor, --min-stability-margin) "
        "add to it. With "
        "--speed and/or --torque the whole operating envelope of a design is checked.",
    )
    p.add_argument(
        "file", help='JSON file holding {"params" or "design": {...}, "settings": {...}}, or -'
    )
    envelope_options(p)
    p.add_argument("--json", metavar="FILE", help="write the gate's report (JSON): the "
                   "envelope's, or with --max-probability the probability gate's")  # fmt: skip
    p.add_argument("--junit", metavar="FILE", help="write a JUnit XML report")
    p.add_argument("--server", metavar="URL", help="run the envelope on a running service "
                   "(API key from GEARCHAOS_API_KEY)")  # fmt: skip
    p.add_argument("--runup", type=rate, default=None, metavar="RATE",
                   help="envelope checks: also run up and down through --speed at RATE rpm/s "
                   "at each torque level (same rules; chaos fails after 0.05 s)")  # fmt: skip
    p.add_argument(
        "--min-stability-margin",
        type=finite,
        default=None,
        metavar="X",
        help="fail when the response is periodic and its Floquet stability margin "
        "1 - max |lambda| is below X (or unavailable); one design only, not an envelope",
    )
    p.add_argument(
        "--max-probability",
        action="append",
        metavar="NAME=P",
        help="fail where the 95 %% upper bound of P(NAME) over the design's "
        f"tolerances exceeds P (NAME one of {', '.join(GATED)}; repeatable, one limit a name)",
    )
    p.add_argument("--samples", type=samples_count, default=None,
                   help="with --max-probability: N, a power of 2 (64), refused when too few "
                   "to prove a limit; or auto: double until every point is decided")  # fmt: skip
    p.add_argument("--seed", type=int, default=None, help="with --max-probability (default 0)")
    p.set_defaults(func=lazy("gearengine.cli.analyze", "cmd_check"))

    p = sub.add_parser("campbell", help="modes and Campbell diagram of a gear train")
    p.add_argument("file", help='JSON file holding {"design": {... "train": {...}}}, or -')
    p.add_argument("--json", action="store_true", help="print the API's JSON response")
    p.add_argument("--plot", metavar="FILE", help="write the diagram (.png or .svg)")
    p.set_defaults(func=lazy("gearengine.cli.campbell", "cmd_campbell"))

    p = sub.add_parser("basins", help="coexisting attractors of a design and their basins")
    p.add_argument("file", help='JSON file holding {"params" or "design": {...}, "settings": '
                   '{"basins": {...}}}, or -')  # fmt: skip
    p.add_argument("--starts", type=int, default=None, metavar="N",
                   help="number of starts (a square on a grid: 16, 64, 256)")  # fmt: skip
    p.add_argument("--json", action="store_true", help="print the API's JSON response")
    p.add_argument("--plot", metavar="FILE", help="write the basin picture (.png or .svg)")
    p.set_defaults(func=lazy("gearengine.cli.basins", "cmd_basins"))

    p = sub.add_parser(
        "remedies",
        help="what to change in a failing design, by how much (exit 1: nothing found)",
        description="For each lever (damping, transmission error, half backlash down and up, "
        "stiffness variation, torque fluctuation) the smallest change that makes the envelope "
        "pass under the gate's rules, numerically (verified by a run) and by the Melnikov "
        "criterion.",
    )
    p.add_argument("file", help='JSON file holding {"design": {...}, "settings": {...}}, or -')
    envelope_options(p, speed_required=True)
    p.add_argument("--lever", action="append", type=lever_range, metavar="PATH=LOW:HIGH",
                   help="search this design field instead of the default levers, e.g. "
                   "mesh.half_backlash=5um:200um (repeatable)")  # fmt: skip
    p.add_argument("--json", metavar="FILE", help="write the result (as POST /v1/remedies)")
    p.set_defaults(func=lazy("gearengine.cli.remedies", "cmd_remedies"))

    p = sub.add_parser("robustness", help="probabilities over a design's tolerances, here")
    p.add_argument("file", help='JSON file holding {"design": {..., "tolerances": {...}}}, or -')
    p.add_argument("--speed", metavar="LOW:HIGH", help="driver speeds: rpm, or with units")
    p.add_argument("--torque", metavar="LOW:HIGH", help="mean driver torques: N m, or with units")
    grid_options(p)
    p.add_argument("--samples", type=int, default=256, help="samples N, a power of 2 (256)")
    p.add_argument("--seed", type=int, default=0, help="seed of the Sobol samples (0)")
    p.add_argument("--sensitivity", action="store_true", help="also Sobol indices (SALib)")
    p.add_argument("--json", metavar="FILE", help="write the result (the API's document)")
    p.add_argument("--plot", metavar="PNG", help="write the probability map")
    p.set_defaults(func=lazy("gearengine.cli.robustness", "cmd_robustness"))

    p = sub.add_parser("sweep", help="run a sweep here, no server: JSON, CSV and PNG")
    p.add_argument("file", help="JSON file holding a sweep request (as POST /v1/sweeps), or -")
    p.add_argument("--out", default=".", help="directory for the outputs (default .); - writes "
                   "the result to standard output instead")  # fmt: skip
    p.add_argument("--format", choices=["json", "csv"], default="json",
                   help="with --out -: the JSON result (default) or the CSV table")  # fmt: skip
    p.set_defaults(func=lazy("gearengine.cli.sweep", "cmd_sweep"))

    p = sub.add_parser("runup", help="run-up / run-down of a design: DTE, contact, FTLE, jumps")
    p.add_argument("file", help='JSON file holding {"design": {...}} (and run-up fields), or -')
    p.add_argument("--from", dest="from_speed", metavar="SPEED", help="lower speed (rpm)")
    p.add_argument("--to", dest="to_speed", metavar="SPEED", help="upper speed (rpm)")
    p.add_argument("--rate", metavar="RATE", help="ramp rate (rpm/s)")
    p.add_argument("--duration", metavar="T", help="duration of each leg instead (s)")
    p.add_argument("--direction", choices=["up", "down", "up_down"], default=None)
    p.add_argument("--bin", type=finite, default=None, metavar="RPM", help="bin width (50)")
    p.add_argument("--to-torque", metavar="TORQUE", help="torque at the end (N m)")
    p.add_argument("--ensemble", type=int, default=None, metavar="N", help="FTLE members (8)")
    p.add_argument("--json", metavar="OUT", help="write the API's document")
    p.add_argument("--plot", metavar="OUT", help="write the figure (.png or .svg)")
    p.set_defaults(func=lazy("gearengine.cli.runup", "cmd_runup"))

    p = sub.add_parser("convert", help="a design in physical units: parameters, derivations, rpm")
    p.add_argument("file", help='JSON file holding {"design": {...}}, or - for stdin')
    p.add_argument("--json", action="store_true", help="print the API's JSON response")
    p.set_defaults(func=lazy("gearengine.cli.convert", "cmd_convert"))

    p = sub.add_parser("signal", help="a recorded series: periodic, quasi-periodic, chaotic or "
                       "noise?")  # fmt: skip
    p.add_argument("file", help="JSON request (as POST /v1/signals), or the samples as text or "
                   "CSV (last column; a first column of times sets the rate), or -")  # fmt: skip
    p.add_argument("--rate", metavar="RATE", help="sample rate: Hz, or with units (20kHz)")
    p.add_argument("--speed", metavar="SPEED", help="shaft speed: rpm, or with units")
    p.add_argument("--teeth", type=int, default=None, help="teeth on that shaft (mesh orders)")
    p.add_argument("--quantity", choices=["transmission_error", "acceleration", "displacement",
                   "velocity", "other"], default=None)  # fmt: skip
    p.add_argument("--unit", default=None, help="unit of the values (um, m/s^2, g)")
    p.add_argument("--design", metavar="FILE", help='JSON file holding {"design": {...}}: the '
                   "model's verdict beside the signal's")  # fmt: skip
    p.add_argument("--seed", type=int, default=None, help="seed of the 0-1 test and surrogates")
    p.add_argument("--json", metavar="OUT", help="write the API's response body")
    p.add_argument("--plot", metavar="OUT", help="write the figure (.png or .svg)")
    p.set_defaults(func=lazy("gearengine.cli.signal", "cmd_signal"))

    for plugin in entry_points(group=PLUGIN_GROUP):
        try:
            plugin.load()(sub)
        except ImportError as exc:  # a plugin whose dependencies are absent adds nothing
            logging.getLogger("gearengine").debug("plugin %s not loaded: %s", plugin.name, exc)
    return parser


RANGE_OPTIONS = ("--speed", "--torque")
"""Options taking LOW:HIGH, whose low end may begin with a minus sign."""


def joined_ranges(argv: Sequence[str]) -> list[str]:
    """``--torque -5:60`` as ``--torque=-5:60``: argparse takes a value beginning with "-"
    for an option ("expected one argument"); joined, the range is read and a negative end
    refused with its reason (a mean torque is a magnitude; a speed is positive)."""
    out: list[str] = []
    it = iter(argv)
    for arg in it:
        value = next(it, None) if arg in RANGE_OPTIONS else None
        if value is not None and re.match(r"-[\d.]", value):
            out.append(f"{arg}={value}")
        else:
            out += [arg] if value is None else [arg, value]
    return out


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code."""
    args = build_parser().parse_args(joined_ranges(sys.argv[1:] if argv is None else argv))
    func: Command = args.func
    try:
        code = func(args)
        sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's exit
    except InvalidInputError as exc:
        for line in exc.lines:
            print(line, file=sys.stderr)
        return EXIT_INVALID
    except BrokenPipeError:
        # the reader went away (``| head``): stop quietly, as Unix tools do. Point stdout at
        # /dev/null so the interpreter's final flush does not fail again.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_PIPE
    except Exception:  # a bug: never mistaken for a failed check (exit 1)
        traceback.print_exc()
        print("gearengine: internal error (please report it)", file=sys.stderr)
        return EXIT_INTERNAL
    return code


def command() -> NoReturn:
    """The ``gearengine`` console script and ``python -m gearengine.cli``: ``main``, then exit.

    The objects left are frozen (``gc.freeze``) before the interpreter exits: its final
    collections then skip the module graph of numba, scipy and pint, which otherwise takes
    0.2-0.4 s after a command's work is done (measured on ``check``). Atexit handlers and
    stream flushes still run."""
    code = main()
    gc.freeze()
    sys.exit(code)
