"""Public names of a package loaded on first use (PEP 562), for the facades that re-export
them: ``import gearengine`` costs nothing until a name is used, and ``gearengine sweep``
imports ``plots.sweep`` without ``plots.analysis`` and the analysis stack behind it.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Collection, Mapping
from typing import Any


def lazy_names(
    package: str, homes: Mapping[str, tuple[str, str]], submodules: Collection[str] = ()
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of ``package``: each public name of ``homes``
    (name -> (module, attribute)) is imported on first access and kept in the package, so the
    next access skips ``__getattr__``; each name of ``submodules`` returns that submodule (as
    after an eager facade's imports). No public name may be a submodule's: keeping it would
    hide the submodule."""

    def attribute(name: str) -> Any:
        home = homes.get(name)
        if home is not None:
            value = getattr(importlib.import_module(home[0]), home[1])
            setattr(sys.modules[package], name, value)
            return value
        if name in submodules:
            return importlib.import_module(f"{package}.{name}")
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def names() -> list[str]:
        """The public names and the module's dunders: not the imports of the facade itself
        (``annotations``, ``TYPE_CHECKING``, ``lazy_names``) nor its submodules."""
        return sorted({*homes, *(n for n in vars(sys.modules[package]) if n.startswith("__"))})

    return attribute, names
