"""The ``gearengine`` command line.

    gearengine melnikov FILE [--json] [--method closed_form|quadrature]
    gearengine analyze FILE [--json]
    gearengine check FILE [--fail-on chaotic|quasi_periodic|diverged|melnikov] [--max-lle V]
    gearengine sweep FILE [--out DIR]

FILE holds ``{"params": {...}}`` (and ``"settings"`` for analyze/check; ``-`` reads standard
input). ``--json`` prints exactly the body the HTTP API returns. Exit codes: 0 success (check:
pass), 1 check failed, 2 invalid input (one line per problem, naming the field).

More commands come from installed plugins: every entry point of the group ``gearengine.commands``
is a function ``register(subparsers)``; the service registers ``serve`` and ``worker`` this way,
so the engine's commands work without the web stack installed.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Callable, Sequence
from importlib.metadata import entry_points

from gearengine.cli.analyze import cmd_analyze, cmd_check
from gearengine.cli.documents import EXIT_INVALID, InvalidInputError
from gearengine.cli.melnikov import cmd_melnikov
from gearengine.cli.sweep import cmd_sweep

PLUGIN_GROUP = "gearengine.commands"
"""Entry-point group of command plugins: each is a ``register(subparsers)`` function."""


def build_parser() -> argparse.ArgumentParser:
    """The engine's commands and those of every installed plugin."""
    parser = argparse.ArgumentParser(
        prog="gearengine",
        description="Periodic or chaotic? Melnikov and numerical verdicts for spur-gear pairs.",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("melnikov", help="Melnikov verdict, thresholds and margins of a design")
    p.add_argument("file", help='JSON file holding {"params": {...}}, or - for stdin')
    p.add_argument("--json", action="store_true", help="print the API's JSON response")
    p.add_argument("--method", choices=["closed_form", "quadrature"], default=None)
    p.set_defaults(func=cmd_melnikov)

    p = sub.add_parser("analyze", help="Melnikov and numerical verdicts of a design")
    p.add_argument("file", help='JSON file holding {"params": {...}, "settings": {...}}, or -')
    p.add_argument("--json", action="store_true", help="print the API's JSON response")
    p.set_defaults(func=cmd_analyze)

    p = sub.add_parser(
        "check",
        help="CI gate: exit 1 when the design fails (0 pass, 2 invalid input)",
        description="--fail-on X fails on X or anything worse "
        "(periodic < quasi_periodic < chaotic < diverged); melnikov fails when a transverse "
        "homoclinic tangle is possible. Default: --fail-on chaotic, unless --max-lle is given.",
    )
    p.add_argument("file", help='JSON file holding {"params": {...}, "settings": {...}}, or -')
    p.add_argument(
        "--fail-on",
        action="append",
        choices=["chaotic", "quasi_periodic", "diverged", "melnikov"],
        help="repeatable",
    )
    p.add_argument("--max-lle", type=float, default=None, help="fail when the LLE exceeds V")
    p.set_defaults(func=cmd_check)

    p = sub.add_parser("sweep", help="run a sweep here, no server: JSON, CSV and PNG")
    p.add_argument("file", help="JSON file holding a sweep request (as POST /v1/sweeps), or -")
    p.add_argument("--out", default=".", help="directory for the outputs (default .)")
    p.set_defaults(func=cmd_sweep)

    for plugin in entry_points(group=PLUGIN_GROUP):
        try:
            plugin.load()(sub)
        except ImportError as exc:  # a plugin whose dependencies are absent adds nothing
            logging.getLogger("gearengine").debug("plugin %s not loaded: %s", plugin.name, exc)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code."""
    args = build_parser().parse_args(argv)
    func: Callable[[argparse.Namespace], int] = args.func
    try:
        return func(args)
    except InvalidInputError as exc:
        for line in exc.lines:
            print(line, file=sys.stderr)
        return EXIT_INVALID
