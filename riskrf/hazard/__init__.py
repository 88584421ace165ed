"""One fall's energy exceedance, mass coupling, the annual energy hazard, design block, barriers, energy study.

Submodules are imported on first attribute access (``riskrf.hazard.<module>``)."""
from simulation._lazy import lazy_exports as _lazy_exports

_lazy_exports(__name__, {})
