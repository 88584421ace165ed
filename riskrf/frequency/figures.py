"""Figures of the frequency stage: the inventory, the magnitude-frequency fit, the Gumbel and return-level plots
and a rate model's events per year.

Each ``plot_x(result, ax=None) -> Axes`` draws on the given axes (or a new figure) and never changes global
matplotlib state; matplotlib is imported only when a figure is drawn.  The results' ``plot()`` methods call these
functions, and :mod:`riskrf.report` re-exports them.
"""
from __future__ import annotations

import numpy as np

from ..core.figures import _axes
from .empirical import _n_unknown_years, gumbel_reduced_variate, plotting_positions


def plot_magnitude_frequency(fit, ax=None, *, level_label=True):
    """Magnitude-cumulative-frequency plot on log-log axes (as in Wyllie 2014, section 8.4.1, the power law).

    Points: the observed annual frequency of falls at least as large as each
    recorded size (above 4,000 distinct sizes, 4,000 of them log-spaced in rank).  Line: the fitted law above m_min, with the band spanned by
    the confidence interval of b (rate at m_min held).  m_min is marked.

    Parameters
    ----------
    fit : GutenbergRichterFit
        A fit that keeps its data (sizes in ``fit.units``).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    level_label : bool
        Name the confidence level in the legend.

    Returns
    -------
    matplotlib.axes.Axes
        x: size [kg or m³]; y: falls of at least that size per year [1/yr].

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, section 8.4.1.
    """
    ax = _axes(ax)
    x = np.sort(np.asarray(fit.data))
    values = np.unique(x)
    counts = x.size - np.searchsorted(x, values, side="left")
    if values.size > 4000:        # large inventories: 4,000 points log-spaced in rank (markers overlap beyond)
        keep = np.unique(values.size - np.round(np.geomspace(1, values.size, 4000)).astype(int))
        values, counts = values[keep], counts[keep]
    ax.loglog(values, counts / fit.duration_years, "o", ms=3.5, mfc="none", color="0.35",
              label=f"inventory ({fit.n_total} falls, {fit.duration_years:g} yr)")
    top = fit.m_max if fit.m_max is not None else max(x.max() * 3, fit.m_min * 10)
    m = np.geomspace(fit.m_min, top * (0.999 if fit.m_max else 1), 200)
    ax.loglog(m, fit.annual_frequency(m), "-", color="C0", lw=2,
              label=f"{fit.method.upper()} fit: b = {fit.b:.3f} ± {fit.b_stderr:.3f}")
    lo, hi = fit.b_ci
    band = [fit.rate_min * (m / fit.m_min) ** (-b) for b in (lo, hi)]
    ax.fill_between(m, np.minimum(*band), np.maximum(*band), color="C0", alpha=0.2,
                    label=f"{fit.level:.0%} interval of b" if level_label else None)
    ax.axvline(fit.m_min, color="C3", ls="--", lw=1, label=f"m_min = {fit.m_min:.4g} {fit.units}")
    ax.set_xlabel(f"size m [{fit.units}]")
    ax.set_ylabel("annual frequency N(≥ m) [1/yr]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def plot_gumbel(fit, ax=None, *, formula: str = "gringorten", level: float = 0.95, units: str = "kg"):
    """Gumbel probability plot: annual maxima against the reduced variate -ln(-ln F).

    Empirical non-exceedance probabilities use ``formula`` plotting positions
    over all years (years without a fall sit below every maximum, as in the
    mixed model).  The fitted line and its delta-method band follow.

    Parameters
    ----------
    fit : GumbelFit
        The fit.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    formula : str
        Plotting-position formula (:func:`riskrf.plotting_positions`).
    level : float
        Level of the band.
    units : str
        Unit of the maxima, for the axis.

    Returns
    -------
    matplotlib.axes.Axes
        x: Gumbel reduced variate [-]; y: annual maximum [``units``].

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, section 8.4.2.
    Gringorten, I. I. (1963). A plotting rule for extreme probability paper. Journal of Geophysical Research
    68(3), 813-814.
    """
    ax = _axes(ax)
    x = np.sort(fit.data)
    n_years = fit.n_years
    F = plotting_positions(n_years, formula)[n_years - x.size:]
    ax.plot(-np.log(-np.log(F)), x, "o", ms=4, mfc="none", color="0.3", label=f"annual maxima ({formula})")
    T = np.geomspace(1.05 / (1 - fit.p_zero), 1000, 100)
    y = gumbel_reduced_variate(T)
    ax.plot(y, fit.return_level(T), "-", color="C0", lw=2, label=f"{type(fit).__name__[:-3]} ({fit.method})")
    try:
        lo, hi = fit.return_level_ci(T, level=level, method="delta")
        ax.fill_between(y, lo, hi, color="C0", alpha=0.2, label=f"{level:.0%} delta-method band")
    except ValueError:
        pass
    ax.set_xlabel("Gumbel reduced variate y = -ln(-ln F)")
    ax.set_ylabel(f"annual maximum [{units}]")
    top = ax.secondary_xaxis("top", functions=(lambda v: v, lambda v: v))
    ticks = np.array([2, 5, 10, 50, 100, 500, 1000])
    top.set_xticks(gumbel_reduced_variate(ticks), [str(t) for t in ticks])
    top.set_xlabel("return period [yr]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def plot_return_levels(fits, ax=None, *, power_law=None, maxima=None, formula: str = "gringorten",
                       level: float = 0.95, units: str = "kg", T_max: float = 1000.0, ci_method: str | None = None):
    """Return level against return period for one or more annual-maximum fits.

    ``fits`` is a fit or a dict ``{label: fit}``.  With ``power_law`` (a
    :class:`~riskrf.GutenbergRichterFit`) the annual-maximum law it implies,
    exp(-N(>=m)) (Frechet when untruncated), is drawn too, so the two models of
    Wyllie's chapter 8 can be compared.  ``maxima`` adds the empirical points.
    The bands are ``level`` intervals by ``ci_method`` (default: each fit's
    ``default_ci_method``, the method of ``design_masses.csv``: profile
    likelihood for maximum-likelihood fits); a lower end at or below zero is
    drawn at the bottom of the axis (a mass is never negative) and an upper end
    the data do not bound (inf) is left open.

    Parameters
    ----------
    fits : GumbelFit, GEVFit or dict
        A fit or ``{label: fit}``.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    power_law : GutenbergRichterFit, optional
        Also draw its annual-maximum law.
    maxima : array_like, optional
        Annual maxima to draw as points [``units``].
    formula : str
        Plotting-position formula.
    level : float
        Level of the bands.
    units : str
        Unit of the maxima.
    T_max : float
        Longest return period drawn [yr].
    ci_method : str, optional
        Interval method (``"profile"``, ``"delta"``, ``"bootstrap"``).

    Returns
    -------
    matplotlib.axes.Axes
        x: return period [yr], log; y: annual maximum [``units``].
    """
    ax = _axes(ax)
    if not isinstance(fits, dict):
        fits = {type(fits).__name__[:-3]: fits}
    methods, bands = [], []
    for i, (label, fit) in enumerate(fits.items()):
        T = np.geomspace(1.05 / (1 - fit.p_zero), T_max, 120)
        ax.semilogx(T, fit.return_level(T), "-", color=f"C{i}", lw=2, label=label)
        how = ci_method or fit.default_ci_method
        Tb = np.geomspace(T[0], T_max, 16)         # the profile interval costs ~10-20 ms per return period
        try:
            lo, hi = fit.return_level_ci(Tb, level=level, method=how)
        except ValueError:
            continue
        methods.append(how)
        bands.append((Tb, np.asarray(lo, dtype=float), np.where(np.isfinite(hi), hi, np.nan), f"C{i}"))
    positive = [lo[lo > 0].min() for _, lo, _, _ in bands if np.any(lo > 0)]
    floor = 0.5 * min(positive) if positive else np.nan
    for Tb, lo, hi, color in bands:
        lo = np.where(lo > 0, lo, floor)               # a mass is never negative: the band stops at the axis
        ax.fill_between(Tb, lo, hi, color=color, alpha=0.15)
    if power_law is not None:
        T0 = 1.0 / (-np.expm1(-power_law.rate_min))
        T = np.geomspace(max(1.05, T0 * 1.001), T_max, 120)
        ax.semilogx(T, power_law.annual_max_return_level(T), "--", color="k", lw=1.5,
                    label=f"implied by power law (b = {power_law.b:.2f})")
    if maxima is not None:
        values = np.asarray(maxima, dtype=float)
        n = values.size + _n_unknown_years(maxima)
        x = np.sort(values[~np.isnan(values)])
        F = plotting_positions(n, formula)[n - x.size:]
        ax.semilogx(1 / (1 - F), x, "o", ms=4, mfc="none", color="0.3", label=f"annual maxima ({formula})")
    ax.set_xlabel("return period T [yr]")
    ax.set_ylabel(f"return level [{units}]")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    names = {"profile": "profile likelihood", "delta": "delta method", "bootstrap": "parametric bootstrap"}
    ax.legend(fontsize="small", title=(f"bands: {level:.0%} " + ", ".join(names[m] for m in dict.fromkeys(methods))
                                       + " intervals") if methods else None)
    return ax


def plot_inventory(inventory, ax=None):
    """Empirical magnitude-frequency curve of an inventory: falls of at least m per year against m, log-log.

    Parameters
    ----------
    inventory : Inventory
        The record (masses [kg], duration [yr]).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
        x: mass m [kg]; y: N(>=m), the recorded falls of at least m divided by the record's length [1/yr].
    """
    from pathlib import Path
    ax = _axes(ax)
    m = np.sort(inventory.masses)[::-1]
    ax.loglog(m, np.arange(1, m.size + 1) / inventory.duration_years, ".", ms=4, color="0.3",
              label=f"{Path(str(inventory.source)).name} ({m.size} falls, {inventory.duration_years:.3g} yr)")
    ax.set_xlabel("mass m [kg]")
    ax.set_ylabel("falls of at least m per year N(>=m) [1/yr]")
    ax.legend(fontsize="small")
    return ax


def plot_rate_counts(model, ax=None):
    """Events per calendar year: recorded (bars) and expected by the preferred model (line).

    Parameters
    ----------
    model : RateModel
        The fitted rate model.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
        x: year; y: events per year.
    """
    import numpy as np
    import pandas as pd

    from ..core.figures import _axes
    ax = _axes(ax)
    year = pd.to_datetime(model.design["period_start"]).dt.year.to_numpy()
    observed = pd.Series(model.design["count"].to_numpy(), index=year).groupby(level=0).sum()
    ax.bar(observed.index, observed.to_numpy(), color="0.75", label="recorded")
    expected = pd.Series(np.asarray(model.fitted(), dtype=float), index=year).groupby(level=0).sum()
    ax.plot(expected.index, expected.to_numpy(), "o-", ms=3, color="C3", label=f"expected ({model.preferred})")
    ax.set_xlabel("year")
    ax.set_ylabel("events per year")
    ax.legend(fontsize="small")
    return ax
