"""Golden numbers: every engine command on the shipped examples, as the CLI prints them.

Each case is a ``gearengine`` argv whose output (its ``--json`` document, written to standard
output or to a file) is stored under ``tests/golden/*.json``. A restructuring must leave every
number the same to 1e-9 relative (``same_numbers``); ``python -m tests.golden.cases --write``
records them anew (only when a number is meant to change, said in the commit).
"""

from __future__ import annotations

import fnmatch
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

from gearengine.studies.runup.request import QUASI_STATIC_SETTINGS

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
EX = "examples"

CASES: dict[str, list[str]] = {
    "melnikov-paper": ["melnikov", f"{EX}/paper-4.1.json", "--json"],
    "melnikov-direct": ["melnikov", f"{EX}/design-direct.json", "--json"],
    "melnikov-geometry": ["melnikov", f"{EX}/design-geometry.json", "--json"],
    "melnikov-light": ["melnikov", f"{EX}/design-light-load.json", "--json"],
    "melnikov-quadrature": ["melnikov", f"{EX}/paper-4.1.json", "--json", "--method", "quadrature"],
    "convert-direct": ["convert", f"{EX}/design-direct.json", "--json"],
    "convert-geometry": ["convert", f"{EX}/design-geometry.json", "--json"],
    "convert-robustness": ["convert", f"{EX}/robustness-gears.json", "--json"],
    "analyze-paper": ["analyze", f"{EX}/paper-4.1.json", "--json"],
    "analyze-ci": ["analyze", f"{EX}/ci/design.json", "--json"],
    "analyze-geometry": ["analyze", f"{EX}/design-geometry.json", "--json"],
    "analyze-light": ["analyze", f"{EX}/design-light-load.json", "--json"],
    "basins-5750": ["basins", f"{EX}/basins-5750rpm.json", "--starts", "16", "--json"],
    "check-ci": [
        "check",
        f"{EX}/ci/design.json",
        "--speed",
        "1000:6000",
        "--starts",
        "1",
        "--speed-points",
        "7",
        "--json",
        "{out}",
    ],
    "check-envelope": [
        "check",
        f"{EX}/envelope-map.json",
        "--speed",
        "4000:6000",
        "--torque",
        "2:11.5",
        "--speed-points",
        "5",
        "--torque-points",
        "2",
        "--starts",
        "4",
        "--json",
        "{out}",
    ],
    "sweep-fig6": ["sweep", f"{EX}/fig6-bifurcation.json", "--out", "-", "--format", "json"],
    "runup-ci": [
        "runup",
        f"{EX}/ci/design.json",
        "--from",
        "3500",
        "--to",
        "4500",
        "--rate",
        "2000",
        "--direction",
        "up_down",
        "--ensemble",
        "2",
        "--json",
        "{out}",
    ],
    "robustness": [
        "robustness",
        f"{EX}/robustness-gears.json",
        "--speed",
        "5000:6000",
        "--torque",
        "5:5",
        "--speed-points",
        "2",
        "--torque-points",
        "1",
        "--samples",
        "8",
        "--json",
        "{out}",
    ],
    "remedies": [
        "remedies",
        f"{EX}/envelope-map.json",
        "--speed",
        "4000:5500",
        "--speed-points",
        "4",
        "--torque",
        "2:11.5",
        "--torque-points",
        "2",
        "--fail-on",
        "chaotic",
        "--starts",
        "1",
        "--json",
        "{out}",
    ],
}
"""Case name -> the command's arguments; ``{out}`` is a file the command writes its JSON to."""

SLOW = {"remedies", "robustness", "runup-ci", "sweep-fig6", "check-envelope"}
"""Cases left out of the test suite's quick run (the before/after check runs them all)."""


FIXED_LENGTH = {"physical_time": False}
"""Settings every integrating case runs with: its transient and record as fixed counts of T0,
the lengths these numbers were recorded with before transients were decided in physical time
(``numerics.physical``, issue 31); tests/test_physical.py checks the physical-time default."""
PINNED: dict[str, str] = {
    **{n: "settings" for n in CASES if n.split("-")[0] in
       ("analyze", "basins", "check", "sweep", "robustness", "remedies")},
    "runup-ci": "quasi_static",
}  # fmt: skip
"""Case -> the field of its input document that takes ``FIXED_LENGTH``."""


def pinned_input(name: str, argv: list[str], tmp: Path) -> list[str]:
    """``argv`` with its input document replaced by a copy in ``tmp`` whose settings (or
    ``quasi_static``, the run-up's) carry ``FIXED_LENGTH``."""
    field = PINNED.get(name)
    if field is None:
        return argv
    i = next(k for k, a in enumerate(argv) if a.endswith(".json") and k == 1)
    doc = json.loads((ROOT / argv[i]).read_text())
    base = dict(doc.get(field) or {})
    if field == "quasi_static":
        base = {**QUASI_STATIC_SETTINGS, **base}
    doc[field] = {**base, **FIXED_LENGTH}
    copy = tmp / Path(argv[i]).name
    copy.write_text(json.dumps(doc))
    return [*argv[:i], str(copy), *argv[i + 1 :]]


def run_case(name: str) -> object:
    """The JSON document of one case, computed now (a ``gearengine`` subprocess in ROOT)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out.json"
        argv = [a.replace("{out}", str(out)) for a in CASES[name]]
        argv = pinned_input(name, argv, Path(tmp))
        done = subprocess.run(
            [sys.executable, "-m", "gearengine.cli", *argv], cwd=ROOT, capture_output=True,
            text=True, timeout=900,
        )  # fmt: skip
        if done.returncode not in (0, 1):
            raise RuntimeError(f"{name}: exit {done.returncode}: {done.stderr[-2000:]}")
        text = out.read_text() if "{out}" in CASES[name] else done.stdout
        return json.loads(text)


def differences(a: object, b: object, rel: float = 1e-9, path: str = "") -> list[str]:
    """Where two documents differ: numbers beyond ``rel`` relative, anything else exactly."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{path}/{k}: only in one" for k in a.keys() ^ b.keys()]
        for k in a.keys() & b.keys():
            out += differences(a[k], b[k], rel, f"{path}/{k}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: length {len(a)} != {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b, strict=True))
                for d in differences(x, y, rel, f"{path}/{i}")]  # fmt: skip
    numbers = (int, float)
    if isinstance(a, numbers) and isinstance(b, numbers) and not isinstance(a, bool):
        if math.isclose(a, b, rel_tol=rel, abs_tol=1e-300):
            return []
        return [f"{path}: {a!r} != {b!r}"]
    return [] if a == b else [f"{path}: {a!r} != {b!r}"]


def golden_path(name: str) -> Path:
    return HERE / f"{name}.json"


def main(argv: list[str]) -> int:
    """``--write [NAME...]`` records, ``--check [NAME...]`` compares (all cases by default; a
    NAME may be a shell pattern such as ``melnikov-*``)."""
    if not argv or argv[0] not in ("--check", "--write"):
        print("usage: python -m tests.golden.cases --check|--write [NAME...]")
        print(f"cases: {list(CASES)}")
        return 2
    mode, patterns = argv[0], argv[1:] or ["*"]
    names = [n for n in CASES if any(fnmatch.fnmatch(n, p) for p in patterns)]
    unknown = [p for p in patterns if not fnmatch.filter(CASES, p)]
    if unknown:
        print(f"no case matches {unknown}; cases: {list(CASES)}")
        return 2
    failed = 0
    for name in names:
        doc = run_case(name)
        if mode == "--write":
            golden_path(name).write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n")
            print(f"wrote {name}")
            continue
        diff = differences(json.loads(golden_path(name).read_text()), doc)
        failed += bool(diff)
        print(f"{name}: {'same' if not diff else f'{len(diff)} differences'}")
        for line in diff[:10]:
            print("   ", line)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
