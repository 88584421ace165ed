"""Figures of the decision analysis: tree diagram, tornado chart, risk profiles, F-N curve."""
from __future__ import annotations

import numpy as np

from ..risk.road_risk import HK_GEO_FN_LINES, HK_GEO_N_CUTOFF, HK_GEO_N_LIMIT, HK_GEO_SCRUTINY_F_MIN
from ..core.figures import _axes


def plot_risk_profiles(profile, ax=None):
    """Cumulative risk profiles (outcome distributions) of the options, from ``DecisionTree.risk_profile()``.

    Parameters
    ----------
    profile : pandas.DataFrame
        Columns ``option``, ``value``, cumulative probability.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax)
    for i, (name, g) in enumerate(profile.groupby("option", sort=False)):
        x = np.concatenate([[g["value"].min()], g["value"].to_numpy()])
        y = np.concatenate([[0.0], g["cumulative"].to_numpy()])
        ax.step(x, y, where="post", color=f"C{i % 10}", label=name)
    ax.set_xlabel("outcome (net cost or value)")
    ax.set_ylabel("cumulative probability")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small")
    return ax


def plot_fn(curves: dict, ax=None, *, criteria: dict | None = None):
    """F-N curves ``{label: DataFrame(N, F)}`` on the Hong Kong GEO diagram (GEO Report 75, ERM-Hong Kong 1998):
    lines F = C / N^k up to N = 1,000, the "intense scrutiny" band for N = 1,000-5,000 and the
    unacceptable region beyond.

    Parameters
    ----------
    curves : dict
        Label → DataFrame with ``N`` (fatalities) and ``F`` (frequency of N or more per year [1/yr]).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    criteria : dict, optional
        Name → (C, k) of the lines F = C / N^k [1/yr], with an ``"unacceptable above"`` entry (default: the GEO
        lines, ``HK_GEO_FN_LINES``).

    Returns
    -------
    matplotlib.axes.Axes

    References
    ----------
    ERM-Hong Kong (1998). Landslides and Boulder Falls from Natural Terrain: Interim Risk Guidelines. GEO Report
    No. 75, Geotechnical Engineering Office, Hong Kong.
    """
    ax = _axes(ax)
    criteria = HK_GEO_FN_LINES if criteria is None else criteria
    for i, (label, df) in enumerate(curves.items()):
        if len(df) and np.any(df["F"] > 0):
            d = df[df["F"] > 0]
            ax.step(d["N"], d["F"], where="post", color=f"C{i % 10}", lw=2, label=label, marker="o", ms=3)
    N = np.geomspace(1, HK_GEO_N_CUTOFF, 50)
    for j, (name, (C, k)) in enumerate(criteria.items()):
        ax.plot(N, C / N ** k, color="k", ls=["--", ":"][j % 2], lw=1, label=f"GEO 1998: {name}")
    c_hi, k_hi = criteria["unacceptable above"]
    top = c_hi / HK_GEO_N_CUTOFF ** k_hi
    ax.plot([HK_GEO_N_CUTOFF, HK_GEO_N_CUTOFF], [HK_GEO_SCRUTINY_F_MIN, top], color="k", lw=1)
    ax.fill_between([HK_GEO_N_CUTOFF, HK_GEO_N_LIMIT], HK_GEO_SCRUTINY_F_MIN, top, color="0.85",
                    label="intense scrutiny (N 1,000-5,000)")
    ax.axvline(HK_GEO_N_LIMIT, color="k", lw=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(0.8, 1e4)
    ax.set_ylim(HK_GEO_SCRUTINY_F_MIN / 10, 1.0)
    ax.set_xlabel("number of fatalities N")
    ax.set_ylabel("annual frequency of N or more fatalities F [1/yr]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="x-small")
    return ax
