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

from simulation._lazy import lazy_exports as _lazy_exports

#: Public name -> the module that holds it.  Imported on first use (PEP 562), so that ``import riskrf`` and the
#: ``riskrf`` command start without loading pandas, scipy and numba until a command needs them.
_EXPORTS = {
    "EnergyHazard": "hazard.annual_hazard",
    "DecisionTree": "risk.decision_tree",
    **dict.fromkeys(["GEVFit", "GumbelFit", "encounter_probability", "fit_gev", "fit_gumbel",
                     "gumbel_frequency_factor"], "frequency.extremes"),
    **dict.fromkeys(["gumbel_reduced_variate", "plotting_positions"], "frequency.empirical"),
    "FrequencyAnalysis": "frequency.study", "analyse_inventory": "frequency.study",
    "exceedance_probability": "hazard.impact_energy", "fit_velocity": "hazard.velocity_models",
    "DEFAULT_DENSITY_KG_M3": "frequency.inventory", "Inventory": "frequency.inventory.record", "read_inventory": "frequency.inventory.reader",
    "MassCoupledSamples": "hazard.mass_coupling", "energy_hazard": "hazard.simulated",
    # the trajectory model's uncertainty: hazards over material draws, ranking and value of calibrating first
    "energy_hazard_ensemble": "hazard.model_uncertainty", "ModelUncertainRanking": "risk.model_decision",
    "GutenbergRichterFit": "frequency.power_law", "find_m_min": "frequency.power_law", "fit_gutenberg_richter": "frequency.power_law",
    "Rainfall": "io.rainfall", "read_rainfall": "io.rainfall",
    "RateModel": "frequency.rates.result", "rate_model": "frequency.rates.fit",
    # mitigation and the whole chain for one site (the user guide's names)
    "MitigationStudy": "risk.mitigation", "load_mitigation": "risk.mitigation",
    "load_site": "app.site", "run_assessment": "app.assess.run",
    "RiskrfError": "core.validation", "RiskrfWarning": "core.validation",
}

__all__ = sorted(_EXPORTS)

_lazy_exports(__name__, _EXPORTS)
