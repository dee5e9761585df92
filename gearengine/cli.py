"""The ``gearengine`` command line.

    gearengine melnikov FILE [--json] [--method closed_form|quadrature]
    gearengine analyze FILE [--json]
    gearengine check FILE [--fail-on chaotic|quasi_periodic|diverged|melnikov] [--max-lle V]
    gearengine serve [--host 127.0.0.1] [--port 8000] [--data-dir DIR] [--workers N]
    gearengine sweep FILE [--out DIR]
    gearengine worker --data-dir DIR [--workers N] [--dask ADDRESS]

FILE holds ``{"params": {...}}`` (and ``"settings"`` for analyze/check; ``-`` reads standard
input). ``--json`` prints exactly the body the HTTP API returns. Exit codes: 0 success (check:
pass), 1 check failed, 2 invalid input (one line per problem, naming the field).
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeVar

from pydantic import BaseModel, ValidationError

from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
from gearengine.jsonio import dumps, error_lines, load_document
from gearengine.melnikov_analysis import melnikov
from gearengine.melnikov_result import MelnikovResult, ParameterThreshold
from gearengine.requests import MelnikovRequest

EXIT_OK, EXIT_FAIL, EXIT_INVALID = 0, 1, 2

R = TypeVar("R", bound=BaseModel)


class InvalidInputError(Exception):
    """Input that cannot be used; carries one message line per problem."""

    def __init__(self, lines: list[str]) -> None:
        super().__init__("\n".join(lines))
        self.lines = lines


def read_request(path: str, model: type[R]) -> R:
    """Read and validate a request document from a file or ``-`` (stdin)."""
    try:
        text = sys.stdin.read() if path == "-" else Path(path).read_text()
    except OSError as exc:
        raise InvalidInputError([f"{path}: {exc.strerror}"]) from None
    try:
        return model.model_validate(load_document(text))
    except ValueError as exc:
        if isinstance(exc, ValidationError):
            raise InvalidInputError(error_lines(exc)) from None
        raise InvalidInputError([f"{path}: {exc}"]) from None


# --- melnikov -------------------------------------------------------------------------------------


def _fmt(v: float | None) -> str:
    return "-" if v is None else f"{v:.6g}"


def _threshold_row(name: str, t: ParameterThreshold) -> str:
    crit = ", ".join(_fmt(v) for v in t.critical_values) or (t.note or "none")
    margin = "-"
    if t.margin is not None:
        margin = f"{t.margin:+.4g}"
        if t.relative_margin is not None:
            margin += f" ({100 * t.relative_margin:+.1f}%)"
    return f"  {name:<8} {_fmt(t.value):>10}  {crit:<36} {_fmt(t.nearest):>10}  {margin}"


def render_melnikov(r: MelnikovResult) -> str:
    """Readable verdict table of a Melnikov result."""
    if not r.applicable:
        return "Melnikov criterion not applicable\n" + "\n".join(f"  note: {n}" for n in r.notes)
    verdict = "POSSIBLE" if r.chaos_possible else "not possible"
    lines = [
        f"Melnikov verdict: chaos {verdict} "
        f"({'transverse' if r.chaos_possible else 'no transverse'} homoclinic intersection)",
        f"  cubic law f_h = -{r.a:g} x + {r.c:g} x^3, forcing period T0 = {_fmt(r.forcing_period)}",
        "  branch  sign change       min M         max M   extrema",
    ]
    for name, b in (r.branches or {}).items():
        change = "yes" if b.sign_change else "no"
        lines.append(f"  {name:<7} {change:<11} {b.min:>13.6g} {b.max:>13.6g}   {b.extrema}")
    lines.append(f"  {'param':<8} {'value':>10}  {'critical values':<36} {'nearest':>10}  margin")
    lines += [_threshold_row(name, t) for name, t in r.thresholds.items()]
    lines += [f"  note: {n}" for n in r.notes]
    return "\n".join(lines)


def cmd_melnikov(args: argparse.Namespace) -> int:
    req = read_request(args.file, MelnikovRequest)
    result = melnikov(req.params, method=args.method or req.method)
    print(dumps(result) if args.json else render_melnikov(result))
    return EXIT_OK


# --- analyze and check ----------------------------------------------------------------------------

SEVERITY = {"periodic": 0, "quasi_periodic": 1, "chaotic": 2, "diverged": 3}
"""--fail-on X fails on X and on anything worse."""


def _numerics_line(r: AnalysisResult) -> str:
    num = r.numerics
    kind = f"periodic {num.period}T" if num.period else num.classification
    lle = "LLE n/a" if num.lle is None else f"LLE {num.lle:+.4g} ± {num.lle_stderr or 0.0:.2g}"
    mel = {True: "possible", False: "not possible", None: "n/a"}[r.melnikov.chaos_possible]
    return f"{kind} ({lle} per unit tau, {num.impact_regime}), Melnikov: chaos {mel}"


def cmd_analyze(args: argparse.Namespace) -> int:
    result = analyze(read_request(args.file, AnalysisRequest))
    if args.json:
        print(dumps(result))
    else:
        print(render_melnikov(result.melnikov))
        print(f"Numerical verdict: {_numerics_line(result)}")
        print(f"  {result.verdict.summary}")
        print(f"  forcing period T0 = {_fmt(result.numerics.forcing_period)}")
        for note in result.numerics.notes:
            print(f"  note: {note}")
    return EXIT_OK


def failures(r: AnalysisResult, fail_on: list[str], max_lle: float | None) -> list[str]:
    """Reasons the design fails the gate (empty: pass)."""
    worst = r.numerics.worst_case.classification
    reasons = [
        f"--fail-on {f}" for f in fail_on if f != "melnikov" and SEVERITY[worst] >= SEVERITY[f]
    ]
    if "melnikov" in fail_on and r.melnikov.chaos_possible:
        reasons.append("--fail-on melnikov")
    lle = r.numerics.worst_case.lle
    if max_lle is not None and (lle is None or lle > max_lle):
        reasons.append(f"--max-lle {max_lle:g}")
    return reasons


def cmd_check(args: argparse.Namespace) -> int:
    """CI gate: exit 0 pass, 1 fail, 2 invalid input; one summary line."""
    result = analyze(read_request(args.file, AnalysisRequest))
    default = [] if args.max_lle is not None else ["chaotic"]  # a bare --max-lle stands alone
    reasons = failures(result, args.fail_on or default, args.max_lle)
    verdict = "FAIL" if reasons else "PASS"
    why = f" [{', '.join(reasons)}]" if reasons else ""
    print(f"{verdict}: {_numerics_line(result)}{why}")
    return EXIT_FAIL if reasons else EXIT_OK


# --- serve ----------------------------------------------------------------------------------------


def _is_loopback(host: str) -> bool:
    import ipaddress

    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def cmd_serve(args: argparse.Namespace) -> int:
    """Start uvicorn with the API (imports the service only here: the engine has no web deps)."""
    import uvicorn

    from service.api.deps import load_key_hashes
    from service.core.config import Settings
    from service.main import create_app

    flags = {
        "host": args.host,
        "port": args.port,
        "data_dir": args.data_dir,
        "workers": args.workers,
        "dask_scheduler": args.dask,
        "insecure": args.insecure or None,
    }
    settings = Settings(**{k: v for k, v in flags.items() if v is not None})
    try:
        keys = load_key_hashes(settings)
    except ValueError as exc:
        raise InvalidInputError([str(exc)]) from None
    if not _is_loopback(settings.host) and not keys and not settings.insecure:
        raise InvalidInputError(
            [
                f"refusing to serve on {settings.host} without API keys: set "
                "GEARCHAOS_API_KEYS, or put key digests in the data directory's "
                "api_keys.sha256, or pass --insecure"
            ]
        )
    try:
        Path(settings.data_dir).mkdir(parents=True, exist_ok=True)
        probe = Path(settings.data_dir) / ".write-probe"
        probe.write_text("ok")
        probe.unlink()
    except OSError as exc:
        raise InvalidInputError(
            [f"data directory {settings.data_dir} is not writable: {exc.strerror}"]
        ) from None
    logging.basicConfig(level=logging.INFO, format="%(message)s")  # JSON access/job lines
    uvicorn.run(
        create_app(settings),
        host=settings.host,
        port=settings.port,
        log_level="info",
        timeout_keep_alive=settings.keep_alive_seconds,
    )
    return EXIT_OK


# --- entry point ----------------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
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

    p = sub.add_parser("serve", help="start the HTTP API and the sweep workers")
    p.add_argument("--host", default=None, help="bind address (default 127.0.0.1)")
    p.add_argument("--port", type=int, default=None, help="TCP port (default 8000)")
    p.add_argument("--data-dir", default=None, help="directory holding all state (default ./data)")
    p.add_argument("--workers", type=int, default=None, help="sweep worker processes")
    p.add_argument("--dask", default=None, metavar="ADDRESS", help="Dask scheduler for sweeps")
    p.add_argument(
        "--insecure", action="store_true", help="allow a non-loopback bind without API keys"
    )
    p.set_defaults(func=cmd_serve)

    p = sub.add_parser("sweep", help="run a sweep here, no server: JSON, CSV and PNG")
    p.add_argument("file", help="JSON file holding a sweep request (as POST /v1/sweeps), or -")
    p.add_argument("--out", default=".", help="directory for the outputs (default .)")
    p.set_defaults(func=_lazy("gearengine.sweep_cli", "cmd_sweep"))

    p = sub.add_parser("worker", help="run sweep workers on a data directory's job store")
    p.add_argument("--data-dir", default=None, help="directory holding the job store")
    p.add_argument("--workers", type=int, default=None, help="worker processes (default: cores)")
    p.add_argument("--dask", default=None, metavar="ADDRESS", help="Dask scheduler to run on")
    p.set_defaults(func=_lazy("service.jobs.worker", "cmd_worker"))
    return parser


def _lazy(module: str, name: str) -> Callable[[argparse.Namespace], int]:
    """A command whose implementation is imported only when it runs."""

    def run(args: argparse.Namespace) -> int:
        return getattr(importlib.import_module(module), name)(args)

    return run


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


if __name__ == "__main__":
    sys.exit(main())
