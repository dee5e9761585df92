"""numba's cache follows every source a kernel depends on (gearengine.jitcache)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import gearengine
import gearengine.homoclinic
import gearengine.systems.spur_pair.kernels as kernels
from gearengine.jitcache import STAMP_SUFFIX, drop_stale, sources_digest


def cache_files(cache: Path) -> list[str]:
    return sorted(p.name for p in cache.iterdir() if p.suffix in (".nbi", ".nbc"))


def test_a_change_in_any_source_drops_the_group_and_only_the_group(tmp_path: Path) -> None:
    a, b = tmp_path / "lockstep.py", tmp_path / "adaptive.py"
    a.write_text("def run_batch(): ...\n")
    b.write_text("ADAPT_WINDOW = 120\n")
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    old = ["lockstep.run_batch-27.py311.1.nbc", "lockstep.run_batch-27.py311.nbi"]
    for name in [*old, "other.f-1.py311.nbi"]:
        (cache / name).write_bytes(b"machine code")
    # no stamp yet: what is cached is of unknown sources, so it goes
    assert drop_stale("lockstep,adaptive", [a, b], cache)
    assert cache_files(cache) == ["other.f-1.py311.nbi"]
    for name in old:  # numba compiles and caches again
        (cache / name).write_bytes(b"machine code")
    assert not drop_stale("lockstep,adaptive", [a, b], cache)  # same sources: kept
    assert cache_files(cache) == sorted([*old, "other.f-1.py311.nbi"])
    b.write_text("ADAPT_WINDOW = 60\n")  # the other file of the group changes
    assert drop_stale("lockstep,adaptive", [a, b], cache)
    assert cache_files(cache) == ["other.f-1.py311.nbi"]
    assert (cache / f"lockstep+adaptive{STAMP_SUFFIX}").read_text() == sources_digest([a, b])


def test_a_cache_that_cannot_be_written_is_left_alone(tmp_path: Path) -> None:
    """Where the stamp cannot be written (here: the cache path lies under a file, which stops
    root too), nothing is dropped and nothing raises: numba then caches elsewhere."""
    source = tmp_path / "k.py"
    source.write_text("x = 1\n")
    blocker = tmp_path / "not-a-directory"
    blocker.write_text("")
    assert not drop_stale("k", [source], blocker / "__pycache__")
    assert blocker.read_text() == ""


def test_the_kernels_caches_are_stamped_with_their_current_sources() -> None:
    """Importing the kernels keeps their caches in step: each stamp holds today's digest of
    every file its group compiles in, so an edit of adaptive.py, periodicity.py or extrema.py
    drops the cached code that froze it on the next import."""
    numerics = Path(kernels.__file__).parent
    signals = Path(gearengine.__file__).parent / "signals"
    homoclinic = Path(gearengine.homoclinic.__file__).parent
    groups = {
        numerics / "__pycache__" / (
            "adaptive+intervals+kink+kinklanes+lockstep+monodromy+phase+ramp+scheduler+smooth"
        ): [
            *numerics.glob("*.py"), signals / "periodicity.py",
            signals / "lyapunov.py", signals / "classify.py",
        ],
        homoclinic / "__pycache__" / "kernels+batch+loops": [
            homoclinic / name for name in ("kernels.py", "batch.py", "extrema.py", "loops.py")
        ],
    }  # fmt: skip
    for stem, sources in groups.items():
        stamp = stem.with_name(stem.name + STAMP_SUFFIX)
        assert stamp.read_text() == sources_digest(sources), stamp


def test_a_cache_moved_elsewhere_leaves_the_source_tree_alone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With NUMBA_CACHE_DIR set (the Docker image), importing the engine wrote a stamp into the
    sources' __pycache__ all the same; now nothing is written or dropped there."""
    source = tmp_path / "k.py"
    source.write_text("x = 1\n")
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    (cache / "k.f-1.py311.nbi").write_bytes(b"machine code")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "elsewhere"))
    assert not drop_stale("k", [source], cache)
    assert sorted(p.name for p in cache.iterdir()) == ["k.f-1.py311.nbi"]


def test_importing_the_engine_with_a_moved_cache_writes_no_stamp(tmp_path: Path) -> None:
    """A fresh process importing the kernels from a copy of the sources under NUMBA_CACHE_DIR."""
    copy = tmp_path / "src"
    shutil.copytree(Path(gearengine.__file__).parent, copy / "gearengine",
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(copy), "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    code = (
        "import gearengine.systems.spur_pair.kernels, gearengine.homoclinic as h; print(h.__file__)"
    )
    run = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, check=True,
                         timeout=300, capture_output=True, text=True)  # fmt: skip
    assert run.stdout.startswith(str(copy))
    assert not list(copy.rglob(f"*{STAMP_SUFFIX}"))
