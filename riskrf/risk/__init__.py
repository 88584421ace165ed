"""Road-user risk, economics, measures, the mitigation study, decision trees, closure rules, RHRS.

Submodules are imported on first attribute access (``riskrf.risk.<module>``)."""
from simulation._lazy import lazy_exports as _lazy_exports

_lazy_exports(__name__, {})
