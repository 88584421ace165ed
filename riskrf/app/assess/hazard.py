"""The hazard stages of the chain: the impact-energy hazard at the barrier line, then its design values.

- :func:`energy_hazard_from_inputs`: the power-law fit of an inventory combined with simulated velocities (a
  scenario, mass-coupled by default) or velocities read from a file, also used by ``riskrf energy``;
  :func:`with_rate_note` notes where the hazard's rate came from;
- :func:`_simulate_hazard`: that hazard for a site (stage 2 of :func:`riskrf.app.assess.run.run_assessment`);
- :func:`_energy_stage`: the design block, the design-energy sensitivity and tornado, the fence checks and the
  site's design (stage 3).
"""
from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from ...core.validation import RiskrfWarning
from ...frequency.inventory.record import Inventory
from ...frequency.power_law import fit_gutenberg_richter
from ...hazard.annual_hazard import EnergyHazard, effective_speeds
from ...hazard.design_block import design_block, resolve_sizes
from ...hazard.energy_study import analyse_energy, design_energy_sensitivity
from ...hazard.energy_tornado import design_energy_tornado
from ...hazard.simulated import simulate_energy_hazard
from ...risk.measures import road_crossings
from ..site import Site
from ..site_design import design_for_site
from .site_inputs import fence_checks_from_site


def energy_hazard_from_inputs(inventory: Inventory, *, m_min=None, m_max=None, rate_scale: float = 1.0,
                              scenario=None, velocities=None, collector: str | None = None, n: int = 50_000,
                              seed=1, reach_probability: float = 1.0, condition_on_mass: bool = False,
                              mass_coupling: str = "simulated", design_masses_kg=(),
                              velocity_unit: str | None = None, drop_height_m=None, velocity_reader=None,
                              rate_note: str | None = None, road_collector: str | None = None):
    """Power-law fit of the inventory combined with simulated or given velocities.

    ``collector`` names the barrier line: in a scenario it defaults to "barrier"; a
    velocity file is filtered to that collector only when one is named.

    With a scenario and ``mass_coupling="simulated"`` (the default) the hazard is
    :func:`riskrf.energy_hazard`: ``n`` blocks simulated across the power law's mass range
    (widened to ``design_masses_kg``: masses [kg], or a function of (power-law fit, rate per year) returning
    them, for masses that follow from the site's law), reach and speed by mass.  ``"independent"`` (or
    ``condition_on_mass``) is the older form from the seeder's own masses.  The returned
    simulation is always the scenario's own seeder run (figures, road share, mitigation).
    ``rate_note`` replaces the hazard's note on ``rate_scale`` (e.g. a rate from the site's rate model).
    ``road_collector``: also return, per block of the mass-coupled run, whether it crossed that line (a boolean
    array, None without a mass-coupled run or such a line) as a fourth element: the road share by block size.

    Returns (power-law fit, EnergyHazard, SimulationResult or None[, road crossings or None]).

    Parameters
    ----------
    inventory : Inventory
        The rock fall inventory (masses [kg], record duration [yr]).
    m_min, m_max : float, optional
        Lower completeness mass and upper truncation of the power law [kg] (None: estimated / untruncated).
    rate_scale : float, optional
        Factor [-] on the fitted rate of falls at or above m_min (default 1).
    scenario : str, pathlib.Path or simulation.Scenario, optional
        Slope to simulate; give exactly one of ``scenario`` and ``velocities``.
    velocities : str or pathlib.Path, optional
        A file of velocities at the barrier line (:func:`riskrf.io.velocities.read_velocities`).
    collector : str, optional
        The barrier line (see above).
    n : int, optional
        Simulated blocks (default 50 000).
    seed : int, optional
        Seed of the simulation (default 1).
    reach_probability : float, optional
        P(a fall reaches the line) [-] with a velocity file (default 1: every fall).
    condition_on_mass : bool, optional
        Use the seeder's own masses (the older form; default False).
    mass_coupling : {"simulated", "independent"}, optional
        How reach and speed depend on the mass (default ``"simulated"``).
    design_masses_kg : sequence of float or callable, optional
        Masses [kg] the simulated mass range must cover, or ``f(fit, rate [1/yr])`` returning them.
    velocity_unit : {"m/s", "km/h"}, optional
        Unit of the velocity file's velocity column when its header does not say.
    drop_height_m : float, optional
        Height drop to the line [m] for the velocity file's plausibility limit.
    velocity_reader : dict, optional
        Further keyword arguments of :func:`riskrf.io.velocities.read_velocities`.
    rate_note : str, optional
        Note on the rate replacing the one on ``rate_scale``.
    road_collector : str, optional
        The road line, for the road crossings per block.

    Returns
    -------
    fit : GutenbergRichterFit
        The power-law fit of the inventory (rate at or above m_min [1/yr]).
    hazard : EnergyHazard
        Annual energy hazard at the barrier line (falls [1/yr], energies [kJ]).
    result : simulation.SimulationResult or None
        The scenario's seeder run (None with a velocity file).
    road_hits : numpy.ndarray of bool or None
        Only when ``road_collector`` is given: per block of the mass-coupled run, did it cross the road line.

    Raises
    ------
    ValueError
        Neither or both of ``scenario`` and ``velocities``, or an unknown ``mass_coupling``.
    """
    gr = fit_gutenberg_richter(inventory.masses, inventory.duration_years, m_min=m_min, m_max=m_max)
    rate = gr.rate_min * rate_scale
    if callable(design_masses_kg):
        design_masses_kg = design_masses_kg(gr, rate)
    if (scenario is None) == (velocities is None):
        raise ValueError("give exactly one of --scenario (simulate the velocities) or --velocities (a file)")
    if scenario is not None:
        hazard, result, road_hits = _scenario_hazard(
            gr, rate, scenario, collector, n=n, seed=seed, mass_coupling=mass_coupling,
            condition_on_mass=condition_on_mass, design_masses_kg=design_masses_kg, road_collector=road_collector)
    else:
        result, road_hits = None, None
        hazard = _velocity_file_hazard(gr, rate, velocities, collector, velocity_unit=velocity_unit,
                                       drop_height_m=drop_height_m, velocity_reader=velocity_reader,
                                       reach_probability=reach_probability)
    hazard = with_rate_note(hazard, rate_scale, rate_note)
    if road_collector is not None:
        return gr, hazard, result, road_hits
    return gr, hazard, result


def _scenario_hazard(gr, rate: float, scenario, collector: str | None, *, n: int, seed, mass_coupling: str,
                     condition_on_mass: bool, design_masses_kg, road_collector: str | None) -> tuple:
    """Energy hazard at the barrier line of a simulated slope (the scenario branch of
    :func:`energy_hazard_from_inputs`).

    The scenario's own seeder run is always made (figures, road share, mitigation); the hazard is the
    mass-coupled :func:`~riskrf.hazard.simulated.simulate_energy_hazard` unless ``mass_coupling`` is
    ``"independent"`` or ``condition_on_mass`` is set, then it is built from the seeder run's crossings.

    Parameters
    ----------
    gr : GutenbergRichterFit
        The power-law fit of the inventory: the law the mass-coupled run draws its block masses [kg] from.
    rate : float
        Falls per year at or above m_min [1/yr], ``rate_scale`` applied: the hazard's rate of falls.
    scenario : str, pathlib.Path or simulation.Scenario
        The slope to simulate.
    collector : str or None
        The barrier line (None: ``"barrier"``).
    n : int
        Simulated blocks.
    seed : int
        Seed of the simulation.
    mass_coupling : {"simulated", "independent"}
        How reach and speed depend on the mass.
    condition_on_mass : bool
        Use the seeder's own masses (the older form).
    design_masses_kg : sequence of float
        Masses [kg] the simulated mass range must cover.
    road_collector : str or None
        The road line, for the road crossings per block.

    Returns
    -------
    hazard : EnergyHazard
        Annual energy hazard at the barrier line (falls [1/yr], energies [kJ]).
    result : simulation.SimulationResult
        The scenario's seeder run.
    road_hits : numpy.ndarray of bool or None
        Per block of the mass-coupled run, did it cross the road line (None without that run or that line).

    Raises
    ------
    KeyError
        The scenario has no line named ``collector``.
    ValueError
        An unknown ``mass_coupling`` (checked before the seeder run).
    """
    import simulation

    sc = scenario if isinstance(scenario, simulation.Scenario) else simulation.load_scenario(scenario)
    collector = collector or "barrier"
    sc.collector_index(collector)
    if mass_coupling not in ("simulated", "independent"):
        raise ValueError(f"mass_coupling = {mass_coupling!r} must be 'simulated' or 'independent'")
    result = simulation.run(sc, n=n, seed=seed)
    road_hits = None
    if mass_coupling == "simulated" and not condition_on_mass:
        hazard, coupled = simulate_energy_hazard(gr, sc, collector, rate_per_year=rate, n=n, seed=seed,
                                                 design_masses_kg=design_masses_kg)
        road_hits = _road_hits_per_block(coupled, sc, road_collector)
    else:
        hazard = EnergyHazard.from_simulation(gr, result, collector, rate_per_year=rate,
                                              condition_on_mass=condition_on_mass)
    return hazard, result, road_hits


def _road_hits_per_block(coupled, scenario, road_collector: str | None):
    """Whether each block of a run crossed the road line.

    Parameters
    ----------
    coupled : simulation.SimulationResult
        The mass-coupled run (anything with ``n`` and ``collector(name, first_only=True)``).
    scenario : simulation.Scenario
        The simulated slope (its collector names).
    road_collector : str or None
        The road line.

    Returns
    -------
    numpy.ndarray of bool or None
        One flag per block of ``coupled`` (None when ``road_collector`` is None or not a line of the scenario).
    """
    if road_collector is None or road_collector not in [c.name for c in scenario.collectors]:
        return None
    road_hits = np.zeros(coupled.n, dtype=bool)
    road_hits[road_crossings(coupled, road_collector)] = True
    return road_hits


def _velocity_file_hazard(gr, rate: float, velocities, collector: str | None, *, velocity_unit: str | None,
                          drop_height_m, velocity_reader, reach_probability: float) -> EnergyHazard:
    """Energy hazard at the barrier line from a file of velocities (the velocity-file branch of
    :func:`energy_hazard_from_inputs`).

    The reader's plausibility warnings are not raised but kept in the hazard's note, together with the sample
    count, whether rotational energy is included (when the file gives spin and radius) and the reach
    probability as given.

    Parameters
    ----------
    gr : GutenbergRichterFit
        The power-law fit of the inventory: the mass law [kg] paired with the file's velocities.
    rate : float
        Falls per year at or above m_min [1/yr], ``rate_scale`` applied; ``reach_probability`` of them reach
        the line.
    velocities : str or pathlib.Path
        The velocity file (:func:`riskrf.io.velocities.read_velocities`).
    collector : str or None
        The barrier line: the file is filtered to it when given.
    velocity_unit : {"m/s", "km/h"} or None
        Unit of the velocity column when its header does not say.
    drop_height_m : float or None
        Height drop to the line [m] for the plausibility limit.
    velocity_reader : dict or None
        Further keyword arguments of :func:`riskrf.io.velocities.read_velocities`.
    reach_probability : float
        P(a fall reaches the line) [-].

    Returns
    -------
    EnergyHazard
        Annual energy hazard at the line (falls [1/yr], effective speeds [m/s], energies [kJ]).
    """
    from ...io.velocities import read_velocities

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RiskrfWarning)      # kept in the hazard's notes below
        df = read_velocities(velocities, collector=collector, velocity_unit=velocity_unit,
                             drop_height_m=drop_height_m, **(velocity_reader or {}))
    v = df["velocity_ms"].to_numpy(dtype=float)
    note = "; ".join([f"velocities: {len(df):,} samples from {velocities}", *df.attrs.get("warnings", [])])
    if "angular_velocity_rads" in df and "radius_m" in df:
        v = effective_speeds(df)
        note += "; rotational energy included"
    note += f"; reach probability {reach_probability:g} as given" + (
        " (default: every fall assumed to reach the line)" if reach_probability == 1.0 else "")
    return EnergyHazard(mass=gr, velocity=v, rate_per_year=rate, reach_probability=reach_probability,
                        heights_m=df["height_m"].to_numpy(dtype=float) if "height_m" in df else None,
                        collector=collector or "", notes=(note,))


def with_rate_note(hazard: EnergyHazard, rate_scale: float, rate_note: str | None = None) -> EnergyHazard:
    """The hazard with a note on where its rate came from appended.

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard.
    rate_scale : float
        Factor [-] applied to the inventory's rate (the share of the inventoried source above this line).
    rate_note : str, optional
        A note replacing the one on ``rate_scale`` (e.g. a rate from the site's rate model).

    Returns
    -------
    EnergyHazard
        ``hazard`` with ``rate_note`` appended to its notes, else with a note on ``rate_scale`` when it is not
        1, else ``hazard`` itself.
    """
    if rate_note is not None:
        return replace(hazard, notes=hazard.notes + (rate_note,))
    if rate_scale != 1.0:
        return replace(hazard, notes=hazard.notes + (
            f"rate scaled by {rate_scale:g} (share of the inventoried source above this line)",))
    return hazard


def _ends(values):
    """(lowest, highest) of a sensitivity list, None when it holds one value or None (nothing to vary)."""
    v = [x for x in values if x is not None]
    return (min(v), max(v)) if len(v) > 1 else None


def _simulate_hazard(site: Site, inventory, rate_scale: float, rate_note, n_blocks: int, seed, design_masses):
    """The impact-energy hazard of the site: simulated trajectories, or velocities read from a file.

    Parameters
    ----------
    site : Site
        The validated site (``[inventory]`` and ``[hazard]`` tables).
    inventory : Inventory
        The site's inventory (masses in kg).
    rate_scale : float
        Factor on the inventory's rate (dimensionless).
    rate_note : str or None
        How the rate was obtained, carried into the hazard.
    n_blocks : int
        Trajectories simulated.
    seed : int or None
        Seed of the simulation.
    design_masses : callable
        ``design_masses(law, rate)``: masses (kg) to simulate (:func:`_design_masses`).

    Returns
    -------
    tuple
        ``(gr, hazard, result, road_hits)`` of :func:`energy_hazard_from_inputs`.
    """
    inv_cfg, hz_cfg = site.inventory, site.hazard
    return energy_hazard_from_inputs(
        inventory, m_min=inv_cfg.m_min_kg, m_max=inv_cfg.m_max_kg, rate_scale=rate_scale,
        scenario=site.resolve(hz_cfg.scenario) if hz_cfg.scenario else None,
        velocities=site.resolve(hz_cfg.velocities) if hz_cfg.velocities else None,
        collector=hz_cfg.collector, n=n_blocks, seed=seed, reach_probability=hz_cfg.reach_probability,
        mass_coupling=hz_cfg.mass_coupling, design_masses_kg=design_masses,
        velocity_unit=hz_cfg.velocity_unit, drop_height_m=hz_cfg.drop_height_m, rate_note=rate_note,
        road_collector=hz_cfg.road_collector)


def _energy_stage(site: Site, inventory, gr, hazard, result, survey, m_max_values, shares, rate_scale: float,
                  site_rates, seed):
    """Design block, design-energy sensitivity and tornado, fence checks and the site's design masses.

    Parameters
    ----------
    site : Site
        The validated site.
    inventory : Inventory
        The site's inventory (masses in kg, duration in years, density in kg/m3).
    gr : GutenbergRichterFit
        The mass law of the hazard (kg).
    hazard : EnergyHazard
        The impact-energy hazard at the barrier line.
    result : object
        The simulation result.
    survey : numpy.ndarray or None
        Block volumes of the survey (m3).
    m_max_values, shares : list
        The design-energy sensitivity inputs (:func:`sensitivity_inputs`).
    rate_scale : float
        Factor on the inventory's rate (dimensionless).
    site_rates : object or None
        The site's rate model when the rate comes from it (changes the tornado's rate label).
    seed : int or None
        Seed of the bootstrap and of the design runs.

    Returns
    -------
    energy : EnergyAnalysis
        Design energies (kJ) and fence checks.
    site_design : object
        The site's design masses (:func:`design_for_site`).
    """
    db_cfg, hz_cfg, inv_cfg = site.design_block, site.hazard, site.inventory
    block = design_block(hazard, rule=db_cfg.rule, percentile=db_cfg.percentile, survey_volumes_m3=survey,
                         survey_source=db_cfg.survey, inventory=inventory,
                         sizes=resolve_sizes(inv_cfg.sizes, inventory),
                         design_T=hz_cfg.design_period_years, density_kg_m3=inventory.density_kg_m3,
                         fractal_dimension=db_cfg.fractal_dimension, iterations=db_cfg.iterations)
    sensitivity = design_energy_sensitivity(
        hazard, inventory.masses, inventory.duration_years, m_min=gr.m_min, m_max_values=m_max_values,
        rate_shares=shares, T=hz_cfg.design_period_years) \
        if hz_cfg.design_period_years * hazard.arrival_rate > 1 else None
    tornado = design_energy_tornado(
        hazard, design_T=hz_cfg.design_period_years, block=block, masses_kg=inventory.masses,
        duration_years=inventory.duration_years, m_max_range=_ends(m_max_values),
        rate_share=rate_scale, rate_share_range=_ends(shares), sensitivity=sensitivity,
        **({"rate_label": "rate factor on the inventory's rate (rate model x rate_scale)"}
           if site_rates is not None else {})) \
        if sensitivity is not None else None
    fences, heights = fence_checks_from_site(site)
    energy = analyse_energy(hazard, fences=fences, fence_height_m=heights,
                            free_board_m=hz_cfg.free_board_m, design_T=hz_cfg.design_period_years,
                            density_kg_m3=inventory.density_kg_m3, n_bootstrap=hz_cfg.bootstrap, seed=seed,
                            design_block=block, sensitivity=sensitivity, tornado=tornado)
    site_design = design_for_site(site, hazard, block, result, inventory.density_kg_m3, seed)
    return energy, site_design
