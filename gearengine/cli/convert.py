"""``gearengine convert FILE [--json]``: a design in physical units as the engine sees it.

Prints the dimensionless parameters of Eq. (9), every derived quantity with its source, and the
engineering block (Melnikov speed windows in rpm, thresholds in gear units); ``--json`` prints
the body of ``POST /v1/conversions/design``.
"""

from __future__ import annotations

import argparse

from gearengine.analysis import DesignRequest, convert
from gearengine.cli.documents import EXIT_OK, read_request
from gearengine.cli.melnikov import render_engineering
from gearengine.jsonio import dumps


def cmd_convert(args: argparse.Namespace) -> int:
    """Print the conversion of the design in ``args.file``."""
    report = convert(read_request(args.file, DesignRequest))
    if args.json:
        print(dumps(report))
        return EXIT_OK
    conv = report.conversion
    print(f"Dimensionless parameters of Eq. (9): {conv.params.model_dump_json()}")
    print("Derived quantities:")
    for name, d in conv.derived.items():
        value = f"{d.value:.6g}" if isinstance(d.value, float) else str(d.value)
        print(f"  {name:<26} {value} {d.unit}  ({d.source})")
    for note in conv.notes:
        print(f"  note: {note}")
    print(render_engineering(report.engineering))
    return EXIT_OK
