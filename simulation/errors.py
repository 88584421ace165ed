"""The base of every input error of riskrf and of its simulator: one home, in the lower package."""
from __future__ import annotations


class RiskrfError(Exception):
    """Base of every riskrf and simulation input error (site, scenario, preset, terrain, corridor, mitigation,
    measures, decision tree, nil hazard), so that ``except riskrf.RiskrfError`` catches them all.  Each concrete
    error also derives from the built-in it was before (:class:`ValueError`), so existing ``except ValueError``
    code keeps working."""
