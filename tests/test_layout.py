"""The engine stands alone: every engine module imports, and every engine command runs, with
the web stack (fastapi, uvicorn, starlette) and the ``service`` package unimportable."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from tests.conftest import PAPER_PARAMS, ROOT

BLOCKER = """
import importlib.abc, sys
BLOCKED = {"fastapi", "uvicorn", "starlette", "service", "fastapi_offline"}
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"blocked: {name}")
        return None
sys.meta_path.insert(0, Block())
"""


def run_blocked(code: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", BLOCKER + code], cwd=cwd, capture_output=True, text=True,
        timeout=300,
    )  # fmt: skip


def test_every_engine_module_imports_without_the_service() -> None:
    code = """
import pkgutil, importlib, gearengine
names = [m.name for m in pkgutil.walk_packages(gearengine.__path__, "gearengine.")]
for name in names:
    if not name.endswith("__main__"):
        importlib.import_module(name)
assert not any(m.split(".")[0] in ("fastapi", "uvicorn", "service") for m in sys.modules)
print(len(names))
"""
    out = run_blocked(code, ROOT)
    assert out.returncode == 0, out.stderr
    assert int(out.stdout) >= 30


def test_engine_commands_run_without_the_service(tmp_path: Path) -> None:
    """melnikov, analyze, check and sweep work; serve is simply not offered."""
    params = tmp_path / "params.json"
    params.write_text(json.dumps({"params": PAPER_PARAMS}))
    design = tmp_path / "design.json"
    design.write_text(json.dumps({"params": PAPER_PARAMS, "settings": {"record_periods": 50}}))
    sweep = tmp_path / "sweep.json"
    sweep.write_text(
        json.dumps(
            {
                "params": PAPER_PARAMS,
                "settings": {"transient_periods": 20, "record_periods": 20},
                "axes": [{"parameter": "F_e1", "start": 0.1, "stop": 0.2, "num": 3}],
            }
        )
    )
    calls = [
        ["melnikov", str(params), "--json"],
        ["analyze", str(design)],
        ["check", str(design)],
        ["sweep", str(sweep), "--out", str(tmp_path / "out")],
    ]
    for argv in calls:
        code = f"from gearengine.cli import main; sys.exit(main({argv!r}))"
        out = run_blocked(code, tmp_path)
        assert out.returncode == 0, (argv, out.stderr)
    assert (tmp_path / "out" / "sweep.png").stat().st_size > 0
    out = run_blocked("from gearengine.cli import main; sys.exit(main(['serve']))", tmp_path)
    assert out.returncode == 2 and "invalid choice: 'serve'" in out.stderr


def test_engine_never_imports_the_service() -> None:
    """No engine source file names the service package in an import."""
    offenders = [
        str(path.relative_to(ROOT))
        for path in (ROOT / "gearengine").rglob("*.py")
        for line in path.read_text().splitlines()
        if line.lstrip().startswith(("import service", "from service"))
    ]
    assert offenders == []
