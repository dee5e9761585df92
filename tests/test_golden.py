"""Every number the engine's commands give on the shipped examples stays the same number.

The documents under ``tests/golden/`` were recorded with ``python -m tests.golden.cases
--write``; this test runs the quick cases in process and compares them to 1e-9 relative (the
slow ones are compared by ``python -m tests.golden.cases --check`` before and after a
restructuring).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
from pathlib import Path

import pytest

from gearengine.cli import main
from tests.golden.cases import CASES, ROOT, SLOW, differences, golden_path, pinned_input


@pytest.mark.parametrize("name", sorted(set(CASES) - SLOW))
def test_numbers_unchanged(name: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out.json"
        argv = [a.replace("{out}", str(out)) for a in CASES[name]]
        argv = pinned_input(name, argv, Path(tmp))  # fixed lengths, as recorded
        printed = io.StringIO()
        cwd = os.getcwd()
        os.chdir(ROOT)
        try:
            with contextlib.redirect_stdout(printed):
                code = main(argv)
        finally:
            os.chdir(cwd)
        assert code in (0, 1)
        doc = json.loads(out.read_text() if "{out}" in CASES[name] else printed.getvalue())
    assert differences(json.loads(golden_path(name).read_text()), doc) == []


def test_differences_sees_a_changed_number() -> None:
    assert differences({"a": [1.0, 2.0]}, {"a": [1.0, 2.0 * (1 + 1e-12)]}) == []
    assert differences({"a": [1.0, 2.0]}, {"a": [1.0, 2.0 * (1 + 1e-8)]}) != []
    assert differences({"a": "periodic"}, {"a": "chaotic"}) != []
