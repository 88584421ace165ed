"""The whole chain for one site: inventory -> fits -> simulation -> energy hazard -> mitigation ranking.

``run_assessment(site)`` computes; ``write_assessment(assessment, directory)`` writes
report.html, summary.json, CSV tables, PNG figures and a copy of the inputs with the
package version and seed.  ``riskrf assess`` and ``riskrf demo`` call both, writing
into a temporary directory that is moved into place only when complete.
"""
from __future__ import annotations

import json
import logging
import platform
import shutil
import sys
import time
import warnings
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path

import numpy as np

from .. import __version__
from ..hazard.annual_hazard import EnergyHazard, effective_speeds
from ..hazard.design_block import (design_block, design_block_candidates_kg, fragment_block_kg, read_block_survey,
                           resolve_sizes)
from ..hazard.energy_study import (
    INTERVAL_COVERS,
    EnergyAnalysis,
    analyse_energy,
    design_energy_sensitivity,
)
from ..hazard.energy_tornado import design_energy_tornado
from ..frequency.study import FrequencyAnalysis, analyse_inventory
from ..frequency.inventory.reader import read_inventory
from ..frequency.inventory.record import Inventory
from ..hazard.simulated import simulate_energy_hazard
from ..risk.measures import road_crossings
from ..risk.mitigation import Exposure, MitigationStudy
from ..io.outputs import relative_paths, relative_paths_in_json_files, write_json
from ..frequency.power_law import fit_gutenberg_richter
from .site_design import design_for_site, with_recommended_run
from .scheduling import InLine
from .site import Site
from ..core.validation import RiskrfWarning

logger = logging.getLogger("riskrf")


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
    from ..io.velocities import read_velocities

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


def road_share(result, barrier: str, road: str | None) -> float:
    """P(reaches the road | reaches the barrier line) from a simulation (1 without a road collector).

    Parameters
    ----------
    result : simulation.SimulationResult or None
        The seeder run of the scenario (None with a velocity file).
    barrier : str
        Name of the barrier line's collector.
    road : str or None
        Name of the road's collector (None: no road line).

    Returns
    -------
    float
        P(road | barrier line) [-], at most 1.
    """
    if result is None or road is None or road not in [c.name for c in result.scenario.collectors]:
        return 1.0
    b = result.reach_probability(barrier)[0]
    return min(result.reach_probability(road)[0] / b, 1.0) if b > 0 else 1.0


def study_context(result, barrier: str, road: str | None, option_blocks: int, seed, inventory, hazard,
                  rate_scale: float = 1.0, road_hits=None) -> dict:
    """The slope model and small falls a :class:`MitigationStudy` needs to derive option effects.

    Falls below the power law's m_min: the inventory's own (their masses, and their count
    over the record scaled by ``rate_scale``), so that every size that reaches the road counts.  ``road_hits``:
    per block of the hazard's mass-coupled run, did it cross the road line (road share by block size).

    Parameters
    ----------
    result : simulation.SimulationResult or None
        The seeder run of the scenario (None with a velocity file: no slope model).
    barrier : str
        Name of the barrier line's collector.
    road : str or None
        Name of the road's collector (the barrier line when absent from the scenario).
    option_blocks : int
        Blocks per re-simulation of an option.
    seed : int
        Seed of the options' re-simulations.
    inventory : Inventory or None
        The inventory (masses [kg], duration [yr]) for the falls below m_min.
    hazard : EnergyHazard
        The energy hazard (its power law's ``m_min`` [kg]).
    rate_scale : float, optional
        Factor [-] on the small falls' count (default 1).
    road_hits : numpy.ndarray of bool, optional
        Road crossings per block of the mass-coupled run.

    Returns
    -------
    dict
        Keyword arguments of :class:`MitigationStudy`: ``context`` (SimulationContext) and ``reference``,
        ``coupled_road_hits``, ``small_fall_masses_kg`` [kg] and ``small_falls_per_year`` [1/yr], each when
        available.
    """
    from ..risk.measures import SimulationContext
    out = {}
    if result is not None:
        names = [c.name for c in result.scenario.collectors]
        out["context"] = SimulationContext(result.scenario, barrier_collector=barrier,
                                           road_collector=road if road in names else barrier,
                                           n_blocks=int(option_blocks), seed=int(seed))
        out["reference"] = result
    if road_hits is not None:
        out["coupled_road_hits"] = road_hits
    m_min = getattr(hazard.mass, "m_min", None)
    if m_min is not None and inventory is not None:
        small = inventory.masses[inventory.masses < m_min]
        out["small_fall_masses_kg"] = small
        out["small_falls_per_year"] = small.size / inventory.duration_years * rate_scale
    return out


def fence_checks_from_site(site) -> tuple:
    """(capacities kJ, heights m) of the fences to check: those of the site's fence and attenuator options
    (each at its own height), else hazard.fences_kj at hazard.fence_height_m.

    Parameters
    ----------
    site : Site
        The checked site.

    Returns
    -------
    capacities : tuple of float
        Energy capacities of the fences [kJ].
    heights : tuple of float
        Their heights [m].
    """
    opts = [o for o in site.mitigation["options"] if o.kind in ("fence", "attenuator") and o.x_m is None]
    if opts:
        return tuple(o.capacity_kj for o in opts), tuple(o.height_m for o in opts)
    fh = site.hazard["fence_height_m"]
    caps = tuple(site.hazard["fences_kj"])
    return caps, tuple(fh) if isinstance(fh, list) else tuple([fh] * len(caps))


def release_factor_for_road_record(hazard, share: float, context: dict, source: str = "",
                                   uncertainty=None) -> float:
    """Factor from falls recorded on the road to falls released: recorded / P(road | release), with P(road |
    release) from the same engine as the ranking (reach of the barrier line by mass, road share by mass, the
    inventory's small falls), so that doing nothing reproduces the recorded road falls exactly.  The released
    sizes are taken to follow the recorded law (an approximation: large blocks reach the road more often).

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard with the recorded rate (falls [1/yr] at or above m_min).
    share : float
        P(road | barrier line) [-] (:func:`road_share`).
    context : dict
        The slope model and small falls (:func:`study_context`).
    source : str, optional
        The site file, named in errors.
    uncertainty : riskrf.risk.mitigation_inputs.Uncertainty, optional
        The study's uncertain inputs (its material draws are switched off here).

    Returns
    -------
    float
        Released falls per fall recorded on the road [-].

    Raises
    ------
    SiteError
        When no simulated fall reaches the road.
    """
    from ..risk.mitigation import MitigationStudy, Option
    from .site import SiteError
    kw = {} if uncertainty is None else {"uncertainty": replace(uncertainty, materials={}, calibration=None)}
    probe = MitigationStudy(hazard=hazard, options=(Option("as recorded", "none"), Option("probe", "none")),
                            road_share=share, source=source or "rate_basis = 'road'", **context, **kw)
    road = probe.evaluate("as recorded").road_falls_per_year
    recorded = float(hazard.rate_per_year) + float(context.get("small_falls_per_year", 0.0))
    if not road > 0:
        raise SiteError(f"{source}: inventory.rate_basis = 'road': no simulated fall reaches the road, so the release "
                        "rate behind the recorded road falls cannot be derived; check the geometry or use "
                        "rate_basis = 'release'")
    return recorded / road


def draw_evaluator(site, inventory, scenario, n_blocks: int, option_blocks: int, seed, uncertainty, *,
                   rate_scale: float, rate_note, mitigation: dict, design_masses) -> tuple:
    """The assessment's chain for one draw of the trajectory model (``[model_uncertainty]``): the energy hazard
    simulated on ``scenario`` with ``n_blocks`` blocks, the road-basis release factor recomputed when the record
    counts road falls, and the mitigation study with ``option_blocks`` per option re-simulation and the study's
    uncertainty ``uncertainty``.  ``rate_scale``, ``rate_note``, ``mitigation`` and ``design_masses``: as the
    assessment used them (before its own release factor).  Returns (hazard, study, seeder run, road share).

    Parameters
    ----------
    site : Site
        The checked site.
    inventory : Inventory
        The site's inventory (masses [kg], duration [yr]).
    scenario : simulation.Scenario
        The slope with the draw's material values.
    n_blocks : int
        Blocks of the hazard's simulation.
    option_blocks : int
        Blocks per option re-simulation.
    seed : int
        Seed of every simulation (common random numbers across draws).
    uncertainty : riskrf.risk.mitigation_inputs.Uncertainty or None
        The study's uncertain inputs for this draw.
    rate_scale : float
        Factor [-] on the fitted rate, as the assessment used it.
    rate_note : str or None
        Note on the rate, as the assessment used it.
    mitigation : dict
        The site's mitigation keyword arguments of :class:`MitigationStudy`.
    design_masses : sequence of float or callable
        Design masses [kg] (or a function of the fit and rate [1/yr]), as the assessment used them.

    Returns
    -------
    hazard : EnergyHazard
        Energy hazard at the barrier line for the draw (falls [1/yr], energies [kJ]).
    study : MitigationStudy
        The mitigation study for the draw (costs [site currency]).
    result : simulation.SimulationResult
        The seeder run of ``scenario``.
    share : float
        P(road | barrier line) [-].
    """
    hz_cfg, inv_cfg = site.hazard, site.inventory
    collector, road = hz_cfg["collector"], hz_cfg["road_collector"]
    _, hz, result, hits = energy_hazard_from_inputs(
        inventory, m_min=inv_cfg["m_min_kg"], m_max=inv_cfg["m_max_kg"], rate_scale=rate_scale, scenario=scenario,
        collector=collector, n=n_blocks, seed=seed, mass_coupling=hz_cfg["mass_coupling"],
        design_masses_kg=design_masses, rate_note=rate_note, road_collector=road)
    share = road_share(result, collector, road)
    if inv_cfg.get("rate_basis", "release") == "road":
        factor = release_factor_for_road_record(
            hz, share, study_context(result, collector, road, option_blocks, seed, inventory, hz, rate_scale, hits),
            str(site.path), uncertainty=uncertainty)
        hz = replace(hz, rate_per_year=hz.rate_per_year * factor)
        rate_scale = rate_scale * factor
    study = MitigationStudy(hazard=hz, road_share=share, source=str(site.path), defaults_used=site.defaults_used,
                            **study_context(result, collector, road, option_blocks, seed, inventory, hz, rate_scale,
                                            hits),
                            **(dict(mitigation, uncertainty=uncertainty) if uncertainty is not None else mitigation))
    return hz, study, result, share


def fence_design_checks(options, energy) -> dict:
    """Option name -> verdict of its fence checks in ``energy`` (an EnergyAnalysis): "adequate" or "NOT ADEQUATE:
    <failed checks>", for the fence and attenuator options checked there; shown in the ranking itself.

    Parameters
    ----------
    options : sequence of Option
        The mitigation options.
    energy : EnergyAnalysis
        The energy study with its fence checks (keyed ``"<capacity> kJ / <height> m"``).

    Returns
    -------
    dict
        Option name -> ``"adequate"`` or ``"NOT ADEQUATE: <failed checks>"``.
    """
    out = {}
    for o in options:
        if o.kind not in ("fence", "attenuator") or o.capacity_kj is None or o.height_m is None:
            continue
        table = energy.fences.get(f"{o.capacity_kj:g} kJ / {o.height_m:g} m")
        if table is None:
            continue
        failed = "; ".join(table.loc[~table["adequate"], "check"])
        out[o.name] = "NOT ADEQUATE: " + failed if failed else "adequate"
    return out


def required_barrier_for_site(site, mitigation: dict, energy, site_design) -> tuple:
    """The options to rank with the required barrier among them, every fence's design verdict, and the required
    barrier itself.

    The verdicts are the fence checks of ``energy`` (:func:`fence_design_checks`), replaced by the governing design
    basis's checks (:func:`riskrf.risk.required_barrier.basis_design_checks`) for the fences the basis checked;
    those decide whether an option may be recommended.  The required barrier
    (:func:`riskrf.risk.required_barrier.required_barrier`) is costed with the site's ``[required_barrier]``
    table (or the ASSUMED default prices, scaled to the site's own priced fences) and appended to the options
    when it can be placed and ``[required_barrier] include`` is true.

    Parameters
    ----------
    site : Site
        The checked site.
    mitigation : dict
        Its mitigation tables (options, traffic, consequences, ...).
    energy : EnergyAnalysis
        Design energies [kJ] and fence checks.
    site_design : SiteDesign or None
        The design basis's requirement at the barrier line and the position search.

    Returns
    -------
    tuple
        ``(mitigation, checks, required)``: the tables with the required barrier among the options, option name
        -> design verdict, and the :class:`~riskrf.risk.required_barrier.RequiredBarrier` (None without a
        requirement or when ``include`` is false).
    """
    from ..risk.required_barrier import basis_design_checks, cost_model_from_site, required_barrier
    options = list(mitigation["options"])
    checks = fence_design_checks(options, energy)
    requirement = getattr(site_design, "requirement", None)
    if requirement is None:
        return mitigation, checks, None
    checks.update(basis_design_checks(requirement))
    exposed = mitigation.get("exposure", Exposure()).exposed_length_m
    fences = [(o.capacity_kj, o.height_m, o.capital_cost, exposed) for o in options
              if o.kind in ("fence", "attenuator") and o.x_m is None]
    model, include = cost_model_from_site(site.required_barrier, site_fences=fences, source=str(site.path))
    if not include:
        return mitigation, checks, None
    currency = mitigation["consequences"].currency if "consequences" in mitigation else ""
    required = required_barrier(requirement, getattr(site_design, "positions", None), model,
                                exposed_length_m=model.length_m or exposed, currency=currency,
                                source=str(site.path))
    if required.placeable and required.option.name not in {o.name for o in options}:
        mitigation = dict(mitigation, options=options + [required.option])
        checks[required.option.name] = required.verdict
    return mitigation, checks, required


def sensitivity_inputs(site, rate_scale: float | None = None) -> tuple:
    """(m_max values [kg], rate shares [-]) for the design-energy sensitivity: low, stated and high values.

    m_max: the site's uncertainty.m_max_kg range, else x0.5 and x2 of inventory.m_max_kg (only the stated value,
    None, when the law is not truncated); rate share: inventory.rate_scale x uncertainty.rate_factor, else x0.5
    and x2.  ``rate_scale`` replaces inventory.rate_scale (a rate from the site's rate model).

    Parameters
    ----------
    site : Site
        The checked site (``inventory`` and ``mitigation["uncertainty"]`` are read).
    rate_scale : float, optional
        Replaces inventory.rate_scale [-].

    Returns
    -------
    m_values : list of float or [None]
        Upper truncation masses [kg], sorted.
    shares : list of float
        Rate shares [-], sorted.
    """
    m_max = site.inventory["m_max_kg"]
    unc = site.mitigation.get("uncertainty")
    if m_max is None:
        m_values = [None]
    elif unc is not None and unc.m_max_kg is not None:
        m_values = sorted({float(unc.m_max_kg[0]), float(m_max), float(unc.m_max_kg[1])})
    else:
        m_values = [0.5 * m_max, float(m_max), 2.0 * m_max]
    share = float(site.inventory["rate_scale"] if rate_scale is None else rate_scale)
    lo, hi = (unc.rate_factor if unc is not None and unc.rate_factor[0] != unc.rate_factor[1] else (0.5, 2.0))
    return m_values, sorted({share * lo, share, share * hi})


def _ends(values):
    """(lowest, highest) of a sensitivity list, None when it holds one value or None (nothing to vary)."""
    v = [x for x in values if x is not None]
    return (min(v), max(v)) if len(v) > 1 else None


@dataclass
class Assessment:
    """Everything one ``riskrf assess`` run computed for a site, in the order of the chain.

    Fields: the :class:`~riskrf.app.site.Site` read, its :class:`~riskrf.frequency.inventory.Inventory`, the frequency analyses
    (power law, and annual maxima when dated), the simulation ``result`` (:class:`simulation.SimulationResult`),
    the :class:`~riskrf.hazard.energy_study.EnergyAnalysis` at the barrier line, the
    :class:`~riskrf.risk.mitigation.MitigationStudy` and its ``decision`` (recommendation dict), the ``seed`` and
    number of simulated blocks, ``warnings`` raised on the way, stage ``timings`` [s] and the site's rate model
    (``rates``, or None).  Written to files by :func:`write_assessment`; nothing here prints.
    """
    site: Site
    inventory: Inventory
    frequency: FrequencyAnalysis
    maxima_frequency: FrequencyAnalysis | None
    result: object
    energy: EnergyAnalysis
    study: MitigationStudy
    decision: dict
    seed: int
    n_blocks: int
    warnings: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    rates: object = None            # SiteRates of the site's [rates] model (riskrf.risk.site_rates), or None
    release_factor: float = 1.0     # rate_basis = "road": released falls per fall recorded on the road
    #: the governing design basis's requirement at the barrier line and along the profile (SiteDesign), or None
    design: object = None
    #: the trajectory model's uncertainty carried to the design energies and the ranking
    #: (:class:`~riskrf.app.model_uncertainty.ModelUncertaintyStudy`), None unless the site asks for it
    model_uncertainty: object = None
    #: whether the trajectory model is calibrated on this slope
    #: (:class:`~riskrf.hazard.trajectory_status.TrajectoryModelStatus`); its sentence leads the warnings when not
    trajectory_model: object = None
    #: figures already being drawn beside the computation: {"dir": Path, "pending": [part with result(), ...]}
    #: (see ``run_assessment(figures_dir=..., runner=...)``); empty when ``write_assessment`` draws them all.
    drawing: dict = field(default_factory=dict, repr=False)

    @property
    def rate_source(self) -> str:
        """Where the hazard's annual rate comes from, in words."""
        inv = self.inventory
        if self.site.inventory.get("rate_from") == "rate_model" and self.rates is not None:
            text = "rate model: " + self.rates.rate_text()
        else:
            text = (f"inventory: {inv.n_events:,} recorded falls in {inv.duration_years:.3g} years "
                    f"({self.frequency.power_law.rate_min:.4g} per year at or above m_min)")
        scale = self.site.inventory["rate_scale"]
        text += (f"; times rate_scale {scale:g} (typed: share of the recorded source above this road)"
                 if scale != 1 else "")
        if self.site.inventory.get("rate_basis", "release") == "road":
            return text + (f"; rate_basis = 'road': the record counts falls that reached the road, so the release "
                           f"rate is {self.release_factor:.4g} times it (1 / P(road | release), simulated; doing "
                           "nothing reproduces the recorded road falls)")
        return text + "; rate_basis = 'release': the record counts falls released from the slope"

    def summary(self) -> dict:
        """Every headline number, machine-readable, with units.

        Returns
        -------
        dict
            JSON-ready headline numbers (``summary.json``); the units are listed under ``units``: mass [kg], volume
            [m3], energy [kJ], height [m], velocity [m/s], rate [1/yr], return period [yr] and money [site currency].
        """
        fr, gr = self.frequency, self.frequency.power_law
        hz = self.energy.hazard
        ranking = self.decision["ranking"]
        nothing = ranking[ranking["kind"] == "none"]
        out = {
            "site": self.site.name, "riskrf_version": __version__, "seed": self.seed, "n_blocks": self.n_blocks,
            "units": {"mass": "kg", "volume": "m3", "energy": "kJ", "height": "m", "velocity": "m/s",
                      "rate": "1/yr", "return_period": "yr", "money": self.study.currency},
            "inventory": {"source": self.inventory.source, "events": self.inventory.n_events,
                          "duration_years": self.inventory.duration_years,
                          "density_kg_m3": self.inventory.density_kg_m3,
                          "density_is_default": self.inventory.density_is_default},
            "power_law": {"b": gr.b, "b_stderr": gr.b_stderr, "b_ci": list(gr.b_ci), "a": gr.a, "m_min_kg": gr.m_min,
                          "m_min_method": gr.m_min_method, "rate_min_per_year": gr.rate_min,
                          "bootstrap_p_value": fr.bootstrap_p},
            "whole_wall_design_masses": fr.design_masses().assign(basis=WHOLE_WALL_BASIS).to_dict(orient="records"),
            "whole_wall_design_masses_basis": WHOLE_WALL_BASIS,
            "site_design_masses": self.energy.site_masses.to_dict(orient="records")
            if self.energy.site_masses is not None else None,
            "design_block": self.energy.design_block.to_dict() if self.energy.design_block is not None else None,
            "design_energy_sensitivity": self.energy.sensitivity.to_dict(orient="records")
            if self.energy.sensitivity is not None else None,
            "design_energy_tornado": self.energy.tornado.to_dict() if self.energy.tornado is not None else None,
            "design_energy_interval_covers": INTERVAL_COVERS,
            "hazard": {"power_law_for_hazard": {"b": float(hz.mass.b), "m_max_kg": hz.mass.m_max,
                                                "m_min_kg": float(hz.mass.m_min)},
                       "mass_coupled": hz.mass_coupled,
                       "falls_per_year": hz.rate_per_year, "rate_source": self.rate_source,
                       "rate_basis": self.site.inventory.get("rate_basis", "release"),
                       "release_factor": self.release_factor,
                       "reach_probability": hz.reach_probability,
                       "arrivals_per_year": hz.arrival_rate,
                       "road_share": self.study.road_share,
                       "energy_p95_kj": float(hz.energy_percentile(95)[0]),
                       "energy_p99_kj": float(hz.energy_percentile(99)[0]),
                       "height_p95_m": float(hz.height_percentile(95)) if hz.heights_m is not None else None},
            "design_energies": self.energy.design.to_dict(orient="records"),
            "fences": self.energy.fence_verdicts().to_dict(orient="records"),
            "ranking": ranking.to_dict(orient="records"),
            "options": self.decision["options"],
            "recommendation": self.decision["recommendation"],
            "effort": self.decision.get("effort"),
            "required_barrier_option": (self.study.required_barrier.to_dict()
                                        if self.study.required_barrier is not None else None),
            "uncertainty": self.decision["uncertainty"],
            "best_option": ranking["option"].iloc[0],
            "second_option": ranking["option"].iloc[1],
            "break_even": self.decision["break_even"].to_dict(orient="records"),
            "value_of_information": self.decision["value_of_information"],
            "release_campaign": self.decision.get("release_campaign"),
            "individual_risk_do_nothing": float(nothing["individual_risk"].iloc[0]) if len(nothing) else None,
            "fn_zone": dict(zip(ranking["option"], ranking["fn_zone"])),
            "defaults_used": list(self.site.defaults_used),
            "warnings": self.warnings,
            "trajectory_model": self.trajectory_model.to_dict() if self.trajectory_model is not None else None,
            "timings_s": self.timings,
        }
        if self.rates is not None:
            out["rate_model"] = self.rates.summary()
        if self.model_uncertainty is not None:
            out["model_uncertainty"] = self.model_uncertainty.to_dict()
        if self.design is not None:
            out.update(self.design.to_dict())
        if fr.gumbel is not None or (self.maxima_frequency and self.maxima_frequency.gumbel is not None):
            src = fr if fr.gumbel is not None else self.maxima_frequency
            out["annual_maxima"] = {"source": src.inventory.source, "gumbel": dict(zip(src.gumbel.param_names,
                                                                                      src.gumbel.params)),
                                    "gev": dict(zip(src.gev.param_names, src.gev.params)) if src.gev else None,
                                    "deviance_test": src.deviance, "preferred_model": src.preferred_model()}
        return out


def run_assessment(site: Site, *, seed: int | None = None, n_blocks: int | None = None, log=None,
                   figures_dir=None, runner=None) -> Assessment:
    """Run the whole chain for a validated site; each stage is logged (``logging`` logger ``riskrf``, level INFO,
    or the callable ``log``) and timed in :attr:`Assessment.timings`.

    ``figures_dir``: a directory (created here, must not exist) that ``write_assessment`` will use as
    ``OUT/figures``; the figures and tables of each stage are then handed to the ``runner`` as they are ready
    (the command line's draws them on the other core beside the later stages) instead of all at the end.  The
    outputs are the same either way.

    ``runner``: where the work needed only later runs (the site's rate model, each stage's figures); see
    :mod:`riskrf.app.scheduling`.  The default, :class:`~riskrf.app.scheduling.InLine`, runs it in this process
    when it is needed; ``riskrf assess`` passes :class:`riskrf.cli.runner.TwoCores` (simulator compiled and
    figures drawn on the other core).

    Parameters
    ----------
    site : Site
        The validated site (:func:`riskrf.app.site.load_site`).
    seed : int, optional
        Seed of the simulations (default the site's ``hazard.seed``).
    n_blocks : int, optional
        Simulated blocks (default the site's ``hazard.n_blocks``).
    log : callable, optional
        ``log(str)`` for stage messages (default the ``riskrf`` logger at INFO).
    figures_dir : str or pathlib.Path, optional
        Directory for figures drawn beside the computation (see above).
    runner : object, optional
        The scheduling hook (``start``, ``beside``, ``before_simulation``; default
        :class:`~riskrf.app.scheduling.InLine`).

    Returns
    -------
    Assessment
        Every stage's result: frequency fit, simulation, energy study (energies [kJ]), mitigation study and
        decision (costs [site currency]), warnings and timings [s].
    """
    log = log or logger.info
    runner = InLine() if runner is None else runner
    figures = None if figures_dir is None else Path(figures_dir)
    pending = []
    if figures is not None:
        figures.mkdir()
        from ..report.files import prepare_drawing
        prepare_drawing()           # pyplot imported once here, not in each process drawing beside
    from ..report.mitigation_text import study_report

    seed = site.hazard["seed"] if seed is None else seed
    n_blocks = site.hazard["n_blocks"] if n_blocks is None else n_blocks
    timings = {}
    stages = 5

    def stage(i, text):
        log(f"[{i}/{stages}] {text}")
        return time.perf_counter()

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RiskrfWarning)
        hz_cfg = site.hazard
        runner.start(bool(hz_cfg["scenario"]), log)
        rates = _start_rates(site, runner)
        t = stage(1, "reading the inventory and fitting magnitude-frequency models")
        inventory, frequency, maxima_frequency = fit_site_inventory(site, seed)
        timings["fits"] = round(time.perf_counter() - t, 2)
        if figures is not None:
            pending.append(runner.beside(partial(_frequency_outputs, frequency, maxima_frequency, figures)))
        survey, rate_scale, rate_note, site_rates, m_max_values, shares, extra = _rate_and_design_inputs(
            site, inventory, rates)
        design_masses = partial(_design_masses, site=site, inventory=inventory, extra=extra)
        runner.before_simulation(timings)
        t = stage(2, f"simulating {n_blocks:,} trajectories" if hz_cfg["scenario"] else "reading velocities")
        gr, hazard, result, road_hits = _simulate_hazard(site, inventory, rate_scale, rate_note, n_blocks, seed,
                                                         design_masses)
        timings["simulation"] = round(time.perf_counter() - t, 2)
        release_factor, hazard, rate_scale, m_max_values, shares = _release_rate_of_road_record(
            site, inventory, hazard, result, road_hits, rate_scale, seed, m_max_values, shares)
        if figures is not None:
            pending.append(runner.beside(partial(_simulation_figures, result, hz_cfg["collector"], figures,
                                                 fences_to_draw(site))))

        t = stage(3, "computing the impact-energy hazard, design block, design energies and fence checks")
        energy, site_design = _energy_stage(site, inventory, gr, hazard, result, survey, m_max_values, shares,
                                            rate_scale, site_rates, seed)
        timings["energy"] = round(time.perf_counter() - t, 2)
        if figures is not None:
            from ..report.files import write_energy_study
            pending.append(runner.beside(partial(write_energy_study, energy, figures)))

        t = stage(4, "ranking mitigation options (expected total cost, break-even, tornado)")
        replicate = partial(draw_evaluator, site, inventory, rate_scale=rate_scale / release_factor,
                            rate_note=rate_note, design_masses=design_masses)
        mitigation, site_rates, study, decision, site_design = _decision_stage(
            site, inventory, hazard, result, road_hits, rate_scale, energy, rates, site_rates, site_design, seed,
            study_report, replicate=replicate if hz_cfg["scenario"] else None, n_blocks=n_blocks)
        timings["decision"] = round(time.perf_counter() - t, 2)
        model_uncertainty = _model_uncertainty_stage(
            site, inventory, hazard, energy, rate_scale, release_factor, rate_note, mitigation, design_masses, log,
            timings)
    notes = _assessment_notes(frequency, [str(c.message) for c in caught], site_rates, inventory)
    status = site_trajectory_status(site)
    if status.uncalibrated:
        notes.insert(0, status.text)
    return Assessment(site=site, inventory=inventory, frequency=frequency, maxima_frequency=maxima_frequency,
                      result=result, energy=energy, study=study, decision=decision, seed=seed, n_blocks=n_blocks,
                      warnings=notes, timings=timings, rates=site_rates, release_factor=release_factor,
                      design=site_design, model_uncertainty=model_uncertainty, trajectory_model=status,
                      drawing={"dir": figures, "pending": pending} if figures is not None else {})


def site_trajectory_status(site: Site):
    """Is the site's trajectory model calibrated on its slope?  (:func:`riskrf.hazard.trajectory_status.
    trajectory_model_status` of its scenario and calibration files.)

    Parameters
    ----------
    site : Site
        The checked site.

    Returns
    -------
    TrajectoryModelStatus
        The status and the sentence the outputs carry.
    """
    from ..hazard.trajectory_status import trajectory_model_status
    data = None
    if site.hazard.get("scenario"):
        from simulation.parameters import scenario_dict
        data, _ = scenario_dict(site.resolve(site.hazard["scenario"]))
    unc = site.mitigation.get("uncertainty") if site.mitigation else None
    mu = site.model_uncertainty or {}
    return trajectory_model_status(data, calibration_bootstrap=getattr(unc, "calibration_source", "") or None,
                                   posterior=mu.get("posterior"))


def _start_rates(site: Site, runner):
    """The site's rate model (hazard rate, closure rules), handed to the runner to evaluate beside the fits.

    Parameters
    ----------
    site : Site
        The validated site.
    runner : object
        The run's scheduling hook (:mod:`riskrf.app.scheduling`).

    Returns
    -------
    object or None
        The rate model being evaluated (its ``result()`` is the ``SiteRates``), None when the site has none.
    """
    if site.rates is None:
        return None
    from ..risk.site_rates import evaluate_rates
    inv_cfg = site.inventory
    return runner.beside(lambda: evaluate_rates(site.rates, site.path.parent, inv_cfg, site.mitigation["options"]))


def fit_site_inventory(site: Site, seed):
    """Read the site's inventory (and its annual maxima, if given) and fit the magnitude-frequency models: the
    fits stage of both the 2-D (:func:`run_assessment`) and the 3-D assessment
    (:func:`riskrf.app.assess3d.run_terrain_assessment`), so that both report the same fits (the site's m_min,
    500 bootstrap replicates; the hazard's law applies m_max on top).

    Parameters
    ----------
    site : Site
        The validated site; its ``[inventory]`` table names the files and the reader's options.
    seed : int or None
        Seed of the bootstrap of the fits.

    Returns
    -------
    inventory : Inventory
        The inventory read (masses in kg).
    frequency : FrequencyAnalysis
        Its magnitude-frequency analysis (500 bootstrap replicates).
    maxima_frequency : FrequencyAnalysis or None
        The analysis of the dated annual maxima (200 replicates), None when the site gives none.
    """
    inv_cfg = site.inventory
    from ..frequency.inventory.reader import READER_OPTIONS
    reader = {k: inv_cfg[k] for k in READER_OPTIONS if inv_cfg.get(k) is not None}
    inventory = read_inventory(site.resolve(inv_cfg["path"]), start=inv_cfg["start"], end=inv_cfg["end"],
                               duration_years=inv_cfg["duration_years"], density_kg_m3=inv_cfg["density_kg_m3"],
                               **reader)
    dated = read_inventory(site.resolve(inv_cfg["annual_maxima"])) if inv_cfg["annual_maxima"] else None
    frequency = analyse_inventory(inventory, m_min=inv_cfg["m_min_kg"], n_bootstrap=500, seed=seed)
    maxima_frequency = None
    if dated is not None:
        maxima_frequency = analyse_inventory(dated, n_bootstrap=200, seed=seed)
    return inventory, frequency, maxima_frequency


def _rate_and_design_inputs(site: Site, inventory, rates):
    """The block survey, the rate factor on the inventory's rate and the masses design values are read at.

    Parameters
    ----------
    site : Site
        The validated site.
    inventory : Inventory
        The site's inventory (masses in kg, density in kg/m3).
    rates : object or None
        The site's rate model being evaluated (``result()``); waited for when ``inventory.rate_from =
        "rate_model"``.

    Returns
    -------
    survey : numpy.ndarray or None
        Block volumes of the survey (m3), None without a survey.
    rate_scale : float
        Factor on the inventory's rate (dimensionless): ``rate_scale``, times the rate model's hazard factor
        when the rate comes from the rate model.
    rate_note : str or None
        How the rate was obtained, None when it is the inventory's times ``rate_scale``.
    site_rates : object or None
        The evaluated rate model when the rate comes from it, else None.
    m_max_values, shares : list
        The upper bounds (kg) and rate factors of the design-energy sensitivity (:func:`sensitivity_inputs`).
    extra : list of float
        Masses (kg) design values are read at: the percentile band of the design block, the largest m_max studied.
    """
    inv_cfg = site.inventory
    db_cfg = site.design_block
    survey = read_block_survey(site.resolve(db_cfg["survey"]), inventory.density_kg_m3) \
        if db_cfg["survey"] else None
    rate_scale, rate_note, site_rates = inv_cfg["rate_scale"], None, None
    if inv_cfg.get("rate_from") == "rate_model":
        site_rates = rates.result()
        rate_scale = inv_cfg["rate_scale"] * site_rates.hazard_factor(inventory)
        rate_note = "rate from the " + site_rates.rate_text() + (
            f"; times rate_scale {inv_cfg['rate_scale']:g}" if inv_cfg["rate_scale"] != 1 else "")
    m_max_values, shares = sensitivity_inputs(site, rate_scale)
    # masses design values are read at: the percentile band of the design block, the largest m_max studied
    extra = design_block_candidates_kg(rule=db_cfg["rule"], percentile=db_cfg["percentile"],
                                       survey_volumes_m3=survey, inventory=inventory,
                                       density_kg_m3=inventory.density_kg_m3)
    extra += [m for m in m_max_values if m is not None]
    return survey, rate_scale, rate_note, site_rates, m_max_values, shares, extra


def _design_masses(law, rate, *, site: Site, inventory, extra) -> list:
    """The masses above and the fragmentation alternative of the site's law (simulated, not borrowed).

    Parameters
    ----------
    law : GutenbergRichterFit
        The mass law of the hazard (kg).
    rate : float
        Its rate of falls at or above m_min (1/year).
    site : Site
        The validated site (design period, design-block and uncertainty tables).
    inventory : Inventory
        The site's inventory (masses in kg, density in kg/m3).
    extra : list of float
        Masses (kg) design values are read at anyway (:func:`_rate_and_design_inputs`).

    Returns
    -------
    list of float
        Masses (kg) to simulate: ``extra``, the fragmented design block if any, and the finest fragment when
        the uncertainty table fragments the blocks.
    """
    db_cfg = site.design_block
    frag = fragment_block_kg(law, rate, design_T=site.hazard["design_period_years"],
                             fractal_dimension=db_cfg["fractal_dimension"], iterations=db_cfg["iterations"],
                             percentile=db_cfg["percentile"], density_kg_m3=inventory.density_kg_m3)
    finest = []
    u = site.mitigation["uncertainty"]
    if u is not None and u.fractal_dimension:     # fragments travel: simulate down to the finest one
        masses = np.asarray(inventory.masses, dtype=float)
        finest = [min(float(law.m_min), float(masses[masses > 0].min(initial=np.inf)))
                  / 8.0 ** u.fragmentation_iterations]
    return extra + ([frag] if frag is not None else []) + finest


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
        inventory, m_min=inv_cfg["m_min_kg"], m_max=inv_cfg["m_max_kg"], rate_scale=rate_scale,
        scenario=site.resolve(hz_cfg["scenario"]) if hz_cfg["scenario"] else None,
        velocities=site.resolve(hz_cfg["velocities"]) if hz_cfg["velocities"] else None,
        collector=hz_cfg["collector"], n=n_blocks, seed=seed, reach_probability=hz_cfg["reach_probability"],
        mass_coupling=hz_cfg["mass_coupling"], design_masses_kg=design_masses,
        velocity_unit=hz_cfg["velocity_unit"], drop_height_m=hz_cfg.get("drop_height_m"), rate_note=rate_note,
        road_collector=hz_cfg["road_collector"])


def _release_rate_of_road_record(site: Site, inventory, hazard, result, road_hits, rate_scale: float, seed,
                                 m_max_values, shares):
    """Turn a record of falls that reached the road (``rate_basis = "road"``) into a release rate.

    The release rate is the recorded rate divided by P(road | release); with ``rate_basis = "release"`` (the
    default) everything is returned unchanged.

    Parameters
    ----------
    site : Site
        The validated site.
    inventory : Inventory
        The site's inventory (masses in kg).
    hazard : EnergyHazard
        The hazard at the recorded rate.
    result : object
        The simulation result (collectors at the barrier line and the road).
    road_hits : object
        The road hits of the simulation (:func:`energy_hazard_from_inputs`).
    rate_scale : float
        Factor on the inventory's rate (dimensionless).
    seed : int or None
        Seed of the option runs.
    m_max_values, shares : list
        The design-energy sensitivity inputs (:func:`sensitivity_inputs`).

    Returns
    -------
    tuple
        ``(release_factor, hazard, rate_scale, m_max_values, shares)``: the factor (dimensionless, 1.0 for a
        release record) and the inputs rescaled by it.
    """
    inv_cfg, hz_cfg = site.inventory, site.hazard
    release_factor = 1.0
    if inv_cfg.get("rate_basis", "release") == "road":
        # the record counts falls that reached the road: release rate = recorded / P(road | release)
        release_factor = release_factor_for_road_record(
            hazard, road_share(result, hz_cfg["collector"], hz_cfg["road_collector"]),
            study_context(result, hz_cfg["collector"], hz_cfg["road_collector"], hz_cfg["option_blocks"], seed,
                          inventory, hazard, rate_scale, road_hits), str(site.path),
            uncertainty=site.mitigation.get("uncertainty"))
        hazard = replace(hazard, rate_per_year=hazard.rate_per_year * release_factor)
        rate_scale = rate_scale * release_factor
        m_max_values, shares = sensitivity_inputs(site, rate_scale)
    return release_factor, hazard, rate_scale, m_max_values, shares


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
    block = design_block(hazard, rule=db_cfg["rule"], percentile=db_cfg["percentile"], survey_volumes_m3=survey,
                         survey_source=db_cfg["survey"], inventory=inventory,
                         sizes=resolve_sizes(inv_cfg["sizes"], inventory),
                         design_T=hz_cfg["design_period_years"], density_kg_m3=inventory.density_kg_m3,
                         fractal_dimension=db_cfg["fractal_dimension"], iterations=db_cfg["iterations"])
    sensitivity = design_energy_sensitivity(
        hazard, inventory.masses, inventory.duration_years, m_min=gr.m_min, m_max_values=m_max_values,
        rate_shares=shares, T=hz_cfg["design_period_years"]) \
        if hz_cfg["design_period_years"] * hazard.arrival_rate > 1 else None
    tornado = design_energy_tornado(
        hazard, design_T=hz_cfg["design_period_years"], block=block, masses_kg=inventory.masses,
        duration_years=inventory.duration_years, m_max_range=_ends(m_max_values),
        rate_share=rate_scale, rate_share_range=_ends(shares), sensitivity=sensitivity,
        **({"rate_label": "rate factor on the inventory's rate (rate model x rate_scale)"}
           if site_rates is not None else {})) \
        if sensitivity is not None else None
    fences, heights = fence_checks_from_site(site)
    energy = analyse_energy(hazard, fences=fences, fence_height_m=heights,
                            free_board_m=hz_cfg["free_board_m"], design_T=hz_cfg["design_period_years"],
                            density_kg_m3=inventory.density_kg_m3, n_bootstrap=hz_cfg["bootstrap"], seed=seed,
                            design_block=block, sensitivity=sensitivity, tornado=tornado)
    site_design = design_for_site(site, hazard, block, result, inventory.density_kg_m3, seed)
    return energy, site_design


def _decision_stage(site: Site, inventory, hazard, result, road_hits, rate_scale: float, energy, rates, site_rates,
                    site_design, seed, study_report, replicate=None, n_blocks: int | None = None):
    """Rank the mitigation options and re-run the recommended one on the site.

    Parameters
    ----------
    site : Site
        The validated site.
    inventory : Inventory
        The site's inventory (masses in kg).
    hazard : EnergyHazard
        The impact-energy hazard at the release rate.
    result : object
        The simulation result.
    road_hits : object
        The road hits of the simulation.
    rate_scale : float
        Factor on the inventory's rate (dimensionless).
    energy : EnergyAnalysis
        Design energies (kJ) and fence checks.
    rates : object or None
        The site's rate model being evaluated (``result()``); its closure rules resolve the closure options.
    site_rates : object or None
        The evaluated rate model so far.
    site_design : object
        The site's design masses.
    seed : int or None
        Seed of the option runs.
    study_report : callable
        :func:`riskrf.report.mitigation_text.study_report`.
    replicate : callable, optional
        :func:`draw_evaluator` with the assessment's rate and design masses bound: the study repeated with
        independent trajectory ensembles for the error budget (:func:`ensemble_replicates`); None: not repeated.
    n_blocks : int, optional
        Blocks of the site's simulation (default ``hazard.n_blocks``).

    Returns
    -------
    tuple
        ``(mitigation, site_rates, study, decision, site_design)``: the mitigation table used, the rate model,
        the :class:`MitigationStudy` with its fence design checks, the decision report and the site's design
        with the recommended option's run.
    """
    hz_cfg = site.hazard
    share = road_share(result, hz_cfg["collector"], hz_cfg["road_collector"])
    mitigation = site.mitigation
    if rates is not None:
        from ..risk.site_rates import resolve_closures
        site_rates = rates.result()
        mitigation = dict(mitigation, options=resolve_closures(mitigation["options"], site_rates))
    mitigation, checks, required = required_barrier_for_site(site, mitigation, energy, site_design)
    study = MitigationStudy(hazard=hazard, road_share=share, source=str(site.path),
                            defaults_used=site.defaults_used,
                            **study_context(result, hz_cfg["collector"], hz_cfg["road_collector"],
                                            hz_cfg["option_blocks"], seed, inventory, hazard,
                                            rate_scale, road_hits),
                            **mitigation)
    ensemble = ensemble_replicates(site, result, seed, replicate, mitigation, study.uncertainty,
                                   n_blocks=n_blocks) if replicate is not None else None
    study = replace(study, design_checks=checks, required_barrier=required, ensemble=ensemble)
    from ..risk.error_budget import adapt_effort
    study, effort = adapt_effort(study, log=logger.info)
    decision = study_report(study)
    decision["effort"] = effort.to_dict()
    decision["recommendation"]["reason"] += " " + effort.text()
    site_design = with_recommended_run(site_design, site, result, decision["recommendation"]["option"], seed,
                                       options=mitigation["options"])
    return mitigation, site_rates, study, decision, site_design


def ensemble_replicates(site: Site, result, seed, replicate, mitigation: dict, uncertainty, *,
                        n_blocks: int | None = None):
    """The mitigation study repeated with independent trajectory ensembles, for the error budget
    (:class:`riskrf.risk.error_budget.EnsembleReplicates`).

    Each of ``[uncertainty] ensemble_replicates`` replicates re-runs the chain (:func:`draw_evaluator`: the energy
    hazard's simulation, the road share and every option's re-simulation, on the slope's own materials: each
    material draw of the study is an independent ensemble already counted by its clustered error) with its own
    simulation seed and ``ensemble_effort`` of the blocks, and the same joint samples of the other inputs (common
    random numbers), so that the between-replicate variance is that of the common trajectory ensembles; it is
    multiplied by the effort (a variance falling as 1 / blocks).

    Parameters
    ----------
    site : Site
        The checked site.
    result : simulation.SimulationResult or None
        The site's simulation (None: no trajectory ensemble, nothing to repeat).
    seed : int
        The assessment's simulation seed; the replicates' seeds are derived from it.
    replicate : callable
        ``replicate(scenario, n_blocks, option_blocks, seed, uncertainty, mitigation=...)`` ->
        (hazard, study, result, share), :func:`draw_evaluator` with the assessment's rate bound.
    mitigation : dict
        The mitigation tables the study ranks (with the required barrier).
    uncertainty : riskrf.risk.mitigation_inputs.Uncertainty
        The study's uncertain inputs (``ensemble_replicates``, ``ensemble_effort``).
    n_blocks : int, optional
        Blocks of the site's simulation (default ``hazard.n_blocks``).

    Returns
    -------
    EnsembleReplicates or None
        Expected costs [currency] and P(best) [-] per replicate and option; None when off (fewer than 2
        replicates) or without a simulation.
    """
    from ..risk.error_budget import EnsembleReplicates
    R = int(uncertainty.ensemble_replicates)
    if R < 2 or result is None:
        return None
    n_full = int(site.hazard["n_blocks"] if n_blocks is None else n_blocks)
    effort = float(uncertainty.ensemble_effort)
    n = max(int(round(n_full * effort)), 1)
    option_blocks = max(int(round(site.hazard["option_blocks"] * effort)), 1)
    seeds = tuple(int(x) for x in np.random.SeedSequence([int(seed or 0), 40]).generate_state(R))
    # the replicates keep the slope's own materials: each material draw of the study is already an ensemble of
    # its own, whose noise its clustered error counts; what is common to all samples is the hazard's simulation
    # and the options' re-simulations, and that is what the replicates measure
    from .model_uncertainty import _without_material_draws
    reference_only = _without_material_draws(uncertainty)
    means, best, names = [], [], None
    for s in seeds:
        _, st, _, _ = replicate(result.scenario, n, option_blocks, s, reference_only, mitigation=mitigation)
        u = st.sampled_costs()
        names = tuple(u["names"])
        means.append(u["mean"])
        best.append(u["probability_best"])
    return EnsembleReplicates(names=names, mean=np.array(means), probability_best=np.array(best),
                              effort=min(n / n_full, 1.0), seeds=seeds)


def _model_uncertainty_stage(site: Site, inventory, hazard, energy, rate_scale: float, release_factor: float,
                             rate_note, mitigation, design_masses, log, timings: dict):
    """Carry the trajectory model's uncertainty to the decision, when the site asks for it.

    Parameters
    ----------
    site : Site
        The validated site; nothing is done when it has no ``[model_uncertainty]`` table.
    inventory : Inventory
        The site's inventory (masses in kg).
    hazard : EnergyHazard
        The reference impact-energy hazard.
    energy : EnergyAnalysis
        Its design energies (the return periods, years, are reused).
    rate_scale : float
        Factor on the inventory's rate (dimensionless), including ``release_factor``.
    release_factor : float
        Factor turning a road record into a release rate (dimensionless); each draw recomputes its own.
    rate_note : str or None
        How the rate was obtained.
    mitigation : dict
        The mitigation table used by the study.
    design_masses : callable
        ``design_masses(law, rate)``: masses (kg) to simulate.
    log : callable
        Called with one line of progress text.
    timings : dict
        Stage timings (s); ``"model_uncertainty"`` is added when the stage runs.

    Returns
    -------
    object or None
        The result of :func:`run_model_uncertainty`, None when the site does not ask for it.
    """
    if site.model_uncertainty is None:
        return None
    from .model_uncertainty import run_model_uncertainty
    t = time.perf_counter()
    log(f"      the trajectory model's uncertainty: {site.model_uncertainty['draws']} draws of the material "
        "parameters re-simulated (design energies, ranking, value of a field calibration)")
    evaluate = partial(draw_evaluator, site, inventory, rate_scale=rate_scale / release_factor,
                       rate_note=rate_note, mitigation=mitigation, design_masses=design_masses)
    model_uncertainty = run_model_uncertainty(
        site, evaluate, reference_hazard=hazard, design_T=site.hazard["design_period_years"],
        T=energy.design["T_years"].tolist(), log=log)
    timings["model_uncertainty"] = round(time.perf_counter() - t, 2)
    return model_uncertainty


def _assessment_notes(frequency, caught: list, site_rates, inventory) -> list:
    """The warnings of an assessment, each once, and the notes on the fits' reach.

    Parameters
    ----------
    frequency : FrequencyAnalysis
        The inventory's magnitude-frequency analysis.
    caught : list of str
        The warnings caught while the assessment ran, in order.
    site_rates : object or None
        The site's rate model, whose notes are added.
    inventory : Inventory
        The site's inventory (duration in years).

    Returns
    -------
    list of str
        The notes: warnings without repeats, then the extrapolation, bootstrap p and tail-size notes.
    """
    notes = []
    for w in list(frequency.warnings) + caught + list(site_rates.notes if site_rates else ()):
        if w not in notes:
            notes.append(w)
    T_max = float(max(frequency.design_masses()["T_years"]))
    if T_max > 2 * inventory.duration_years:
        notes.append(f"design values for {T_max:g} years extrapolate a {inventory.duration_years:.3g}-year "
                     "record far beyond the data")
    if frequency.bootstrap_p is not None and frequency.bootstrap_p <= 0.1:
        notes.append(f"the power law is questionable for this inventory (bootstrap p = {frequency.bootstrap_p:.3f})")
    if frequency.power_law.n_tail < 50:
        notes.append(f"only {frequency.power_law.n_tail} falls above m_min: the exponent b is uncertain")
    return notes


def write_assessment(a: Assessment, out: Path, log=None, runner=None) -> dict:
    """Write every output of an assessment into ``out`` (an empty directory); returns the summary.

    Parameters
    ----------
    a : Assessment
        The result of :func:`run_assessment`.
    out : pathlib.Path
        An empty, existing output directory.
    log : callable, optional
        ``log(str)`` for stage messages (default the ``riskrf`` logger at INFO).
    runner : object, optional
        Where the figures are drawn (:mod:`riskrf.app.scheduling`; default
        :class:`~riskrf.app.scheduling.InLine`, this process); pass the one given to :func:`run_assessment`.

    Returns
    -------
    dict
        :meth:`Assessment.summary` with paths relative to the site file's folder.
    """
    log = log or logger.info
    runner = InLine() if runner is None else runner
    from ..report.html import render_report
    from ..report.mitigation_text import write_mitigation_outputs, write_tree_figure
    from ..report.files import write_energy_study

    log("[5/5] writing the report, tables and figures")
    t = time.perf_counter()
    out = Path(out)
    figs = out / "figures"
    drawn = a.drawing.get("dir") is not None and figs.resolve() == Path(a.drawing["dir"]).resolve()
    if not drawn:
        figs.mkdir()

    # The figures are drawn in parts handed to the runner (the command line's draws them on the other core, see
    # riskrf.cli.runner); parts that run_assessment started beside its later stages are only waited for, while
    # this process draws the decision's.
    if drawn:
        tree = runner.beside(partial(write_tree_figure, a.study, figs))
        write_mitigation_outputs(a.study, a.decision, figs, tree_figure=False)
        for part in a.drawing["pending"] + [tree]:
            part.result()
    else:
        def simulation_and_decision_outputs():
            _simulation_figures(a.result, a.site.hazard["collector"], figs, fences_to_draw(a.site))
            write_mitigation_outputs(a.study, a.decision, figs)

        beside = runner.beside(simulation_and_decision_outputs)
        _frequency_outputs(a.frequency, a.maxima_frequency, figs)
        write_energy_study(a.energy, figs)
        beside.result()
    for name in ("summary.json", "completeness.csv", "whole_wall_design_masses.csv"):
        shutil.move(str(figs / name), str(out / ("frequency_" + name if name == "summary.json" else name)))
    for name in ("energy_summary.json", "design_energies.csv", "fence_checks.csv", "design_energy_sensitivity.csv",
                 "design_energy_tornado.csv", "design_block.csv", "site_design_masses.csv"):
        if (figs / name).exists():
            shutil.move(str(figs / name), str(out / name))
    for name in ("ranking.csv", "tornado.csv", "break_even.csv", "decision.json"):
        shutil.move(str(figs / name), str(out / name))
    if a.model_uncertainty is not None:
        a.model_uncertainty.write(out)
        a.model_uncertainty.figures(figs)
    a.timings["report"] = round(time.perf_counter() - t, 2)
    summary = a.summary()
    write_json(summary, out / "summary.json")
    if a.design is not None:
        _design_outputs(a, out, figs)
    from ..report.pdf import write_pdf_report
    # the PDF (from the assessment and the finished figures) on the other core while this one writes the rest
    pdf = runner.beside(partial(write_pdf_report, a, out / "report.pdf", figs))
    (out / "report.html").write_text(render_report(a, figs), encoding="utf-8")
    _copy_inputs(a, out / "inputs")
    relative_paths_in_json_files(out, a.site.path.parent)          # paths relative to the site file
    pdf.result()
    return relative_paths(summary, a.site.path.parent)


#: What the inventory fit's design-mass table is, in the outputs of an assessment.
WHOLE_WALL_BASIS = ("whole monitored wall (inventory fit), untruncated power law, rate not scaled: reference only, "
                    "not the site's design masses (site_design_masses.csv)")


def _frequency_outputs(frequency, maxima_frequency, figs: Path) -> None:
    """Tables and figures of the inventory's fits (and of the annual-maximum record, in a subfolder), their
    design-mass tables labelled as references, not the site's design masses."""
    from ..report.files import write_frequency_study
    write_frequency_study(frequency, figs, design_masses_name="whole_wall_design_masses", basis=WHOLE_WALL_BASIS)
    if maxima_frequency is not None:
        sub = figs / "annual_maxima"
        sub.mkdir()
        write_frequency_study(maxima_frequency, sub, design_masses_name="record_design_masses",
                               basis=f"annual-maximum record {Path(str(maxima_frequency.inventory.source)).name}: "
                                     "another record's fit, untruncated: reference only, not this site's design "
                                     "masses")


def fences_to_draw(site) -> list:
    """(x [m] or None for the barrier line, height [m], label) of the site's fence and attenuator options, else
    of the candidate fences of ``hazard.fences_kj``: what the profile figure draws at its height.

    Parameters
    ----------
    site : Site
        The checked site.

    Returns
    -------
    list of tuple
        ``(x [m] or None, height [m], label)`` per fence.
    """
    opts = [o for o in site.mitigation["options"] if o.kind in ("fence", "attenuator")]
    if opts:
        return [(o.x_m, o.height_m, f"{o.name} ({o.height_m:g} m high)" if f"{o.capacity_kj:g}" in o.name
                 else f"{o.name}: {o.capacity_kj:,.0f} kJ, {o.height_m:g} m high") for o in opts]
    caps, heights = fence_checks_from_site(site)
    return [(None, h, f"candidate fence {c:,.0f} kJ, {h:g} m") for c, h in zip(caps, heights)]


def _simulation_figures(result, collector: str, figs: Path, fences=()) -> None:
    """Trajectories (with the fences at their height), the barrier line's distributions and the envelopes
    (nothing for a velocity file).  A fence with x None stands at the ``collector`` line."""
    if result is None:
        return
    from ..report.files import write_simulation_figures
    line_x = result.scenario.collectors[result.scenario.collector_index(collector)].x
    fences = [(line_x if x is None else x, h, label) for x, h, label in fences]
    write_simulation_figures(result, figs, [collector], file_names={collector: "collector_distributions.png"},
                             fences=fences)

def _design_outputs(a: Assessment, out: Path, figs: Path) -> None:
    """The design basis's tables (design_requirement.csv, design_checks.csv, barrier_positions.csv) and figures
    (options on the profile, stop points, barrier positions, catchment retention)."""
    from ..report.design_figures import (catchment_figure, options_profile_figure, position_search_figure,
                                        stop_points_figure)
    from ..report.files import save_figure
    d = a.design
    d.summary().to_csv(out / "design_requirement.csv")
    if d.requirement is not None:
        d.requirement.candidates.to_csv(out / "design_checks.csv", index=False)
    if d.positions is not None:
        d.positions.table.to_csv(out / "barrier_positions.csv", index=False)
        save_figure(position_search_figure(d.positions), figs / "barrier_positions.png")
    if a.result is not None:
        sc = a.result.scenario
        save_figure(options_profile_figure(sc, a.site.mitigation["options"], barrier_x=d.barrier_x_m,
                                           road_x=d.road_x_m, requirement=d.requirement),
                    figs / "options_profile.png")
        ditches = [(o.x_m, o.x_m + o.width_m, o.name) for o in a.site.mitigation["options"]
                   if o.kind == "ditch" and o.x_m is not None and o.width_m is not None]
        save_figure(stop_points_figure(a.result, road_x=d.road_x_m, ditches=ditches,
                                       option=d.recommended), figs / "stop_points.png")
        if d.recommended is not None:
            from simulation.plotting import plot_profile
            ax = plot_profile(d.recommended[1])
            ax.set_title(f"Trajectories with the recommended option: {d.recommended[0]}", fontsize=10)
            save_figure(ax.figure, figs / "recommended_trajectories.png")
    if d.catchment is not None:
        d.catchment.curve.to_csv(out / "catchment_retention.csv", index=False)
        save_figure(catchment_figure(d.catchment), figs / "catchment_retention.png")


def _copy_inputs(a: Assessment, dest: Path) -> None:
    """Copy the site file and everything it names, with the version, seed and command, for exact reruns."""
    dest.mkdir()
    site = a.site
    text = site.path.read_text(encoding="utf-8")
    for table, key in (("inventory", "path"), ("inventory", "annual_maxima"), ("hazard", "scenario"),
                       ("hazard", "velocities"), ("design_block", "survey"), ("rates", "record"),
                       ("rates", "rainfall"), ("rates", "warnings"), ("model_uncertainty", "posterior")):
        rel = {"inventory": site.inventory, "hazard": site.hazard, "design_block": site.design_block,
               "rates": site.rates or {}, "model_uncertainty": site.model_uncertainty or {}}[table].get(key)
        if rel:
            src = site.resolve(rel)
            shutil.copy2(src, dest / src.name)
            text = text.replace(f'"{rel}"', f'"{src.name}"').replace(f"'{rel}'", f"'{src.name}'")
            side = src.with_suffix(".toml")
            if table in ("inventory", "rates") and side.exists():
                shutil.copy2(side, dest / side.name)
    (dest / site.path.name).write_text(text, encoding="utf-8")   # paths now point at the copies beside it
    (dest / "run.json").write_text(json.dumps({
        "riskrf_version": __version__, "seed": a.seed, "n_blocks": a.n_blocks, "site_file": site.path.name,
        "command": " ".join([Path(sys.argv[0]).name, *sys.argv[1:]]),   # the program by name, arguments as typed
        "python": platform.python_version(),
        "rerun": f"riskrf assess {site.path.name} --seed {a.seed} -n {a.n_blocks} --out DIR"},
        indent=2) + "\n", encoding="utf-8")
