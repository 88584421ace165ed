"""Everything that draws or writes for people: figures (matplotlib), the HTML report, printed text.

This package is the only part of :mod:`riskrf` that imports matplotlib, and it does so
only inside functions, so ``import riskrf`` never loads it and never changes a
notebook user's backend.  Each ``plot_x(..., ax=None) -> Axes`` draws on the given
axes or on a new figure.

- :mod:`riskrf.report.fit_figures`: magnitude-frequency, Gumbel, return levels, energy figures;
- :mod:`riskrf.report.decision_figures`: decision tree, tornado, risk profiles, F-N curve;
- :mod:`riskrf.report.files`: writing the figure files of ``riskrf fit``, ``energy``, ``simulate``;
- :mod:`riskrf.report.mitigation_text`: printed and written results of a mitigation study;
- :mod:`riskrf.report.html`: the self-contained HTML report of ``riskrf assess``.
"""
from .decision_figures import plot_fn, plot_risk_profiles, plot_tornado, plot_tree
from .fit_figures import (
                          plot_energy_exceedance,
                          plot_gumbel,
                          plot_magnitude_frequency,
                          plot_mass_velocity,
                          plot_return_levels,
)

__all__ = ["plot_energy_exceedance", "plot_fn", "plot_gumbel", "plot_magnitude_frequency", "plot_mass_velocity",
           "plot_return_levels", "plot_risk_profiles", "plot_tornado", "plot_tree"]
