"""Orchestration: site files, ``riskrf assess``, corridors, argument pre-flight, background figure writers.

Submodules are imported on first attribute access (``riskrf.app.<module>``)."""
from simulation._lazy import lazy_exports as _lazy_exports

_lazy_exports(__name__, {})
