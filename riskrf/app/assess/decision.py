"""The risk and decision stages of the chain: the mitigation study, its ranking and what feeds it.

- :func:`road_share`, :func:`study_context`: P(road | barrier line) and the slope model and small falls a
  :class:`~riskrf.risk.mitigation.MitigationStudy` derives option effects from;
- :func:`release_factor_for_road_record`, :func:`_release_rate_of_road_record`: a record of falls on the road
  (``rate_basis = "road"``) turned into a release rate;
- :func:`fence_design_checks`, :func:`required_barrier_for_site`: every fence's design verdict and the required
  barrier among the options;
- :func:`_decision_stage`: the options ranked, the recommended one re-run on the site (stage 4 of
  :func:`riskrf.app.assess.run.run_assessment`);
- :func:`draw_evaluator`, :func:`ensemble_replicates`, :func:`_model_uncertainty_stage`: the chain repeated for a
  draw of the trajectory model, for the error budget's repeated ensembles and the ``[model_uncertainty]`` study.
"""
from __future__ import annotations

import logging
import time
from dataclasses import replace
from functools import partial

import numpy as np

from ...risk.mitigation import MitigationStudy
from ..scheduling import Deferred
from ..site import Site, SiteMitigation
from ..site_design import with_recommended_run
from .hazard import energy_hazard_from_inputs
from .site_inputs import sensitivity_inputs

logger = logging.getLogger("riskrf")


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
    from ...risk.measures import SimulationContext
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
    from ...risk.mitigation import MitigationStudy, Option
    from ..site import SiteError
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
                   rate_scale: float, rate_note, mitigation: SiteMitigation, design_masses) -> tuple:
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
    mitigation : SiteMitigation
        The site's mitigation tables (:meth:`SiteMitigation.study_kwargs` are passed to :class:`MitigationStudy`).
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
    collector, road = hz_cfg.collector, hz_cfg.road_collector
    _, hz, result, hits = energy_hazard_from_inputs(
        inventory, m_min=inv_cfg.m_min_kg, m_max=inv_cfg.m_max_kg, rate_scale=rate_scale, scenario=scenario,
        collector=collector, n=n_blocks, seed=seed, mass_coupling=hz_cfg.mass_coupling,
        design_masses_kg=design_masses, rate_note=rate_note, road_collector=road)
    share = road_share(result, collector, road)
    if inv_cfg.rate_basis == "road":
        factor = release_factor_for_road_record(
            hz, share, study_context(result, collector, road, option_blocks, seed, inventory, hz, rate_scale, hits),
            str(site.path), uncertainty=uncertainty)
        hz = replace(hz, rate_per_year=hz.rate_per_year * factor)
        rate_scale = rate_scale * factor
    study = MitigationStudy(hazard=hz, road_share=share, source=str(site.path), defaults_used=site.defaults_used,
                            **study_context(result, collector, road, option_blocks, seed, inventory, hz, rate_scale,
                                            hits),
                            **(replace(mitigation, uncertainty=uncertainty) if uncertainty is not None
                               else mitigation).study_kwargs())
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


def required_barrier_for_site(site, mitigation: SiteMitigation, energy, site_design) -> tuple:
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
    mitigation : SiteMitigation
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
    from ...risk.required_barrier import basis_design_checks, cost_model_from_site, required_barrier
    options = list(mitigation.options)
    checks = fence_design_checks(options, energy)
    requirement = getattr(site_design, "requirement", None)
    if requirement is None:
        return mitigation, checks, None
    checks.update(basis_design_checks(requirement))
    exposed = mitigation.exposure.exposed_length_m
    fences = [(o.capacity_kj, o.height_m, o.capital_cost, exposed) for o in options
              if o.kind in ("fence", "attenuator") and o.x_m is None]
    model, include = cost_model_from_site(site.required_barrier, site_fences=fences, source=str(site.path))
    if not include:
        return mitigation, checks, None
    currency = mitigation.consequences.currency
    required = required_barrier(requirement, getattr(site_design, "positions", None), model,
                                exposed_length_m=model.length_m or exposed, currency=currency,
                                source=str(site.path))
    if required.placeable and required.option.name not in {o.name for o in options}:
        mitigation = replace(mitigation, options=options + [required.option])
        checks[required.option.name] = required.verdict
    return mitigation, checks, required


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
    if inv_cfg.rate_basis == "road":
        # the record counts falls that reached the road: release rate = recorded / P(road | release)
        release_factor = release_factor_for_road_record(
            hazard, road_share(result, hz_cfg.collector, hz_cfg.road_collector),
            study_context(result, hz_cfg.collector, hz_cfg.road_collector, hz_cfg.option_blocks, seed,
                          inventory, hazard, rate_scale, road_hits), str(site.path),
            uncertainty=site.mitigation.uncertainty)
        hazard = replace(hazard, rate_per_year=hazard.rate_per_year * release_factor)
        rate_scale = rate_scale * release_factor
        m_max_values, shares = sensitivity_inputs(site, rate_scale)
    return release_factor, hazard, rate_scale, m_max_values, shares


def _decision_stage(site: Site, inventory, hazard, result, road_hits, rate_scale: float, energy, rates, site_rates,
                    site_design, seed, study_report, replicate=None, n_blocks: int | None = None, beside=None):
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
    beside : callable, optional
        The runner's ``beside`` (:mod:`riskrf.app.scheduling`): where the repeated ensembles run (default: in
        this process, when they are needed).

    Returns
    -------
    tuple
        ``(mitigation, site_rates, study, decision, site_design)``: the mitigation table used, the rate model,
        the :class:`MitigationStudy` with its fence design checks, the decision report and the site's design
        with the recommended option's run.
    """
    hz_cfg = site.hazard
    share = road_share(result, hz_cfg.collector, hz_cfg.road_collector)
    mitigation = site.mitigation
    if rates is not None:
        from ...risk.site_rates import resolve_closures
        site_rates = rates.result()
        mitigation = replace(mitigation, options=resolve_closures(mitigation.options, site_rates))
    mitigation, checks, required = required_barrier_for_site(site, mitigation, energy, site_design)
    study = MitigationStudy(hazard=hazard, road_share=share, source=str(site.path),
                            defaults_used=site.defaults_used, design_checks=checks, required_barrier=required,
                            **study_context(result, hz_cfg.collector, hz_cfg.road_collector,
                                            hz_cfg.option_blocks, seed, inventory, hazard,
                                            rate_scale, road_hits),
                            **mitigation.study_kwargs())
    if replicate is not None:
        # the repeated ensembles beside (the command line's runner: on the other core) while this process
        # computes the study's slope models and option chains, which they do not change
        ensemble = (beside or Deferred)(partial(ensemble_replicates, site, result, seed, replicate, mitigation,
                                                study.uncertainty, n_blocks=n_blocks))
        study.parameter_ranges()
        study = study.with_ensemble(ensemble.result())
    from ...risk.error_budget import adapt_effort
    study, effort = adapt_effort(study, log=logger.info)
    decision = study_report(study)
    decision["effort"] = effort.to_dict()
    decision["recommendation"]["reason"] += " " + effort.text()
    site_design = with_recommended_run(site_design, site, result, decision["recommendation"]["option"], seed,
                                       options=mitigation.options)
    return mitigation, site_rates, study, decision, site_design


def ensemble_replicates(site: Site, result, seed, replicate, mitigation: SiteMitigation, uncertainty, *,
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
    mitigation : SiteMitigation
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
    from ...risk.error_budget import EnsembleReplicates
    R = int(uncertainty.ensemble_replicates)
    if R < 2 or result is None:
        return None
    n_full = int(site.hazard.n_blocks if n_blocks is None else n_blocks)
    effort = float(uncertainty.ensemble_effort)
    n = max(int(round(n_full * effort)), 1)
    option_blocks = max(int(round(site.hazard.option_blocks * effort)), 1)
    seeds = tuple(int(x) for x in np.random.SeedSequence([int(seed or 0), 40]).generate_state(R))
    # the replicates keep the slope's own materials: each material draw of the study is already an ensemble of
    # its own, whose noise its clustered error counts; what is common to all samples is the hazard's simulation
    # and the options' re-simulations, and that is what the replicates measure
    from ..model_uncertainty import _without_material_draws
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
    mitigation : SiteMitigation
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
    from ..model_uncertainty import run_model_uncertainty
    t = time.perf_counter()
    log(f"      the trajectory model's uncertainty: {site.model_uncertainty.draws} draws of the material "
        "parameters re-simulated (design energies, ranking, value of a field calibration)")
    evaluate = partial(draw_evaluator, site, inventory, rate_scale=rate_scale / release_factor,
                       rate_note=rate_note, mitigation=mitigation, design_masses=design_masses)
    model_uncertainty = run_model_uncertainty(
        site, evaluate, reference_hazard=hazard, design_T=site.hazard.design_period_years,
        T=energy.design["T_years"].tolist(), log=log)
    timings["model_uncertainty"] = round(time.perf_counter() - t, 2)
    return model_uncertainty
