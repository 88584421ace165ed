"""How a science result's ``plot()`` reaches its drawing function in :mod:`riskrf.report` without importing it.

The stages import one way only (``core < io < frequency < hazard < risk < report < app``; checked by
tests/test_architecture.py): the science never imports ``riskrf.report``, so that the science loads without
matplotlib and no import cycle can form.  A result's ``plot()`` still belongs on the result (a notebook user
finds it by tab completion), so the science names its figure by a key of :data:`FIGURES`, and :func:`draw`
resolves the key to a function of a ``riskrf.report`` module when the user asks for the plot, never at import.
The table below is the only place where a science result is tied to a report function; a test checks that
every entry names a ``riskrf.report`` module and a function that exists.

Plain Python: no numpy, no matplotlib.
"""
from __future__ import annotations

import importlib

#: figure key -> "module:function" of the report function that draws it.  Each function takes the result and
#: ``ax=None`` (a matplotlib Axes to draw on, a new figure when None) and returns the axes.
FIGURES = {
    "position_search": "riskrf.report.design_figures:plot_position_search",
    "catchment": "riskrf.report.design_figures:plot_catchment",
    "inventory": "riskrf.report.fit_figures:plot_inventory",
    "magnitude_frequency": "riskrf.report.fit_figures:plot_magnitude_frequency",
    "return_levels": "riskrf.report.fit_figures:plot_return_levels",
    "energy_exceedance": "riskrf.report.fit_figures:plot_energy_exceedance",
    "mass_classes": "riskrf.report.fit_figures:plot_mass_classes",
    "rainfall": "riskrf.report.rate_figures:plot_rainfall",
    "rate_counts": "riskrf.report.rate_figures:plot_rate_counts",
    "decision_tree": "riskrf.report.decision_figures:plot_tree",
    "mitigation_tornado": "riskrf.report.decision_figures:plot_study_tornado",
    "mitigation_ranking": "riskrf.report.decision_figures:plot_study_ranking",
}


def draw(key: str, result, ax=None, **kwargs):
    """Draw ``result`` with the report function registered under ``key``; returns what it returns (the axes).

    Parameters
    ----------
    key : str
        A key of :data:`FIGURES`.
    result : object
        The science result to draw.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    **kwargs
        Passed to the report function.

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    KeyError
        ``key`` is not in :data:`FIGURES` (the message lists the keys).
    """
    try:
        target = FIGURES[key]
    except KeyError:
        raise KeyError(f"no figure {key!r}; registered figures: {', '.join(sorted(FIGURES))}") from None
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)(result, ax=ax, **kwargs)


__all__ = ["FIGURES", "draw"]
