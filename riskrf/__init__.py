"""riskrf: rock fall hazard, risk and mitigation decision analysis (after Wyllie 2014).

Public API (units: mass kg, volume m³, energy kJ, velocity m/s, time yr)::

    inv = riskrf.read_inventory(path)
    gr = riskrf.fit_gutenberg_richter(inv.masses, inv.duration_years)
    g = riskrf.fit_gumbel(inv.annual_maxima()); gev = riskrf.fit_gev(inv.annual_maxima())
"""
__version__ = "0.1.0"

from .extremes import (GEVFit, GumbelFit, encounter_probability, fit_gev, fit_gumbel, gumbel_frequency_factor,
                       gumbel_reduced_variate, plotting_positions)
from .frequency import FrequencyAnalysis, analyse_inventory
from .inventory import DEFAULT_DENSITY_KG_M3, Inventory, read_inventory
from .magnitude import GutenbergRichterFit, find_m_min, fit_gutenberg_richter
from .validation import RiskrfWarning
from .decision import DecisionTree
from .energy import exceedance_probability, fit_velocity
from .hazard import EnergyHazard

__all__ = [
    "DEFAULT_DENSITY_KG_M3", "DecisionTree", "EnergyHazard", "FrequencyAnalysis", "exceedance_probability", "fit_velocity", "GEVFit", "GumbelFit", "GutenbergRichterFit", "Inventory",
    "RiskrfWarning", "analyse_inventory", "encounter_probability", "find_m_min", "fit_gev", "fit_gumbel",
    "fit_gutenberg_richter", "gumbel_frequency_factor", "gumbel_reduced_variate", "plotting_positions",
    "read_inventory",
]
