"""``gearengine robustness FILE --speed LOW:HIGH --torque LOW:HIGH --samples N``: a robustness
study here, no server (the same registry as the service: ``--json`` writes the API's document
byte for byte), and the probability gate of ``gearengine check ... --max-probability
chaotic=0.01``: it fails where the 95 % upper bound of a probability exceeds its limit, naming
the points (and in JUnit, one test case per point).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from xml.etree import ElementTree

from gearengine.cli.documents import (
    EXIT_FAIL,
    EXIT_OK,
    InvalidInputError,
    read_document,
    validated_input,
)
from gearengine.cli.envelope import axis
from gearengine.cli.sweep import progress
from gearengine.gate.envelope import ENVELOPE_SETTINGS
from gearengine.model.units import display_unit
from gearengine.studies.robustness.study import (
    RobustnessRequest,
    RobustnessResult,
    checked,
    run_local,
)

GATED = ("chaotic", "quasi_periodic", "diverged", "impacts", "back_flank",
         "dynamic_factor_above_limit", "melnikov_chaos_possible")  # fmt: skip
"""Probabilities a gate may limit."""


def robustness_request(args: argparse.Namespace) -> RobustnessRequest:
    """The study of the design file under ``args`` (its tolerances; light settings unless the
    file gives its own; axes from --speed/--torque)."""
    doc = read_document(args.file)
    if not isinstance(doc, dict) or "design" not in doc:
        raise InvalidInputError([f'{args.file}: a robustness study needs {{"design": {{...}}}}'])
    axes = []
    if args.speed:
        axes.append(axis("speed", args.speed, "rpm", args.speed_points))
    if args.torque:
        axes.append(axis("torque", args.torque, "N*m", args.torque_points))
    settings = doc.get("settings", {})
    if not isinstance(settings, dict):
        raise InvalidInputError([f"{args.file}: settings must be an object"])
    body = {**{k: v for k, v in doc.items() if k not in ("params",)},
            "settings": {**ENVELOPE_SETTINGS, **settings}, "axes": axes or doc.get("axes", []),
            "samples": args.samples, "seed": args.seed}  # fmt: skip
    if getattr(args, "sensitivity", False):
        body["sensitivity"] = True
    return validated_input(lambda d: checked(RobustnessRequest.model_validate(d)), body, args.file)


def study(args: argparse.Namespace) -> tuple[RobustnessRequest, RobustnessResult]:
    request = robustness_request(args)
    tick = progress(time.monotonic(), "robustness")
    return request, run_local(request, tick, workers=os.cpu_count() or 1)


def point_name(values: dict[str, float]) -> str:
    """A point in gear units: "speed 3000 rpm, torque 60 N*m" (or "operating point")."""
    parts = [f"{k} {v:g} {display_unit(k)[0]}" for k, v in values.items()]
    return ", ".join(parts) or "operating point"


def limits_of(texts: list[str]) -> dict[str, float]:
    """``["chaotic=0.01", ...]`` as {name: limit}; InvalidInputError naming a bad one."""
    out = {}
    for text in texts:
        name, _, value = text.partition("=")
        try:
            limit = float(value)
        except ValueError:
            limit = -1.0
        if name not in GATED or not 0.0 <= limit <= 1.0:
            raise InvalidInputError([f"--max-probability {text}: give NAME=P with P in [0, 1] "
                                     f"and NAME one of {', '.join(GATED)}"])  # fmt: skip
        out[name] = limit
    return out


def failures(result: RobustnessResult, limits: dict[str, float]) -> list[list[str]]:
    """Per point, the limits its 95 % upper bounds exceed, in words."""
    out = []
    for p in result.points:
        why = []
        for name, limit in limits.items():
            prob = p.probabilities[name]
            if prob.interval is None or prob.interval[1] > limit:
                upper = "no samples" if prob.interval is None else f"{prob.interval[1]:.3g}"
                why.append(f"P({name}) upper bound {upper} > {limit:g} "
                           f"({prob.count}/{prob.samples} samples)")  # fmt: skip
        out.append(why)
    return out


def junit(result: RobustnessResult, why: list[list[str]], name: str) -> str:
    """JUnit XML: one test case per operating point, failed with its reasons."""
    suite = ElementTree.Element("testsuite", name=name, tests=str(len(why)),
                                failures=str(sum(bool(w) for w in why)))  # fmt: skip
    for p, reasons in zip(result.points, why, strict=True):
        case = ElementTree.SubElement(suite, "testcase", classname="robustness",
                                      name=point_name(p.shown))  # fmt: skip
        if reasons:
            ElementTree.SubElement(case, "failure", message="; ".join(reasons))
    return ElementTree.tostring(suite, encoding="unicode", xml_declaration=True) + "\n"


def cmd_robustness(args: argparse.Namespace) -> int:
    """Run the study; print one line per point; --json and --plot write the outputs."""
    request, result = study(args)
    for p in result.points:
        pr = p.probabilities
        words = ", ".join(
            f"{k} {pr[k].value:.3f} [{pr[k].interval[0]:.3f}, {pr[k].interval[1]:.3f}]"
            for k in ("chaotic", "impacts", "back_flank")
        )
        print(f"{point_name(p.shown)}: {words} ({p.samples} samples)")
        for line in p.ranking or []:
            print(f"  {line}")
    if args.json:
        Path(args.json).write_text(result.model_dump_json())
    if args.plot:
        from gearengine.plots.robustness import robustness_figure

        Path(args.plot).write_bytes(robustness_figure(request, result, "png"))
    return EXIT_OK


def cmd_probability_gate(args: argparse.Namespace) -> int:
    """``check --max-probability``: exit 1 where an upper bound exceeds its limit."""
    limits = limits_of(args.max_probability)
    _, result = study(args)
    why = failures(result, limits)
    for p, reasons in zip(result.points, why, strict=True):
        verdict = "FAIL" if reasons else "PASS"
        print(f"{verdict}: {point_name(p.shown)}" + (f" [{'; '.join(reasons)}]" if reasons else ""))
    if args.json:
        Path(args.json).write_text(result.model_dump_json())
    if args.junit:
        Path(args.junit).write_text(junit(result, why, f"robustness of {args.file}"))
    failed = sum(bool(w) for w in why)
    print(f"{'FAIL' if failed else 'PASS'}: {failed} of {len(why)} points over a probability "
          "limit", file=sys.stderr)  # fmt: skip
    return EXIT_FAIL if failed else EXIT_OK
