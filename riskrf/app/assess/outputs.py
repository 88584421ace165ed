"""Writing an assessment (stage 5): :func:`write_assessment` fills an empty folder with report.html, report.pdf,
summary.json, the CSV tables, the PNG figures and a copy of the inputs with the package version and seed.

The helpers draw the figures of each stage (:func:`_frequency_outputs`, :func:`_simulation_figures` with
:func:`fences_to_draw`, :func:`_design_outputs`); :func:`riskrf.app.assess.run.run_assessment` hands the first two
to the runner as soon as their stage is done.  :func:`_copy_inputs` copies the site file and every file it names.
"""
from __future__ import annotations

import json
import logging
import platform
import shutil
import sys
import time
from functools import partial
from pathlib import Path

from ... import __version__
from ...io.outputs import relative_paths, relative_paths_in_json_files, write_json
from ..scheduling import InLine
from .result import WHOLE_WALL_BASIS, Assessment
from .site_inputs import fence_checks_from_site

logger = logging.getLogger("riskrf")


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
    from ...report.html import render_report
    from ...report.mitigation_text import write_mitigation_figures, write_mitigation_outputs, write_tree_figure
    from ...report.files import write_energy_study

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
    from ...report.pdf import write_pdf_report
    summary = pdf = gate = None
    try:
        if drawn:
            # The PDF first, beside the decision's figures: it lays out its pages (fonts, title page, tables) and
            # at each figure not written yet waits until its file appears or the gate opens (every figure written).
            # A *.png present is whole (save_figure renames it into place), so the earlier stages' figures still
            # being drawn are simply not finished yet.
            gate = runner.gate() if hasattr(runner, "gate") else None
            if gate is not None:
                pdf = runner.beside(partial(write_pdf_report, a, out / "report.pdf", figs, wait=gate.wait,
                                            finished=sorted(figs.rglob("*.png"))))
            # the decision's and the design's figures beside this process's tables and summary (but those
            # run_assessment handed to the runner as soon as their inputs were known, waited for with them)
            early = a.drawing.get("early", ())
            parts = list(a.drawing["pending"])
            if "mitigation" not in early:
                parts.append(runner.beside(partial(write_mitigation_figures, a.study, a.decision, figs)))
            if "tree" not in early:
                parts.append(runner.beside(partial(write_tree_figure, a.study, figs)))
            if a.design is not None:
                parts += [runner.beside(partial(_design_figures, a, figs, part)) for part in (0, 1)
                          if f"design_{part}" not in early]
            write_mitigation_outputs(a.study, a.decision, figs, tree_figure=False, figures=False)
            # the summary (about a second: the percentiles of the hazard, every table as records) while the
            # figures are drawn; its stage timings are completed below
            summary = a.summary()
            for part in parts:
                part.result()
        else:
            def simulation_and_decision_outputs():
                _simulation_figures(a.result, a.site.hazard.collector, figs, fences_to_draw(a.site))
                write_mitigation_outputs(a.study, a.decision, figs)

            beside = runner.beside(simulation_and_decision_outputs)
            _frequency_outputs(a.frequency, a.maxima_frequency, figs)
            write_energy_study(a.energy, figs)
            beside.result()
        for name in ("summary.json", "completeness.csv", "whole_wall_design_masses.csv"):
            shutil.move(str(figs / name), str(out / ("frequency_" + name if name == "summary.json" else name)))
        for name in ("energy_summary.json", "design_energies.csv", "fence_checks.csv",
                     "design_energy_sensitivity.csv", "design_energy_tornado.csv", "design_block.csv",
                     "site_design_masses.csv"):
            if (figs / name).exists():
                shutil.move(str(figs / name), str(out / name))
        for name in ("ranking.csv", "tornado.csv", "break_even.csv", "decision.json"):
            shutil.move(str(figs / name), str(out / name))
        if a.model_uncertainty is not None:
            a.model_uncertainty.write(out)
            a.model_uncertainty.figures(figs)
        if gate is not None:
            gate.open()                                 # every figure is written: the PDF goes on
        a.timings["report"] = round(time.perf_counter() - t, 2)
        if summary is None:
            summary = a.summary()
        summary["timings_s"] = a.timings
        write_json(summary, out / "summary.json")
        if a.design is not None:
            _design_outputs(a, out, figs, figures=not drawn)
        if pdf is None:
            # the PDF (from the assessment and the finished figures) on the other core while this one writes
            pdf = runner.beside(partial(write_pdf_report, a, out / "report.pdf", figs))
        (out / "report.html").write_text(render_report(a, figs), encoding="utf-8")
        _copy_inputs(a, out / "inputs")
        relative_paths_in_json_files(out, a.site.path.parent)          # paths relative to the site file
        pdf.result()
    finally:
        if gate is not None:          # opened (a PDF waiting in a child goes on), its read end closed here
            getattr(gate, "close", gate.open)()
    return relative_paths(summary, a.site.path.parent)


def _frequency_outputs(frequency, maxima_frequency, figs: Path) -> None:
    """Tables and figures of the inventory's fits (and of the annual-maximum record, in a subfolder), their
    design-mass tables labelled as references, not the site's design masses."""
    from ...report.files import write_frequency_study
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
    opts = [o for o in site.mitigation.options if o.kind in ("fence", "attenuator")]
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
    from ...report.files import write_simulation_figures
    line_x = result.scenario.collectors[result.scenario.collector_index(collector)].x
    fences = [(line_x if x is None else x, h, label) for x, h, label in fences]
    write_simulation_figures(result, figs, [collector], file_names={collector: "collector_distributions.png"},
                             fences=fences)


def _design_outputs(a: Assessment, out: Path, figs: Path, figures: bool = True) -> None:
    """The design basis's tables (design_requirement.csv, design_checks.csv, barrier_positions.csv,
    catchment_retention.csv) and, unless ``figures`` is False (drawn apart by :func:`_design_figures`), figures."""
    d = a.design
    d.summary().to_csv(out / "design_requirement.csv")
    if d.requirement is not None:
        d.requirement.candidates.to_csv(out / "design_checks.csv", index=False)
    if d.positions is not None:
        d.positions.table.to_csv(out / "barrier_positions.csv", index=False)
    if d.catchment is not None:
        d.catchment.curve.to_csv(out / "catchment_retention.csv", index=False)
    if figures:
        _design_figures(a, figs)


def _design_figures(a: Assessment, figs: Path, part: int | None = None) -> None:
    """The design basis's figures: barrier positions and options on the profile (``part`` 0), stop points,
    trajectories with the recommended option and catchment retention (``part`` 1); both parts when ``part`` is
    None."""
    draw_design_figures(a.design, a.result, a.site, figs, part)


def draw_design_figures(d, result, site, figs: Path, part: int | None = None) -> None:
    """The figures of :func:`_design_figures` from the site's design ``d`` (``SiteDesign``), the site's
    simulation ``result`` (or None) and the ``site``.  Part 0 needs only what the energy stage found (barrier
    positions, requirement), so :func:`~riskrf.app.assess.run.run_assessment` hands it to the runner then; part 1
    needs the recommended option's run.

    Parameters
    ----------
    d : riskrf.app.site_design.SiteDesign
        The site's design (barrier positions, requirement, recommended option's run).
    result : simulation.SimulationResult or None
        The site's simulation.
    site : Site
        The checked site (its mitigation options).
    figs : pathlib.Path
        Folder the PNG figures are written into.
    part : int, optional
        0 or 1 (see above); both when None.
    """
    from ...report.design_figures import (catchment_figure, options_profile_figure, position_search_figure,
                                        stop_points_figure)
    from ...report.files import save_figure
    if part in (None, 0):
        if d.positions is not None:
            save_figure(position_search_figure(d.positions), figs / "barrier_positions.png")
        if result is not None:
            save_figure(options_profile_figure(result.scenario, site.mitigation.options,
                                               barrier_x=d.barrier_x_m, road_x=d.road_x_m,
                                               requirement=d.requirement),
                        figs / "options_profile.png")
    if part in (None, 1):
        if result is not None:
            ditches = [(o.x_m, o.x_m + o.width_m, o.name) for o in site.mitigation.options
                       if o.kind == "ditch" and o.x_m is not None and o.width_m is not None]
            save_figure(stop_points_figure(result, road_x=d.road_x_m, ditches=ditches,
                                           option=d.recommended), figs / "stop_points.png")
            if d.recommended is not None:
                from simulation.plotting import plot_profile
                ax = plot_profile(d.recommended[1])
                ax.set_title(f"Trajectories with the recommended option: {d.recommended[0]}", fontsize=10)
                save_figure(ax.figure, figs / "recommended_trajectories.png")
        if d.catchment is not None:
            save_figure(catchment_figure(d.catchment), figs / "catchment_retention.png")


def _copy_inputs(a: Assessment, dest: Path) -> None:
    """Copy the site file and everything it names, with the version, seed and command, for exact reruns."""
    dest.mkdir()
    site = a.site
    text = site.path.read_text(encoding="utf-8")
    for table, key in (("inventory", "path"), ("inventory", "annual_maxima"), ("hazard", "scenario"),
                       ("hazard", "velocities"), ("design_block", "survey"), ("rates", "record"),
                       ("rates", "rainfall"), ("rates", "warnings"), ("model_uncertainty", "posterior")):
        section = getattr(site, table)              # rates and model_uncertainty are None when absent
        rel = getattr(section, key) if section is not None else None
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
