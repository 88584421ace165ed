"""Figures of the input records: daily rainfall.

``plot_rainfall(record, ax=None) -> Axes`` draws on the given axes (or a new figure) and never changes global
matplotlib state; matplotlib is imported only when a figure is drawn.  :meth:`riskrf.io.rainfall.RainfallRecord.plot`
calls it.
"""
from __future__ import annotations

from pathlib import Path


def plot_rainfall(rainfall, ax=None):
    """Daily rainfall against date (missing days left blank).

    Parameters
    ----------
    rainfall : Rainfall
        The daily record [mm].
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
        x: date; y: daily rainfall [mm].
    """
    from ..core.figures import _axes
    ax = _axes(ax, figsize=(9.0, 3.5))
    ax.plot(rainfall.daily.index, rainfall.daily.to_numpy(), lw=0.5, color="C0")
    ax.set_xlabel("date")
    ax.set_ylabel("daily rainfall [mm]")
    ax.set_title(Path(str(rainfall.source)).name, fontsize="small")
    return ax
