"""The axes a ``plot_x(..., ax=None)`` function draws on, shared by the figure modules of :mod:`riskrf.report`."""
from __future__ import annotations

from simulation._display import axes


def _axes(ax, figsize=(6.4, 4.8)):
    """``ax``, or the axes of a new figure of ``figsize`` [in] when ``ax`` is None (pyplot imported only then)."""
    return axes(ax, figsize)
