"""Write the app's OpenAPI document: ``python -m service.openapi [PATH]`` (default openapi.json)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from service.core.config import Settings
from service.main import create_app


def document() -> str:
    """The OpenAPI JSON of the app, stable: sorted keys, two-space indent, final newline."""
    spec = create_app(Settings(api_keys="")).openapi()
    return json.dumps(spec, indent=2, sort_keys=True) + "\n"


def main() -> None:
    path = Path(sys.argv[1] if len(sys.argv) > 1 else "openapi.json")
    path.write_text(document())
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
