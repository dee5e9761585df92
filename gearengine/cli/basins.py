"""``gearengine basins FILE [--starts N] [--json] [--plot FILE]``: the coexisting attractors of
one design, a table of their basin fractions, and the basin picture.

FILE is an analysis request ({"params" or "design": ..., "settings": ...}); its
``settings.basins`` are used, else the defaults, ``--starts`` overriding the count (a square on
a grid). ``--json`` prints the body POST /v1/analyses returns for the same request;
``--plot out.png`` (or .svg) writes the bytes of POST /v1/analyses/basins/plot.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
from gearengine.cli.documents import EXIT_OK, STARTS_FIELD, read_document, validated_input
from gearengine.jsonio import dumps
from gearengine.numerics.headline import percent


def basins_request(args: argparse.Namespace) -> AnalysisRequest:
    """The file's analysis request with basins (its own, the defaults, ``--starts``)."""
    doc = read_document(args.file)
    if isinstance(doc, dict):
        settings = dict(doc.get("settings") or {})
        basins = dict(settings.get("basins") or {})
        if args.starts is not None:
            basins["starts"] = args.starts
        doc = {**doc, "settings": {**settings, "basins": basins}}
    options = {STARTS_FIELD: "--starts"} if args.starts is not None else {}
    return validated_input(AnalysisRequest.model_validate, doc, args.file, options)


def table(result: AnalysisResult) -> list[str]:
    """One line per attractor: fraction [interval], count, period, LLE, DTE, start."""
    num = result.numerics
    assert num.attractors is not None and num.basins is not None
    design = result.engineering is not None
    head = f"{'attractor':<40} {'basin':>6} {'95 % interval':>15} {'starts':>6} {'LLE':>9}"
    if design:
        head += f" {'DTE µm':>8} {'dyn.f.':>7}"
    lines = [head]
    for a in num.attractors:
        lle = "n/a" if a.lle is None else f"{a.lle:+.4f}"
        row = (f"{a.label:<40} {percent(a.fraction):>6} "
               f"{f'{percent(a.interval[0])} - {percent(a.interval[1])}':>15} {a.count:>6} "
               f"{lle:>9}")  # fmt: skip
        if design:
            row += f" {a.dte_um or 0.0:>8.3g} {a.dynamic_factor or 0.0:>7.3g}"
        lines.append(row)
    b = num.basins
    lines.append(f"{b.starts} starts: {b.diverged} diverged, {b.unsettled} unsettled")
    return lines


def cmd_basins(args: argparse.Namespace) -> int:
    """Print the attractors (or the API's JSON); write the basin picture with ``--plot``."""
    result = analyze(basins_request(args))
    if args.json:
        print(dumps(result))
    else:
        print("\n".join(table(result)))
        print(f"Verdict: {result.verdict.summary}")
    if args.plot:
        from gearengine.plots.basins import basins_figure

        fmt = "svg" if args.plot.endswith(".svg") else "png"
        Path(args.plot).write_bytes(basins_figure(result, fmt))
    return EXIT_OK
