"""Design figures: every option's geometry on the slope profile, the stop-point (run-out) distribution, the
barrier-position search and a ditch's retention beside a catchment chart.  Nothing here computes a design
value; each function draws what the science modules computed and returns the matplotlib figure."""
from __future__ import annotations

import numpy as np

from ..hazard.figures import plot_catchment, plot_position_search

OPTION_COLOURS = {"fence": "tab:red", "attenuator": "tab:orange", "ditch": "tab:blue", "shed": "tab:purple",
                  "scaling": "tab:green", "realignment": "tab:brown", "required": "black", "bench": "tab:cyan",
                  "bund": "tab:olive", "drape": "tab:pink"}


def _profile_axes(ax, profile, title=None):
    x, z = np.asarray(profile.x, dtype=float), np.asarray(profile.z, dtype=float)
    ax.fill_between(x, z, z.min() - 5.0, color="0.88", zorder=0)
    ax.plot(x, z, color="0.2", lw=1.2, zorder=1)
    ax.set_xlabel("horizontal distance x [m]")
    ax.set_ylabel("elevation z [m]")
    ax.set_aspect("equal", adjustable="datalim")
    if title:
        ax.set_title(title, fontsize=10)
    return x, z


def options_profile_figure(scenario, options, *, barrier_x=None, road_x=None, requirement=None):
    """The slope profile with each option's geometry: ditches dug into it, benches cut and bunds built, fences and
    attenuators at their height, a shed roof over the road, the scaling zone and a drape on the face, a realigned
    road; and the required barrier (dashed)
    at the barrier line.  ``options``: :class:`~riskrf.risk.mitigation_inputs.Option` objects; ``requirement``: a
    :class:`~riskrf.hazard.design_requirement.DesignRequirement` or None.

    Parameters
    ----------
    scenario : simulation.Scenario
        The slope (profile in m).
    options : sequence of Option
        The mitigation options.
    barrier_x, road_x : float, optional
        Barrier line and road edge [m].
    requirement : DesignRequirement, optional
        The required barrier.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    from ..risk.measures import ditch_profile, ground_z
    prof = scenario.profile
    fig, ax = plt.subplots(figsize=(10, 5.2))
    x, z = _profile_axes(ax, prof, "Mitigation options drawn on the slope profile")
    drawn = set()

    def label(kind, text):
        if kind in drawn:
            return None
        drawn.add(kind)
        return text
    for o in options:
        c = OPTION_COLOURS.get(o.kind, "0.4")
        if o.kind == "ditch" and o.x_m is not None and o.width_m is not None:
            kw = {k: getattr(o, k) for k in ("inner_slope_hv", "outer_slope_hv") if getattr(o, k) is not None}
            dug = ditch_profile(prof, o.x_m, o.width_m, o.depth_m, **kw)
            sel = (dug.x >= o.x_m - 0.5) & (dug.x <= o.x_m + o.width_m + 0.5)
            ax.plot(dug.x[sel], dug.z[sel], color=c, lw=2.2, label=label("ditch", f"ditch: {o.name} "
                                                                         f"({o.width_m:g} m x {o.depth_m:g} m)"))
        elif o.kind in ("fence", "attenuator"):
            xf = o.x_m if o.x_m is not None else barrier_x
            if xf is None or o.height_m is None:
                continue
            zg = float(ground_z(prof, xf))
            ax.plot([xf, xf], [zg, zg + o.height_m], color=c, lw=2.5,
                    label=f"{o.name}: {o.capacity_kj:,.0f} kJ, {o.height_m:g} m at x = {xf:g} m")
        elif o.kind == "shed" and road_x is not None:
            zr = float(ground_z(prof, road_x))
            ax.fill_between([road_x - 6.0, road_x + 6.0], zr + 5.5, zr + 6.5, color=c, alpha=0.8,
                            label=label("shed", f"{o.name}: roof over the road"))
            ax.plot([road_x + 6.0, road_x + 6.0], [zr, zr + 6.5], color=c, lw=2)
        elif o.kind == "scaling" and o.zone_x_m is not None:
            xs = np.linspace(o.zone_x_m[0], o.zone_x_m[1], 20)
            ax.plot(xs, [ground_z(prof, v) for v in xs], color=c, lw=5, alpha=0.6,
                    label=label("scaling", f"{o.name}: zone x = {o.zone_x_m[0]:g}-{o.zone_x_m[1]:g} m"))
        elif o.kind in ("bench", "bund") and o.x_m is not None and o.width_m is not None \
                and (o.kind == "bench" or o.height_m is not None):
            from ..risk.geometry_measures import bench_profile, bund_profile
            kw = {k: getattr(o, k) for k in ("inner_slope_hv",) + (("outer_slope_hv",) if o.kind == "bund" else ())
                  if getattr(o, k) is not None}
            new = bench_profile(prof, o.x_m, o.width_m, **kw) if o.kind == "bench" else \
                bund_profile(prof, o.x_m, o.width_m, o.height_m, **kw)
            sel = (new.x >= o.x_m - 0.5) & (new.x <= o.x_m + o.width_m + 0.5)
            what = f"{o.width_m:g} m wide" if o.kind == "bench" else f"{o.height_m:g} m high, {o.width_m:g} m base"
            ax.plot(new.x[sel], new.z[sel], color=c, lw=2.2, label=label(o.kind, f"{o.kind}: {o.name} ({what})"))
        elif o.kind == "drape" and o.zone_x_m is not None:
            xs = np.linspace(o.zone_x_m[0], o.zone_x_m[1], 20)
            ax.plot(xs, [ground_z(prof, v) for v in xs], color=c, lw=3, ls=":",
                    label=label("drape", f"{o.name}: mesh over x = {o.zone_x_m[0]:g}-{o.zone_x_m[1]:g} m"))
        elif o.kind == "realignment":
            xr = o.road_x_m if o.road_x_m is not None else float(x[-1])
            ax.annotate("", xy=(xr, float(ground_z(prof, min(xr, x[-1] - 1e-6))) + 1.0),
                        xytext=(road_x or xr, float(ground_z(prof, road_x or xr)) + 1.0),
                        arrowprops={"arrowstyle": "->", "color": c})
            ax.plot([], [], color=c, label=label("realignment", f"{o.name}: road moved to x = {xr:g} m"))
    if road_x is not None:
        zr = float(ground_z(prof, road_x))
        ax.plot([road_x], [zr + 0.4], marker="s", color="0.1", ms=8, ls="", label=f"road line x = {road_x:g} m")
    if requirement is not None and barrier_x is not None and np.isfinite(requirement.required_net_height_m):
        zg = float(ground_z(prof, barrier_x))
        cls = requirement.required_class_kj
        text = (f"{cls:,.0f} kJ" if np.isfinite(cls) else f"{requirement.required_mel_kj:,.0f} kJ (above every "
                "product class)")
        ax.plot([barrier_x + 1.0, barrier_x + 1.0], [zg, zg + requirement.required_net_height_m], color="black",
                ls="--", lw=2, label=f"required by {requirement.basis.basis}: MEL {text}, "
                                     f"{requirement.required_net_height_m:g} m")
    ax.legend(fontsize=7, loc="upper right")
    return fig


def stop_points_figure(result, *, road_x=None, ditches=(), option=None):
    """Where the simulated blocks stopped: histogram of the stop x and the share travelling beyond each x
    (run-out exceedance), with the road line and ditch spans marked; ``option`` = (name, result) adds the stop
    points on the slope with that option built.

    Parameters
    ----------
    result : simulation.SimulationResult
        The run.
    road_x : float, optional
        Road edge [m].
    ditches : sequence of (float, float)
        Ditch spans (from, to) [m].
    option : tuple of (str, simulation.SimulationResult), optional
        An option's name and its run.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    runs = [("existing slope", result, "tab:gray", "k")]
    if option is not None:
        runs.append((f"with {option[0]}", option[1], "tab:blue", "tab:blue"))
    for label, res, fill, line in runs:
        xs = res.runout["x_stop_m"].to_numpy(dtype=float)
        xs = xs[np.isfinite(xs)]
        a1.hist(xs, bins=80, color=fill, alpha=0.6 if option is not None else 1.0, density=True,
                label=f"{label} ({res.n:,} blocks)")
        s = np.sort(xs)
        beyond = 1.0 - np.arange(1, s.size + 1) / max(s.size, 1)
        a2.semilogy(s, np.maximum(beyond, 0.5 / max(s.size, 1)), color=line, label=label)
    a1.set_ylabel("share of blocks stopped per metre")
    a1.set_title("Stop points of the simulated blocks (the scenario seeder's masses)", fontsize=10)
    a2.legend(fontsize=8, loc="lower left")
    a2.set_ylabel("share travelling beyond x")
    a2.set_xlabel("horizontal distance x [m]")
    for ax in (a1, a2):
        if road_x is not None:
            ax.axvline(road_x, color="tab:red", ls="--", label=f"road line x = {road_x:g} m")
        for (x0, x1, name) in ditches:
            ax.axvspan(x0, x1, color="tab:blue", alpha=0.15, label=f"ditch: {name}")
    a1.legend(fontsize=8)
    return fig


def position_search_figure(search):
    """The two-panel position-search figure (slope with positions; requirement per position).

    Parameters
    ----------
    search : PositionSearch
        A :class:`~riskrf.hazard.design_requirement.PositionSearch`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    return plot_position_search(search).figure


def catchment_figure(study):
    """The catchment retention figure (:func:`plot_catchment` on a new figure).

    Parameters
    ----------
    study : CatchmentStudy
        The catchment study.

    Returns
    -------
    matplotlib.figure.Figure
    """
    return plot_catchment(study).figure
