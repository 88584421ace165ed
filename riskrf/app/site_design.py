"""The barrier and ditch design of one site, from its ``[design]`` table: the governing basis's requirement at
the barrier line, the position search along the profile, the run-out to the road and the catchment retention
of the site's cut.  Orchestration only: the computations are :mod:`riskrf.hazard.design_basis`,
:mod:`riskrf.hazard.design_requirement` and :mod:`riskrf.hazard.catchment`."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..hazard.design_basis import DesignBasis, design_basis_from_site
from ..hazard.design_requirement import design_requirement, position_search


@dataclass(frozen=True)
class SiteDesign:
    """Design outputs of a site: ``basis`` (:class:`~riskrf.hazard.design_basis.DesignBasis`), ``requirement``
    at the barrier line (:class:`~riskrf.hazard.design_requirement.DesignRequirement`), ``positions``
    (:class:`~riskrf.hazard.design_requirement.PositionSearch` or None, with the reason in ``notes``), ``runout`` (dict:
    shares of released blocks reaching the barrier line and the road, stop-point percentiles [m]), ``catchment``
    (:class:`~riskrf.hazard.catchment.CatchmentStudy` of the site's cut, or None) and ``notes``."""

    basis: DesignBasis
    requirement: object
    positions: object
    runout: dict
    catchment: object
    barrier_x_m: float | None
    road_x_m: float | None
    notes: tuple = ()
    #: (option name, simulation.SimulationResult) of the recommended option's slope (ditch dug, fence standing),
    #: or None when the option leaves the profile as it is
    recommended: tuple | None = None

    def summary(self) -> pd.DataFrame:
        """The requirement at the barrier line (one-column table; the reason when there is none).

        Returns
        -------
        pandas.DataFrame
            One column ``value``, one row per quantity with its unit.
        """
        if self.requirement is None:
            return pd.DataFrame({"value": pd.Series({"design basis": self.basis.basis,
                                                     "requirement": "; ".join(self.notes)}, dtype=object)})
        return self.requirement.summary()

    def to_dict(self) -> dict:
        """The design entries of summary.json: design_basis, required_barrier, deflection_check, position_search,
        runout, ditch_chart_comparison.

        Returns
        -------
        dict
            The design entries, JSON-ready.
        """
        r = self.requirement
        if r is None:
            return {"design_basis": {"basis": self.basis.basis, "text": self.basis.text(),
                                     "factors": dict(self.basis.factors),
                                     "factors_not_stated": self.basis.unverified,
                                     "frequent_T_years": self.basis.frequent_T_years},
                    "required_barrier": None, "deflection_check": None, "position_search": None,
                    "runout": self.runout,
                    "ditch_chart_comparison": self.catchment.to_dict() if self.catchment is not None else None,
                    "recommended_option_runout": self.recommended_runout(), "design_notes": list(self.notes)}
        cand = r.candidates
        elong = cand[cand["check"].str.startswith("elongation")] if len(cand) else cand
        return {
            "design_basis": {"basis": self.basis.basis, "text": self.basis.text(), "factors": dict(self.basis.factors),
                             "factors_not_stated": self.basis.unverified,
                             "frequent_T_years": self.basis.frequent_T_years},
            "required_barrier": r.to_dict(),
            "deflection_check": {"clearance_m": r.clearance_m, "gamma_d": self.basis.factors["gamma_d"],
                                 "permitted_max_elongation_m": r.permitted_elongation_m,
                                 "candidates": elong.to_dict(orient="records")},
            "position_search": (self.positions.table.to_dict(orient="records") if self.positions is not None
                                else None),
            "runout": self.runout,
            "ditch_chart_comparison": self.catchment.to_dict() if self.catchment is not None else None,
            "recommended_option_runout": self.recommended_runout(),
            "design_notes": list(self.notes),
        }


    def recommended_runout(self) -> dict | None:
        """Run-out of the recommended option's slope: its name, the shares of released blocks reaching the road
        with and without it, and the stop-point percentiles [m]; None without such a simulation.

        Returns
        -------
        dict or None
            Option name, shares of released blocks reaching the road [-] and stop-point percentiles [m].
        """
        if self.recommended is None:
            return None
        name, res = self.recommended
        xs = res.runout["x_stop_m"].to_numpy(dtype=float)
        out = {"option": name, "blocks": int(res.n), "stop_x_p50_m": float(np.nanpercentile(xs, 50)),
               "stop_x_p95_m": float(np.nanpercentile(xs, 95))}
        road = [c.name for c in res.scenario.collectors if c.x == self.road_x_m]
        if road:
            out["share_reaching_road"] = float(res.reach_probability(road[0])[0])
            out["share_reaching_road_without"] = self.runout.get("share_reaching_road")
        return out


def option_scenario(site, scenario, option_name: str, options=None):
    """The scenario with the option ``option_name`` built into it (its ditches dug, its fences and attenuators
    standing as barriers at their lines), or None when the option does not change the slope (scaling, shed,
    closure, realignment, doing nothing).

    Parameters
    ----------
    site : Site
        The checked site.
    scenario : Scenario
        The site's slope scenario.
    option_name : str
        Name of a mitigation option of the site.
    options : sequence of Option, optional
        The options ranked (default: the site's own; the ranking adds the required barrier).

    Returns
    -------
    Scenario or None
        The scenario with the option built in.
    """
    from dataclasses import replace

    from ..risk.measures import Ditch, scenario_with_ditches
    opts = {o.name: o for o in (site.mitigation.options if options is None else options)}
    o = opts[option_name]
    parts = [opts[n] for n in o.options] if o.kind == "combined" else [o]
    ditches = [Ditch(p.x_m, p.width_m, p.depth_m, **{k: getattr(p, k) for k in ("inner_slope_hv", "outer_slope_hv")
                                                      if getattr(p, k) is not None}, material=p.material,
                     option=p.name)
               for p in parts if p.kind == "ditch" and p.x_m is not None and p.retention is None]
    fences = [p for p in parts if p.kind in ("fence", "attenuator") and p.retention is None]
    if not ditches and not fences:
        return None
    sc = scenario
    if ditches:
        sc = scenario_with_ditches(sc, ditches, where=str(site.path), road_collector=site.hazard.road_collector)
    for f in fences:
        if f.x_m is None:
            sc = sc.with_barrier(site.hazard.collector, f.capacity_kj, f.height_m)
        else:
            from simulation.scenario import Collector
            sc = replace(sc, collectors=sc.collectors + (Collector(name=f"{f.name} line", x=float(f.x_m),
                                                                     capacity_kj=float(f.capacity_kj),
                                                                     height_m=float(f.height_m)),))
    return sc


def with_recommended_run(design: SiteDesign, site, result, option_name: str | None, seed,
                         options=None) -> SiteDesign:
    """``design`` with the recommended option's slope simulated (``hazard.option_blocks`` blocks, the seeder's
    masses), for its trajectories and stop points; unchanged when the option leaves the slope as it is.

    Parameters
    ----------
    design : SiteDesign
        The site's design outputs.
    site : Site
        The checked site.
    result : SimulationResult or None
        The site's simulation (None: no slope to re-run).
    option_name : str or None
        Name of the recommended option (None: no option is recommended, nothing is run).
    seed : int
        Random seed.
    options : sequence of Option, optional
        The options ranked (default: the site's own).

    Returns
    -------
    SiteDesign
        ``design`` with the recommended option's run.
    """
    from dataclasses import replace

    import simulation
    if result is None or option_name is None:
        return design
    sc = option_scenario(site, result.scenario, option_name, options)
    if sc is None:
        return design
    res = simulation.run(sc, n=int(site.hazard.option_blocks), seed=seed)
    return replace(design, recommended=(option_name, res))


def design_for_site(site, hazard, block, result, density_kg_m3: float, seed) -> SiteDesign:
    """Compute the site's design outputs (see :class:`SiteDesign`).

    Parameters
    ----------
    site : Site
        The checked site.
    hazard : EnergyHazard
        Impact-energy hazard at the barrier line.
    block : DesignBlock or None
        The design block.
    result : SimulationResult or None
        The site's simulation.
    density_kg_m3 : float
        Rock density [kg/m3].
    seed : int
        Random seed.

    Returns
    -------
    SiteDesign
        Design basis, requirement, position search, run-out and catchment outputs.
    """
    positions_x = site.design.positions_x_m
    n_pos = site.design.position_blocks or site.hazard.option_blocks
    basis = design_basis_from_site(site.design, design_T=site.hazard.design_period_years,
                                   free_board_m=site.hazard.free_board_m)
    notes = []
    barrier_x = road_x = None
    if result is not None:
        names = [c.name for c in result.scenario.collectors]
        barrier_x = result.scenario.collectors[names.index(site.hazard.collector)].x
        road = site.hazard.road_collector
        road_x = result.scenario.collectors[names.index(road)].x if road in names else None
    clearance = (road_x - barrier_x) if road_x is not None and barrier_x is not None else None
    fences = [o for o in site.mitigation.options if o.kind in ("fence", "attenuator") and o.x_m is None]
    candidates = [(o.name, o.capacity_kj, o.height_m, getattr(o, "kit", None)) for o in fences] or [
        (f"candidate fence {c:g} kJ", c, h) for c, h in zip(*_fence_list(site))]
    try:
        req = design_requirement(hazard, basis, block=block, density_kg_m3=density_kg_m3,
                                 x_m=barrier_x if barrier_x is not None else float("nan"), clearance_m=clearance,
                                 candidates=candidates)
    except ValueError as exc:          # e.g. no T-year energy: fewer than one fall reaches the line in T years
        notes.append(f"no requirement under {basis.basis}: {exc}")
        req = None
    positions = None
    if req is None:
        pass
    elif result is not None and hazard.mass_coupled:
        positions = position_search(hazard, result.scenario, basis, block=block, density_kg_m3=density_kg_m3,
                                    positions_m=positions_x, road_collector=site.hazard.road_collector,
                                    barrier_x=barrier_x, n=int(n_pos), seed=seed)
    else:
        notes.append("no position search: it needs a simulated, mass-coupled hazard (a scenario, "
                     "hazard.mass_coupling = 'simulated')")
    runout, catchment = {}, None
    if result is not None:
        from ..hazard.catchment import retention_from_result
        ro = result.runout
        xs = ro["x_stop_m"].to_numpy(dtype=float)
        runout = {"blocks": int(result.n), "masses": "the scenario seeder's",
                  "stop_x_p50_m": float(np.nanpercentile(xs, 50)), "stop_x_p95_m": float(np.nanpercentile(xs, 95)),
                  "stop_x_p99_m": float(np.nanpercentile(xs, 99))}
        if barrier_x is not None:
            runout["share_reaching_barrier_line"] = float(result.reach_probability(site.hazard.collector)[0])
        if road_x is not None:
            runout["share_reaching_road"] = float(result.reach_probability(site.hazard.road_collector)[0])
        catchment = retention_from_result(result)
    return SiteDesign(basis=basis, requirement=req, positions=positions, runout=runout, catchment=catchment,
                      barrier_x_m=barrier_x, road_x_m=road_x, notes=tuple(notes))


def _fence_list(site):
    caps = list(site.hazard.fences_kj)
    fh = site.hazard.fence_height_m
    return caps, (list(fh) if isinstance(fh, list) else [fh] * len(caps))


__all__ = ["SiteDesign", "design_for_site", "option_scenario", "with_recommended_run"]
