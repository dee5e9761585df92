"""``gearengine robustness FILE --speed LOW:HIGH --torque LOW:HIGH --samples N``: a robustness
study here, no server (the same registry as the service: ``--json`` writes the API's document
byte for byte), and the probability gate of ``gearengine check ... --max-probability
chaotic=0.01``: it fails where the 95 % upper bound of a probability exceeds its limit (at
99.3 % a look with ``--samples auto``), naming the points (and in JUnit, one test case per
point); its ``--json`` is the gate's report (``gate.probability``), the study inside it.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from gearengine.cli.documents import (
    EXIT_FAIL,
    EXIT_OK,
    GATED,
    STARTS_FIELD,
    InvalidInputError,
    axis_options,
    counted_points,
    read_document,
    validated_input,
)
from gearengine.cli.envelope import budget_refusal, option_axes
from gearengine.cli.sweep import progress
from gearengine.gate.envelope import gate_settings, level_text
from gearengine.gate.junit import probability_junit
from gearengine.gate.probability import ONE_LOOK, probability_report, proofs, sampling_notes
from gearengine.jsonio import dumps
from gearengine.model.design import Design
from gearengine.model.units import IMPACTS_REFUSED, display_unit
from gearengine.model.units import shown as rounded
from gearengine.studies import jobs
from gearengine.studies.robustness.results import SALTELLI_SAMPLES, RobustnessResult
from gearengine.studies.robustness.sequential import (
    FIRST_SAMPLES,
    looks,
    sequential,
    unreachable,
)
from gearengine.studies.robustness.study import RobustnessRequest, checked, point_work, run_local
from gearengine.studies.robustness.tolerances import samples_to_prove
from gearengine.studies.sweep.points import PhysicalValue


def robustness_request(args: argparse.Namespace, doc: object) -> RobustnessRequest:
    """The study of the design document ``doc`` (``args.file`` read; its tolerances; its
    settings, merged over the request's light ones; axes from --speed/--torque)."""
    if not isinstance(doc, dict) or "design" not in doc:
        raise InvalidInputError([f'{args.file}: a robustness study needs {{"design": {{...}}}}'])
    axes = option_axes(args)
    settings = doc.get("settings", {})
    if not isinstance(settings, dict):
        raise InvalidInputError([f"{args.file}: settings must be an object"])
    if getattr(args, "starts", None) is not None:  # check --starts: starts per sample too
        settings = gate_settings(settings, args.starts)
    body = {**{k: v for k, v in doc.items() if k not in ("params",)},
            "settings": settings, "axes": axes or doc.get("axes", []),
            "samples": args.samples, "seed": args.seed}  # fmt: skip
    if getattr(args, "sensitivity", False):
        body["sensitivity"] = True
    counted_points(body["axes"], "robustness study")
    options = {"samples": "--samples", "seed": "--seed",
               **axis_options(axes, list(range(len(axes))))}  # fmt: skip
    if getattr(args, "starts", None) is not None:
        options[STARTS_FIELD] = "--starts"
    request = validated_input(
        lambda d: checked(RobustnessRequest.model_validate(d)), body, args.file, options
    )
    gate = getattr(args, "max_probability", None) and not getattr(args, "auto", False)
    why = budget_refusal("robustness", request, "robustness study",
                         PROBABILITY_WAYS if gate else STUDY_WAYS)  # fmt: skip
    if why is not None:
        raise InvalidInputError([why])
    return request


FEWER_POINTS = ("use fewer points (--speed-points, --torque-points, or a narrower --speed/--torque "
                "range at the same spacing)")  # fmt: skip
ALLOW = f"or allow it here with {jobs.BUDGET_ENV[0]}=STEPS in the environment"
STUDY_WAYS = f"{FEWER_POINTS}, starts (--starts) or --samples; {ALLOW}"
"""The ways out of a robustness study over the job budget, in the CLI's options."""
PROBABILITY_WAYS = (
    f"{FEWER_POINTS}, starts (--starts) or samples (--samples, not below the count that can "
    f"prove the limits); {ALLOW}; or --samples auto: each point sampled only until it is decided, "
    "within the budget (a point with no events still needs those samples: points the budget "
    "leaves undecided are reported undecided and fail the gate)"
)
"""The ways out of a probability gate over the job budget."""


def study(args: argparse.Namespace, doc: object) -> tuple[RobustnessRequest, RobustnessResult]:
    request = robustness_request(args, doc)
    return request, run_study(request)


def run_study(request: RobustnessRequest) -> RobustnessResult:
    """The study of ``request`` here, its progress on standard error."""
    tick = progress(time.monotonic(), "robustness", "runs")  # a sample at a point: one run
    return run_local(request, tick, workers=os.cpu_count() or 1)


def point_name(values: dict[str, float]) -> str:
    """A point in gear units: "speed 3000 rpm, torque 60 N*m" (or "operating point")."""
    parts = [f"{k} {v:g} {display_unit(k)[0]}" for k, v in values.items()]
    return ", ".join(parts) or "operating point"


def limits_of(texts: list[str]) -> dict[str, float]:
    """``["chaotic=0.01", ...]`` as {name: limit}; InvalidInputError naming a bad one or a
    name given twice, and the old word ``impacts`` saying which two words to write
    (``IMPACTS_REFUSED``)."""
    out = {}
    for text in texts:
        name, _, value = text.partition("=")
        if name == "impacts":
            raise InvalidInputError([f"--max-probability {text}: {IMPACTS_REFUSED}"])
        try:
            limit = float(value)
        except ValueError:
            limit = -1.0
        if name not in GATED or not 0.0 <= limit <= 1.0:
            raise InvalidInputError([f"--max-probability {text}: give NAME=P with P in [0, 1] "
                                     f"and NAME one of {', '.join(GATED)}"])  # fmt: skip
        if name in out:
            raise InvalidInputError([f"--max-probability {text}: P({name}) is limited twice "
                                     f"({name}={out[name]:g} before); give one limit a "
                                     "name"])  # fmt: skip
        out[name] = limit
    return out


def cmd_robustness(args: argparse.Namespace) -> int:
    """Run the study; print one line per point; --json and --plot write the outputs."""
    request, result = study(args, read_document(args.file))
    shown = {
        "chaotic": "chaotic",
        "separation": "separation",
        "back_flank": "back_flank",
        "dynamic_factor_above_limit": f"dynamic factor > {result.dynamic_factor_limit:g}",
    }
    for p in result.points:
        pr = p.probabilities
        words = ", ".join(
            f"{label} {pr[k].value:.3f} [{pr[k].interval[0]:.3f}, {pr[k].interval[1]:.3f}]"
            for k, label in shown.items()
        )
        if pr["diverged"].count:  # no class or contact known for them: never hidden
            words += f", diverged {pr['diverged'].count} of {p.samples}"
        print(f"{point_name(p.shown)}: {words} ({p.samples} samples, {result.starts_text()})")
        for line in p.ranking or []:
            print(f"  {line}")
    if result.settings is not None:
        print(f"settings: {result.settings.run_text()}")
    if request.sensitivity:
        print(f"note: {SALTELLI_SAMPLES}")
    if args.json:
        Path(args.json).write_text(result.model_dump_json())
    if args.plot:
        from gearengine.plots.robustness import robustness_figure

        Path(args.plot).write_bytes(robustness_figure(request, result, "png"))
    return EXIT_OK


def samples_needed(limits: dict[str, float], samples: int | str) -> int:
    """The fewest samples (a power of 2, as the Sobol points need) that can prove every limit
    (``samples_to_prove``): refused before computing when ``samples`` (a count) is fewer or a
    limit is 0, which no count proves."""
    need = {name: samples_to_prove(limit) for name, limit in limits.items()}
    for name, n in need.items():
        if n is None:
            raise InvalidInputError(
                [
                    f"--max-probability {name}=0: no number of samples can "
                    "prove a probability of 0 (with 0 events the 95 % upper "
                    "bound is 1 - 0.025^(1/n) > 0); give a limit above 0"
                ]
            )
    for name, n in need.items():
        if samples != "auto" and int(samples) < n:  # type: ignore[operator]
            upper = 1.0 - 0.025 ** (1.0 / int(samples))
            raise InvalidInputError([
                f"--samples {samples} cannot prove P({name}) <= {limits[name]:g}: even 0 of "
                f"{samples} samples leave a 95 % Clopper-Pearson upper bound of {upper:.3g}; it "
                f"takes {n} samples with 0 events (--samples {_power_of_two(n)}, a power of 2, "
                "or --samples auto to sample until every point is decided)"
            ])  # fmt: skip
    return _power_of_two(max(need.values(), default=1))


def _power_of_two(n: int) -> int:
    return 1 << max(0, (int(n) - 1).bit_length())


def gate_study(request: RobustnessRequest, limits: dict[str, float], auto: bool
               ) -> tuple[RobustnessResult, float, list[str]]:  # fmt: skip
    """The study the probability gate judges, the confidence its verdicts read at, and what it
    said on standard error: a fixed count's (``run_study``, one look at 95 %), or with
    ``--samples auto`` from ``request``, the study of its first round (``FIRST_SAMPLES`` at
    every point, refused over the job budget when it was built), each point sampled until it
    is decided within the job budget (``studies.robustness.sequential``): first why points
    without events may end undecided (``unreachable``, said before computing, as a fixed
    count's refusal is), then how it stopped."""
    if not auto:
        return run_study(request), ONE_LOOK, []
    budget = jobs.job_step_budget()
    unit = point_work(request)  # a sample's RK4 steps at each point, converted once for both
    short = unreachable(unit, limits, budget)
    notes = [] if short is None else [f"--samples auto: {short}"]
    for note in notes:
        print(note, file=sys.stderr)
    tick = progress(time.monotonic(), "robustness", "points decided")
    out = sequential(request, unit, limits, budget, workers=os.cpu_count() or 1, progress=tick)
    rounds = ", ".join(str(n) for n in out.rounds)
    notes.append(f"--samples auto: {out.stopped} (rounds of {rounds} samples, {out.steps} RK4 "
                 f"steps of a budget of {budget}); each look decides at "
                 f"{100 * out.confidence:.3g} %, the 5 % error shared over the {looks()} looks "
                 "a point may take")  # fmt: skip
    print(notes[-1], file=sys.stderr)
    return out.result, out.confidence, notes


def own_point(design: Design) -> dict[str, PhysicalValue]:
    """The design's own speed and torque in gear units: the point a study without axes
    samples (the gate named it 'operating point', its report's point {})."""
    out = {}
    for name in ("speed", "torque"):
        unit, factor = display_unit(name)
        out[name] = PhysicalValue(value=rounded(getattr(design, name) * factor), unit=unit)
    return out


GATE_SAMPLES = 64
"""``check --max-probability``'s samples a point when ``--samples`` is not given."""


def cmd_probability_gate(args: argparse.Namespace, doc: object) -> int:
    """``check --max-probability`` of the design document ``doc``: exit 1 where a point is over
    a limit or undecided (its interval holds the limit); a sample count that cannot prove a
    limit is refused before computing (``samples_needed``), as is a study over the job budget."""
    limits = limits_of(args.max_probability)
    args.samples = GATE_SAMPLES if args.samples is None else args.samples
    args.seed = 0 if args.seed is None else args.seed
    samples_needed(limits, args.samples)
    auto = args.samples == "auto"
    if auto:  # the first round's request: its budget refused in the user's terms
        args.samples, args.auto = FIRST_SAMPLES, True
    request = robustness_request(args, doc)  # the document read into a request once, here
    own = own_point(request.design)
    result, confidence, notes = gate_study(request, limits, auto)
    told = sampling_notes(result, limits)
    report = probability_report(result, limits, confidence, notes + told, own)
    counts = sorted({p.samples for p in result.points})
    sampled = f"{counts[0]}" if len(counts) == 1 else f"{counts[0]} to {counts[-1]}"
    print(f"probabilities from {sampled} samples a point, {result.starts_text()}")
    for note in told:
        print(note)
    for p, v in zip(result.points, report.verdicts, strict=True):
        shown = {"pass": "PASS", "fail": "FAIL", "undecided": "UNDECIDED"}[v.verdict]
        said = v.reasons or proofs(p, v)  # a pass names the bounds that prove it
        extra = f" [{'; '.join(said)}]" if said else ""
        print(f"{shown}: {level_text(v.point)} ({v.samples} samples){extra}")
    if args.json:
        Path(args.json).write_text(dumps(report))
    if args.junit:
        Path(args.junit).write_text(probability_junit(report, f"robustness of {args.file}"))
    named = ", ".join(f"P({k}) <= {v:g}" for k, v in limits.items())
    print(f"{'PASS' if report.passed else 'FAIL'}: {report.failing_points} of {report.points} "
          f"points over a probability limit ({named}), {report.undecided_points} "
          "undecided")  # fmt: skip
    return EXIT_OK if report.passed else EXIT_FAIL
