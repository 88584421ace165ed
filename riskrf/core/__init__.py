"""Units and named constants, number formatting, argument validation: imports nothing else of riskrf.

Submodules are imported on first attribute access (``riskrf.core.<module>``)."""
from simulation._lazy import lazy_exports as _lazy_exports

_lazy_exports(__name__, {})
