"""Figures of the hazard stage: the annual energy exceedance at a line, reach and speed by mass class, the
barrier-position search and a ditch's retention beside a catchment chart.

Each ``plot_x(result, ax=None) -> Axes`` draws what the hazard modules computed (nothing here computes a design
value) on the given axes (or a new figure) and never changes global matplotlib state; matplotlib is imported only
when a figure is drawn.  The results' ``plot()`` methods call these functions.
"""
from __future__ import annotations

import numpy as np

from ..core.figures import _axes


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


def plot_position_search(search, ax=None):
    """Required MEL [kJ] and product class at each searched barrier position, with the required net height [m] on
    a second y axis; with ``ax=None`` a new two-panel figure also shows the slope profile and the positions above.

    Parameters
    ----------
    search : PositionSearch
        A :class:`~riskrf.hazard.design_requirement.PositionSearch` (its ``table``: position [m], required MEL [kJ],
        height [m]).
    ax : matplotlib.axes.Axes, optional
        Axes of the requirement panel (a new two-panel figure when None).

    Returns
    -------
    matplotlib.axes.Axes
        The requirement panel (its figure: ``ax.figure``).
    """
    import matplotlib.pyplot as plt
    t = search.table
    if ax is None:
        _, (a0, a1) = plt.subplots(2, 1, figsize=(9, 7), sharex=True, gridspec_kw={"height_ratios": [1, 1.2]})
        px, pz = search.profile
        a0.fill_between(px, pz, np.min(pz) - 5.0, color="0.88")
        a0.plot(px, pz, color="0.2")
        a0.plot(t["x_m"], t["ground_z_m"], "v", color="tab:red", label="searched positions")
        if search.road_x_m is not None:
            a0.axvline(search.road_x_m, color="k", ls=":", label="road line")
        a0.set_ylabel("elevation z [m]")
        a0.legend(fontsize=8)
        a0.set_title(f"Barrier position search ({search.basis.basis} governs; {search.n:,} blocks simulated)",
                     fontsize=10)
    else:
        a1 = ax
        a1.set_title(f"Barrier position search ({search.basis.basis} governs)", fontsize=10)
    mel = t["required_mel_kj"].to_numpy(dtype=float)
    cls = t["required_class_kj"].to_numpy(dtype=float)
    a1.semilogy(t["x_m"], mel, "o-", color="tab:red", label="required MEL [kJ]")
    ok = np.isfinite(cls)
    a1.semilogy(t["x_m"][ok], cls[ok], "s", color="tab:red", mfc="none", ms=10, label="product class [kJ]")
    top = max(search.basis.mel_classes_kj)
    a1.axhline(top, color="tab:red", ls=":", lw=1, label=f"largest product class {top:,.0f} kJ")
    a1.set_ylabel("energy [kJ]")
    a1.set_xlabel("barrier position x [m]")
    b = a1.twinx()
    b.plot(t["x_m"], t["required_net_height_m"], "^--", color="tab:blue", label="required net height [m]")
    b.set_ylabel("required net height [m]", color="tab:blue")
    h1, l1 = a1.get_legend_handles_labels()
    h2, l2 = b.get_legend_handles_labels()
    a1.legend(h1 + h2, l1 + l2, fontsize=8, loc="upper right")
    return a1


def plot_catchment(study, ax=None):
    """Retention against catchment width from the re-simulation, with the widths for 90/95/99 %, the Modified
    Ritchie Criterion width and the chart values beside it (when given).

    Parameters
    ----------
    study : CatchmentStudy
        A :class:`~riskrf.hazard.catchment.CatchmentStudy` (its ``curve``: ``width_m`` [m], ``retained`` [-]).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax, figsize=(7, 4.5))
    ax.plot(study.curve["width_m"], 100 * study.curve["retained"], color="k",
            label=f"re-simulated ({study.blocks_counted:,} blocks over the face)")
    for q, w in study.widths.items():
        ax.axhline(q, color="0.7", lw=0.8)
        if np.isfinite(w):
            ax.plot([w], [q], "o", color="tab:blue")
            ax.annotate(f"{w:.1f} m", (w, q), textcoords="offset points", xytext=(4, -12), fontsize=8)
    w_mrc = study.ritchie_width_m
    ax.axvline(w_mrc, color="tab:green", ls="--",
               label=f"Modified Ritchie Criterion 0.2 H + 4.5 m = {w_mrc:.1f} m")
    if study.chart is not None and len(study.chart):
        ax.plot(study.chart["width_m"], study.chart["retained_percent"], "s", color="tab:red",
                label=f"chart: {study.chart_source}")
    ax.set_xlabel("catchment width from the toe [m]")
    ax.set_ylabel("blocks retained [%]")
    ax.set_ylim(0, 101)
    ax.set_title(study.title, fontsize=10)
    ax.legend(fontsize=8)
    return ax


def plot_design_energy_split(split, T=None, ax=None):
    """Each draw's T-year energy with its bootstrap interval (points and bars), the combined interval
    (band) and the reference value (line).

    Parameters
    ----------
    split : DesignEnergySplit
        The result drawn.
    T : float, optional
        Return period [yr]; None for the largest return period defined in every draw.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ok = split.table[split.table["variance_total_kj2"] > 0]
    T = float(ok["T_years"].max() if T is None else T)
    r = split.row(T)
    d = split.per_draw[np.isclose(split.per_draw["T_years"], T)]
    ax = _axes(ax, figsize=(6.5, 3.6))
    x = np.arange(len(d))
    ax.axhspan(r["combined_low_kj"], r["combined_high_kj"], color="0.85",
               label=f"combined {split.level:.0%} interval ({r['share_from_trajectory_model']:.0%} of its "
                     "variance: trajectory model)")
    ax.errorbar(x, d["energy_kj"], yerr=[d["energy_kj"] - d["ci_low_kj"], d["ci_high_kj"] - d["energy_kj"]],
                fmt="o", color="C0", capsize=3, label="draw: point estimate and bootstrap interval")
    if np.isfinite(r["energy_kj_reference"]):
        ax.axhline(r["energy_kj_reference"], color="C3", lw=1, label="scenario's own values")
    ax.set_xticks(x)
    ax.set_xlabel("draw of the material parameters")
    ax.set_ylabel(f"{T:g}-year energy [kJ]")
    ax.legend(fontsize="small", loc="best")
    return ax
