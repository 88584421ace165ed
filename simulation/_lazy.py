"""Public names of a package imported on first use (PEP 562), shared by :mod:`simulation` and :mod:`riskrf`."""
from __future__ import annotations

import importlib
import sys
import types


def lazy_exports(package: str, exports: dict) -> None:
    """Make the public names of ``package`` (an imported package, usually ``__name__`` in its ``__init__``)
    resolve on first use: ``exports`` maps each name to the submodule that holds it.  A resolved name is kept
    in the package; other attribute names resolve to the submodule of that name, as an eager ``__init__``
    importing it would have given.

    A public name that is also a submodule's name (``riskrf.rate_model``, the function in the module of that
    name) stays the public object: importing the submodule anywhere does not replace it with the module, as
    it would in a plain lazy package, where the import system sets the package attribute after the import.
    """
    module = sys.modules[package]

    class LazyPackage(types.ModuleType):
        def __getattr__(self, name: str):
            """A public name, or a submodule, imported on first use."""
            if name in exports:
                value = getattr(importlib.import_module(f"{package}.{exports[name]}"), name)
                setattr(self, name, value)
                return value
            if not name.startswith("__"):
                try:
                    return importlib.import_module(f"{package}.{name}")
                except ModuleNotFoundError as exc:
                    if exc.name != f"{package}.{name}":
                        raise
            raise AttributeError(f"module {package!r} has no attribute {name!r}")

        def __setattr__(self, name: str, value):
            if name in exports and isinstance(value, types.ModuleType) and hasattr(value, name):
                value = getattr(value, name)
            super().__setattr__(name, value)

        def __dir__(self):
            """The package's names, public ones included before their first use."""
            return sorted(set(vars(self)) | set(exports))

    module.__class__ = LazyPackage
