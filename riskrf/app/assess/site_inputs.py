"""What the chain reads from a site file before it simulates: the inventory and its fits, the rate model, the block
survey, the sensitivity inputs, the masses to simulate, the fences to check and whether the trajectory model is
calibrated.

- :func:`fit_site_inventory`: the fits stage (inventory and annual maxima read, magnitude-frequency models fitted),
  shared by the 2-D chain (:func:`riskrf.app.assess.run.run_assessment`) and the 3-D one
  (:func:`riskrf.app.assess3d.run_terrain_assessment`);
- :func:`_start_rates`: the site's rate model handed to the runner to evaluate beside the fits;
- :func:`_rate_and_design_inputs`, :func:`sensitivity_inputs`, :func:`_design_masses`: the block survey, the
  factor on the inventory's rate, the design-energy sensitivity inputs and the masses [kg] the simulation covers;
- :func:`fence_checks_from_site`: the capacities [kJ] and heights [m] of the fences to check;
- :func:`site_trajectory_status`: is the trajectory model calibrated on this slope.
"""
from __future__ import annotations

import numpy as np

from ...frequency.inventory.reader import read_inventory
from ...frequency.study import analyse_inventory
from ...hazard.design_block import design_block_candidates_kg, fragment_block_kg, read_block_survey
from ..site import Site


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
    opts = [o for o in site.mitigation.options if o.kind in ("fence", "attenuator") and o.x_m is None]
    if opts:
        return tuple(o.capacity_kj for o in opts), tuple(o.height_m for o in opts)
    fh = site.hazard.fence_height_m
    caps = tuple(site.hazard.fences_kj)
    return caps, tuple(fh) if isinstance(fh, list) else tuple([fh] * len(caps))


def sensitivity_inputs(site, rate_scale: float | None = None) -> tuple:
    """(m_max values [kg], rate shares [-]) for the design-energy sensitivity: low, stated and high values.

    m_max: the site's uncertainty.m_max_kg range, else x0.5 and x2 of inventory.m_max_kg (only the stated value,
    None, when the law is not truncated); rate share: inventory.rate_scale x uncertainty.rate_factor, else x0.5
    and x2.  ``rate_scale`` replaces inventory.rate_scale (a rate from the site's rate model).

    Parameters
    ----------
    site : Site
        The checked site (``inventory`` and ``mitigation.uncertainty`` are read).
    rate_scale : float, optional
        Replaces inventory.rate_scale [-].

    Returns
    -------
    m_values : list of float or [None]
        Upper truncation masses [kg], sorted.
    shares : list of float
        Rate shares [-], sorted.
    """
    m_max = site.inventory.m_max_kg
    unc = site.mitigation.uncertainty
    if m_max is None:
        m_values = [None]
    elif unc is not None and unc.m_max_kg is not None:
        m_values = sorted({float(unc.m_max_kg[0]), float(m_max), float(unc.m_max_kg[1])})
    else:
        m_values = [0.5 * m_max, float(m_max), 2.0 * m_max]
    share = float(site.inventory.rate_scale if rate_scale is None else rate_scale)
    lo, hi = (unc.rate_factor if unc is not None and unc.rate_factor[0] != unc.rate_factor[1] else (0.5, 2.0))
    return m_values, sorted({share * lo, share, share * hi})


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
    from ...hazard.trajectory_status import trajectory_model_status
    data = None
    if site.hazard.scenario:
        from simulation.parameters import scenario_dict
        data, _ = scenario_dict(site.resolve(site.hazard.scenario))
    unc = site.mitigation.uncertainty
    mu = site.model_uncertainty
    return trajectory_model_status(data, calibration_bootstrap=getattr(unc, "calibration_source", "") or None,
                                   posterior=mu.posterior if mu is not None else None)


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
    from ...risk.site_rates import evaluate_rates
    return runner.beside(lambda: evaluate_rates(site.rates, site.path.parent, site.inventory,
                                                site.mitigation.options))


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
    from ...frequency.inventory.reader import READER_OPTIONS
    reader = {k: getattr(inv_cfg, k) for k in READER_OPTIONS if getattr(inv_cfg, k) is not None}
    inventory = read_inventory(site.resolve(inv_cfg.path), start=inv_cfg.start, end=inv_cfg.end,
                               duration_years=inv_cfg.duration_years, density_kg_m3=inv_cfg.density_kg_m3,
                               **reader)
    dated = read_inventory(site.resolve(inv_cfg.annual_maxima)) if inv_cfg.annual_maxima else None
    frequency = analyse_inventory(inventory, m_min=inv_cfg.m_min_kg, n_bootstrap=500, seed=seed)
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
    survey = read_block_survey(site.resolve(db_cfg.survey), inventory.density_kg_m3) \
        if db_cfg.survey else None
    rate_scale, rate_note, site_rates = inv_cfg.rate_scale, None, None
    if inv_cfg.rate_from == "rate_model":
        site_rates = rates.result()
        rate_scale = inv_cfg.rate_scale * site_rates.hazard_factor(inventory)
        rate_note = "rate from the " + site_rates.rate_text() + (
            f"; times rate_scale {inv_cfg.rate_scale:g}" if inv_cfg.rate_scale != 1 else "")
    m_max_values, shares = sensitivity_inputs(site, rate_scale)
    # masses design values are read at: the percentile band of the design block, the largest m_max studied
    extra = design_block_candidates_kg(rule=db_cfg.rule, percentile=db_cfg.percentile,
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
    frag = fragment_block_kg(law, rate, design_T=site.hazard.design_period_years,
                             fractal_dimension=db_cfg.fractal_dimension, iterations=db_cfg.iterations,
                             percentile=db_cfg.percentile, density_kg_m3=inventory.density_kg_m3)
    finest = []
    u = site.mitigation.uncertainty
    if u is not None and u.fractal_dimension:     # fragments travel: simulate down to the finest one
        masses = np.asarray(inventory.masses, dtype=float)
        finest = [min(float(law.m_min), float(masses[masses > 0].min(initial=np.inf)))
                  / 8.0 ** u.fragmentation_iterations]
    return extra + ([frag] if frag is not None else []) + finest
