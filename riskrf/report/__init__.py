"""Everything that draws or writes for people: figures (matplotlib), the HTML report, printed text.

Each ``plot_x(..., ax=None) -> Axes`` draws on the given axes or on a new figure, and matplotlib is imported only
inside functions, so ``import riskrf`` never loads it and never changes a notebook user's backend.  The figures of
one stage's results live with that stage (``riskrf.frequency.figures``, ``riskrf.io.figures``,
``riskrf.hazard.figures``, ``riskrf.risk.figures``: each result's ``plot()`` calls them); this package re-exports
the public ones and draws the rest.

- :mod:`riskrf.report.fit_figures`: the energy figures of ``riskrf energy`` (mass-velocity, design-energy
  sensitivity and tornado);
- :mod:`riskrf.report.decision_figures`: risk profiles, F-N curve;
- :mod:`riskrf.report.design_figures`: the options on the slope profile, the stop points;
- :mod:`riskrf.report.files`: writing the figure files of ``riskrf fit``, ``energy``, ``simulate``;
- :mod:`riskrf.report.mitigation_text`: printed and written results of a mitigation study;
- :mod:`riskrf.report.html`: the self-contained HTML report of ``riskrf assess``.
"""
from ..frequency.figures import plot_gumbel, plot_magnitude_frequency, plot_return_levels
from ..hazard.figures import plot_energy_exceedance
from ..risk.figures import plot_tornado, plot_tree
from .decision_figures import plot_fn, plot_risk_profiles
from .fit_figures import plot_mass_velocity

__all__ = ["plot_energy_exceedance", "plot_fn", "plot_gumbel", "plot_magnitude_frequency", "plot_mass_velocity",
           "plot_return_levels", "plot_risk_profiles", "plot_tornado", "plot_tree"]
