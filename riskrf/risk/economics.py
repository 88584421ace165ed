"""Discounting for cost comparisons over a horizon (Wyllie 2014, 8.5.5; any engineering-economics text).

Money is a plain number with a currency label; rates are per year as fractions (0.03 = 3 %).
Every function accepts a discount rate array so that uncertainty samples are evaluated at once.
"""
from __future__ import annotations

import numpy as np

from ..core.validation import check_positive


def pv_factor(rate, years):
    """Uniform-series present-value factor (1 - (1 + r)^-n) / r; n when r = 0.

    e.g. 18.256 for 5 % over 50 years, 25.730 for 3 % over 50 years (domain-methods.md section 5).
    ``rate`` may be an array (one factor per rate).

    Parameters
    ----------
    rate : float or array_like
        Discount rate [1/yr] as a fraction (0.03 = 3 %), in [0, 1).
    years : float
        Horizon n [yr], > 0.

    Returns
    -------
    float or numpy.ndarray
        Present value of 1 a year for n years [yr], one per rate.

    Raises
    ------
    ValueError
        When a rate lies outside [0, 1).

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, section 8.5.5.
    """
    r = np.asarray(rate, dtype=float)
    n = check_positive(years, "years")
    if np.any(r < 0) or np.any(r >= 1):
        raise ValueError(f"discount rate must lie in [0, 1); got {rate!r}")
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(r == 0, n, -np.expm1(-n * np.log1p(r)) / np.where(r == 0, 1.0, r))
    return float(f) if f.ndim == 0 else f


def renewal_factor(life_years, horizon_years, rate):
    """Present value of re-building every ``life_years`` within the horizon per unit of first cost.

    sum over k = 1, 2, ... with k L < horizon of (1 + r)^-(k L) (the first build excluded).

    Parameters
    ----------
    life_years : float
        Life L of the structure [yr], > 0.
    horizon_years : float
        Horizon [yr].
    rate : float or array_like
        Discount rate [1/yr] as a fraction (0.03 = 3 %), in [0, 1).

    Returns
    -------
    float or numpy.ndarray
        Present value of the renewals per unit of first cost [-], one per rate.

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, section 8.5.5.
    """
    life = check_positive(life_years, "life_years")
    k = np.arange(1, int(np.floor((float(horizon_years) - 1e-9) / life)) + 1)
    r = np.asarray(rate, dtype=float)
    f = np.sum((1.0 + r[..., None]) ** -(k * life), axis=-1)
    return float(f) if np.ndim(f) == 0 else f


def pv_of_renewals(cost, life_years, horizon_years, rate):
    """Present value of re-building every ``life_years`` within the horizon (the first build excluded).

    Parameters
    ----------
    cost : float
        Cost of one build [currency], e.g. [CHF].
    life_years : float
        Life L of the structure [yr], > 0.
    horizon_years : float
        Horizon [yr].
    rate : float
        Discount rate [1/yr] as a fraction.

    Returns
    -------
    float
        Present value of the renewals [currency].
    """
    return float(cost * renewal_factor(life_years, horizon_years, float(rate)))


__all__ = ["pv_factor", "pv_of_renewals", "renewal_factor"]
