"""numba's cache follows every source a kernel depends on (gearengine.jitcache)."""

from __future__ import annotations

from pathlib import Path

import gearengine.homoclinic
import gearengine.numerics.kernels as kernels
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
    homoclinic = Path(gearengine.homoclinic.__file__).parent
    groups = {
        numerics / "__pycache__" / (
            "adaptive+intervals+kink+kinklanes+lockstep+monodromy+phase+ramp+smooth"
        ): [
            *numerics.glob("*.py"), numerics.parent / "periodicity.py",
            numerics.parent / "lyapunov.py", numerics.parent / "classify.py",
        ],
        homoclinic / "__pycache__" / "kernels+batch+loops": [
            homoclinic / name for name in ("kernels.py", "batch.py", "extrema.py", "loops.py")
        ],
    }  # fmt: skip
    for stem, sources in groups.items():
        stamp = stem.with_name(stem.name + STAMP_SUFFIX)
        assert stamp.read_text() == sources_digest(sources), stamp
