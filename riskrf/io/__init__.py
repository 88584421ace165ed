"""Table readers, agency records, rainfall, velocities and all-or-nothing output files (imports riskrf.core).

Submodules are imported on first attribute access (``riskrf.io.<module>``)."""
from simulation._lazy import lazy_exports as _lazy_exports

_lazy_exports(__name__, {})
