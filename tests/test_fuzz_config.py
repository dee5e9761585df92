"""schemathesis.toml accepts a 422 to schema-valid data only where a rule across fields is
documented (issue 30 item 7): every listed operation quotes its rules in a "cross-field:"
comment, each rule stands in that operation's OpenAPI description (``service.api.rules``), and
no other operation, nor the global check, accepts a 422, so the list cannot grow silently."""

from __future__ import annotations

import json
import re
import tomllib

from service.api.rules import CROSS_FIELD_RULES
from tests.conftest import ROOT

TEXT = (ROOT / "schemathesis.toml").read_text()
CONFIG = tomllib.loads(TEXT)
SPEC = json.loads((ROOT / "openapi.json").read_text())
OPERATIONS = {op["operationId"]: op for ops in SPEC["paths"].values() for op in ops.values()}


def listed() -> dict[str, list[str]]:
    """Operation id -> the rules its entry's "cross-field:" comment quotes."""
    out = {}
    for block in TEXT.split("[[operations]]")[1:]:
        quoted = re.search(r"^# cross-field: (.+)$", block, re.MULTILINE)
        op_id = re.search(r'^include-operation-id = "([^"]+)"$', block, re.MULTILINE)
        assert quoted and op_id, block
        out[op_id.group(1)] = quoted.group(1).split("; ")
    return out


def accepts_422(checks: dict) -> bool:
    statuses = checks.get("positive_data_acceptance", {}).get("expected-statuses", [])
    return "422" in [str(s) for s in statuses]


def test_every_listed_operation_documents_each_quoted_rule() -> None:
    entries = listed()
    assert len(entries) == len(CONFIG["operations"])
    for op_id, rules in entries.items():
        assert op_id in OPERATIONS, op_id
        description = OPERATIONS[op_id].get("description", "")
        assert "Rules across fields that the schema cannot state" in description, op_id
        for rule in rules:
            assert rule in description, (op_id, rule)


def test_422_is_accepted_only_on_the_listed_operations() -> None:
    assert not accepts_422(CONFIG.get("checks", {}))
    for entry in CONFIG["operations"]:
        assert set(entry) == {"include-operation-id", "checks"}, entry
        assert set(entry["checks"]) == {"positive_data_acceptance"}
    assert {e["include-operation-id"] for e in CONFIG["operations"] if accepts_422(e["checks"])} \
        <= set(CROSS_FIELD_RULES)  # fmt: skip


def test_the_documented_rules_are_the_listed_ones() -> None:
    """An operation documented with rules across fields is listed, and the other way round."""
    assert set(listed()) == set(CROSS_FIELD_RULES)
