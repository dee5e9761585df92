"""``gearengine convert FILE [--json]``: a design in physical units as the engine sees it.

Prints the dimensionless parameters of Eq. (9), every derived quantity with its source, and the
engineering block (Melnikov speed windows in rpm, thresholds in gear units); ``--json`` prints
the body of ``POST /v1/conversions/design``.
"""

from __future__ import annotations

import argparse

from gearengine.analysis import DesignRequest, convert
from gearengine.cli.documents import EXIT_OK, read_request, validated_input
from gearengine.cli.melnikov import render_engineering
from gearengine.jsonio import dumps
from gearengine.model.params import GearParams


def harmonics_text(harmonics: list[dict[str, float]], unit: str) -> str:
    """Harmonics r = 1, 2, ... as "r=1 1.34e+08 N/m @ -1.859 rad; r=2 ..." (``unit`` empty for
    dimensionless amplitudes)."""
    unit = f" {unit}" if unit else ""
    return (
        "; ".join(
            f"r={r} {h['amplitude']:.6g}{unit} @ {h['phase']:.4g} rad"
            for r, h in enumerate(harmonics, start=1)
        )
        or "none"
    )


def params_lines(params: GearParams) -> list[str]:
    """The dimensionless parameters of Eq. (9), one readable line each."""
    law = params.backlash.model_dump()
    lines = [
        f"  {'mu~ (damping)':<26} {params.damping:.6g}",
        f"  {'F~_m (mean force)':<26} {params.mean_force:.6g}",
        f"  {'backlash law':<26} " + ", ".join(f"{k} = {v}" for k, v in law.items()),
    ]
    for name, exc in params.excitations():
        terms = harmonics_text([h.model_dump() for h in exc.harmonics], "")
        lines.append(f"  {name:<26} Omega = {exc.frequency:.6g}: {terms}")
    return lines


def cmd_convert(args: argparse.Namespace) -> int:
    """Print the conversion of the design in ``args.file``."""
    report = validated_input(convert, read_request(args.file, DesignRequest), args.file)
    if args.json:
        print(dumps(report))
        return EXIT_OK
    conv = report.conversion
    print("Dimensionless parameters of Eq. (9):")
    print("\n".join(params_lines(conv.params)))
    print("Derived quantities:")
    for name, d in conv.derived.items():
        if isinstance(d.value, list):
            value = harmonics_text(d.value, d.unit.split(",")[0])
        else:
            value = f"{d.value:.6g} {d.unit}"
        print(f"  {name:<26} {value}  ({d.source})")
    for note in conv.notes:
        print(f"  note: {note}")
    print(render_engineering(report.engineering))
    return EXIT_OK
