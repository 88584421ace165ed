"""``riskrf assess`` on 3-D terrain: a site whose ``hazard.scenario`` is a ``[terrain]`` scenario.

The chain, from one site file (the same fields as a 2-D site; see docs/user-guide/terrain-3d.md):

1. the inventory and its fits, by the 2-D chain's own fits stage (:func:`riskrf.app.assess.site_inputs.fit_site_inventory`:
   the site's m_min, the same bootstrap sizes, the annual maxima when given); the hazard's power law takes the
   site's m_min and m_max, and the rate at the source is its rate above m_min times ``inventory.rate_scale``;
2. the mass-coupled energy hazard at the barrier line ``hazard.collector`` (a plan polyline of the terrain
   scenario): ``hazard.n_blocks`` blocks with masses spread log-uniformly over the law's range run by the
   3-D kernel (:func:`riskrf.hazard.simulated.simulate_energy_hazard`), reach, speed and bounce height by mass;
3. the energy study at that line (:func:`riskrf.hazard.energy_study.analyse_energy`: design energies with
   confidence intervals, the checks of ``hazard.fences_kj`` at ``hazard.fence_height_m``, UNI 11211-4);
4. the falls reaching the road line ``hazard.road_collector`` and the road-user risk per metre of it
   (:func:`riskrf.risk.road_profile.road_risk_along_line`, with the site's ``[traffic]`` and
   ``[consequences]``), from the same run.

Not done on 3-D terrain yet (refused by :func:`riskrf.app.site.load_site` rather than ignored): ranking
mitigation options, the rate model, the uncertainty study, and an inventory counted at the road.

Outputs (all or nothing): ``summary.json``, ``design_energies.csv``, ``fence_checks.csv`` and the energy
study's files and figures, ``barrier_crossings.csv`` (first crossing of the barrier line per simulated block,
position along the line, speed, height, mass, energy, outcome), ``road_per_metre.csv`` and
``road_per_metre.png``, ``stops.csv``, ``plan.png`` (paths and stops over the hillshade).
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..frequency.inventory.record import Inventory
from ..hazard.energy_study import analyse_energy
from ..hazard.simulated import simulate_energy_hazard
from ..io.outputs import relative_paths, write_json
from ..risk.road_profile import road_risk_along_line, vulnerability_from_consequences
from .site import Site

logger = logging.getLogger("riskrf")

#: Bin length [m] of the road-per-metre table.
ROAD_BIN_M = 1.0
#: The simulated masses are not a sample of the mass law: said beside every per-block table.
MASS_NOTE = ("simulated masses are spread log-uniformly over the mass law's range (stratified), not drawn from "
             "it: weight rows by the mass law (road_per_metre.csv does) before reading shares")


@dataclass(frozen=True)
class TerrainAssessment:
    """The outputs of ``riskrf assess`` on a 3-D site (see the module docstring)."""

    site: Site
    inventory: Inventory = field(repr=False)
    frequency: object = field(repr=False)
    hazard: object = field(repr=False)
    result: object = field(repr=False)
    energy: object = field(repr=False)
    road: object = field(repr=False)
    seed: int = 1
    n_blocks: int = 0
    warnings: tuple = ()
    timings: dict = field(default_factory=dict)
    #: the fits of the dated annual maxima (FrequencyAnalysis), None when the site gives none
    maxima_frequency: object = field(default=None, repr=False)

    def barrier_crossings(self) -> pd.DataFrame:
        """First crossing of the barrier line by each simulated block (see :meth:`TerrainResult.collector`).

        Returns
        -------
        pandas.DataFrame
            One row per block crossing the barrier line.
        """
        return self.result.collector(self.site.hazard.collector, first_only=True)

    def summary(self) -> dict:
        """Machine-readable summary: rate, reach, design energies, fence verdicts, road totals, assumptions.

        Returns
        -------
        dict
            The summary, JSON-ready.
        """
        hz = self.hazard
        design = self.energy.design
        line = self.result.scenario.collectors[self.result.scenario.collector_index(self.site.hazard.collector)]
        out = {"site": self.site.name, "source": str(self.site.path), "terrain": True,
               "scenario": self.site.hazard.scenario, "seed": self.seed, "n_blocks": self.n_blocks,
               "hazard": {"collector": hz.collector, "line": line.description(),
                          "rate_per_year_at_source": hz.rate_per_year,
                          "reach_probability": hz.reach_probability, "arrival_rate_per_year": hz.arrival_rate,
                          "notes": list(hz.notes)},
               "design_energies": design.to_dict(orient="records"),
               "fence_checks": {k: v.to_dict(orient="records") for k, v in self.energy.fences.items()},
               "road": None if self.road is None else {**self.road.totals(), "notes": list(self.road.notes)},
               "mass_note": MASS_NOTE, "warnings": list(self.warnings), "defaults_used": list(self.site.defaults_used),
               "not_done_on_3d_terrain": ["ranking of mitigation options", "rate model", "uncertainty study",
                                          "inventory counted at the road (rate_basis = 'road')"],
               "timings_s": dict(self.timings)}
        return out

    def write(self, out) -> dict:
        """Write every output into the existing empty directory ``out``; returns the summary.

        Parameters
        ----------
        out : str or pathlib.Path
            Existing empty output directory.

        Returns
        -------
        dict
            The summary, with paths relative to the site file's folder.
        """
        from ..report.files import figure_note, save_figure, write_energy_study
        from .assess.site_inputs import site_trajectory_status
        out = Path(out)
        with figure_note(site_trajectory_status(self.site).figure_note):
            write_energy_study(self.energy, out)
            self.barrier_crossings().to_csv(out / "barrier_crossings.csv", index=False)
            self.result.stops().to_csv(out / "stops.csv", index=False)
            if self.road is not None:
                self.road.summary().to_csv(out / "road_per_metre.csv", index=False)
                save_figure(self.road.plot().figure, out / "road_per_metre.png", dpi=120)
            ax = self.result.plot()
            ax.set_title(f"{self.site.name}: {self.result.n:,} blocks (masses over the law's range)")
            save_figure(ax.figure, out / "plan.png", dpi=120)
        s = self.summary()
        write_json(s, out / "summary.json")
        return relative_paths(s, self.site.path.parent)


def run_terrain_assessment(site: Site, *, seed: int | None = None, n_blocks: int | None = None,
                           log=None, workers: int = 1) -> TerrainAssessment:
    """Run the 3-D chain for a checked site (``site.three_d``); see the module docstring.

    Parameters
    ----------
    site : Site
        A checked 3-D site (``site.three_d``).
    seed : int, optional
        Random seed (default: the site's).
    n_blocks : int, optional
        Blocks simulated (default: the site's).
    log : callable, optional
        Receives progress lines.
    workers : int, optional
        Threads running the kernel.

    Returns
    -------
    TerrainAssessment
        Inventory, frequency, hazard, simulation, design and road outputs of the site.
    """
    log = log or logger.info
    if not site.three_d:
        raise ValueError(f"{site.path}: hazard.scenario is not a 3-D terrain scenario; use run_assessment")
    seed = site.hazard.seed if seed is None else seed
    n_blocks = site.hazard.n_blocks if n_blocks is None else n_blocks
    inv_cfg, hz_cfg = site.inventory, site.hazard
    timings = {}
    t = time.perf_counter()
    log("[1/4] reading the inventory and fitting the power law")
    from .assess.site_inputs import fit_site_inventory
    inventory, frequency, maxima = fit_site_inventory(site, seed)     # the 2-D chain's fits stage
    from ..frequency.power_law import fit_gutenberg_richter
    gr = fit_gutenberg_richter(inventory.masses, inventory.duration_years, m_min=inv_cfg.m_min_kg,
                               m_max=inv_cfg.m_max_kg)
    rate = gr.rate_min * inv_cfg.rate_scale
    timings["fits"] = round(time.perf_counter() - t, 2)

    t = time.perf_counter()
    log(f"[2/4] simulating {n_blocks:,} trajectories on the 3-D terrain across the mass range")
    import simulation
    scenario = simulation.load_terrain_scenario(site.resolve(hz_cfg.scenario))
    hazard, result = simulate_energy_hazard(gr, scenario, hz_cfg.collector, rate_per_year=rate, n=n_blocks,
                                            seed=seed, workers=workers)
    from .assess.hazard import with_rate_note
    hazard = with_rate_note(hazard, inv_cfg.rate_scale)
    timings["simulation"] = round(time.perf_counter() - t, 2)

    t = time.perf_counter()
    log("[3/4] design energies and fence checks at the barrier line")
    from .assess.site_inputs import fence_checks_from_site
    fences, heights = fence_checks_from_site(site)
    energy = analyse_energy(hazard, fences=fences, fence_height_m=heights, free_board_m=hz_cfg.free_board_m,
                            design_T=hz_cfg.design_period_years, density_kg_m3=inventory.density_kg_m3,
                            n_bootstrap=hz_cfg.bootstrap, seed=seed)
    timings["energy"] = round(time.perf_counter() - t, 2)

    t = time.perf_counter()
    road = None
    rname = hz_cfg.road_collector
    if rname in [c.name for c in scenario.collectors]:
        log(f"[4/4] falls and road-user risk per metre of {rname!r}")
        line = scenario.collectors[scenario.collector_index(rname)]
        pos = np.full(result.n, np.nan)
        df = result.collector(rname, first_only=True)
        pos[df["block"].to_numpy()] = df["position_m"].to_numpy()
        ex, co = site.mitigation.exposure, site.mitigation.consequences
        road = road_risk_along_line(hazard.velocity, gr, rate, pos, line.length_m, road=rname, bin_m=ROAD_BIN_M,
                                    lanes=ex.lane_list(), vehicle_length_m=ex.vehicle_length_m,
                                    occupants=ex.occupants_per_vehicle, hours_on_road=ex.hours_rock_on_road,
                                    p_cannot_stop=ex.p_cannot_stop, share_stopping_on_road=ex.share_stopping_on_road,
                                    vulnerability=vulnerability_from_consequences(co))
    else:
        log(f"[4/4] no road line named {rname!r} in the scenario: no road outputs")
    timings["road"] = round(time.perf_counter() - t, 2)
    warnings = list(frequency.warnings)
    from .assess.site_inputs import site_trajectory_status
    status = site_trajectory_status(site)
    if status.uncalibrated:
        warnings.insert(0, status.text)
    if road is None:
        warnings.append(f"hazard.road_collector = {rname!r} is not a line of the terrain scenario: no road outputs")
    return TerrainAssessment(site=site, inventory=inventory, frequency=frequency, hazard=hazard, result=result,
                             energy=energy, road=road, seed=int(seed), n_blocks=int(n_blocks),
                             warnings=tuple(warnings), timings=timings, maxima_frequency=maxima)


__all__ = ["TerrainAssessment", "run_terrain_assessment"]
