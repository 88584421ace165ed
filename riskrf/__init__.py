"""riskrf: rock fall hazard, risk and mitigation decision analysis (after Wyllie 2014).

Public API (units: mass kg, volume m³, energy kJ, velocity m/s, time yr)::

    inv = riskrf.read_inventory(path)
    gr = riskrf.fit_gutenberg_richter(inv.masses, inv.duration_years)
    g = riskrf.fit_gumbel(inv.annual_maxima()); gev = riskrf.fit_gev(inv.annual_maxima())
    riskrf.exceedance_probability(500, mass=gr, velocity=samples)
    hazard = riskrf.energy_hazard(mass=gr, scenario=scenario, collector="barrier", n=20_000, seed=1)  # mass-coupled
    hazard = riskrf.EnergyHazard.from_simulation(gr, result, "barrier")   # mass-independent form
    tree = riskrf.DecisionTree.from_dict(spec); tree.rollback(); tree.ranking()
"""
__version__ = "0.1.0"

from .annual_hazard import EnergyHazard
from .decision_tree import DecisionTree
from .extremes import (
                       GEVFit,
                       GumbelFit,
                       encounter_probability,
                       fit_gev,
                       fit_gumbel,
                       gumbel_frequency_factor,
                       gumbel_reduced_variate,
                       plotting_positions,
)
from .frequency_study import FrequencyAnalysis, analyse_inventory
from .impact_energy import exceedance_probability, fit_velocity
from .inventory import DEFAULT_DENSITY_KG_M3, Inventory, read_inventory
from .mass_coupling import MassCoupledSamples, energy_hazard
from .power_law import GutenbergRichterFit, find_m_min, fit_gutenberg_richter
from .rainfall import Rainfall, read_rainfall
from .rate_model import RateModel, rate_model
from .validation import RiskrfWarning

__all__ = [
    "DEFAULT_DENSITY_KG_M3", "DecisionTree", "EnergyHazard", "FrequencyAnalysis", "GEVFit", "GumbelFit",
    "GutenbergRichterFit", "Inventory", "MassCoupledSamples", "RiskrfWarning", "analyse_inventory", "energy_hazard",
    "encounter_probability",
    "exceedance_probability", "find_m_min", "fit_gev", "fit_gumbel", "fit_gutenberg_richter", "fit_velocity",
    "gumbel_frequency_factor", "gumbel_reduced_variate", "plotting_positions", "read_inventory",
    "Rainfall", "RateModel", "rate_model", "read_rainfall",
]
