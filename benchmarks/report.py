"""benchmarks/README.md holds one section per benchmark script, each rewritten only by its own
script between ``<!-- name:start -->`` and ``<!-- name:end -->`` markers."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parent / "README.md"
HEADER = (
    "# Benchmarks\n\nMeasured on this project's 2-core machine. Each section is written by the "
    "script named in it; speed is reported as ratios against a baseline run in the same "
    "process, never as timed tests.\n"
)


def write_section(name: str, markdown: str) -> None:
    """Replace (or append) the section ``name`` of benchmarks/README.md with ``markdown``."""
    text = README.read_text() if README.exists() else HEADER
    block = f"<!-- {name}:start -->\n{markdown.strip()}\n<!-- {name}:end -->"
    pattern = re.compile(
        rf"<!-- {re.escape(name)}:start -->.*?<!-- {re.escape(name)}:end -->", re.S
    )
    text = (
        pattern.sub(lambda _: block, text)
        if pattern.search(text)
        else f"{text.rstrip()}\n\n{block}\n"
    )
    README.write_text(text)
