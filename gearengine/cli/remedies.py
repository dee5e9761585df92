"""``gearengine remedies DESIGN --speed 500:6000 --torque 2:40``: what to change, by how much.

For a design that fails its envelope under the gate's rules (``gearengine check``'s options),
searches each lever (``gate.remedies.search``) for the smallest change that makes the
envelope pass, with the Melnikov guarantee beside it, and prints the ranked answer.
``--lever PATH=LOW:HIGH`` (repeatable) searches the given levers instead of the default ones.
``--json FILE`` writes the document ``POST /v1/remedies`` returns. Exit 0 when a remedy (or the
design itself) passes, 1 when nothing found clears the envelope, 2 on invalid input.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from gearengine.cli.documents import (
    EXIT_FAIL,
    EXIT_OK,
    InvalidInputError,
    read_document,
    validated_input,
)
from gearengine.cli.envelope import rules_of
from gearengine.cli.sweep import progress
from gearengine.gate.remedies import RemediesRequest, RemediesResult, remedies
from gearengine.jsonio import dumps


def remedies_request(args: argparse.Namespace) -> RemediesRequest:
    """The request of the design file under ``args`` (the document ``POST /v1/remedies`` takes)."""
    doc = read_document(args.file)
    if not isinstance(doc, dict) or "design" not in doc:
        raise InvalidInputError([f'{args.file}: remedies need {{"design": {{...}}}}'])
    envelope: dict[str, object] = {"speed": args.speed}
    for name in ("speed_points", "torque_points"):
        if getattr(args, name) is not None:
            envelope[name] = getattr(args, name)
    if args.refine is not None:
        envelope["refine"] = args.refine
    if args.torque:
        envelope["torque"] = args.torque
    body = {"design": doc["design"], "envelope": envelope,
            **rules_of(args).model_dump(exclude_none=True)}  # fmt: skip
    if "settings" in doc:
        body["settings"] = doc["settings"]
    if args.starts is not None:
        body["starts"] = args.starts
    if args.lever:
        body["levers"] = args.lever
    options = dict(OPTIONS)
    for i, lever in enumerate(args.lever or []):
        options[f"levers[{i}]"] = f"--lever {lever['lever']}"
        for k, end in enumerate(("low", "high")):
            options[f"levers[{i}].bounds[{k}]"] = f"--lever {lever['lever']} (its {end} end)"
    return validated_input(RemediesRequest.model_validate, body, args.file, options)


OPTIONS = {"envelope.speed": "--speed", "envelope.torque": "--torque",
           "envelope.speed_points": "--speed-points", "envelope.torque_points": "--torque-points",
           "envelope.refine": "--refine", "envelope": "--speed/--torque", "starts": "--starts",
           "fail_on": "--fail-on", "max_lle": "--max-lle", "max_dte_um": "--max-dte",
           "max_dynamic_factor": "--max-dynamic-factor", "min_basin": "--min-basin"}  # fmt: skip
"""The option that gave each field of the request (``documents.by_options``); the design's own
fields keep their paths in the file."""


def print_result(result: RemediesResult) -> None:
    """The answer in words, then one line per remedy and per unreachable lever."""
    print(result.answer[0].upper() + result.answer[1:] + ".")
    if result.check is not None and result.check.resolution is not None:
        print(f"  the design's check: {result.check.resolution.text()}")
    for r in result.remedies:
        unit = "" if r.unit == "1" else f" {r.unit}"
        grid = "" if r.check.resolution is None else f" on {r.check.resolution.text()}"
        print(f"  {r.bound:9s} {r.lever}: {r.from_:g} -> {r.to:.4g}{unit} "
              f"({'monotone' if r.monotone else 'NOT monotone: not unique'}; check "
              f"{'PASS' if r.check.passed else 'FAIL'}{grid})")  # fmt: skip
    for u in result.unreachable:
        print(f"  {u.bound:9s} {u.lever}: none in {u.searched[0]} to {u.searched[1]}")
    if result.combination is not None:
        print(f"  combined: {result.combination.summary} ({result.combination.how})")


def cmd_remedies(args: argparse.Namespace) -> int:
    """Remedies of a failing envelope; exit 0 something passes, 1 nothing does, 2 invalid."""
    request = remedies_request(args)
    tick = progress(time.monotonic(), "remedies", "searches")
    result = remedies(request, tick, workers=os.cpu_count() or 1)
    print_result(result)
    if args.json:
        Path(args.json).write_text(dumps(result))
    found = (
        result.passed_already
        or result.combination is not None
        or any(r.bound == "numerical" for r in result.remedies)
    )
    return EXIT_OK if found else EXIT_FAIL
