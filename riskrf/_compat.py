"""Old flat module paths (``riskrf.inventory``, ``riskrf.assess``, ...) kept importable for one release.

The modules of :mod:`riskrf` moved into stage packages (``riskrf.core``, ``io``, ``frequency``, ``hazard``,
``risk``, ``app``).  ``import riskrf.inventory`` and ``from riskrf.assess import run_assessment`` still work:
a meta-path finder answers each old name with the module at its new path (the same module object, so a
``monkeypatch.setattr("riskrf.assess.x", ...)`` patches the code that runs) and issues a
:class:`DeprecationWarning` naming the new path.  No file is left at an old path.

A public name that is also an old module name (``riskrf.rate_model``, the function) stays the public object
as an attribute of the package; only ``import riskrf.rate_model`` / ``from riskrf.rate_model import ...``
reach the module (see :func:`simulation._lazy.lazy_exports`).
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: Old module path -> new module path.  Remove one release after the move.
MOVED = {
    "riskrf._extremes_kernels": "riskrf.frequency._extremes_kernels",
    "riskrf._power_law_kernels": "riskrf.frequency._power_law_kernels",
    "riskrf.annual_hazard": "riskrf.hazard.annual_hazard",
    "riskrf.assess": "riskrf.app.assess",
    "riskrf.background": "riskrf.app.background",
    "riskrf.barriers": "riskrf.hazard.barriers",
    "riskrf.closure": "riskrf.risk.closure",
    "riskrf.corridor": "riskrf.app.corridor",
    "riskrf.decision_tree": "riskrf.risk.decision_tree",
    "riskrf.design_block": "riskrf.hazard.design_block",
    "riskrf.economics": "riskrf.risk.economics",
    "riskrf.energy_study": "riskrf.hazard.energy_study",
    "riskrf.extremes": "riskrf.frequency.extremes",
    "riskrf.frequency_study": "riskrf.frequency.study",
    "riskrf.impact_energy": "riskrf.hazard.impact_energy",
    "riskrf.inventory": "riskrf.frequency.inventory",
    "riskrf.mass_coupling": "riskrf.hazard.mass_coupling",
    "riskrf.measures": "riskrf.risk.measures",
    "riskrf.mitigation": "riskrf.risk.mitigation",
    "riskrf.mitigation_inputs": "riskrf.risk.mitigation_inputs",
    "riskrf.outputs": "riskrf.io.outputs",
    "riskrf.power_law": "riskrf.frequency.power_law",
    "riskrf.preflight": "riskrf.app.preflight",
    "riskrf.rainfall": "riskrf.io.rainfall",
    "riskrf.rate_model": "riskrf.frequency.rates",
    "riskrf.records": "riskrf.io.records",
    "riskrf.rhrs": "riskrf.risk.rhrs",
    "riskrf.road_risk": "riskrf.risk.road_risk",
    "riskrf.site": "riskrf.app.site",
    "riskrf.site_rates": "riskrf.risk.site_rates",
    "riskrf.tables": "riskrf.io.tables",
    "riskrf.units": "riskrf.core.units",
    "riskrf.validation": "riskrf.core.validation",
}


_SPECS = {}


def _importer_level() -> int:
    """``stacklevel`` of the first frame outside the import machinery: the line with the old import.
    (:func:`warnings.warn` does not count the frozen importlib frames.)"""
    level, frame = 2, sys._getframe(2)
    while frame is not None:
        name = frame.f_code.co_filename
        if not name.startswith("<frozen"):
            if name not in (__file__, importlib.__file__) and not name.endswith("_lazy.py"):
                return level
            level += 1
        frame = frame.f_back
    return 2


class _Alias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds an old module path and loads it as the module at its new path."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in MOVED:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        new = MOVED[spec.name]
        warnings.warn(f"old module path {spec.name} is deprecated and will be removed in the next release; "
                      f"import {new}", DeprecationWarning, stacklevel=_importer_level())
        module = importlib.import_module(new)
        _SPECS[module.__name__] = module.__spec__   # the import system overwrites __spec__ with the alias spec
        return module

    def exec_module(self, module):
        module.__spec__ = _SPECS[module.__name__]   # the module keeps its own spec (name, origin)


def install() -> None:
    """Put the alias finder first on :data:`sys.meta_path` (before any editable-install finder)."""
    if not any(isinstance(f, _Alias) for f in sys.meta_path):
        sys.meta_path.insert(0, _Alias())
