"""Start-up pays only for what a command uses: the facade and the command line load lazily, and
the lazy names are the same objects as before."""

from __future__ import annotations

import importlib
import pkgutil
import subprocess
import sys

import gearengine
from tests.conftest import ROOT

HEAVY = ("numba", "scipy", "matplotlib", "pint", "nolds")


def loaded_after(statement: str) -> set[str]:
    """The top-level packages among ``HEAVY`` that ``statement`` imports in a fresh interpreter."""
    code = f"import sys\n{statement}\nprint(' '.join({{m.split('.')[0] for m in sys.modules}}))"
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    return set(out.stdout.split()) & set(HEAVY)


def test_the_command_line_imports_nothing_heavy() -> None:
    assert loaded_after("import gearengine.cli.main") == set()
    assert loaded_after("from gearengine.cli.main import build_parser; build_parser()") == set()


def test_the_facade_imports_nothing_until_used() -> None:
    assert loaded_after("import gearengine") == set()
    assert loaded_after("from gearengine import GearParams") == set()


def test_every_public_name_is_its_modules_object() -> None:
    import gearengine.homoclinic as homoclinic
    import gearengine.studies.sweep as sweeps

    for name in gearengine.__all__:
        assert getattr(gearengine, name) is not None, name
    assert gearengine.melnikov is homoclinic.melnikov
    assert gearengine.run_sweep is sweeps.run_local
    assert set(gearengine.__all__) <= set(dir(gearengine))


def test_no_public_name_shadows_a_module() -> None:
    """``gearengine.melnikov`` is the verb; a lazily cached name must never hide a submodule."""
    modules = {m.name for m in pkgutil.iter_modules(gearengine.__path__)}
    assert not modules & set(gearengine.__all__)
    assert modules == gearengine._SUBMODULES
    for name in modules:  # ``gearengine.numerics`` after a bare ``import gearengine``
        assert getattr(gearengine, name) is importlib.import_module(f"gearengine.{name}")
