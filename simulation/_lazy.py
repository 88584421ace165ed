"""Public names of a package imported on first use (PEP 562), shared by :mod:`simulation` and :mod:`riskrf`."""
from __future__ import annotations

import importlib


def lazy_exports(package: str, exports: dict, namespace: dict):
    """``(__getattr__, __dir__)`` for the package ``package`` whose public names map to the submodules that hold
    them (``exports``); a resolved name is kept in ``namespace`` (the package's globals).  Other attribute
    names resolve to the submodule of that name, as an eager ``__init__`` importing it would have given."""

    def __getattr__(name: str):
        """A public name, or a submodule, imported on first use."""
        if name in exports:
            value = getattr(importlib.import_module(f"{package}.{exports[name]}"), name)
            namespace[name] = value
            return value
        if not name.startswith("__"):
            try:
                return importlib.import_module(f"{package}.{name}")
            except ModuleNotFoundError as exc:
                if exc.name != f"{package}.{name}":
                    raise
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        """The package's names, public ones included before their first use."""
        return sorted(set(namespace) | set(exports))

    return __getattr__, __dir__
