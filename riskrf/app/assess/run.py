"""The chain for one site, stage by stage: :func:`run_assessment` (fits -> simulation -> energy -> decision, each
stage logged and timed) and :func:`_assessment_notes`, the warnings and notes the outputs carry.

The stages live in :mod:`~riskrf.app.assess.site_inputs` (1, fits), :mod:`~riskrf.app.assess.hazard` (2 and 3,
hazard and design energies), :mod:`~riskrf.app.assess.decision` (4, ranking) and
:mod:`~riskrf.app.assess.outputs` (5, :func:`~riskrf.app.assess.outputs.write_assessment`).
"""
from __future__ import annotations

import logging
import time
import warnings
from functools import partial
from pathlib import Path

from ...core.validation import RiskrfWarning
from ..scheduling import InLine
from ..site import Site
from .decision import _decision_stage, _model_uncertainty_stage, _release_rate_of_road_record, draw_evaluator
from .hazard import _energy_stage, _simulate_hazard
from .outputs import _frequency_outputs, _simulation_figures, draw_design_figures, fences_to_draw
from .result import Assessment
from .site_inputs import (_design_masses, _rate_and_design_inputs, _start_rates, fit_site_inventory,
                          site_trajectory_status)

logger = logging.getLogger("riskrf")


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
    pending, early = [], set()        # work handed to the runner; which of the report's figures it draws early
    if figures is not None:
        figures.mkdir()
        from ...report.files import prepare_drawing
        prepare_drawing()           # pyplot imported once here, not in each process drawing beside
    from ...report.mitigation_text import study_report

    seed = site.hazard.seed if seed is None else seed
    n_blocks = site.hazard.n_blocks if n_blocks is None else n_blocks
    timings = {}
    stages = 5

    def stage(i, text):
        log(f"[{i}/{stages}] {text}")
        return time.perf_counter()

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RiskrfWarning)
        hz_cfg = site.hazard
        runner.start(bool(hz_cfg.scenario), log)
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
        t = stage(2, f"simulating {n_blocks:,} trajectories" if hz_cfg.scenario else "reading velocities")
        gr, hazard, result, road_hits = _simulate_hazard(site, inventory, rate_scale, rate_note, n_blocks, seed,
                                                         design_masses)
        timings["simulation"] = round(time.perf_counter() - t, 2)
        release_factor, hazard, rate_scale, m_max_values, shares = _release_rate_of_road_record(
            site, inventory, hazard, result, road_hits, rate_scale, seed, m_max_values, shares)
        if figures is not None:
            pending.append(runner.beside(partial(_simulation_figures, result, hz_cfg.collector, figures,
                                                 fences_to_draw(site))))

        t = stage(3, "computing the impact-energy hazard, design block, design energies and fence checks")
        energy, site_design = _energy_stage(site, inventory, gr, hazard, result, survey, m_max_values, shares,
                                            rate_scale, site_rates, seed)
        timings["energy"] = round(time.perf_counter() - t, 2)
        if figures is not None:
            from ...report.files import write_energy_study
            pending.append(runner.beside(partial(write_energy_study, energy, figures)))
            if site_design is not None:         # barrier positions and options on the profile: known now
                pending.append(runner.beside(partial(draw_design_figures, site_design, result, site, figures, 0)))
                early.add("design_0")

        t = stage(4, "ranking mitigation options (expected total cost, break-even, tornado)")
        decision_report = study_report
        if figures is not None:
            def decision_report(study):         # the study is final: its tree drawn beside the ranking's report
                from ...report.mitigation_text import write_mitigation_figures, write_tree_figure
                from ...risk.campaign import release_campaign_value
                # the value of a release campaign (the longest part of the report) first, beside the rest
                campaign = runner.beside(partial(release_campaign_value, study))
                pending.append(runner.beside(partial(write_tree_figure, study, figures)))
                early.add("tree")
                # its tornado and F-N figures too, beside the rest of the report
                tornado = study.tornado()
                pending.append(runner.beside(partial(write_mitigation_figures, study, {"tornado": tornado},
                                                     figures)))
                early.add("mitigation")
                return study_report(study, tornado=tornado, campaign=campaign)
        replicate = partial(draw_evaluator, site, inventory, rate_scale=rate_scale / release_factor,
                            rate_note=rate_note, design_masses=design_masses)
        mitigation, site_rates, study, decision, site_design = _decision_stage(
            site, inventory, hazard, result, road_hits, rate_scale, energy, rates, site_rates, site_design, seed,
            decision_report, replicate=replicate if hz_cfg.scenario else None, n_blocks=n_blocks,
            beside=runner.beside)
        timings["decision"] = round(time.perf_counter() - t, 2)
        if figures is not None and site_design is not None:     # the recommended option's run is known now
            pending.append(runner.beside(partial(draw_design_figures, site_design, result, site, figures, 1)))
            early.add("design_1")
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
                      drawing={"dir": figures, "pending": pending, "early": early} if figures is not None else {})


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
