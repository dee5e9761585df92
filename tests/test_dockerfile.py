"""Docker cannot run here: check the Dockerfile does what the Makefile and CLI do."""

from __future__ import annotations

import re

from gearengine.cli.main import build_parser
from tests.conftest import ROOT

DOCKERFILE = (ROOT / "Dockerfile").read_text()
MAKEFILE = (ROOT / "Makefile").read_text()


def test_base_image_and_user() -> None:
    assert re.search(r"^FROM python:3\.11-slim", DOCKERFILE, re.M)
    assert re.search(r"^USER (?!root)\w+", DOCKERFILE, re.M)


def test_installs_the_project_like_the_makefile() -> None:
    assert re.search(r"pip install --quiet (--no-compile )?-e \.", MAKEFILE)
    assert re.search(r"pip install --no-cache-dir \"?\.(\$\{EXTRAS\})?\"?$", DOCKERFILE, re.M)
    for path in ("pyproject.toml", "gearengine", "service"):
        assert path in DOCKERFILE


def test_cmd_is_a_valid_serve_invocation() -> None:
    cmd = re.search(r"^CMD \[(.*)\]", DOCKERFILE, re.M).group(1)
    argv = [a.strip().strip('"') for a in cmd.split(",")]
    assert argv[:2] == ["gearengine", "serve"]
    args = build_parser().parse_args(argv[1:])
    assert args.host == "0.0.0.0"
    assert "gearengine serve" in MAKEFILE


def test_healthcheck_hits_health() -> None:
    assert re.search(r"^HEALTHCHECK .*\n?.*/v1/health", DOCKERFILE, re.M)
