"""Empirical probabilities of ordered data: plotting positions and the Gumbel reduced variate.

What an annual-maxima series is plotted against (Gringorten 1963; Wyllie 2014, section 8.4.2), used by the
extreme-value fits of :mod:`riskrf.frequency.extremes` and by the return-level figures of
:mod:`riskrf.frequency.figures`.
"""
from __future__ import annotations

import numpy as np

from ..core.validation import check_choice, check_return_periods


#: Plotting-position constants ``a`` of ``(i - a) / (n + 1 - 2a)`` for ascending rank i.
PLOTTING_POSITIONS = {"weibull": 0.0, "gringorten": 0.44, "cunnane": 0.4, "hazen": 0.5, "blom": 0.375}


def plotting_positions(n: int, formula: str = "gringorten") -> np.ndarray:
    """Non-exceedance probabilities of the ascending order statistics 1..n.

    ``(i - a) / (n + 1 - 2a)`` with a = 0 (Weibull, i/(n+1)), 0.44 (Gringorten,
    recommended for Gumbel), 0.4 (Cunnane), 0.5 (Hazen, (i-0.5)/n) or 0.375 (Blom).

    Parameters
    ----------
    n : int
        Number of ordered values (years), >= 1.
    formula : str
        ``"gringorten"`` (default), ``"weibull"``, ``"cunnane"``, ``"hazen"`` or ``"blom"``.

    Returns
    -------
    numpy.ndarray
        n non-exceedance probabilities [-], increasing.

    References
    ----------
    Gringorten, I. I. (1963). A plotting rule for extreme probability paper. Journal of Geophysical Research
    68(3), 813-814.
    """
    check_choice(formula, "formula", tuple(PLOTTING_POSITIONS))
    if int(n) < 1:
        raise ValueError(f"n must be >= 1; got {n}")
    a = PLOTTING_POSITIONS[formula]
    i = np.arange(1, int(n) + 1)
    return (i - a) / (n + 1 - 2 * a)


def gumbel_reduced_variate(T):
    """y_T = -ln(-ln(1 - 1/T)): the Gumbel reduced variate of return period T [yr].

    Parameters
    ----------
    T : float or array_like
        Return period [yr], > 1.

    Returns
    -------
    numpy.ndarray
        Reduced variate y_T [-].

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, section 8.4.2.
    """
    T = check_return_periods(T)
    return -np.log(-np.log1p(-1.0 / T))


def _n_unknown_years(maxima) -> int:
    """Years left out of an annual-maxima series because their falls have no exact size (see Inventory.annual_maxima)."""
    return len(getattr(maxima, "attrs", {}).get("years_without_exact_size", ()))
