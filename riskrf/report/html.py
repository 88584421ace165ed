"""The self-contained HTML report of an assessment (figures embedded, no network needed).

Built with :class:`riskrf.report.format.Document`: numbered sections, tables and figures, a table of
contents, a viewport tag for phones and a print stylesheet (A4, no table or figure split across
pages).  Numbers carry the significant figures their uncertainty supports (:func:`sig`), money is
written for a manager (:func:`money`), column headers are words with units, and no absolute path of
the machine that ran it appears.
"""
from __future__ import annotations

import datetime as _dt
import re
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd

from .. import __version__
from ..hazard.energy_study import INTERVAL_COVERS, sensitivity_grid
from ..hazard.velocity_models import PairedSamples
from ..risk.road_risk import fn_zone
from .format import Document, cell, human_header, money, probability, sig
from .format import escape as _e
from . import sections as S
from .sections import SOFTWARE_METRICS  # noqa: F401  (re-exported: riskrf.report.html.SOFTWARE_METRICS)
from .sections import render as render_sections


def _name(path) -> str:
    """A file named by its name only: the report never shows the machine's directories."""
    return Path(str(path)).name


#: Directory part of an absolute path in text.  Not inside a base64 data URI, where "/" always follows one
#: of [A-Za-z0-9+/=,], nor in "km/h", "1/4" or closing tags.
_ABSOLUTE_DIRS = re.compile(r"(?<![\w.:/&;+=,<-])/(?:[\w.-]+/)+(?=[\w.-])")


#: Reader's names of the site-file fields that can appear in the assumptions table (the field name is kept
#: beside the label); a field not listed here is named from its own name (``human_header``).
_FIELD_LABELS = {
    "inventory.rate_from": "rate of falls taken from",
    "inventory.rate_scale": "rate share of the inventory at this slope",
    "inventory.sizes": "what the inventory's sizes measure",
    "hazard.collector": "collector line of the barrier",
    "hazard.road_collector": "collector line of the road",
    "hazard.n_blocks": "simulated blocks",
    "hazard.reach_probability": "probability of reaching the barrier line (velocity file)",
    "hazard.fences_kj": "fence capacities checked [kJ]",
    "hazard.fence_height_m": "fence height [m]",
    "hazard.free_board_m": "free board above a block's passing height [m]",
    "hazard.design_period_years": "design return period [yr]",
    "hazard.bootstrap": "bootstrap replicates",
    "hazard.seed": "random seed",
    "hazard.option_blocks": "simulated blocks per option",
    "hazard.mass_coupling": "mass coupling of reach and speed",
    "design_block.rule": "design-block rule",
    "design_block.percentile": "design-block percentile [%]",
    "rates.record": "rate model: record of falls",
    "rates.period": "rate model: counting period",
    "rates.windows_days": "rate model: rainfall windows [days]",
    "rates.rain_transform": "rate model: rainfall transform",
    "rates.season": "rate model: seasonal term",
    "rates.trend": "rate model: trend term",
    "traffic.vehicles_per_day": "traffic [vehicles/day]",
    "traffic.vehicle_length_m": "vehicle length [m]",
    "traffic.speed_kmh": "traffic speed [km/h]",
    "traffic.occupants_per_vehicle": "occupants per vehicle",
    "traffic.occupants_distribution": "distribution of occupants per vehicle",
    "traffic.commuter_trips_per_day": "trips per day of the most exposed commuter",
    "traffic.hours_rock_on_road": "hours a fallen rock lies on the road",
    "traffic.p_cannot_stop": "probability a driver cannot stop",
    "traffic.share_stopping_on_road": "share of falls stopping on the road",
    "traffic.exposed_length_m": "exposed length of road [m]",
    "consequences.value_of_statistical_life": "value of a statistical life",
    "consequences.vulnerability_moving_vehicle": "vulnerability, rock hitting a moving vehicle (P(death), block mass)",
    "consequences.vulnerability_striking_rock": "vulnerability, vehicle striking a fallen rock (P(death), block mass)",
    "consequences.vehicle_damage": "vehicle damage per hit",
    "consequences.closure_days_per_fall": "road closure per fall on the road [days]",
    "consequences.closure_cost_per_day": "closure cost per day",
    "consequences.detour_hours": "detour per vehicle during a closure [h]",
    "consequences.value_of_time_per_hour": "value of road users' time per hour",
    "consequences.cleanup_cost_per_fall": "clean-up cost per fall on the road",
    "consequences.currency": "currency",
    "economics.discount_rate": "discount rate [1/yr]",
    "economics.horizon_years": "horizon of the study [yr]",
    "criteria.individual_risk_per_year": "tolerable individual risk [1/yr]",
    "criteria.fn_diagram": "societal risk (F-N) criterion",
    "uncertainty.samples": "uncertainty: joint samples",
    "uncertainty.seed": "uncertainty: random seed",
    "uncertainty.rate_factor": "uncertainty: range of the rate factor",
    "uncertainty.m_max_kg": "uncertainty: range of m_max [kg]",
    "uncertainty.value_of_statistical_life": "uncertainty: range of the value of a statistical life",
    "uncertainty.vulnerability_factor": "uncertainty: range of the vulnerability factor",
    "uncertainty.vehicles_per_day": "uncertainty: range of traffic [vehicles/day]",
    "uncertainty.sample_power_law": "uncertainty: sample the power law's b and rate",
    "uncertainty.sample_retention": "uncertainty: sample derived retentions",
}

_TUPLE_REPR = re.compile(r"\((?:\s*\([^()]*\)\s*,?)+\s*\)")   # ((a, b), (c, d), ...) in text


def _field_label(field: str) -> str:
    """A reader's name for a site-file field such as ``hazard.free_board_m``."""
    if field in _FIELD_LABELS:
        return _FIELD_LABELS[field]
    table, _, key = field.rpartition(".")
    label = human_header(key)
    label = label[:1].lower() + label[1:]
    return f"{table}: {label}" if table else label


def _plain_value(value, field: str = "") -> str:
    """A default's value for a reader: yes/no, "not given", numbers to 3 significant figures, a curve of
    (mass, value) pairs as "10 kg: 0.05; 100 kg: 0.3", lists separated by semicolons; no quotes."""
    if value is None:
        return "not given"
    if isinstance(value, dict):
        return "; ".join(f"{k}: {_plain_value(v)}" for k, v in value.items())
    if isinstance(value, (list, tuple)):
        if value and all(isinstance(v, (list, tuple)) and len(v) == 2 for v in value):
            unit = " kg" if "vulnerability" in field or "mass" in field else ""
            return "; ".join(f"{_plain_value(m)}{unit}: {_plain_value(y)}" for m, y in value)
        return "; ".join(_plain_value(v) for v in value)
    return cell(value)          # yes/no, whole numbers with separators, 3 significant figures, text as it is


def _plain_text(text: str, field: str = "") -> str:
    """A default's value as written by the site reader (a Python repr, or words around one) for a reader."""
    import ast
    text = text.strip()
    try:
        return _plain_value(ast.literal_eval(text), field)
    except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
        pass
    quoted = re.fullmatch(r"'([^']*)'(\s.*)?", text, flags=re.S)      # 'x.csv' (inventory.path)
    if quoted:
        return quoted.group(1) + (quoted.group(2) or "")
    return _TUPLE_REPR.sub(lambda m: _plain_value(ast.literal_eval(m.group(0)), field), text)


def _assumptions(a, hz, rate_scale) -> pd.DataFrame:
    """Defaults and judgement inputs of an assessment: input (a reader's name), site-file field, value, basis.

    One row per input: a default that is also labelled a typed assumption (the vulnerability curves) is
    listed once, with both bases."""
    rows = {}

    def add(field, label, value, basis):
        if field in rows:
            old = rows[field]
            if basis not in old[3]:
                rows[field] = (old[0], old[1], old[2], f"{old[3]}; {basis}")
            return
        rows[field] = (label, field, value, basis)

    if getattr(hz.mass, "m_max", None):
        add("inventory.m_max_kg", "maximum credible block m_max [kg]", sig(hz.mass.m_max), "judgement (site file)")
    add("inventory.rate_scale", _field_label("inventory.rate_scale"), sig(rate_scale),
        "judgement (site file)" if rate_scale != 1 else "whole inventory (no scaling)")
    from_model = a.site.inventory.rate_from == "rate_model"
    add("inventory.rate_from", "hazard rate source", a.rate_source, "computed: rate model ([rates])" if from_model
        else "computed: the inventory's record")
    if a.rates is not None and a.rates.climate and from_model:
        add("inventory.rain_factor", "stated change of climate", a.rates.climate, "typed assumption")
    # model limitations (no site-file field)
    frag = a.study.uncertainty.fractal_dimension
    rows["limitation: volumes"] = (
        ("event volume vs block in the loss engine", "uncertainty.fractal_dimension",
         f"fractal fragmentation, D {frag[0]:g}-{frag[1]:g}, {a.study.uncertainty.fragmentation_iterations} "
         "generations", "judgement (site file); the fragments travel, road users meet each event once (upper-bound "
         "vulnerability: spared only if every reaching fragment spares them)")
        if frag else
        ("event volume vs block in the loss engine", "\u2014", "each event volume one intact block",
         "model limitation: conservative for fence and shed loads; fragmentation of the design block (if stated) "
         "is used only for the design block"))
    rows["limitation: queues"] = (
        "queued or stopped vehicles behind a blockage", "\u2014", "not modelled",
        "model limitation: road users meet falls as moving vehicles at the impact point or by striking a rock lying "
        "on the road; vehicles queued or stopped behind a blockage and hit by a later fall are not counted")
    for entry in a.site.defaults_used:
        name, _, value = str(entry).partition(" = ")
        if ": ASSUMPTION" in name or "ASSUMPTION" in value:
            name, _, value = str(entry).partition(": ASSUMPTION ")
            value = value.replace(" (mass_kg, probability of death)", "")
            add(name, _field_label(name), _plain_text(value, name), "typed assumption")
        elif value.endswith("(default)"):
            add(name, _field_label(name), _plain_text(value[: -len("(default)")], name), "riskrf default")
        else:
            add(name, _field_label(name), _plain_text(value, name), "riskrf default")
    return pd.DataFrame(list(rows.values()), columns=["input", "site-file field", "value", "basis"])


def _item_table(df: pd.DataFrame) -> pd.DataFrame:
    """A summary() frame indexed by item names, as two readable columns."""
    out = df.reset_index()
    out.columns = ["item"] + [str(c) for c in out.columns[1:]]
    return out


def _tornado_section(doc, tornado, figs: Path) -> None:
    """One-way sensitivity (tornado) of the design energies: text naming the dominant input of each, figure, table."""
    n_fig, n_tab = doc.next_figure, doc.next_table
    dom = tornado.dominant()
    said = "".join(
        f"<li>{_e(r['design_energy'])}: <b>{_e(r['input'])}</b> dominates, moving it from "
        f"{sig(r['energy_low_kj'], 2)} to {sig(r['energy_high_kj'], 2)} kJ (base {sig(r['energy_base_kj'], 2)} kJ; "
        f"{r['share_of_swings']:.0%} of the summed swings).</li>" for _, r in dom.iterrows())
    t = tornado.table
    table = t[["design_energy", "input", "low", "base", "high", "energy_low_kj", "energy_base_kj", "energy_high_kj",
               "swing_kj", "range_basis"]].rename(columns={
        "design_energy": "design energy moved", "low": "input low", "base": "input base", "high": "input high",
        "energy_low_kj": "energy at low [kJ]", "energy_base_kj": "energy at base [kJ]",
        "energy_high_kj": "energy at high [kJ]", "swing_kj": "swing [kJ]", "range_basis": "range from"})
    doc.add("<h3>One-way sensitivity of the design energies (tornado)</h3>",
            f"<p>Each input moved alone to its low and high value, the others at base, on the same simulated slope "
            f"(the mass law re-scaled or refitted, nothing re-simulated). Each panel of {n_fig} and each row of "
            f"{n_tab} names the design energy it moves: the {tornado.design_T:g}-year energy at the barrier line "
            "(hazard curve) and the design-block energy &frac12; m v<sub>p</sub><sup>2</sup> (one block at a "
            "percentile speed of blocks of its mass) are separate numbers and are not mixed in one bar set. "
            "Ranges marked ASSUMPTION are typed, not measured.</p>",
            "<ul>" + said + "</ul>",
            "<ul>" + "".join(f"<li>{_e(n)}</li>" for n in tornado.notes) + "</ul>",
            doc.figure(figs / "design_energy_tornado.png", "Tornado of the design energies: each input at its low "
                       "(blue) and high (red) value, one panel per design energy, bars sorted by swing"),
            doc.table(table, "One-way sensitivity of the design energies", digits=3))


#: Body of each report section (riskrf.report.sections), called as fn(doc, a, figs, section).
BODIES: dict = {}


def render_report(a, figs: Path) -> str:
    """HTML of the hazard and mitigation report for assessment ``a`` (figures read from ``figs``).

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.
    figs : pathlib.Path
        Folder of its figures (PNG), embedded as data URIs.

    Returns
    -------
    str
        A complete HTML document.
    """
    site = a.site
    doc = Document(title=f"{site.name} - rock fall hazard and mitigation")
    header = (f"<h1>Rock fall hazard and mitigation: {_e(site.name)}</h1><p>{_e(site.description)}</p>"
              f"<p><small>riskrf {__version__} &middot; seed {a.seed} &middot; {a.n_blocks:,} simulated blocks "
              f"&middot; generated {_dt.datetime.now().strftime('%Y-%m-%d %H:%M')} &middot; method after Wyllie "
              f"(2014) <i>Rock Fall Engineering</i>, ch. 3-8</small></p>")
    header += _summary_box(a)
    bodies = {key: partial(fn, doc, a, figs) for key, fn in BODIES.items()}
    render_sections(a, bodies, lambda s: doc.section(s.title, appendix=s.appendix))
    return _ABSOLUTE_DIRS.sub("", doc.render(header=header))


def _money_formatters(cur: str):
    """Formatters of amounts in currency ``cur``: typed amounts in full, computed ones to 3 significant figures."""

    def money_cur(v):
        """A typed amount (capital cost), in full."""
        return "" if v is None or pd.isna(v) else money(v, cur)

    def money_est(v):
        """A computed, uncertain amount (means, intervals, expected losses): 3 significant figures."""
        return "" if v is None or pd.isna(v) else money(v, cur, sig=3)

    return money_cur, money_est


def _summary_box(a) -> str:
    """HTML of the report's summary box: inventory, law, hazard, design energies, fences, risk and ranking."""
    inv, gr = a.inventory, a.frequency.power_law
    en, hz = a.energy, a.energy.hazard
    ranking, cur = a.decision["ranking"], a.study.currency
    best, second = ranking["option"].iloc[0], ranking["option"].iloc[1]
    design = en.design.set_index("T_years")
    rate_scale = a.site.inventory.rate_scale
    money_est = _money_formatters(cur)[1]
    verdicts = en.fence_verdicts()
    summary = ["<div class='box'><b>Summary.</b><ul>",
               (f"<li>{inv.n_events:,} recorded falls in {sig(inv.duration_years)} years; power law b = "
               f"{sig(gr.b)} &plusmn; {sig(gr.b_stderr, 2)} above {sig(gr.m_min)} kg ({sig(gr.rate_min)} falls per "
               "year at or above it in the inventory).</li>"), f"<li>Rate of falls for the hazard from the {_e(a.rate_source)}.</li>"]
    if getattr(hz.mass, "m_max", None):
        summary.append(f"<li>For the hazard the law is refitted with the maximum credible block m<sub>max</sub> = "
                       f"{sig(hz.mass.m_max)} kg (b = {sig(hz.mass.b)})"
                       + (f" and its rate scaled by {sig(rate_scale)} (a typed assumption: the share of the "
                          "inventory's falls that come down this slope)" if rate_scale != 1 else "") + ".</li>")
    summary.append(f"<li>About {sig(hz.arrival_rate)} falls a year reach the barrier line (reach probability "
                   f"{sig(hz.reach_probability)}); 95 % of them carry less than "
                   f"{sig(hz.energy_percentile(95)[0], 2)} kJ.</li>")
    for T in (100.0, 300.0):
        if T in design.index:
            row = design.loc[T]
            summary.append(f"<li>{T:g}-year impact energy: {sig(row['energy_kj'], 2)} kJ (95 % interval "
                           f"{sig(row['ci_low_kj'], 2)} - {sig(row['ci_high_kj'], 2)} kJ, covering b, the rate and "
                           "the finite simulation only).</li>")
    if en.sensitivity is not None and len(en.sensitivity):
        sv = en.sensitivity
        summary.append(f"<li>Over the judgement inputs (m<sub>max</sub> {sig(sv['m_max_kg'].min())} - "
                       f"{sig(sv['m_max_kg'].max())} kg, rate share {sig(sv['rate_share'].min())} - "
                       f"{sig(sv['rate_share'].max())}) the {en.design_T:g}-year energy spans "
                       f"{sig(sv['energy_kj'].min(), 2)} - {sig(sv['energy_kj'].max(), 2)} kJ ({S.section_number(a, 'hazard')}).</li>")
    if en.tornado is not None and len(en.tornado.table):
        d = en.tornado.dominant()
        if len(d):
            r = d.iloc[0]
            summary.append(f"<li>The {_e(r['design_energy'])} is most sensitive to {_e(r['input'])} "
                           f"({sig(r['energy_low_kj'], 2)} - {sig(r['energy_high_kj'], 2)} kJ; tornado in "
                           f"{S.section_number(a, 'hazard')}).</li>")
    if en.design_block is not None:
        b = en.design_block
        summary.append(f"<li>Design block: <b>{sig(b.mass_kg)} kg ({sig(b.volume_m3)} m&sup3;, diameter "
                       f"{sig(b.diameter_m)} m)</b> by the {_e(b.rule)} rule"
                       + "".join(f"; {_e(x)}" for x in b.assumptions[:1]) + ".</li>")
    if getattr(a, "design", None) is not None and a.design.requirement is None:
        summary.append(f"<li>Design basis {_e(a.design.basis.basis)}: {_e('; '.join(a.design.notes))}.</li>")
    elif getattr(a, "design", None) is not None:
        summary.append(f"<li>Design basis: <b>{_e(a.design.requirement.text())}</b>.  The fence checks below "
                       "(the design-period energy against MEL and SEL) are shown for comparison; the design basis "
                       "governs.</li>")
    for _, r in verdicts.iterrows():
        cls = "ok" if r["adequate"] else "fail"
        summary.append(f"<li>Fence {_e(r['fence'])}: <span class='{cls}'>"
                       f"{'adequate' if r['adequate'] else 'not adequate'}</span>"
                       f"{'' if r['adequate'] else ' (' + _e(r['failed checks']) + ')'}.</li>")
    best_row = ranking.iloc[0]
    summary.append(f"<li>With {_e(best)}: {sig(best_row['road_falls_per_year'], 2)} falls reach the road a year; "
                   f"individual risk {probability(best_row['individual_risk'])} per year (AGS 2007 limit "
                   f"10<sup>-4</sup>); societal risk {_e(fn_zone(a.study.fn_curve(best)))} against the Hong Kong "
                   "GEO F-N lines.</li>")
    summary.append(f"<li>Lowest expected total cost: <b>{_e(best)}</b> "
                   f"({money_est(ranking['expected_total_cost'].iloc[0])}), then {_e(second)} "
                   f"({money_est(ranking['expected_total_cost'].iloc[1])}).</li>")
    mu = getattr(a, "model_uncertainty", None)
    if mu is not None:
        summary += [f"<li>Trajectory model: {_e(t)}.</li>" for t in mu.energy.text(mu.design_T)]
        summary.append(f"<li>Over {mu.ranking.n_draws} draws of the trajectory model the least expected cost is "
                       f"<b>{_e(mu.ranking.best_now())}</b>; <b>{_e(mu.verdict())}</b>.</li>")
    summary.append("</ul></div>")
    return "".join(summary)


def _site_data_body(doc, a, figs: Path, s) -> None:
    """The inventory, its completeness and (when fitted to the site's own record) the rate model."""
    inv = a.inventory
    doc.add(doc.table(_item_table(inv.summary()), f"The inventory ({_e(_name(inv.source))})"),
            "<h3>Completeness</h3><p>Falls per year and the smallest recorded size show whether recording "
            "was consistent over the record.</p>",
            doc.table(inv.completeness().reset_index().head(60), "Completeness of the record by year"))
    if a.rates is not None and not S.rates_transferred(a):
        _rate_model(doc, a)
    elif a.rates is not None:
        doc.add(f"<p>The rate model is fitted to another site's record: see {S.section_number(a, 'other_sites')}.</p>")


def _rate_model(doc, a) -> None:
    """The rate model with its closure rules."""
    inv, cur = a.inventory, a.study.currency
    r = a.rates
    closures = pd.DataFrame([{"option": k, **{c: v for c, v in d.items() if not c.startswith("evaluated")},
                              "evaluated over": f"{d['evaluated_from']} to {d['evaluated_to']}"}
                             for k, d in r.summary()["closures"].items()])
    closures = closures.rename(columns={
        "share_while_closed": "share of falls while closed (model)",
        "recorded_share_while_closed": "share of recorded falls while closed",
        "closure_hours_per_year": "closure hours [h/yr]", "closures_per_year": "closures [1/yr]",
        "cost_per_hour": f"cost per closure hour [{cur}/h]"})
    transferred = _name(r.record) != _name(inv.source)
    doc.add(f"<h3>Rate model ({_e(_name(r.record))}, rainfall {_e(_name(r.rainfall))})</h3>"
            "<p>Counts of the dated record against antecedent rainfall, season and trend (Poisson and negative "
            "binomial regression; docs: Rates and rainfall). Closure options given as rules take their share of "
            "falls while closed and their closure hours from this model."
            + (" The record is not this site's inventory: its rates, and the closure shares and hours computed "
               "from it, are transferred to this site (an assumption; see the site description)."
               if transferred else "") + "</p>",
            doc.table(_item_table(r.model_summary.map(lambda v: re.sub(
                r"-?\d+(?:\.\d+)?e[+-]\d+", lambda m: sig(float(m.group())), str(v)))), "Rate model"))
    if len(closures):
        doc.add(doc.table(closures, "Closure rules computed from the rate model"))


def _magnitude_frequency_body(doc, a, figs: Path, s) -> None:
    """The power law, its goodness of fit and the design masses of the site and of the whole wall."""
    fr, gr, en = a.frequency, a.frequency.power_law, a.energy
    n_table = doc.next_table
    doc.add(f"<p>log<sub>10</sub> N(&ge;m) = a &minus; b log<sub>10</sub> m, N per year, m in kg; "
            f"{_e(gr.summary().loc['method', 'note'])}; completeness threshold m<sub>min</sub> by "
            f"{'the Kolmogorov-Smirnov method (Clauset et al. 2009)' if gr.m_min_method == 'ks' else 'the user'} "
            f"({n_table}).</p>",
            doc.table(gr.summary().reset_index(), "Power-law fit"),
            f"<p>Goodness of fit: KS distance {sig(gr.ks_distance, 2)}; semiparametric bootstrap p = "
            f"{sig(fr.bootstrap_p, 2)} ({fr.n_bootstrap:,} replicates) &mdash; the power law is "
            f"{'plausible' if (fr.bootstrap_p or 0) > 0.1 else 'questionable'} (p &gt; 0.1 needed).</p>",
            doc.table(fr.comparison.reset_index(), "Candidate laws compared"),
            doc.figure(figs / "magnitude_frequency.png",
                       "Magnitude - cumulative frequency with the fitted law and the interval of b"),
            "<h3>Design masses of the site</h3>",
            "<p>The site's law, the one the hazard uses: truncated at the maximum credible block m<sub>max</sub> "
            "and with the rate of the share of the source above the line. T-year fall at the source "
            "(rate &times; P(M &gt; m) = 1/T) and reaching the line (with the reach probability of each mass). "
            "Nothing exceeds m<sub>max</sub>; blank where fewer than one such fall is expected in T years. "
            f"These are event sizes; the design block ({S.section_number(a, 'hazard')}) separates the block from "
            "the event.</p>",
            doc.table(en.site_masses.drop(columns="law"), "Design masses of the site's law: "
                      + str(en.site_masses["law"].iloc[0])) if en.site_masses is not None else "",
            "<h3>For reference: the whole monitored wall (regional fit, untruncated, rate not scaled)</h3>",
            "<p>Not the site's design values: this fit describes every fall of the inventoried wall, with no upper "
            "bound, so its long-return-period masses can exceed any credible block.</p>",
            doc.table(fr.design_masses(), "Design masses of the whole wall's law (reference only)"))


def _annual_maxima_body(doc, a, figs: Path, s) -> None:
    """Gumbel and GEV fits of the annual maxima of the site's inventory (another record's: in the appendix)."""
    fr = a.frequency
    if fr.gumbel is not None:
        _annual_maxima(doc, a, fr, figs)
    elif a.maxima_frequency is not None and a.maxima_frequency.gumbel is not None:
        doc.add("<p>Not fitted to this site's inventory (it has no dates). The dated record the site file names "
                f"(inventory.annual_maxima) is fitted in {S.section_number(a, 'other_sites')}, with the data of "
                "other sites: it does not enter the design values.</p>")
    else:
        doc.add("<p>Not fitted: the inventory has no dates, so there are no annual maxima, and the site "
                "file names no dated record (inventory.annual_maxima).</p>")


def _annual_maxima(doc, a, mf, figs: Path) -> None:
    """Gumbel and GEV fits of the annual maxima of ``mf`` (the site's frequency study or a dated record's)."""
    fr = a.frequency
    sub = figs if mf is fr else figs / "annual_maxima"
    d = mf.deviance or {}
    pref = mf.preferred_model()
    preferred = f"{pref['model']}</b>: {_e(pref['reason'])}<b>"
    doc.add(f"<p>Record used: <code>{_e(_name(mf.inventory.source))}</code> &mdash; {_e(mf.inventory.site)}. "
            f"{mf.gumbel.data.size:,} annual maxima in {mf.gumbel.n_years:,} years; years without a fall "
            f"(p0 = {sig(mf.gumbel.p_zero, 2)}) enter through the mixed model. Location and scale are "
            "masses in kg."
            + (" The fits, the power law and the bootstrap p-value quoted in the preferred-model text below "
               f"are of this record, not of the site's inventory in {S.section_number(a, 'magnitude_frequency')}."
               if mf is not fr else "")
            + "</p>",
            doc.table(mf.gumbel.summary().reset_index(), "Gumbel fit of the annual maxima"))
    if mf.gev is not None:
        doc.add(doc.table(mf.gev.summary().reset_index(), "GEV fit of the annual maxima"),
                f"<p>Deviance test Gumbel vs GEV: D = {sig(d.get('deviance', np.nan))}, p = "
                f"{sig(d.get('p_value', np.nan), 2)}. Preferred model: <b>{preferred}</b>.</p>")
    doc.add(doc.figure(sub / "gumbel_plot.png", "Gumbel probability plot"),
            doc.figure(sub / "return_levels.png",
                       "Return levels of the annual maximum, with the law the power law implies"))


def _other_sites_body(doc, a, figs: Path, s) -> None:
    """Appendix: the data of other sites (a regional record's annual maxima, a transferred rate model)."""
    doc.add("<p>These records are not this site's: they show the methods (annual maxima, rainfall rate model) and "
            "do not enter the design values.</p>")
    mf = a.maxima_frequency
    if mf is not None and mf.gumbel is not None:
        doc.add("<h3>Annual maxima of the regional record</h3>")
        _annual_maxima(doc, a, mf, figs)
    if S.rates_transferred(a):
        _rate_model(doc, a)


def _run_record_body(doc, a, figs: Path, s) -> None:
    """Appendix: the run record (version, seed, blocks, site file, outputs)."""
    doc.add(doc.table(pd.DataFrame(S.run_record(a), columns=["item", "value"]), "Run record"))


def _trajectories_body(doc, a, figs: Path, s) -> None:
    """The scenario, the simulation summary and its figures (or where the velocities come from)."""
    hz = a.energy.hazard
    if a.result is not None:
        res = a.result
        sc = res.scenario
        which = ("the design basis (section 'Design basis') designs with the site's mass law; "
                 if getattr(a, "design", None) is not None else "the design values come from the site's mass law; ")
        doc.add(f"<p>Scenario <b>{_e(sc.name)}</b>: {_e(sc.description)}</p>",
                "<p>The speeds, heights and energies of this table are of the scenario seeder's own masses: they "
                f"describe how the slope behaves, they design nothing ({_e(which)}the energy hazard below gives the "
                "percentiles of the falls under that law).</p>",
                doc.table(_item_table(res.summary().drop(index=list(SOFTWARE_METRICS), errors="ignore")),
                          "Simulation summary"),
                doc.figure(figs / "profile_trajectories.png", "Slope profile and a sample of trajectories"),
                doc.figure(figs / "collector_distributions.png",
                           "Speed, bounce height and energy at the barrier line (of the simulated blocks)"),
                doc.figure(figs / "envelopes.png", "Envelopes along the slope"))
    else:
        doc.add(f"<p>{_e(hz.notes[0] if hz.notes else 'velocities from a file')}</p>")


def _hazard_body(doc, a, figs: Path, s) -> None:
    """The impact energy hazard, design energies, mass classes, sensitivity, design block and UNI."""
    en, hz = a.energy, a.energy.hazard
    doc.add("<p>&lambda;(E &gt; e) = rate of falls &times; P(reach) &times; P(E &gt; e), with the mass "
            "distribution of the fitted power law and the simulated velocities (rotation included). "
            "Intervals: seeded parametric bootstrap over b, the rate and the finite simulation.</p>",
            doc.table(_item_table(hz.summary()), "Energy hazard at the barrier line"),
            "<ul>" + "".join(f"<li>{_e(n)}</li>" for n in hz.notes) + "</ul>",
            doc.figure(figs / "energy_exceedance.png", "Annual frequency of impacts above each energy"),
            doc.figure(figs / "mass_velocity.png", "Masses and velocities with iso-energy lines"),
            "<h3>Design energies</h3>", f"<p>The interval covers the {_e(INTERVAL_COVERS)}.</p>",
            doc.table(en.design, "Design energies by return period", digits=2))
    if hz.mass_coupled:
        doc.add("<h3>Reach, speed and bounce height by block mass</h3>",
                "<p>Blocks simulated with masses spread log-uniformly over the mass law's range (stratified), so "
                "that heavier blocks move as the simulator says; the hazard integrates the mass law over these "
                "classes. Speeds include rotation; heights are of the block centre.</p>",
                doc.table(hz.velocity.class_table(), "Simulated blocks by mass class at the barrier line"))
    if en.sensitivity is not None and len(en.sensitivity):
        doc.add(f"<h3>Sensitivity of the {en.design_T:g}-year energy to the judgement inputs</h3>",
                "<p>The maximum credible block m<sub>max</sub> (rows; the power law refitted with each) and the "
                "share of the inventoried source above the line (columns), at the same simulated slope. These are "
                "judgement, not sampling: the bootstrap interval above does not include them. Energies in kJ.</p>",
                doc.table(sensitivity_grid(en.sensitivity).reset_index().rename(columns={"index": "m_max"}),
                          f"{en.design_T:g}-year energy [kJ] by m_max and rate share", digits=2),
                doc.figure(figs / "design_energy_sensitivity.png", f"The {en.design_T:g}-year energy against the "
                           "rate share, one line per maximum credible block"))
    if en.tornado is not None and len(en.tornado.table):
        _tornado_section(doc, en.tornado, figs)
    if en.design_block is not None:
        b = en.design_block
        doc.add("<h3>Design block</h3>",
                f"<div class='box'>Design block <b>{sig(b.mass_kg)} kg</b> ({sig(b.volume_m3)} m&sup3;, "
                f"equivalent sphere diameter {sig(b.diameter_m)} m): {_e(b.basis)}.</div>",
                "<p>An inventory of event volumes is not a list of blocks: a large detachment breaks up on the way "
                "down. The alternatives side by side, each with the 95th-percentile speed of simulated blocks of "
                "its own mass and the energy &frac12; m v<sub>95</sub><sup>2</sup> it carries:</p>",
                doc.table(b.alternatives, "Design block and its alternatives"),
                "<ul>" + "".join(f"<li>{_e(x)}</li>" for x in b.assumptions) + "</ul>")
    if en.uni is not None:
        u = en.uni
        what = "design block" if en.design_block is not None else f"{en.design_T:g}-year block"
        doc.add(f"<p>UNI 11211-4 design energy of the {what} at the 95th-percentile "
                f"velocity{' of blocks of its mass' if hz.mass_coupled else ''}: E<sub>k</sub> = {sig(u.characteristic_energy_kj, 2)} kJ, E<sub>d</sub> = "
                f"{sig(u.design_energy_kj, 2)} kJ with factors {_e(cell(u.factors))}.</p>")


def _kv_table(doc, rows, caption: str) -> str:
    """A two-column table (item, value) of text rows."""
    return doc.table(pd.DataFrame(rows, columns=["item", "value"]), caption)


def _design_values_body(doc, a, figs: Path, s) -> None:
    """The design values sheet: design block, speeds, energies, bounce heights and the required barrier."""
    from .report_rows import design_values_rows
    doc.add(_kv_table(doc, design_values_rows(a), "Design values at the barrier line"),
            "<p>Energies in kJ, lengths in m.  The shares stopped / over / through take bounce height and energy "
            "of the arriving falls (under the site's mass law) as independent.</p>")


def _design_basis_body(doc, a, figs: Path, s) -> None:
    """The design basis, its factors, what it requires at the barrier line and the candidate fences' checks."""
    d = a.design
    doc.add(f"<p>{_e(d.basis.text())}</p>")
    if d.requirement is None:
        doc.add(f"<p>{_e('; '.join(d.notes))}</p>")
    doc.add(doc.table(pd.DataFrame({"factor": list(d.basis.factors), "value": list(d.basis.factors.values())}),
                      "Partial factors of the design basis") if getattr(d.basis, "factors", None) else "",
            doc.table(d.summary().reset_index().rename(columns={"index": "quantity"}),
                      "What the design basis requires at the barrier line"),
            doc.table(d.requirement.candidates if d.requirement is not None else None, S.T_CANDIDATES))


def _positions_body(doc, a, figs: Path, s) -> None:
    """The barrier-position search: the requirement at each searched position."""
    doc.add(doc.table(a.design.positions.summary(), S.T_POSITIONS),
            *(doc.figure(figs / name, cap) for name, cap in s.figures))


def _slope_model_body(doc, a, figs: Path, s) -> None:
    """The slope model: profile vertices with segment dips, materials with the source of their values."""
    from .report_rows import slope_tables
    sc, vert, mats = slope_tables(a.site)
    doc.add(f"<p>Scenario {_e(_name(a.site.hazard.scenario))}: {_e(sc.description.strip())}</p>",
            "<h3>Profile vertices and segment angles</h3>",
            doc.table(pd.DataFrame(vert, columns=list(S.SLOPE_VERTEX_COLUMNS)), "Profile vertices and segment angles"),
            "<h3>Materials and the source of their values</h3>",
            doc.table(pd.DataFrame(mats, columns=list(S.SLOPE_MATERIAL_COLUMNS)),
                      "Materials and the source of their values"))


def _figures_body(doc, a, figs: Path, s) -> None:
    """A section made of its figures (``s.figures``)."""
    doc.add(*(doc.figure(figs / name, cap) for name, cap in s.figures))


def _runout_body(doc, a, figs: Path, s) -> None:
    """The stop points with their run-out statistics."""
    from .report_rows import runout_rows
    doc.add(*(doc.figure(figs / name, cap) for name, cap in s.figures),
            doc.figure(figs / "recommended_trajectories.png", "Trajectories on the slope with the recommended option"))
    rows = runout_rows(getattr(a, "design", None))
    if rows:
        doc.add(_kv_table(doc, rows, "Run-out of the simulated blocks"))


def _catchment_body(doc, a, figs: Path, s) -> None:
    """The catchment ditch: widths for each retention beside the Modified Ritchie Criterion, the chart."""
    c = a.design.catchment
    widths, rule = S.catchment_tables(c)
    doc.add(f"<p>{_e(S.catchment_text(c))}</p>",
            doc.table(widths, S.T_CATCHMENT_WIDTHS),
            doc.table(rule, S.T_RITCHIE),
            f"<p>{_e(S.RITCHIE_CAVEAT)}</p>",
            doc.table(c.chart, "Published chart against the re-simulation") if c.chart is not None else "",
            *(doc.figure(figs / name, cap) for name, cap in s.figures))


def _fence_checks_body(doc, a, figs: Path, s) -> None:
    """The fence checks against MEL and SEL (for comparison; the design basis governs)."""
    for name, table in a.energy.fences.items():
        doc.add(f"<h3>{_e(name)}</h3>", doc.table(table, f"Checks of {name}"))


def _road_risk_body(doc, a, figs: Path, s) -> None:
    """Individual and societal risk to road users by option: Bunce per lane, the risk table, the F-N curves."""
    doc.add(f"<p>{_e(S.road_risk_text(a))}</p>",
            doc.table(S.bunce_table(a), S.T_BUNCE, digits=3),
            doc.table(S.road_risk_table(a), S.T_RISK, digits=2),
            *(doc.figure(figs / name, f"{cap} ({a.study.criteria.fn_diagram})") for name, cap in s.figures))


def _decision_body(doc, a, figs: Path, s) -> None:
    """Recommendation, design checks, options, costs, uncertain inputs, break-even, tornado and value of
    information."""
    ranking, cur = a.decision["ranking"], a.study.currency
    money_cur, money_est = _money_formatters(cur)
    be = a.decision["break_even"]
    rec = a.decision["recommendation"]
    unc = a.decision["uncertainty"]
    costs = pd.DataFrame({
        "rank": ranking["rank"], "option": ranking["option"],
        "expected total cost": ranking["expected_total_cost"].map(money_est),
        "5 % - 95 %": [f"{money_est(x)} - {money_est(y)}" for x, y in zip(ranking["cost_p05"], ranking["cost_p95"])],
        "probability cheapest": ranking["probability_best"].map(lambda v: f"{v:.0%}"),
        "expected regret": ranking["expected_regret"].map(money_est),
        "cost at central values": ranking["cost_at_central_values"].map(money_est),
        "capital (central)": ranking["capital"].map(money_cur),
        "renewals (PV, central)": ranking["pv_renewals"].map(money_est),
        "maintenance, repairs, replacements (PV, central)": ranking["pv_maintenance"].map(money_est),
        "expected losses (PV, central)": ranking["pv_expected_loss"].map(money_est),
        "meets criteria": ranking["meets_criteria"].map(lambda v: "yes" if v else "no"),
        "meets them in (share of samples)": ranking["probability_meets_criteria"].map(lambda v: f"{v:.0%}"),
        **({"design adequate": ranking["design_adequate"].map(lambda v: "yes" if v else "NO")}
           if "design_adequate" in ranking else {}),
        **({"design check": ranking["design_check"]} if "design_check" in ranking else {}),
        **({"ALARP test": ranking["alarp"]} if "alarp" in ranking else {})})
    opts = a.decision["options_table"].copy()
    opts["retention"] = opts["retention"].map(lambda v: "" if v is None or pd.isna(v) else f"{v:.0%}")
    opts["effectiveness"] = opts["effectiveness"].map(lambda v: f"{v:.0%}")
    opts = opts.rename(columns={"effectiveness": "falls kept off the road", "effect_basis": "effect from"})
    tornado = a.decision["tornado"]
    central_best = ranking.loc[ranking["cost_at_central_values"].idxmin()]
    lines = S.recommendation_lines(a)
    doc.add(f"<div class='box'><b>{_e(lines[0])}</b>" + "".join(f"<br>{_e(t)}" for t in lines[1:]) + "</div>",
            "<h3>Design checks of the options</h3><p>An option whose design checks fail stays in the ranking, "
            "marked NOT ADEQUATE, and is never recommended.</p>",
            doc.table(S.design_checks_table(a), S.T_DESIGN_CHECKS),
            "<h3>The options</h3><p>Each option is a change of the site; its effect is derived (re-simulated "
            "profile, simulated heights and energies at the barrier line, the mass model) unless marked as a typed "
            "assumption. Retention: share of the falls that would reach the road which the structure stops.</p>",
            doc.table(opts, "Mitigation options and where their effect comes from"),
            "<h3>Costs</h3>",
            f"<p>Expected total cost = capital + present value of renewals + present value of maintenance, repairs "
            f"(impacts between SEL and MEL) and replacements (impacts above capacity) + present value of expected "
            f"losses, over {a.study.economics.horizon_years:g} years at {a.study.economics.discount_rate:.1%}. "
            f"Mean and 5-95 % over {unc['samples']:,} joint samples of the uncertain inputs (seed {unc['seed']}); "
            "probability cheapest: share of the samples in which the option costs least (they sum to 100 %). "
            "The columns marked central are at the central values of the inputs and add up to the cost at central "
            "values; the expected total cost is the mean over the samples and differs from it where the losses "
            "have a long tail or a stated range is not centred on the central value.</p>",
            doc.table(costs, f"{S.T_RANKING} [{cur}]"),
            "<h3>Uncertain inputs</h3>",
            doc.table(pd.DataFrame([{"input": k, "low": v["low"], "high": v["high"], "law": v["law"]}
                                    for k, v in unc["inputs"].items()]), "Uncertain inputs sampled jointly"),
            "<p>Low and high: the ends of a stated range, or the 5th and 95th percentiles of the law it is drawn from.</p>",
            f"<p>Not sampled: {_e('; '.join(unc['not_sampled']))}.</p>" if unc["not_sampled"] else "",
            doc.figure(figs / "tree.png", "Decision tree at central values; the optimal path in red"),
            "<h3>Break-even: input values at which the two cheapest options at central values tie</h3>",
            f"<p>The break-even values, the tornado and the value of information below are computed at the central "
            f"values of the inputs, where <b>{_e(central_best['option'])}</b> costs least "
            f"({money_est(central_best['cost_at_central_values'])})"
            + ("" if central_best["meets_criteria"] else
               f"; it does not meet the tolerability criteria (F-N zone {_e(central_best['fn_zone'])}, "
               f"F(N&ge;1) = {probability(central_best['F_N1_per_year'])}/yr; individual risk "
               f"{probability(central_best['individual_risk'])}/yr; met in "
               f"{central_best['probability_meets_criteria']:.0%} of the joint samples), so it is not the "
               "recommendation") + ". They compare costs only; the criteria are not applied.</p>",
            doc.table(be[np.isfinite(be["break_even"])], S.T_BREAK_EVEN),
            doc.figure(figs / "tornado.png", f"{S.F_TORNADO} (x0.5 / x2 where none is stated); the 15 inputs that "
                                             "change the best option or the order first, then by swing"),
            "<h3>Inputs that change the best option or the order</h3>",
            doc.table(tornado.loc[tornado["changes_order"], ["parameter", "low", "high", "range", "best_at_low",
                                                             "best_at_high", "changes_best"]],
                      "Inputs whose range changes the ranking"))
    voi = a.decision["value_of_information"]
    doc.add("<p>Value of perfect information about the rate of falls (true rate half, as estimated or "
            "double the estimate, with probabilities 1/4, 1/2, 1/4; at central values, costs only"
            + (f": the cheapest option is {_e(', '.join(f'{v} at {k}' for k, v in voi['best_by_rate'].items()))}"
               if voi.get("best_by_rate") else "") + "): "
            f"<b>{money_est(voi['evpi'])}</b>; about all "
            f"sampled inputs at once: <b>{money_est(voi['evpi_all_sampled_inputs'])}</b> &mdash; the most that "
            "investigations settling them are worth.</p>")
    campaign = a.decision.get("release_campaign")
    if campaign is not None and a.model_uncertainty is None:
        doc.add(f"<p>Value of a release campaign, priced from the {campaign['draws']} material draws of the "
                f"ranking (stated ranges, uniform): <b>{_e(campaign['verdict'])}</b>.</p>")


def _assumptions_body(doc, a, figs: Path, s) -> None:
    """Assumptions, defaults and judgement inputs, and warnings."""
    en, hz = a.energy, a.energy.hazard
    rate_scale = a.site.inventory.rate_scale
    classed = isinstance(hz.velocity, PairedSamples)
    items = [("Lumped-mass trajectories of round blocks; restitution and friction parameters are starting values "
              "to be calibrated on site (Wyllie 2014, ch. 7)."),
             ("Reach probability, speed and bounce height depend on block mass as simulated (blocks released "
              "across the mass law's range)." if hz.mass_coupled else
              "Velocities are taken with the simulated block mass they belong to (the seeder's masses); one reach "
              "probability for all masses." if classed else
              "Velocities and the reach probability are taken as independent of block mass "
              "(hazard.mass_coupling = 'independent')."),
             ("The rate and mass distribution come from the fitted power law, applied at the barrier line"
              + (f" with the rate scaled by {sig(rate_scale)} (typed assumption)" if rate_scale != 1 else "") + "."),
             f"Rate of falls from the {a.rate_source}.",
             "Judgement inputs not in any interval: m_max and the rate share (see the sensitivity table and the "
             f"tornado of the design energies in {S.section_number(a, 'hazard')})."]
    if en.design_block is not None:
        items += [f"Design block ({en.design_block.rule} rule): {x}" for x in en.design_block.assumptions]
    doc.add("<div class='warn'><ul>" + "".join(f"<li>{_e(t)}</li>" for t in items) + "</ul></div>")
    doc.add("<p>Every input the site file did not give, and every judgement input, with where its value "
            "comes from:</p>", doc.table(_assumptions(a, hz, rate_scale), "Defaults and judgement inputs"))
    if a.warnings:
        doc.add("<h3>Warnings</h3><div class='warn'><ul>"
                + "".join(f"<li>{_e(w)}</li>" for w in a.warnings) + "</ul></div>")


def _model_uncertainty_body(doc, a, figs: Path, s) -> None:
    """The trajectory model's uncertainty: the design energies' split, the ranking over the draws, the EVPI and
    the EVSI of a field calibration (riskrf.app.model_uncertainty)."""
    mu, cur = a.model_uncertainty, a.study.currency
    e = mu.energy.summary()
    e = e[["T_years", "energy_kj_reference", "energy_kj_mean", "combined_low_kj", "combined_high_kj",
           "model_low_kj", "model_high_kj", "statistical_low_kj", "statistical_high_kj",
           "share_from_trajectory_model"]]
    rank = mu.ranking.summary()
    money_cols = [c for c in rank.columns if "cost" in c]
    doc.add(f"<p>The slope was re-simulated for {mu.ranking.n_draws} draws of its material parameters "
            f"({_e(mu.basis)}); for each draw the energy hazard, the design energies and the mitigation study were "
            "computed again with the same seed and the same samples of the other inputs.  The interval of a design "
            "energy is split by the law of total variance into the part from the trajectory model (the spread of "
            "the draws) and the statistical part (b, the rate, the finite number of trajectories).</p>",
            doc.table(e, f"Design energies over the draws [kJ] ({mu.energy.level:.0%} intervals)",
                      headers={"energy_kj_reference": "at the scenario's values [kJ]",
                               "energy_kj_mean": "mean of the draws [kJ]",
                               "share_from_trajectory_model": "share of the variance from the trajectory model"}),
            doc.figure(figs / "design_energy_model_uncertainty.png",
                       f"The {mu.design_T:g}-year energy of each draw with its bootstrap interval"),
            doc.table(rank, f"Ranking over the draws of the trajectory model [{cur}]", money_columns=money_cols,
                      currency=cur),
            doc.figure(figs / "ranking_model_uncertainty.png", "Expected total cost of each option under each draw"),
            f"<div class='box'><b>{_e(mu.verdict())}</b></div>",
            "<div class='warn'><ul>" + "".join(f"<li>{_e(n)}</li>" for n in mu.notes) + "</ul></div>")


BODIES.update({
    "design_values": _design_values_body, "design_basis": _design_basis_body, "positions": _positions_body,
    "slope_model": _slope_model_body, "options_profile": _figures_body, "runout": _runout_body,
    "catchment": _catchment_body, "trajectories": _trajectories_body, "hazard": _hazard_body,
    "fence_checks": _fence_checks_body, "road_risk": _road_risk_body, "decision": _decision_body,
    "model_uncertainty": _model_uncertainty_body, "site_data": _site_data_body,
    "magnitude_frequency": _magnitude_frequency_body, "annual_maxima": _annual_maxima_body,
    "assumptions": _assumptions_body, "other_sites": _other_sites_body, "run_record": _run_record_body})
