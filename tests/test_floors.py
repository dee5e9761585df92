"""The engine's rooms stand on floors: a room imports only rooms below it, and no module
imports itself back through others (no circle). Every import counts: at module level, inside a
function, or under ``TYPE_CHECKING``. Also: no engine module over ``MAX_LINES`` lines outside
the listed numba kernels."""

from __future__ import annotations

import ast
from pathlib import Path

from tests.conftest import ROOT

FLOORS: dict[str, int] = {
    "gearengine.lazyload": 0,
    "gearengine.jitcache": 0,
    "gearengine.model": 1,
    "gearengine.jsonio": 2,
    "gearengine.signals": 2,
    "gearengine.systems": 3,
    "gearengine.numerics": 4,
    "gearengine.homoclinic": 4,
    "gearengine.engineering": 5,
    "gearengine.analysis": 6,
    "gearengine.studies": 7,
    "gearengine.rig": 8,
    "gearengine.gate": 8,
    "gearengine.plots": 9,
    "gearengine.cli": 10,
    "gearengine": 10,  # the facade, gearengine/__init__.py
}
"""Room (a package or module of the engine) -> its floor; the data flows upwards: model ->
systems (their kernels) -> numerics (drives any system) and homoclinic -> one point's verdicts
-> studies (job kinds) -> gates, and the model beside a rig's series (``rig``, whose long
readings are a job kind of ``studies.jobs``) -> plots -> commands and the facade. ``signals``
reads a series with array functions only (a rig's or a simulation's), so it stands on the model
alone and the kernels and numerics hand their series to it."""

MAX_LINES = 450
LONG_KERNELS: frozenset[str] = frozenset()
"""Numba kernels allowed over ``MAX_LINES`` where splitting them costs speed (none today)."""


def engine_modules() -> dict[str, Path]:
    out = {}
    for path in sorted((ROOT / "gearengine").rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def room(module: str) -> str:
    """The longest key of ``FLOORS`` that ``module`` is, or lies in."""
    best = ""
    for key in FLOORS:
        if (module == key or module.startswith(key + ".")) and len(key) > len(best):
            best = key
    return best


def imports_of(module: str, path: Path, known: set[str]) -> set[str]:
    """Engine modules that ``module`` imports (``from a import b`` counts a.b when that is a
    module, else a)."""
    tree = ast.parse(path.read_text())
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1]
                                + ([base] if base else []))  # fmt: skip
            for alias in node.names:
                full = f"{base}.{alias.name}"
                found.add(full if full in known else base)
    return {m for m in found if m.split(".")[0] == "gearengine" and m in known and m != module}


def graph() -> dict[str, set[str]]:
    modules = engine_modules()
    known = set(modules)
    return {m: imports_of(m, p, known) for m, p in modules.items()}


def test_every_engine_module_has_a_floor() -> None:
    assert [m for m in engine_modules() if not room(m)] == []


def test_no_room_imports_a_room_above_or_beside_it() -> None:
    wrong = []
    for module, targets in graph().items():
        here = room(module)
        for target in targets:
            there = room(target)
            if there != here and FLOORS[there] >= FLOORS[here] and here != "gearengine":
                wrong.append(f"{module} (floor {FLOORS[here]}) -> {target} ({FLOORS[there]})")
    assert wrong == []


def test_no_import_circle() -> None:
    edges = graph()
    # package __init__ files re-export their room: an arrow into one is an arrow to the room,
    # so only arrows between plain modules (and from __init__ files outward) close a circle
    inits = {m for m, p in engine_modules().items() if p.name == "__init__.py"}
    edges = {m: {t for t in ts if t not in inits} for m, ts in edges.items()}
    state: dict[str, int] = {}
    circles: list[list[str]] = []

    def visit(m: str, stack: list[str]) -> None:
        state[m] = 1
        for t in sorted(edges[m]):
            if state.get(t) == 1:
                circles.append([*stack[stack.index(t) :], t])
            elif t not in state:
                visit(t, [*stack, t])
        state[m] = 2

    for m in sorted(edges):
        if m not in state:
            visit(m, [m])
    assert circles == []


def test_no_engine_module_over_the_line_limit() -> None:
    long = {
        m: n for m, p in engine_modules().items()
        if (n := len(p.read_text().splitlines())) > MAX_LINES and m not in LONG_KERNELS
    }  # fmt: skip
    assert long == {}


def test_the_architecture_doc_names_every_module() -> None:
    doc = (ROOT / "docs" / "architecture.md").read_text()
    missing = [str(p.relative_to(ROOT)) for p in engine_modules().values()
               if f"`{p.relative_to(ROOT)}`" not in doc]  # fmt: skip
    assert missing == []
