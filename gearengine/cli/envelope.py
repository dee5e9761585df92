"""``gearengine check DESIGN --speed 500:6000 --torque 20:200``: the CI gate over an operating
envelope.

Sweeps the design over a grid of driver speeds (rpm unless a unit is given) and mean torques
(N m unless a unit is given), checks every point against the rules (``gate.envelope``), prints
the failing windows, and exits 1 when any point fails, 0 when none does, 2 on invalid input.
Each point runs ``--starts N`` initial states (default ``GATE_STARTS``, a grid over the
default basin box) and every attractor found whose basin fraction is above ``--min-basin``
(default: any) is checked; ``--starts 1`` checks the settings' own start only.
``--json FILE`` writes the report (with the API's sweep result in it), ``--junit FILE`` a
JUnit XML report, ``--server URL`` runs the sweep on a running service (its queue, its
workers) instead of in this process, with the same report.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Callable
from pathlib import Path

from gearengine.cli.documents import (
    EXIT_FAIL,
    EXIT_OK,
    STARTS_FIELD,
    InvalidInputError,
    Options,
    axis_options,
    counted_points,
    validated_input,
)
from gearengine.cli.sweep import progress
from gearengine.gate.envelope import (
    REFINE_DEPTH,
    envelope_axis,
    envelope_sweep,
    gate_settings,
    refined_report,
    sweep_here,
)
from gearengine.gate.envelope_text import report_lines
from gearengine.gate.junit import envelope_junit
from gearengine.gate.resolution import GRID_POINTS
from gearengine.gate.rules import Rules
from gearengine.homoclinic.train_reduction import not_judged_reason
from gearengine.jsonio import dumps
from gearengine.numerics.settings import SimulationSettings
from gearengine.studies import jobs
from gearengine.studies.sweep.axes import axis_unit
from gearengine.studies.sweep.request import SweepRequest, validated
from gearengine.studies.sweep.results import SweepResult

POLL_SECONDS = 1.0


OPTION_UNITS = {"speed": "rpm", "torque": "N*m"}
"""The unit of a bare number in --speed and --torque."""


def option_axes(args: argparse.Namespace, design: dict | None = None) -> list[dict[str, object]]:
    """The axes that --speed and --torque give (``gate.envelope.envelope_axis``), an error
    naming its option; with a ``design`` and no --speed, the design's own speed as one point."""
    given = {name: getattr(args, name) for name in OPTION_UNITS}
    nums = {name: getattr(args, f"{name}_points") for name in OPTION_UNITS}
    unused = [f"--{name}-points: counts the points of a {name} range, and none is given "
              f"(--{name} LOW:HIGH)"
              for name, num in nums.items() if num is not None and not given[name]]  # fmt: skip
    if unused:
        raise InvalidInputError(unused)
    if design is not None and not args.speed:
        given["speed"], nums["speed"] = _here(design, "speed"), 1
    axes = []
    for name, text in ((n, t) for n, t in given.items() if t):
        num = GRID_POINTS[name] if nums[name] is None else nums[name]
        try:
            axes.append(envelope_axis(name, text, OPTION_UNITS[name], num))
        except ValueError as exc:
            raise InvalidInputError([f"--{name}: {exc}"]) from None
    return axes


def envelope_request(args: argparse.Namespace, doc: object) -> SweepRequest:
    """The speed x torque sweep of the design document ``doc`` (``args.file`` read)."""
    if not isinstance(doc, dict) or "design" not in doc:
        raise InvalidInputError([f'{args.file}: an envelope check needs {{"design": {{...}}}}'])
    design = doc["design"]
    axes = option_axes(args, design)
    settings = doc.get("settings", {})
    if not isinstance(settings, dict):
        raise InvalidInputError([f"{args.file}: settings must be an object"])
    sweep = envelope_sweep(
        design,
        gate_settings(settings, args.starts, getattr(args, "min_basin", None)),
        axes,
        f"envelope check of {Path(args.file).name}",
    )
    counted_points(axes, "envelope check")  # before the sweep's checks build its grids
    given = [i for i, name in enumerate(["speed", "torque"]) if getattr(args, name)]
    options = axis_options(axes, given)
    if args.starts is not None:
        options[STARTS_FIELD] = "--starts"
    request = validated_input(validated, sweep, args.file, options)
    why = budget_refusal("sweep", request, "envelope check", ENVELOPE_WAYS)
    if why is not None:
        raise InvalidInputError([why])
    return request


ENVELOPE_WAYS = (
    "use fewer points (--speed-points, --torque-points, or a narrower --speed/--torque range at "
    "the same spacing) or starts (--starts), or run it on a server (--server URL); or allow it "
    f"here with {jobs.BUDGET_ENV[0]}=STEPS in the environment"
)
"""The ways out of an envelope check over the job budget, in the CLI's options."""


def budget_refusal(kind: str, request: object, noun: str, ways: str) -> str | None:
    """``jobs.over_budget`` of a CLI command, a bad ``GEARCHAOS_MAX_JOB_STEPS`` refused as
    invalid input."""
    try:
        return jobs.over_budget(kind, request, noun, ways)  # type: ignore[arg-type]
    except ValueError as exc:
        raise InvalidInputError([str(exc)]) from None


def _here(design: dict, name: str) -> str:
    """The design's own value as a one-point range (when only the other axis is given); a bare
    number is the design's, in the field's SI unit (speed rad/s), which the range says, since
    a bare number on the command line is read in gear units (rpm)."""
    value = design.get(name)
    if value is None:
        raise InvalidInputError([f"--{name}: give a range, the design has no {name}"])
    if isinstance(value, int | float) and not isinstance(value, bool):
        value = f"{value} {axis_unit(name)}"
    return f"{value}:{value}"


def run_on_server(url: str, request: SweepRequest, key: str | None,
                  report: Callable[[int, int], None]) -> SweepResult:  # fmt: skip
    """Submit the sweep to a running service, follow its progress, fetch the result."""
    base = url.rstrip("/")
    job = _call(f"{base}/v1/sweeps", key, request.model_dump_json().encode())
    while job["status"] in ("queued", "running"):
        time.sleep(POLL_SECONDS)
        job = _call(f"{base}/v1/sweeps/{job['id']}", key)
        report(job["progress"]["done"], job["progress"]["total"])
    if job["status"] != "succeeded":
        raise InvalidInputError([f"{base}: sweep {job['id']} {job['status']}"])
    return SweepResult.model_validate(_call(f"{base}/v1/sweeps/{job['id']}/result", key))


def _call(url: str, key: str | None, body: bytes | None = None) -> dict:
    headers = {"content-type": "application/json", "accept": "application/json"}
    if key:
        headers["authorization"] = f"Bearer {key}"
    req = urllib.request.Request(url, data=body, headers=headers)
    try:
        with urllib.request.urlopen(req, timeout=60) as response:
            return json.loads(response.read())
    except urllib.error.HTTPError as exc:
        detail = exc.read().decode(errors="replace")
        raise InvalidInputError([f"{url}: {exc.code} {detail}"]) from None
    except urllib.error.URLError as exc:
        raise InvalidInputError([f"{url}: {exc.reason}"]) from None


RULE_OPTIONS: Options = {
    "max_lle": "--max-lle",
    "max_dte_um": "--max-dte",
    "max_dynamic_factor": "--max-dynamic-factor",
    "min_basin": "--min-basin",
}
"""The option that gives each limit of ``Rules``, for its refusals."""


def rules_of(args: argparse.Namespace) -> Rules:
    """--fail-on classes (default chaotic; limits add to them, never replace them); a limit
    ``Rules`` refuses (a DTE at or under 0, a basin fraction over 1) is named by its option."""
    given = {"fail_on": args.fail_on or ["chaotic"], "max_lle": args.max_lle,
             "max_dte_um": args.max_dte, "max_dynamic_factor": args.max_dynamic_factor,
             "min_basin": getattr(args, "min_basin", None)}  # fmt: skip
    return validated_input(Rules.model_validate, given, "check", RULE_OPTIONS)


def settings_text(settings: SimulationSettings) -> str:
    """The integration settings that matter for cost and verdict, in one line."""
    rand = settings.random_initial_states
    starts = "" if rand is None else f", {rand.count} random starts (seed {rand.seed})"
    return f"settings: {settings.run_text()}{starts}"


NOMINAL_ONLY = (
    "the design has tolerances: this check judges the nominal design only; --max-probability "
    "NAME=P (a second check) judges the tolerances, e.g. --max-probability chaotic=0.05"
)
"""The envelope check's note on a design with tolerances (it passed while the probability
gate failed every point, and said nothing of them)."""


RAMP_OPTIONS = {
    "rate": "--runup",
    "bin_rpm": "--runup (the bin it sets)",
    "from_speed": "--speed (its low end)",
    "to_speed": "--speed (its high end)",
}
"""The options that set the fields of ``check --runup``'s run-ups (``gate.runup.gate_runups``)."""


def cmd_envelope(args: argparse.Namespace, doc: object, rules: Rules) -> int:
    """The envelope gate of the design document ``doc`` under ``rules`` (``rules_of``); exit 0
    pass, 1 fail, 2 invalid input."""
    if args.min_stability_margin is not None:
        raise InvalidInputError(
            [
                "--min-stability-margin checks one design (sweep points have no Floquet "
                "multipliers): drop --speed/--torque, or check each operating point"
            ]
        )
    request = envelope_request(args, doc)
    if getattr(args, "runup", None) is not None:  # a bad ramp refused before any compute
        from gearengine.gate.runup import gate_envelope, gate_runups

        runups = validated_input(lambda r: gate_runups(request, r), args.runup, "--runup",
                                 RAMP_OPTIONS)  # fmt: skip
    print(settings_text(request.settings), file=sys.stderr)
    tick = progress(time.monotonic(), "envelope")
    workers = os.cpu_count() or 1
    if args.server:  # its result refined here, as a result computed here is
        result = run_on_server(args.server, request, os.environ.get("GEARCHAOS_API_KEY"), tick)
    else:
        result = sweep_here(request, tick, workers)
    depth = REFINE_DEPTH if args.refine is None else args.refine
    report = refined_report(request, result, rules, depth, workers=workers)
    if getattr(args, "runup", None) is not None:  # run-ups through the range (gate.runup)
        report = gate_envelope(report, runups)
    if request.design is not None and request.design.tolerances is not None:
        report = report.model_copy(update={"notes": [*report.notes, NOMINAL_ONLY]})
    why = not_judged_reason(request.design)  # why Melnikov judges no point where it does not
    for line in report_lines(report, why):
        print(line)
    if args.json:
        Path(args.json).write_text(dumps(report))
    if args.junit:
        Path(args.junit).write_text(envelope_junit(report, f"operating envelope of {args.file}"))
    return EXIT_OK if report.passed else EXIT_FAIL
