"""numba's on-disk cache of the compiled kernels, kept in step with every source they depend on.

numba keys a cached function (``cache=True``) on the timestamp and size of the one file that
defines it. A kernel that calls a compiled function of another file (``lockstep.run_batch`` calls
``adaptive.settled``), or freezes another module's constant into its machine code
(``adaptive.ADAPT_WINDOW``, ``periodicity.REL_TOL``), keeps stale code after that other file
changes: an edit of the stopping rule would silently not run. ``drop_stale`` keeps a digest of
all the sources of a group of kernels beside their cache and deletes the group's cache files
when the digest changes, so the next call compiles from the current sources.

Only the in-tree cache (``__pycache__`` next to the sources, where a developer's edits happen) is
kept in step; a read-only install, whose sources do not change, is left as it is, and so is a
cache moved elsewhere with ``NUMBA_CACHE_DIR`` (the Docker image, built once from fixed sources).
A process still running code compiled before an edit may write a stale entry after the new
stamp: restart what runs while kernels are being edited.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterable
from pathlib import Path

STAMP_SUFFIX = ".sources.sha256"
"""Suffix of the digest file written beside a group's cache files."""


def sources_digest(sources: Iterable[Path]) -> str:
    """sha256 over the names and contents of ``sources``, in sorted order."""
    h = hashlib.sha256()
    for path in sorted(sources):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def drop_stale(group: str, sources: Iterable[Path], cache_dir: Path) -> bool:
    """Delete the numba cache files of ``group`` (a module name such as ``lockstep``, files
    ``GROUP.*.nbi`` and ``GROUP.*.nbc``; several names joined by ``,``) in ``cache_dir`` unless
    the digest of ``sources`` is the one recorded at the last call. True if files were dropped.
    A directory that cannot be read or written is left alone (False), and so is every directory
    while ``NUMBA_CACHE_DIR`` moves numba's cache elsewhere: nothing of the cache is there, and
    importing the engine must not write stamp files into the source tree."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return False
    digest = sources_digest(sources)
    stamp = cache_dir / (group.replace(",", "+") + STAMP_SUFFIX)
    try:
        if stamp.read_text() == digest:
            return False
    except OSError:
        pass  # no stamp yet: caches written before it are of unknown sources
    try:
        cache_dir.mkdir(exist_ok=True)
        dropped = False
        for name in group.split(","):
            for pattern in (f"{name}.*.nbi", f"{name}.*.nbc"):
                for path in cache_dir.glob(pattern):
                    path.unlink(missing_ok=True)
                    dropped = True
        temporary = stamp.with_suffix(f".{os.getpid()}.tmp")
        temporary.write_text(digest)
        os.replace(temporary, stamp)
    except OSError:
        return False
    return dropped
