"""The axes a ``plot_x(result, ax=None)`` function draws on, shared by every figure module.

Each stage draws its own results: ``riskrf.frequency.figures``, ``riskrf.io.figures``, ``riskrf.hazard.figures``
and ``riskrf.risk.figures`` hold the drawing functions of that stage's results, and each result's ``plot()``
method calls its function (imported inside the method, so that the stage loads without matplotlib).  The
stages import one way only (``core < io < frequency < hazard < risk < report < app``; checked by
tests/test_architecture.py); :mod:`riskrf.report` draws the documents' figures and re-exports the stages'
plotting functions.
"""
from __future__ import annotations

from simulation._display import axes


def _axes(ax, figsize=(6.4, 4.8)):
    """``ax``, or the axes of a new figure of ``figsize`` [in] when ``ax`` is None (pyplot imported only then)."""
    return axes(ax, figsize)


__all__ = ["_axes"]
