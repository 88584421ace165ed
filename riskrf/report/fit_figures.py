"""Figures of the fits.  Each ``plot_x(result, ax=None) -> Axes`` draws on the given axes
(or a new figure) and never changes global matplotlib state.  matplotlib is imported
only when a figure is drawn."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..frequency.extremes import _n_unknown_years, gumbel_reduced_variate, plotting_positions
from ..core.units import KG_PER_TONNE, mass_for_energy_kg
from .axes import _axes


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


def plot_energy_exceedance(hazard, ax=None, *, fences=(), level: float = 0.95, n_bootstrap: int = 200, seed=1):
    """Annual frequency of impacts above each energy at the barrier line (log-log), with the
    bootstrap band of the energy for each frequency and candidate fence capacities marked.

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    fences : sequence of float
        Fence capacities to mark [kJ].
    level : float
        Level of the band.
    n_bootstrap : int
        Replicates of the band.
    seed : int
        Seed of the band.

    Returns
    -------
    matplotlib.axes.Axes
        x: energy [kJ]; y: impacts above it per year [1/yr].
    """
    ax = _axes(ax)
    e = np.geomspace(1.0, 1e8, 200)
    lam = hazard.annual_frequency(e)
    keep = lam > 1e-7
    ax.loglog(e[keep], lam[keep], color="C0", lw=2, label="annual frequency of impacts > E")
    T = np.geomspace(max(1.01, 1.0 / hazard.arrival_rate * 1.01), 1e5, 40)
    lo, hi = hazard.energy_at_return_period_ci(T, level=level, n_bootstrap=n_bootstrap, seed=seed)
    ax.fill_betweenx(1.0 / T, lo, hi, color="C0", alpha=0.2, label=f"{level:.0%} interval of the energy")
    for i, cap in enumerate(fences):
        ax.axvline(cap, color=f"C{i + 1}", ls="--", lw=1.5, label=f"fence {cap:g} kJ (SEL {cap / 3:.0f} kJ)")
    for t in (100, 300):
        ax.axhline(1.0 / t, color="0.5", ls=":", lw=1)
        ax.annotate(f"{t} yr", (e[0] * 1.5, 1.0 / t), fontsize="small", va="bottom")
    ax.set_xlabel("impact energy E [kJ]")
    ax.set_ylabel("annual frequency λ(E > e) [1/yr]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def plot_mass_velocity(hazard, ax=None, *, energies=(100, 500, 1000, 2000, 5000, 10000), n_points: int = 3000,
                       seed=1):
    """Sampled masses and velocities of falls reaching the line, with iso-energy curves E = 1/2 m v^2.

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    energies : sequence of float
        Iso-energy curves drawn [kJ].
    n_points : int
        Falls sampled.
    seed : int
        Seed of the sample.

    Returns
    -------
    matplotlib.axes.Axes
        x: velocity at the barrier [m/s]; y: block mass [kg], log.

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, eq. 3.1.
    """
    from ..hazard.mass_models import mass_model
    ax = _axes(ax)
    rng = np.random.default_rng(seed)
    m = mass_model(hazard.mass).rvs(n_points, rng)
    v = hazard.velocity
    vs = None
    if getattr(hazard, "mass_coupled", False):     # simulated (mass, speed) pairs: speed depends on mass
        pick = rng.integers(0, v.velocity_ms.size, n_points)
        m, vs = v.arriving_mass_kg[pick], v.velocity_ms[pick]
    elif hasattr(v, "velocity_ms"):
        v = v.velocity_ms
    if vs is not None:
        pass
    elif hasattr(v, "rvs"):
        vs = np.abs(v.rvs(size=n_points, random_state=rng))
    elif hasattr(v, "dist"):
        vs = np.abs(v.dist.rvs(size=n_points, random_state=rng))
    else:
        vs = rng.choice(np.asarray(v), size=n_points)
    ax.scatter(vs, m, s=3, alpha=0.3, color="0.3", label="sampled falls")
    vv = np.linspace(max(vs.min(), 0.5), vs.max() * 1.05, 100)
    for i, e in enumerate(energies):
        ax.plot(vv, mass_for_energy_kg(e, vv), color=f"C{i % 10}", lw=1.2, label=f"{e:g} kJ")
    ax.set_yscale("log")
    ax.set_ylim(max(m.min() * 0.5, 1e-3), m.max() * 2)
    ax.set_xlabel("velocity at the barrier [m/s]")
    ax.set_ylabel("block mass [kg]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="x-small", title="E = ½ m v²", ncol=2)
    return ax


def plot_design_energy_sensitivity(table, ax=None):
    """The T-year energy [kJ] against the rate share, one line per maximum credible block m_max
    (a table from :func:`riskrf.hazard.energy_study.design_energy_sensitivity`).

    Parameters
    ----------
    table : pandas.DataFrame
        Columns ``m_max_kg`` [kg], ``rate_share`` [-] and ``energy_kj``, the T-year energy [kJ].
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax)
    for i, (m_max, g) in enumerate(table.groupby("m_max_kg")):
        g = g.sort_values("rate_share")
        label = f"m_max {m_max / KG_PER_TONNE:,.4g} t" if np.isfinite(m_max) else "no m_max"
        ax.plot(g["rate_share"], g["energy_kj"], "o-", color=f"C{i}", label=label)
    T = float(table["T_years"].iloc[0])
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("rate share of the source above the line [-]")
    ax.set_ylabel(f"{T:g}-year impact energy [kJ]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small", title="judgement inputs")
    return ax


def plot_design_energy_tornado(tornado, axes=None):
    """One tornado per design energy of a :class:`~riskrf.hazard.energy_tornado.DesignEnergyTornado` (stacked panels,
    each with its own base line and x axis in kJ), drawn by :func:`riskrf.report.decision_figures.plot_tornado`.

    Parameters
    ----------
    tornado : DesignEnergyTornado
        The tornado tables.
    axes : sequence of matplotlib.axes.Axes, optional
        One per design energy (a new figure when None).

    Returns
    -------
    list of matplotlib.axes.Axes
        One per design energy.
    """
    from .decision_figures import plot_tornado
    names = tornado.design_energies
    subs = [tornado.table[tornado.table["design_energy"] == n] for n in names]
    if axes is None:
        import matplotlib.pyplot as plt
        heights = [0.5 * len(s) + 1.1 for s in subs]
        fig, axes = plt.subplots(len(names), 1, figsize=(7.5, sum(heights) + 0.5), squeeze=False,
                                 gridspec_kw={"height_ratios": heights})
        axes = list(axes[:, 0])
        fig.suptitle("Each input at its low (blue) and high (red) value, the others at base", fontsize="medium")
    for ax, name, sub in zip(axes, names, subs):
        labels = [f"{r['input']}\n{_short(r['low'])} / {_short(r['high'])}" for _, r in sub.iterrows()]
        t = pd.DataFrame({"parameter": labels, "base": sub["energy_base_kj"].to_numpy(),
                          "value_at_low": sub["energy_low_kj"].to_numpy(),
                          "value_at_high": sub["energy_high_kj"].to_numpy()})
        plot_tornado(t, ax=ax, xlabel=f"{name} [kJ]", annotate=True)
        ax.get_legend().remove()
        ax.margins(x=0.12)
        ax.tick_params(axis="y", labelsize="small")
        ax.set_title(f"{name}: base {_short(t['base'].iloc[0])} kJ", fontsize="small")
    return axes


def _short(v) -> str:
    from .format import sig
    return sig(v, 3)


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


def plot_mass_classes(samples, ax=None):
    """Reach probability and median speed at the line by mass class of a mass-coupled simulation.

    Parameters
    ----------
    samples : MassCoupledSamples
        The simulated blocks by mass class.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None); the speed is drawn on a twin y axis.

    Returns
    -------
    matplotlib.axes.Axes
        x: block mass [kg], log; left y: P(reach the line) [-]; right y (twin): median speed [m/s].
    """
    ax = _axes(ax)
    t = samples.class_table()
    mid = np.sqrt(t["mass_low_kg"] * t["mass_high_kg"])
    ax.semilogx(mid, t["reach_probability"], "o-", color="C0", label="P(reach)")
    ax.set_xlabel("block mass [kg]")
    ax.set_ylabel("P(reach the line)", color="C0")
    twin = ax.twinx()
    twin.semilogx(mid, t["velocity_p50_ms"], "s--", color="C3")
    twin.set_ylabel("median speed at the line [m/s]", color="C3")
    return ax
