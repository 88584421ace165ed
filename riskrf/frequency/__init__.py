"""Rock fall inventories, power-law (Gutenberg-Richter) fits, annual maxima (Gumbel, GEV), rate models.

Submodules are imported on first attribute access (``riskrf.frequency.<module>``)."""
from simulation._lazy import lazy_exports as _lazy_exports

_lazy_exports(__name__, {})
