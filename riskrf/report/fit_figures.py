"""Figures of the fits.  Each ``plot_x(result, ax=None) -> Axes`` draws on the given axes
(or a new figure) and never changes global matplotlib state.  matplotlib is imported
only when a figure is drawn."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..core.units import KG_PER_TONNE, mass_for_energy_kg
from ..core.figures import _axes


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
    each with its own base line and x axis in kJ), drawn by :func:`riskrf.risk.figures.plot_tornado`.

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
    from ..risk.figures import plot_tornado
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


