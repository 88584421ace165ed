"""Figure of the road-user risk validation: predicted vs recorded consequences per fall reaching a road."""
from __future__ import annotations

import numpy as np

from ..core.figures import _axes


def plot_road_validation(validation, ax=None):
    """Per fall reaching a road, on a log axis: the prediction's 5-95 % range and mean (bar and dot) and the
    record's exact 95 % Poisson interval and rate (line and square), for vehicles involved, deaths, injuries.

    Parameters
    ----------
    validation : object
        A road-risk validation with ``summary()`` (:mod:`riskrf.risk.road_validation`).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on.

    Returns
    -------
    matplotlib.axes.Axes
        x: consequences per fall reaching a road (log); y: the consequence.
    """
    ax = _axes(ax)
    s = validation.summary()
    y = np.arange(len(s))
    for i, (name, r) in enumerate(s.iterrows()):
        ax.plot([r["predicted_p05"], r["predicted_p95"]], [i + 0.12] * 2, color="tab:blue", lw=6, alpha=0.5,
                solid_capstyle="butt", label="predicted 5-95 %" if i == 0 else None)
        ax.plot(r["predicted_per_fall"], i + 0.12, "o", color="tab:blue", label="predicted mean" if i == 0 else None)
        ax.plot([max(r["recorded_low_95"], 1e-6), r["recorded_high_95"]], [i - 0.12] * 2, color="black", lw=1.5,
                label="recorded, 95 % Poisson" if i == 0 else None)
        ax.plot(r["recorded_per_fall"], i - 0.12, "s", color="black", label="recorded" if i == 0 else None)
    ax.set_xscale("log")
    ax.set_yticks(y)
    ax.set_yticklabels(list(s.index))
    ax.set_xlabel("per fall reaching a road")
    rec = validation.records
    ax.set_title(f"Hong Kong CEDD/GEO register: {rec.falls} falls\nreaching a road in {rec.years} years", fontsize=10)
    ax.set_ylim(-0.6, len(s) - 0.4 + 0.9)
    ax.legend(loc="upper left", fontsize=8, ncol=2)
    return ax
