"""report.pdf: the assessment as a deliverable a checking engineer can sign.

A4 pages with a title block (project, site, location, revision, date, author, checker from the site file's
``[report]`` table), page numbers "page X of N", a table of contents, the design-values sheet, the design basis
and its checks, the barrier-position search, the slope model (vertices with segment angles, materials with
their sources), every option drawn on the profile, the stop points, the ditch retention, the hazard, the
ranking and the assumptions; data of other sites (a regional record) in an appendix.

This module writes the document and the body of each section (:data:`BODIES`, one per
:attr:`riskrf.report.sections.Section.key`).  The fonts, the A4 page with its title block, the tables and figures
and the number formatting are in :mod:`riskrf.report.pdf_layout`; the rows both report formats print (design values,
slope model, run-out) in :mod:`riskrf.report.report_rows`.

Engine: fpdf2 (pure Python, installs with ``pip install .`` alone, no system libraries; tables, outline and
table of contents built in).  Text is set in DejaVu Sans, the font matplotlib ships, so Greek letters and
symbols print on any machine.
"""
from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from . import sections as S
from .format import cell
from .pdf_layout import _Report, _toc, fmt, title_block, year
from .report_rows import design_values_rows, runout_rows, slope_tables
from .sections import render as render_sections


def write_pdf_report(a, path, figs, *, wait=None, finished=None) -> Path:
    """Write report.pdf for the assessment ``a`` (figures read from ``figs``); returns the path.

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.
    path : str or path
        The PDF written.
    figs : str or path
        Folder of its figures (PNG).
    wait : callable, optional
        ``wait(path)``, called before each figure that is not in ``finished`` (the figures may still be drawn
        beside this work when it starts): it returns when that figure's file exists (False) or every figure is
        written (True; it is not called again).
    finished : collection of str or path, optional
        Figures known to be written already (``wait`` is not called for them); default none.

    Returns
    -------
    pathlib.Path
    """
    figs = Path(figs)
    tb = title_block(a.site)
    rep = _Report(tb, wait=wait, finished=finished)
    pdf = rep.pdf
    _title_page(rep, a, tb)

    # ---- contents -------------------------------------------------------------------------------
    pdf.add_page()
    pdf.insert_toc_placeholder(_toc, pages=1)       # it starts the next page itself
    rep.fresh_page = True

    render_sections(a, {key: partial(fn, rep, a, figs) for key, fn in BODIES.items()},
                    lambda sec: rep.section(sec.title, appendix=sec.appendix))
    path = Path(path)
    tmp = path.with_suffix(".pdf.part")
    pdf.output(str(tmp))
    tmp.replace(path)
    return path


def _title_page(rep, a, tb):
    """Write the title page: title block, design statement, recommendation and signature fields.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    tb : dict
        The title-block fields (:func:`title_block`).
    """
    pdf = rep.pdf
    d = a.design
    req = d.requirement if d is not None else None
    pdf.add_page()
    pdf.set_font("DejaVu", "B", 18)
    pdf.multi_cell(0, 9, "Rock fall hazard assessment and barrier design", new_x="LMARGIN", new_y="NEXT")
    pdf.set_font("DejaVu", "", 12)
    pdf.multi_cell(0, 7, tb["project"], new_x="LMARGIN", new_y="NEXT")
    pdf.ln(4)
    rep.kv([("project", tb["project"]), ("site", tb["site"]), ("location", tb["location"]),
            ("client", tb["client"]), ("revision", tb["revision"]), ("date", tb["date"]),
            ("author", tb["author"]), ("checker", tb["checker"]),
            ("software", f"riskrf {_version()}"),
            ("seed; simulated blocks", f"{a.seed}; {a.n_blocks:,}")], size=9.5)
    if d is not None and req is None:
        rep.heading("Design statement")
        rep.text(f"{d.basis.basis}: " + "; ".join(d.notes), size=10, style="B")
    if req is not None:
        rep.heading("Design statement")
        rep.text(req.text() + ".", size=10, style="B")
        rep.text(d.basis.text(), size=8.5)
    rec = a.decision["recommendation"]
    rep.text(f"Recommended option by expected total cost and tolerability: {rec['option'] or 'none'} ({rec['basis']}).",
             size=10)
    rep.text("Signature fields: author ____________________   checker ____________________", size=9.5)


def _design_values_sheet(rep, a, figs, s):
    """Write the design values sheet (:func:`design_values_rows`).

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment; its ``design.requirement`` is not None.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    rep.kv(design_values_rows(a), widths=(2, 3))
    rep.text("Energies in kJ, lengths in m.  The shares stopped / over / through take bounce height and energy "
             "of the arriving falls (under the site's mass law) as independent.", size=8)


def _design_checks(rep, a, figs, s):
    """Write the design basis, its factors, the requirement at the barrier line and the candidate fences' checks.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment; its ``design`` is not None.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    d = a.design
    req = d.requirement
    rep.text(d.basis.text())
    if req is None:
        rep.text("; ".join(d.notes), size=9)
    rep.caption("Partial factors of the design basis")
    rep.table(["factor", "value"], [[k, fmt(v, 3)] for k, v in d.basis.factors.items()], widths=[2, 1])
    if req is None:
        return
    rep.sub("Requirement at the barrier line")
    rep.caption("What the design basis requires at the barrier line")
    rep.table(["quantity", "value"], [[k, fmt(v) if not isinstance(v, str) else v]
                                      for k, v in req.summary()["value"].items()], widths=[3, 2],
              align=["LEFT", "RIGHT"])
    if len(req.candidates):
        rep.sub("Checks of the candidate fences")
        rep.caption(S.T_CANDIDATES)
        rep.table(["fence", "check", "demand", "capacity", "unit", "adequate"],
                  [[r["fence"], r["check"], fmt(r["demand"]), fmt(r["capacity"]), r["unit"],
                    "not given" if r["adequate"] is None or (isinstance(r["adequate"], float)
                                                              and np.isnan(r["adequate"]))
                    else ("yes" if r["adequate"] else "NO")]
                   for _, r in req.candidates.iterrows()], widths=[2, 4, 1.2, 1.2, 0.7, 1])
        rep.text("Elongation: state the kit's maximum elongation at MEL (from its European Technical "
                 "Assessment) in [design] elongation_m to check it; the permitted value is the clearance to the "
                 "road divided by gamma_d (ONR 24810: also at most the clearance less 1 m).", size=8)


def _barrier_positions(rep, a, figs, s):
    """Write the barrier-position search: the requirement at each searched position and the cheapest one.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment; its ``design.positions`` is not None.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    d = a.design
    t = d.positions.table
    rep.text(f"The requirement of {d.basis.basis} repeated at {len(t)} positions from one simulation of "
             f"{d.positions.n:,} blocks across the site's mass range.")
    rep.caption(S.T_POSITIONS)
    rep.table(["x [m]", "ground z [m]", "reaching [%]", "arrivals per year", "E_d [kJ]",
               "required MEL [kJ]", "product class [kJ]", "net height [m]", "to road [m]"],
              [[fmt(r["x_m"], 4), fmt(r["ground_z_m"], 3), f"{100 * r['reach_share']:.1f}",
                fmt(r["arrivals_per_year"]), fmt(r["E_d_kj"]), fmt(r["required_mel_kj"]),
                fmt(r["required_class_kj"]) if np.isfinite(r["required_class_kj"]) else "none",
                fmt(r["required_net_height_m"]), fmt(r["clearance_m"], 3)] for _, r in t.iterrows()])
    best = d.positions.cheapest()
    if best is not None:
        rep.text(f"Smallest product class at x = {fmt(best['x_m'], 4)} m: {fmt(best['required_class_kj'])} kJ, "
                 f"{fmt(best['required_net_height_m'])} m.")
    else:
        rep.text("No searched position can be protected by a single certified kit of the listed classes.")
    rep.figures(figs, s, max_height=150)


def _slope_model(rep, a, figs, s):
    """Write the slope model: the scenario's profile vertices with segment angles and its materials' sources.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment; its site's ``hazard`` table names a scenario.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    site = a.site
    sc, vert, mats = slope_tables(site)
    rep.text(f"Scenario {Path(str(site.hazard.scenario)).name}: {sc.description.strip()}", size=8.5)
    rep.sub("Profile vertices and segment angles")
    rep.table(list(S.SLOPE_VERTEX_COLUMNS), vert, widths=[0.8, 1, 1, 2, 2])
    rep.sub("Materials and the source of their values")
    rep.table(list(S.SLOPE_MATERIAL_COLUMNS), mats,
              widths=[1.1, 1.6, 1.6, 1.0, 1.0, 1.0, 4.3], size=7,
              align=["LEFT", "LEFT", "LEFT", "RIGHT", "LEFT", "RIGHT", "LEFT"])


def _options_profile(rep, a, figs, s):
    """Write every option drawn on the profile.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    rep.figures(figs, s, max_height=110)


def _runout(rep, a, figs, s):
    """Write the stop points with their run-out statistics.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    rep.figures(figs, s, max_height=120)
    rep.figure(figs / "recommended_trajectories.png", "Trajectories on the slope with the recommended option",
               max_height=100)
    rows = runout_rows(getattr(a, "design", None))
    if rows:
        rep.caption("Run-out of the simulated blocks")
        rep.kv(rows)


def _catchment(rep, a, figs, s):
    """Write the catchment ditch: widths needed for each retention beside the Modified Ritchie Criterion, the chart.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment; its ``design.catchment`` is not None.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    c = a.design.catchment
    widths, rule = S.catchment_tables(c)
    rep.text(S.catchment_text(c))
    rep.frame(widths, S.T_CATCHMENT_WIDTHS, widths=[1, 2])
    rep.frame(rule, S.T_RITCHIE, widths=[2, 3], align=["LEFT", "LEFT"])
    rep.text(S.RITCHIE_CAVEAT, size=8)
    if c.chart is not None:
        rep.frame(c.chart, "Published chart against the re-simulation")
    rep.figures(figs, s, max_height=100)


def _trajectories(rep, a, figs, s):
    """Write the trajectories at the barrier line: the scenario, the simulation summary and its figures.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    hz = a.energy.hazard
    if a.result is None:
        rep.text(hz.notes[0] if hz.notes else "velocities from a file")
        return
    res = a.result
    rep.text(f"Scenario {res.scenario.name}: {res.scenario.description.strip()}", size=8.5)
    rep.text("The speeds, heights and energies of this table are of the scenario seeder's own masses: they describe "
             "how the slope behaves, they design nothing (the design basis designs with the site's mass law).",
             size=8.5)
    summ = res.summary().drop(index=list(S.SOFTWARE_METRICS), errors="ignore")
    rep.caption("Simulation summary")
    rep.table(["item", "value"], [[str(k), " ".join(cell(v) for v in row.values)] for k, row in summ.iterrows()],
              widths=[3, 2])
    rep.figures(figs, s, max_height=110)
    rep.figure(figs / "collector_distributions.png",
               "Speed, bounce height and energy at the barrier line (of the simulated blocks)", max_height=110)


def _hazard(rep, a, figs, s):
    """Write the impact-energy hazard at the barrier line: rates, return-period energies, the design block.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    hz = a.energy.hazard
    rep.text(f"Falls per year at the source {fmt(hz.rate_per_year)}; reach probability {fmt(hz.reach_probability)}; "
             f"arrivals per year {fmt(hz.arrival_rate)}.  Rate: {a.rate_source}.")
    de = a.energy.design
    rep.caption("Design energies by return period")
    rep.table(["return period [years]", "annual exceedance", "energy [kJ]", "95 % interval [kJ]",
               "probability in 50 years"],
              [[year(r["T_years"]), fmt(r["annual_exceedance"]), fmt(r["energy_kj"]),
                f"{fmt(r['ci_low_kj'])} - {fmt(r['ci_high_kj'])}", fmt(r["probability_in_50_years"])]
               for _, r in de.iterrows()])
    if a.energy.design_block is not None:
        alt = a.energy.design_block.alternatives
        rep.sub("Design block and its alternatives")
        rep.table(["rule", "mass [kg]", "volume [m³]", "diameter [m]", "v95 [m/s]", "energy at v95 [kJ]", "chosen"],
                  [[r["rule"], fmt(r["mass_kg"]), fmt(r["volume_m3"]), fmt(r["diameter_m"]),
                    fmt(r["velocity_p95_ms"]), fmt(r["energy_at_v95_kj"]), "yes" if r["chosen"] else ""]
                   for _, r in alt.iterrows()], widths=[3, 1, 1, 1, 1, 1.2, 0.7])
        rep.text("Which value designs: the governing basis above; the p95 energy of arriving falls under the site's "
                 "law and the return-period energies are shown for comparison only.", size=8)
    rep.figures(figs, s, max_height=110)


def _fence_checks(rep, a, figs, s):
    """Write the fence checks against MEL and SEL (for comparison; the design basis governs).

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    for name, table in a.energy.fences.items():
        rep.sub(name)
        rep.frame(table, f"Checks of {name}", size=7)


def _road_risk(rep, a, figs, s):
    """Write the risk to road users: Bunce et al. (1997) per lane, individual and societal risk, the F-N curves.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    rep.text(S.road_risk_text(a), size=8.5)
    rep.frame(S.bunce_table(a), S.T_BUNCE, widths=[3.2, 1, 1, 1.1, 1.1, 1.3], size=7.2)
    rep.frame(S.road_risk_table(a), S.T_RISK, digits=2, widths=[2.2, 1, 1, 1, 1, 1, 1.3], size=7.2)
    for name, cap in s.figures:
        rep.figure(figs / name, f"{cap} ({a.study.criteria.fn_diagram})", max_height=110)


def _decision(rep, a, figs, s):
    """Write the mitigation decision: the recommendation, the design checks of every option, the ranking by expected
    total cost, the break-even values and the tornado chart.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    rank = a.decision["ranking"]
    cur = a.study.currency
    lines = S.recommendation_lines(a)
    rep.text(lines[0], size=10, style="B")
    for line in lines[1:]:
        rep.text(line, size=8.5)
    rep.sub("Design checks of the options")
    rep.text("An option whose design checks fail stays in the ranking, marked NOT ADEQUATE, and is never "
             "recommended.", size=8.5)
    rep.frame(S.design_checks_table(a), S.T_DESIGN_CHECKS, widths=[0.8, 2.2, 1.3, 5.6, 1.5], size=7,
              align=["RIGHT", "LEFT", "LEFT", "LEFT", "LEFT"])
    rep.sub("Costs")
    rep.caption(f"{S.T_RANKING} [{cur}]")
    adequate = rank["design_adequate"] if "design_adequate" in rank else [True] * len(rank)
    rep.table(["option", f"capital [{cur}]", f"expected total cost [{cur}]", "5-95 % [" + cur + "]",
               "P(cheapest)", "road falls per year", "individual risk per year", "societal risk",
               "tolerable", "adequate"],
              [[r["option"], fmt(r["capital"]), fmt(r["expected_total_cost"]),
                f"{fmt(r['cost_p05'])} - {fmt(r['cost_p95'])}", f"{r['probability_best']:.0%}",
                fmt(r["road_falls_per_year"]), fmt(r["individual_risk"]), str(r["fn_zone"]),
                "yes" if r["meets_criteria"] else "no", "yes" if ok else "NO"]
               for (_, r), ok in zip(rank.iterrows(), adequate)],
              widths=[1.9, 1.3, 1.3, 1.8, 1.4, 1, 1.1, 1.2, 1.1, 1.3], size=6.8)
    rep.text("Tolerable: meets the tolerability criteria (individual and societal risk); adequate: passes its "
             "design checks (see the table above).  An option that is not adequate is never recommended.", size=8)
    opts = a.decision.get("options_table")
    if opts is not None and len(opts):       # every effect's basis, ASSUMED parts labelled (as in report.html)
        rep.caption("Mitigation options and where their effect comes from")
        rep.table(["option", "what it is and assumes", "falls kept off the road", "effect from"],
                  [[r["option"], str(r["what it is and assumes"]), f"{r['effectiveness']:.0%}", str(r["effect_basis"])]
                   for _, r in opts.iterrows()], widths=[1.9, 5.6, 1.3, 4.6], size=6.5)
    ec = a.study.economics
    rep.text(f"Expected total cost = capital + present value of renewals, maintenance, repairs and replacements + "
             f"present value of expected losses, over {ec.horizon_years:g} years at {ec.discount_rate:.1%}; mean "
             f"and 5-95 % over {a.decision['uncertainty']['samples']:,} joint samples of the uncertain inputs.",
             size=8)
    be = a.decision["break_even"]
    be = be[np.isfinite(be["break_even"])]
    if len(be):
        rep.sub("Break-even: input values at which the two cheapest options at central values tie")
        rep.frame(be, S.T_BREAK_EVEN, size=7, widths=[2.2] + [1] * (be.shape[1] - 2) + [3.2],
                  align=["LEFT"] + ["RIGHT"] * (be.shape[1] - 2) + ["LEFT"])
    rep.figures(figs, s, max_height=100)
    voi = a.decision["value_of_information"]
    rep.text(f"Value of perfect information about the rate of falls: {fmt(voi['evpi'])} {cur}; about all sampled "
             f"inputs at once: {fmt(voi['evpi_all_sampled_inputs'])} {cur} (the most that investigations settling "
             "them are worth).", size=8.5)
    campaign = a.decision.get("release_campaign")
    if campaign is not None and a.model_uncertainty is None:
        rep.text(f"Value of a release campaign, priced from the {campaign['draws']} material draws of the ranking "
                 f"(stated ranges, uniform): {campaign['verdict']}.", size=8.5)


def _model_uncertainty(rep, a, figs, s):
    """Write the trajectory model uncertainty: design energy and ranking over draws of the material parameters.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment; its ``model_uncertainty`` is not None.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    mu, cur = a.model_uncertainty, a.study.currency
    rep.text(f"The slope re-simulated for {mu.ranking.n_draws} draws of its material parameters ({mu.basis}).",
             size=8.5)
    for line in mu.energy.text(mu.design_T):
        rep.text(line, size=8.5)
    rank_mu = mu.ranking.summary()
    rep.table(["option", f"expected total cost [{cur}]", f"trajectory model 5-95 % [{cur}]", "P(best | model)",
               "cost variance from the model"],
              [[r["option"], fmt(r["expected_total_cost"]), f"{fmt(r['model_cost_p05'])} - "
                f"{fmt(r['model_cost_p95'])}", f"{r['probability_best_given_model']:.2f}",
                f"{r.get('share_of_variance_from_trajectory_model', float('nan')):.0%}"]
               for _, r in rank_mu.iterrows()], widths=[2.2, 1.3, 1.9, 1, 1.2], size=7.2)
    rep.text(mu.verdict(), size=8.5, style="B")
    rep.figure(figs / "design_energy_model_uncertainty.png",
               f"The {mu.design_T:g}-year energy of each draw with its bootstrap interval.", max_height=90)


def _site_data(rep, a, figs, s):
    """Write the site's inventory and the completeness of its record.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    inv = a.inventory
    rep.kv([("inventory", Path(str(inv.source)).name), ("recorded falls", f"{inv.n_events:,}"),
            ("record length", f"{fmt(inv.duration_years)} years")])
    comp = inv.completeness().reset_index().head(60)
    rep.sub("Completeness")
    rep.frame(comp, "Completeness of the record by year", size=7)
    if a.rates is not None and not S.rates_transferred(a):
        rep.text("Rate model: " + a.rates.rate_text(), size=8.5)
    elif a.rates is not None:
        rep.text(f"The rate model is fitted to another site's record: see {S.section_number(a, 'other_sites')}.",
                 size=8.5)


def _magnitude_frequency(rep, a, figs, s):
    """Write the magnitude-frequency law of the inventory.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    gr = a.frequency.power_law
    rep.kv([("power-law exponent b", f"{fmt(gr.b)} ± {fmt(gr.b_stderr, 2)}"), ("m_min", f"{fmt(gr.m_min)} kg"),
            ("falls per year at or above m_min", fmt(gr.rate_min))])
    if a.energy.site_masses is not None:
        rep.frame(a.energy.site_masses.drop(columns="law"),
                  "Design masses of the site's law: " + str(a.energy.site_masses["law"].iloc[0]), size=7)
    rep.figures(figs, s, max_height=110)


def _annual_maxima_of(rep, mf, sub):
    """Write the Gumbel fit of a frequency study's annual maxima and its plot."""
    rep.kv([("record", Path(str(mf.inventory.source)).name), ("events", f"{mf.inventory.n_events:,}"),
            ("years", f"{year(mf.inventory.duration_years)}")])
    rep.frame(mf.gumbel.summary().reset_index(), "Gumbel fit of the annual maxima", size=7.5)
    rep.figure(sub / "gumbel_plot.png", "Gumbel probability plot", max_height=100)


def _annual_maxima(rep, a, figs, s):
    """Write the extreme values of the site's annual maxima, or where they are (another record) or why not.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    if a.frequency.gumbel is not None:
        _annual_maxima_of(rep, a.frequency, figs)
    elif a.maxima_frequency is not None and a.maxima_frequency.gumbel is not None:
        rep.text("Not fitted to this site's inventory (it has no dates). The dated record the site file names "
                 f"(inventory.annual_maxima) is fitted in {S.section_number(a, 'other_sites')}, with the data of "
                 "other sites: it does not enter the design values.")
    else:
        rep.text("Not fitted: the inventory has no dates, so there are no annual maxima, and the site file names no "
                 "dated record (inventory.annual_maxima).")


def _assumptions(rep, a, figs, s):
    """Write the assumptions, defaults and warnings.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    from ..io.outputs import relative_paths
    for w in a.warnings:
        rep.text("• " + str(relative_paths(str(w), a.site.path.parent)), size=8.5)
    if a.site.defaults_used:
        rep.sub("Defaults applied (not stated in the site file)")
        for entry in a.site.defaults_used:
            rep.text("• " + str(entry), size=8)


def _other_sites(rep, a, figs, s):
    """Write the data of other sites: a regional record's annual maxima, a transferred rate model.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    rep.text("These records are not this site's: they show the methods (annual maxima, rainfall rate model) and "
             "do not enter the design values.", size=9)
    mf = a.maxima_frequency
    if mf is not None and mf.gumbel is not None:
        rep.sub("Annual maxima of the regional record")
        _annual_maxima_of(rep, mf, figs / "annual_maxima")
    if S.rates_transferred(a):
        rep.text("Rate model: " + a.rates.rate_text(), size=8.5)


def _run_record(rep, a, figs, s):
    """Write the run record.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    s : riskrf.report.sections.Section
        The section.
    """
    rep.caption("Run record")
    rep.kv(S.run_record(a))


#: Body of each report section (riskrf.report.sections), called as fn(rep, a, figs, section).
BODIES = {
    "design_values": _design_values_sheet, "design_basis": _design_checks, "positions": _barrier_positions,
    "slope_model": _slope_model, "options_profile": _options_profile, "runout": _runout, "catchment": _catchment,
    "trajectories": _trajectories, "hazard": _hazard, "fence_checks": _fence_checks, "road_risk": _road_risk,
    "decision": _decision, "model_uncertainty": _model_uncertainty, "site_data": _site_data,
    "magnitude_frequency": _magnitude_frequency, "annual_maxima": _annual_maxima, "assumptions": _assumptions,
    "other_sites": _other_sites, "run_record": _run_record}


def _version():
    from .. import __version__
    return __version__


__all__ = ["write_pdf_report"]
