"""``gearengine campbell FILE [--json] [--plot OUT]``: a gear train's modes and Campbell diagram.

Prints each mode (frequency, damping ratio, mesh strain-energy share) and the crossings of the
order lines with the modes in rpm; ``--json`` prints the body of ``POST /v1/analyses/campbell``;
``--plot`` writes the diagram (.png or .svg).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from gearengine.cli.documents import EXIT_OK, read_request, validated_input
from gearengine.jsonio import dumps
from gearengine.systems.gear_train.campbell import CampbellRequest, campbell


def cmd_campbell(args: argparse.Namespace) -> int:
    """Print (or write) the Campbell diagram of the train in ``args.file``."""
    result = validated_input(campbell, read_request(args.file, CampbellRequest), args.file)
    if args.plot:
        from gearengine.plots.campbell import campbell_figure  # matplotlib only when drawing

        out = Path(args.plot)
        out.write_bytes(campbell_figure(result, "svg" if out.suffix == ".svg" else "png"))
    if args.json:
        print(dumps(result))
        return EXIT_OK
    found = result.modes
    print(f"Modes of the train linearised in contact (stiff limit {found.stiff_limit_hz:.1f} Hz):")
    for k, mode in enumerate(found.modes):
        mark = "  <- mesh mode" if k == found.mesh_mode else ""
        print(f"  {k + 1}: {mode.frequency_hz:9.1f} Hz  zeta {mode.damping_ratio:.4f}  "
              f"mesh share {mode.mesh_energy_share:6.1%}{mark}")  # fmt: skip
    lo, hi = result.speed_range_rpm
    print(f"Crossings of the order lines, {lo:,.0f}-{hi:,.0f} rpm "
          f"(mesh resonance {result.mesh_resonance_rpm:,.0f} rpm):")  # fmt: skip
    for c in result.crossings:
        print(
            f"  {c.speed_rpm:9,.0f} rpm  {c.line:<20} mode {c.mode + 1} ({c.frequency_hz:.1f} Hz)"
        )
    return EXIT_OK
