"""Figures of a simulation: profile with trajectories, collector distributions, envelopes, pooled calibration.

Each function draws on ``ax`` (or a new figure) and returns the Axes; matplotlib
is imported only when called and no global style is changed.
"""
from __future__ import annotations

import numpy as np

from ._display import axes


def _axes(ax, figsize=(8, 4.5)):
    return axes(ax, figsize)


def plot_profile(result, ax=None, *, n_paths: int = 20, fences=()):
    """Slope profile coloured by material, collectors and barriers, and recorded trajectories.

    ``result`` is a :class:`~simulation.SimulationResult` or a :class:`~simulation.Scenario` (then no
    trajectories are drawn).

    ``fences``: (x [m], height [m], label) of fences to draw at their height (e.g. a study's fence options
    at the barrier line), each a vertical bar from the ground to ground + height.  The legend stands
    outside the axes, so it hides no part of the slope or a label.

    Parameters
    ----------
    result : SimulationResult or Scenario
        The run (or scenario) to draw.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    n_paths : int, optional
        Number of recorded trajectories to draw.
    fences : sequence of (float, float, str), optional
        Fences to draw: (x [m], height [m], label).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.
    """
    ax = _axes(ax)
    sc = getattr(result, "scenario", result)
    paths = getattr(result, "paths", None)
    prof = sc.profile
    for i, name in enumerate(prof.material_names):
        segs = np.flatnonzero(prof.material_index == i)
        for j, s in enumerate(segs):
            ax.plot(prof.x[s:s + 2], prof.z[s:s + 2], color=f"C{i}", lw=3, label=name if j == 0 else None)
    blocks = np.unique(paths["block"])[:n_paths] if paths is not None else []
    for b in blocks:
        p = result.path(int(b))
        ax.plot(p["x_m"], p["z_m"], color="0.4", lw=0.6, alpha=0.7)
    zmin, zmax = prof.z.min(), prof.z.max()
    for c in sc.collectors:
        zg = float(prof.ground(c.x))
        if c.is_barrier:
            ax.plot([c.x, c.x], [zg, zg + c.height_m], color="C3", lw=3)
            ax.annotate(f"{c.name}\n{c.capacity_kj:g} kJ, {c.height_m:g} m", (c.x, zg + c.height_m),
                        fontsize="small", ha="center", va="bottom")
        else:
            ax.axvline(c.x, color="C3", ls=":", lw=1)
            ax.annotate(c.name, (c.x, zmax), fontsize="small", ha="left", va="top", rotation=90)
    styles = ("-", "--", "-.", ":")
    for i, (x, h, label) in enumerate(sorted(fences, key=lambda f: -float(f[1]))):   # tallest behind
        zg = float(prof.ground(x))
        ax.plot([x, x], [zg, zg + float(h)], color=f"C{(i + 4) % 10}", lw=4 - 0.8 * min(i, 3),
                ls=styles[i % len(styles)], solid_capstyle="butt", label=label, zorder=3 + i)
    sd = sc.seeder
    ax.axvspan(sd.x_low, max(sd.x_high, sd.x_low + 0.2), color="C1", alpha=0.2, label="release")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_ylim(zmin - 0.05 * (zmax - zmin + 1), None)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax.set_title(sc.name if result is sc else f"{sc.name}: {len(blocks)} of {result.n:,} trajectories")
    return ax


def plot_collector_distributions(result, name: str, axes=None):
    """Histograms and exceedance curves of speed, height and energy at collector ``name`` (2 x 3 axes).

    Parameters
    ----------
    result : SimulationResult
        The run.
    name : str
        Name of the collector.
    axes : numpy.ndarray of matplotlib.axes.Axes, optional
        2 x 3 axes to draw on (a new figure when None).

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
        The 2 x 3 axes: speed [m/s], height [m] and energy [kJ].
    """
    import matplotlib.pyplot as plt
    df = result.collector(name, first_only=True)
    if axes is None:
        fig, axes = plt.subplots(2, 3, figsize=(12, 6.5))
        fig.subplots_adjust(wspace=0.3, hspace=0.38)     # room for the labels without a layout pass
    cols = (("velocity_ms", "speed [m/s]"), ("height_m", "height above slope [m]"), ("energy_kj", "energy [kJ]"))
    for j, (col, label) in enumerate(cols):
        x = np.sort(df[col].to_numpy())
        top, bottom = axes[0][j], axes[1][j]
        if x.size == 0:
            top.set_title(f"{name}: no block reached")
            continue
        log = col == "energy_kj" and x.max() > 100 * max(np.percentile(x, 5), 1e-6)
        bins = np.geomspace(max(x.min(), 1e-3), x.max() * 1.001, 40) if log else 40
        top.hist(x, bins=bins, color="C0", alpha=0.8, histtype="stepfilled")   # one artist, not 40 bars
        if log:
            top.set_xscale("log")
        top.set_xlabel(label)
        top.set_ylabel("blocks")
        # The exceedance curve at every block up to 2,000, else at 2,000 points spaced evenly in rank and
        # in log-probability (the tail keeps its resolution; drawing 50,000 steps took 15 s for nothing).
        idx = np.arange(x.size)
        if x.size > 2000:
            idx = np.unique(np.concatenate([np.linspace(0, x.size - 1, 1000),
                                            x.size - np.geomspace(1, x.size, 1000)]).astype(int))
        p = 1.0 - idx / x.size
        xs = x[idx]
        bottom.step(xs, p, where="post", color="C0")
        lo = np.clip(p - 1.96 * np.sqrt(p * (1 - p) / x.size), 1 / x.size / 10, 1)
        hi = np.clip(p + 1.96 * np.sqrt(p * (1 - p) / x.size), 0, 1)
        bottom.fill_between(xs, lo, hi, step="post", color="C0", alpha=0.2, label="95% Monte Carlo band")
        bottom.set_yscale("log")
        if log:
            bottom.set_xscale("log")
        for q in (95, 99):
            v = np.percentile(x, q)
            bottom.axvline(v, color="C3", ls=":", lw=1)
            bottom.annotate(f"p{q} {v:,.0f}" if abs(v) >= 100 else f"p{q} {v:.3g}", (v, 0.5), rotation=90,
                            fontsize="x-small", va="center")
        bottom.set_xlabel(label)
        bottom.set_ylabel("P(exceeded | reaches)")
        bottom.grid(True, which="both", alpha=0.3)
    axes[0][0].set_title(f"{name}: {len(df):,} blocks reached ({len(df) / result.n:.1%})", loc="left")
    axes[1][0].legend(fontsize="x-small")
    return axes


def plot_envelopes(result, axes=None):
    """Maximum and mean speed, bounce height and energy along the slope (3 stacked axes).

    Parameters
    ----------
    result : SimulationResult
        The run.
    axes : sequence of matplotlib.axes.Axes, optional
        3 axes to draw on (a new figure when None).

    Returns
    -------
    sequence of matplotlib.axes.Axes
        The 3 axes: speed [m/s], bounce height [m] and energy [kJ] against x [m].
    """
    import matplotlib.pyplot as plt
    env = result.envelopes
    if axes is None:
        fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for ax, (col, label) in zip(axes, (("velocity", "speed [m/s]"), ("height", "height [m]"),
                                       ("energy", "energy [kJ]"))):
        unit = {"velocity": "ms", "height": "m", "energy": "kj"}[col]
        ax.plot(env["x_m"], env[f"{col}_max_{unit}"], color="C3", label="maximum")
        ax.plot(env["x_m"], env[f"{col}_mean_{unit}"], color="C0", label="mean")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    for c in result.scenario.collectors:
        for ax in axes:
            ax.axvline(c.x, color="0.5", ls=":", lw=1)
    axes[0].legend(fontsize="small")
    axes[-1].set_xlabel("x [m]")
    axes[0].set_title("Envelopes along the slope")
    return axes


def plot_posterior_pairs(calibration, ax=None, fig=None):
    """Pairwise scatter of a pooled posterior sample: histograms against the prior box on the diagonal,
    scatter below, Pearson correlations above.

    Parameters
    ----------
    calibration : PooledCalibration
        The calibration (:func:`simulation.pooled.calibrate_pooled`).
    ax : matplotlib.axes.Axes, optional
        Axes for a single parameter's histogram (more parameters need a figure of their own).
    fig : matplotlib.figure.Figure, optional
        Figure to draw the panels in (a new one when None).

    Returns
    -------
    matplotlib.axes.Axes
        The lower-left panel; its ``figure`` holds every panel.

    Raises
    ------
    ValueError
        ``ax`` given for more than one parameter.
    """
    names = list(calibration.posterior.columns)
    d = len(names)
    if ax is not None and d > 1:
        raise ValueError(f"plot_posterior_pairs: {d} parameters need a figure of their own (pass fig=, not ax=)")
    if ax is not None:
        grid = [[ax]]
    else:
        if fig is None:
            import matplotlib.pyplot as plt
            fig = plt.figure(figsize=(2.6 * d + 1, 2.6 * d + 0.5))
        grid = fig.subplots(d, d, squeeze=False)
    post, bounds = calibration.posterior, calibration.bounds
    corr = calibration.correlations() if d > 1 else None
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            panel = grid[i][j]
            if i == j:
                panel.hist(post[a], bins=30, color="C0")
                panel.set_xlim(*bounds[a])
            elif i > j:
                panel.plot(post[b], post[a], ".", ms=2, alpha=0.4)
                panel.set_xlim(*bounds[b])
                panel.set_ylim(*bounds[a])
            else:
                panel.axis("off")
                panel.text(0.5, 0.5, f"r = {corr.loc[a, b]:.2f}", ha="center", va="center",
                           transform=panel.transAxes)
            if i == d - 1:
                panel.set_xlabel(b.split(".", 1)[-1], fontsize="small")
            if j == 0 and i > 0:
                panel.set_ylabel(a.split(".", 1)[-1], fontsize="small")
    grid[0][0].figure.suptitle(f"pooled posterior ({len(calibration.releases)} releases, ESS {calibration.ess:.0f})",
                               fontsize="small")
    return grid[d - 1][0]


def plot_pooled_coverage(calibration, ax=None):
    """Per release of a pooled calibration: the central 90 % (thick) and 99 % (thin) posterior-predictive
    intervals of the stops and the observed stops (points), with the share of stops inside each interval.

    Parameters
    ----------
    calibration : PooledCalibration
        The calibration; its ``coverage_table`` must have rows (``n_predictive`` > 0).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    ValueError
        The calibration has no posterior-predictive coverage (it was run with ``n_predictive=0``).
    """
    t = calibration.coverage_table
    if len(t) == 0:
        raise ValueError("plot_pooled_coverage: the calibration has no posterior-predictive coverage "
                         "(calibrate_pooled(..., n_predictive=0)); run it with n_predictive > 0")
    ax = _axes(ax, figsize=(7, 0.35 * len(t) + 1.5))
    y = np.arange(len(t))
    ax.hlines(y, t["p005"], t["p995"], color="C0", lw=1, label="99 % predictive interval")
    ax.hlines(y, t["p05"], t["p95"], color="C0", lw=4, alpha=0.6, label="90 % predictive interval")
    observed = {r.name: np.asarray(r.x_stop_m, dtype=float).ravel() for r in calibration.releases}
    first = True
    for i, name in enumerate(t.index):
        x = observed.get(name)
        if x is not None and x.size:
            ax.plot(x, np.full(x.size, y[i]), "o", color="C3", ms=3, label="observed stops" if first else None)
            first = False
    cov = calibration.coverage()
    ax.set_yticks(y, list(t.index))
    ax.invert_yaxis()
    ax.set_xlabel("stop x along the profile [m] (plan runout from the release for a 3-D release)")
    ax.set_title(f"{cov['inside_90']:.0%} of {int(cov['observed_stops'])} stops inside their 90 % interval, "
                 f"{cov['inside_99']:.0%} inside the 99 %", fontsize="small")
    ax.legend(fontsize="small")
    return ax
