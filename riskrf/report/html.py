"""The self-contained HTML report of an assessment (figures embedded, no network needed)."""
from __future__ import annotations

import base64
import datetime as _dt
import html
from pathlib import Path

import numpy as np
import pandas as pd

from .. import __version__
from ..energy_study import INTERVAL_COVERS, sensitivity_grid
from ..road_risk import fn_zone

CSS = """
body{font-family:Georgia,'Times New Roman',serif;max-width:1100px;margin:2em auto;padding:0 1.5em;color:#222;
line-height:1.45}
h1{font-size:1.7em;border-bottom:2px solid #444;padding-bottom:.2em}h2{font-size:1.3em;margin-top:2em;
border-bottom:1px solid #aaa}h3{font-size:1.05em}
table{border-collapse:collapse;margin:.6em 0;font-size:.85em;font-family:Helvetica,Arial,sans-serif}
th,td{border:1px solid #ccc;padding:.25em .5em;text-align:right}th{background:#eee}td:first-child,th:first-child
{text-align:left}.box{background:#f4f7fb;border:1px solid #9ab;padding:.8em 1.2em;margin:1em 0}
.warn{background:#fff6e5;border:1px solid #e0b060;padding:.6em 1.2em}figure{margin:1em 0;text-align:center}
figure img{max-width:100%;height:auto;border:1px solid #ddd}figcaption{font-size:.85em;color:#555}
.ok{color:#17692a;font-weight:bold}.fail{color:#a4161a;font-weight:bold}code{font-size:.9em}
"""


def _e(text) -> str:
    return html.escape(str(text))


def _table(df: pd.DataFrame, *, index=False, fmt="{:,.4g}") -> str:
    def f(v):
        if isinstance(v, (float, np.floating)):
            return "" if np.isnan(v) else fmt.format(v)
        return v
    return df.map(f).to_html(index=index, escape=True, border=0)


def _figure(path: Path, caption: str) -> str:
    if not path.exists():
        return ""
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (f'<figure><img alt="{_e(caption)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{_e(caption)}</figcaption></figure>")


def render_report(a, figs: Path) -> str:
    """HTML of the hazard and mitigation report for assessment ``a`` (figures read from ``figs``)."""
    site, inv, fr, gr = a.site, a.inventory, a.frequency, a.frequency.power_law
    en, hz = a.energy, a.energy.hazard
    ranking, cur = a.decision["ranking"], a.study.currency
    best, second = ranking["option"].iloc[0], ranking["option"].iloc[1]
    design = en.design.set_index("T_years")
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{_e(site.name)} - rock fall "
             f"hazard and mitigation</title><style>{CSS}</style></head><body>",
             f"<h1>Rock fall hazard and mitigation: {_e(site.name)}</h1>",
             f"<p>{_e(site.description)}</p>",
             f"<p><small>riskrf {__version__} &middot; seed {a.seed} &middot; {a.n_blocks:,} simulated blocks "
             f"&middot; generated {_dt.datetime.now().strftime('%Y-%m-%d %H:%M')} &middot; method after Wyllie "
             f"(2014) <i>Rock Fall Engineering</i>, ch. 3-8</small></p>"]
    verdicts = en.fence_verdicts()
    e100 = design.loc[100.0] if 100.0 in design.index else None
    e300 = design.loc[300.0] if 300.0 in design.index else None
    summary = ["<div class='box'><b>Summary.</b><ul>",
               f"<li>{inv.n_events} recorded falls in {inv.duration_years:.3g} years; power law b = {gr.b:.3f} "
               f"± {gr.b_stderr:.3f} above {gr.m_min:,.4g} kg ({gr.rate_min:.3g} falls per year in the inventory).</li>",
               (f"<li>For the hazard the law is refitted with the maximum credible block m<sub>max</sub> = "
                f"{hz.mass.m_max:,.4g} kg (b = {hz.mass.b:.3f})"
                + (f" and its rate scaled by {site.inventory['rate_scale']:g}" if site.inventory["rate_scale"] != 1
                   else "") + ".</li>") if getattr(hz.mass, "m_max", None) else "",
               f"<li>About {hz.arrival_rate:.3g} falls a year reach the barrier line "
               f"(reach probability {hz.reach_probability:.3f}); 95 % of them carry less than "
               f"{hz.energy_percentile(95)[0]:,.4g} kJ.</li>"]
    for T, row in ((100, e100), (300, e300)):
        if row is not None:
            summary.append(f"<li>{T}-year impact energy: {row['energy_kj']:,.4g} kJ (95 % interval "
                           f"{row['ci_low_kj']:,.4g} - {row['ci_high_kj']:,.4g} kJ, covering b, the rate and the "
                           "finite simulation only).</li>")
    if en.sensitivity is not None and len(en.sensitivity):
        sv = en.sensitivity
        summary.append(f"<li>Over the judgement inputs (m<sub>max</sub> {sv['m_max_kg'].min():,.3g} - "
                       f"{sv['m_max_kg'].max():,.3g} kg, rate share {sv['rate_share'].min():g} - "
                       f"{sv['rate_share'].max():g}) the {en.design_T:g}-year energy spans "
                       f"{sv['energy_kj'].min():,.4g} - {sv['energy_kj'].max():,.4g} kJ (table in section 5).</li>")
    if en.design_block is not None:
        b = en.design_block
        summary.append(f"<li>Design block: <b>{b.mass_kg:,.4g} kg ({b.volume_m3:,.3g} m&sup3;, diameter "
                       f"{b.diameter_m:.3g} m)</b> by the {_e(b.rule)} rule"
                       + "".join(f"; {_e(x)}" for x in b.assumptions[:1]) + ".</li>")
    for _, r in verdicts.iterrows():
        cls = "ok" if r["adequate"] else "fail"
        summary.append(f"<li>Fence {_e(r['fence'])}: <span class='{cls}'>"
                       f"{'adequate' if r['adequate'] else 'not adequate'}</span>"
                       f"{'' if r['adequate'] else ' (' + _e(r['failed checks']) + ')'}.</li>")
    best_row = ranking.iloc[0]
    summary.append(f"<li>With {_e(best)}: {best_row['road_falls_per_year']:.3g} falls reach the road a year; "
                   f"individual risk {best_row['individual_risk']:.2g}/yr (AGS 2007 limit 1e-4); societal risk "
                   f"{_e(fn_zone(a.study.fn_curve(best)))} against the Hong Kong GEO F-N lines.</li>")
    summary.append(f"<li>Lowest expected total cost: <b>{_e(best)}</b> "
                   f"({ranking['expected_total_cost'].iloc[0]:,.0f} {_e(cur)}), then {_e(second)} "
                   f"({ranking['expected_total_cost'].iloc[1]:,.0f} {_e(cur)}).</li></ul></div>")
    parts += summary

    # 1. Site and data
    parts += ["<h2>1. Site and data</h2>", _table(inv.summary().reset_index().rename(columns={"index": "item"})),
              "<h3>Completeness</h3><p>Falls per year and the smallest recorded size show whether recording "
              "was consistent over the record.</p>", _table(inv.completeness().reset_index().head(60))]

    # 2. Magnitude-frequency
    comp = fr.comparison.reset_index()
    parts += ["<h2>2. Magnitude-frequency relation (Wyllie 2014, 8.4.1)</h2>",
              f"<p>log<sub>10</sub> N(&ge;m) = a &minus; b log<sub>10</sub> m, N per year, m in kg; "
              f"{_e(gr.summary().loc['method', 'note'])}; completeness threshold m<sub>min</sub> by "
              f"{'the Kolmogorov-Smirnov method (Clauset et al. 2009)' if gr.m_min_method == 'ks' else 'the user'}.</p>",
              _table(gr.summary().reset_index()),
              f"<p>Goodness of fit: KS distance {gr.ks_distance:.4f}; semiparametric bootstrap p = "
              f"{fr.bootstrap_p:.3f} ({fr.n_bootstrap} replicates) &mdash; the power law is "
              f"{'plausible' if (fr.bootstrap_p or 0) > 0.1 else 'questionable'} (p &gt; 0.1 needed).</p>",
              _table(comp), _figure(figs / "magnitude_frequency.png", "Magnitude - cumulative frequency with the "
                                                                      "fitted law and the interval of b"),
              "<h3>Design masses of the site</h3>",
              "<p>The site's law, the one the hazard uses: truncated at the maximum credible block m<sub>max</sub> "
              "and with the rate of the share of the source above the line. T-year fall at the source "
              "(rate &times; P(M &gt; m) = 1/T) and reaching the line (with the reach probability of each mass). "
              "Nothing exceeds m<sub>max</sub>; blank where fewer than one such fall is expected in T years. "
              "These are event sizes; the design block (section 5) separates the block from the event.</p>",
              _table(en.site_masses.drop(columns="law")) if en.site_masses is not None else "",
              f"<p><small>Law: {_e(en.site_masses['law'].iloc[0]) if en.site_masses is not None else ''}.</small></p>",
              "<h3>For reference: the whole monitored wall (regional fit, untruncated, rate not scaled)</h3>",
              "<p>Not the site's design values: this fit describes every fall of the inventoried wall, with no upper "
              "bound, so its long-return-period masses can exceed any credible block.</p>",
              _table(fr.design_masses())]

    # 3. Annual maxima
    mf = fr if fr.gumbel is not None else a.maxima_frequency
    parts.append("<h2>3. Extreme values of annual maxima (Wyllie 2014, 8.4.2)</h2>")
    if mf is None or mf.gumbel is None:
        parts.append("<p>Not fitted: the inventory has no dates, so there are no annual maxima, and the site "
                     "file names no dated record (inventory.annual_maxima).</p>")
    else:
        sub = figs if mf is fr else figs / "annual_maxima"
        d = mf.deviance or {}
        preferred = ("Gumbel (the deviance test does not reject it)" if d.get("gumbel_adequate")
                     else "GEV (the deviance test rejects the Gumbel)")
        parts += [f"<p>Record used: <code>{_e(mf.inventory.source)}</code> &mdash; {_e(mf.inventory.site)}. "
                  f"{mf.gumbel.data.size} annual maxima in {mf.gumbel.n_years} years; years without a fall "
                  f"(p0 = {mf.gumbel.p_zero:.3f}) enter through the mixed model.</p>",
                  _table(mf.gumbel.summary().reset_index())]
        if mf.gev is not None:
            parts += [_table(mf.gev.summary().reset_index()),
                      f"<p>Deviance test Gumbel vs GEV: D = {d.get('deviance', np.nan):.3f}, p = "
                      f"{d.get('p_value', np.nan):.3f}. Preferred model: <b>{preferred}</b>.</p>"]
        parts += [_figure(sub / "gumbel_plot.png", "Gumbel probability plot"),
                  _figure(sub / "return_levels.png", "Return levels of the annual maximum, with the law the power "
                                                     "law implies")]

    # 4. Simulation
    parts.append("<h2>4. Trajectories at the barrier line (Wyllie 2014, ch. 3-7)</h2>")
    if a.result is not None:
        res = a.result
        sc = res.scenario
        parts += [f"<p>Scenario <b>{_e(sc.name)}</b>: {_e(sc.description)}</p>",
                  _table(res.summary().reset_index().rename(columns={"index": "item"})),
                  _figure(figs / "profile_trajectories.png", "Slope profile and a sample of trajectories"),
                  _figure(figs / "collector_distributions.png", "Speed, bounce height and energy at the barrier "
                                                                "line (of the simulated blocks)"),
                  _figure(figs / "envelopes.png", "Envelopes along the slope")]
    else:
        parts.append(f"<p>{_e(hz.notes[0] if hz.notes else 'velocities from a file')}</p>")

    # 5. Energy
    parts += ["<h2>5. Impact energy hazard (Wyllie 2014, 8.1-8.3)</h2>",
              "<p>&lambda;(E &gt; e) = rate of falls &times; P(reach) &times; P(E &gt; e), with the mass "
              "distribution of the fitted power law and the simulated velocities (rotation included). "
              "Intervals: seeded parametric bootstrap over b, the rate and the finite simulation.</p>",
              _table(hz.summary().reset_index().rename(columns={"index": "item"})),
              "<ul>" + "".join(f"<li>{_e(n)}</li>" for n in hz.notes) + "</ul>",
              _figure(figs / "energy_exceedance.png", "Annual frequency of impacts above each energy"),
              _figure(figs / "mass_velocity.png", "Masses and velocities with iso-energy lines"),
              "<h3>Design energies</h3>",
              f"<p>The interval covers the {_e(INTERVAL_COVERS)}.</p>", _table(en.design)]
    if hz.mass_coupled:
        parts += ["<h3>Reach, speed and bounce height by block mass</h3>",
                  "<p>Blocks simulated with masses spread log-uniformly over the mass law's range (stratified), "
                  "so that heavier blocks move as the simulator says; the hazard integrates the mass law over these "
                  "classes. Speeds include rotation; heights are of the block centre.</p>",
                  _table(hz.velocity.class_table(), fmt="{:,.4g}")]
    if en.sensitivity is not None and len(en.sensitivity):
        parts += [f"<h3>Sensitivity of the {en.design_T:g}-year energy to the judgement inputs</h3>",
                  "<p>The maximum credible block m<sub>max</sub> (rows; the power law refitted with each) and the "
                  "share of the inventoried source above the line (columns), at the same simulated slope. These are "
                  "judgement, not sampling: the bootstrap interval above does not include them. Energies in kJ.</p>",
                  _table(sensitivity_grid(en.sensitivity).reset_index().rename(columns={"index": ""})),
                  _figure(figs / "design_energy_sensitivity.png", f"The {en.design_T:g}-year energy against the rate "
                          "share, one line per maximum credible block")]
    if en.design_block is not None:
        b = en.design_block
        parts += ["<h3>Design block</h3>",
                  f"<div class='box'>Design block <b>{b.mass_kg:,.4g} kg</b> ({b.volume_m3:,.4g} m&sup3;, "
                  f"equivalent sphere diameter {b.diameter_m:.3g} m): {_e(b.basis)}.</div>",
                  "<p>An inventory of event volumes is not a list of blocks: a large detachment breaks up on the way "
                  "down. The alternatives side by side, each with the 95th-percentile speed of simulated blocks of "
                  "its own mass and the energy &frac12; m v<sub>95</sub><sup>2</sup> it carries:</p>",
                  _table(b.alternatives, fmt="{:,.4g}"),
                  "<ul>" + "".join(f"<li>{_e(x)}</li>" for x in b.assumptions) + "</ul>"]
    if en.uni is not None:
        u = en.uni
        what = "design block" if en.design_block is not None else f"{en.design_T:g}-year block"
        parts.append(f"<p>UNI 11211-4 design energy of the {what} at the 95th-percentile "
                     f"velocity{' of blocks of its mass' if hz.mass_coupled else ''}: E<sub>k</sub> = {u.characteristic_energy_kj:,.4g} kJ, E<sub>d</sub> = "
                     f"{u.design_energy_kj:,.4g} kJ with factors {_e(u.factors)}.</p>")

    # 6. Fences
    parts.append("<h2>6. Fence checks (ETAG 027 / EAD 340059: MEL, SEL = MEL/3)</h2>")
    for name, table in en.fences.items():
        parts += [f"<h3>{_e(name)}</h3>", _table(table)]

    # 7. Risk
    ir_limit = a.study.criteria.individual_risk_per_year
    risk = ranking[["option", "road_falls_per_year", "deaths_per_year", "individual_risk"]].copy()
    risk[f"meets {ir_limit:.0e}/yr"] = risk["individual_risk"] <= ir_limit
    risk["F(N>=1) [1/yr]"] = ranking["F_N1_per_year"]
    risk["Hong Kong GEO F-N zone"] = ranking["fn_zone"]
    parts += ["<h2>7. Risk to road users</h2>",
              f"<p>Bunce et al. (1997): P(S:T) = N<sub>v</sub> L<sub>v</sub> / (24 &times; 1000 &times; "
              f"V<sub>v</sub>) for {a.study.exposure.vehicles_per_day:,.0f} vehicles a day of "
              f"{a.study.exposure.vehicle_length_m:g} m at {a.study.exposure.speed_kmh:g} km/h; a vehicle striking "
              "a rock on the road; individual risk of a commuter (AGS 2007). Both individual and societal risk count "
              "direct hits and strikes on fallen rocks, falls of every size reaching the road (the power law above "
              "m<sub>min</sub> and the inventory's smaller falls below it), a probability of death that grows with "
              "block mass (an assumption anchored to AGS 2000 / Finlay et al. 1999, see the defaults) and occupants "
              "per vehicle as a distribution. F-N zones on the Hong Kong diagram (ERM-Hong Kong, GEO Report 75, "
              "1998): lines F = 10<sup>-3</sup>/N and 10<sup>-5</sup>/N to N = 1,000, intense scrutiny for "
              "N = 1,000-5,000, unacceptable beyond.</p>",
              _table(risk, fmt="{:.3g}"), _figure(figs / "fn_curve.png", "F-N curves with Hong Kong GEO criteria")]

    # 8. Decision
    be = a.decision["break_even"]
    rec = a.decision["recommendation"]
    unc = a.decision["uncertainty"]

    from .format import money

    def _money(v):
        return "" if v is None or pd.isna(v) else money(v, cur)
    costs = pd.DataFrame({
        "rank": ranking["rank"], "option": ranking["option"],
        "expected total cost": ranking["expected_total_cost"].map(_money),
        "5 % - 95 %": [f"{_money(x)} - {_money(y)}" for x, y in zip(ranking["cost_p05"], ranking["cost_p95"])],
        "probability cheapest": ranking["probability_best"].map(lambda v: f"{v:.0%}"),
        "expected regret": ranking["expected_regret"].map(_money),
        "capital": ranking["capital"].map(_money), "renewals (PV)": ranking["pv_renewals"].map(_money),
        "maintenance, repairs, replacements (PV)": ranking["pv_maintenance"].map(_money),
        "expected losses (PV)": ranking["pv_expected_loss"].map(_money),
        "meets criteria": ranking["meets_criteria"].map(lambda v: "yes" if v else "no"),
        "meets them in (share of samples)": ranking["probability_meets_criteria"].map(lambda v: f"{v:.0%}")})
    opts = a.decision["options_table"].copy()
    opts["retention"] = opts["retention"].map(lambda v: "" if v is None or pd.isna(v) else f"{v:.0%}")
    opts["effectiveness"] = opts["effectiveness"].map(lambda v: f"{v:.0%}")
    opts = opts.rename(columns={"effectiveness": "falls kept off the road", "effect_basis": "effect from"})
    parts += ["<h2>8. Mitigation decision (Wyllie 2014, 8.5.5)</h2>",
              f"<div class='box'><b>Recommendation: {_e(rec['option'])}</b> ({_e(rec['basis'])}).<br>"
              f"{_e(rec['reason'])}</div>",
              "<h3>The options</h3><p>Each option is a change of the site; its effect is derived (re-simulated "
              "profile, simulated heights and energies at the barrier line, the mass model) unless marked as a typed "
              "assumption. Retention: share of the falls that would reach the road which the structure stops.</p>",
              _table(opts),
              "<h3>Costs</h3>",
              f"<p>Expected total cost = capital + present value of renewals + present value of maintenance, repairs "
              f"(impacts between SEL and MEL) and replacements (impacts above capacity) + present value of expected "
              f"losses, over {a.study.economics.horizon_years:g} years at {a.study.economics.discount_rate:.1%}. "
              f"Mean and 5-95 % over {unc['samples']:,} joint samples of the uncertain inputs (seed {unc['seed']}); "
              "probability cheapest: share of the samples in which the option costs least (they sum to 100 %).</p>",
              _table(costs),
              "<h3>Uncertain inputs</h3>",
              _table(pd.DataFrame([{"input": k, "low": v["low"], "high": v["high"], "law": v["law"]}
                                   for k, v in unc["inputs"].items()]), fmt="{:,.4g}"),
              f"<p>Not sampled: {_e('; '.join(unc['not_sampled']))}.</p>",
              _figure(figs / "tree.png", "Decision tree at central values; the optimal path in red"),
              "<h3>What would make the runner-up as good (break-even)</h3>",
              _table(be[np.isfinite(be["break_even"])], fmt="{:,.4g}"),
              _figure(figs / "tornado.png", "Tornado: the lowest expected total cost as each input moves over its "
                                            "stated range (x0.5 / x2 where none is stated); the 15 inputs that change "
                                            "the best option or the order first, then by swing"),
              "<h3>Inputs that change the best option or the order</h3>",
              _table(a.decision["tornado"].loc[a.decision["tornado"]["changes_order"],
                                               ["parameter", "low", "high", "range", "best_at_low", "best_at_high",
                                                "changes_best"]], fmt="{:,.4g}")]
    voi = a.decision["value_of_information"]
    parts.append(f"<p>Value of perfect information about the rate of falls (true rate half, as estimated or "
                 f"double the estimate, with probabilities 1/4, 1/2, 1/4): <b>{_money(voi['evpi'])}</b>; about all "
                 f"sampled inputs at once: <b>{_money(voi['evpi_all_sampled_inputs'])}</b> &mdash; the most that "
                 "investigations settling them are worth.</p>")

    # 9. Assumptions
    parts += ["<h2>9. Assumptions, defaults and warnings</h2><div class='warn'><ul>",
              "<li>Lumped-mass trajectories of spheres; restitution and friction parameters are starting values "
              "to be calibrated on site (Wyllie 2014, ch. 7).</li>",
              ("<li>Reach probability, speed and bounce height depend on block mass as simulated (blocks released "
               "across the mass law's range); "
               if hz.mass_coupled else
               "<li>Velocities and the reach probability are taken as independent of block mass "
               "(hazard.mass_coupling = 'independent'); ")
              + "the rate and mass distribution come from the fitted power law, applied at the barrier line"
              + (f" with the rate scaled by {site.inventory['rate_scale']:g}" if site.inventory["rate_scale"] != 1
                 else "") + ".</li>"]
    if en.design_block is not None:
        parts += [f"<li>Design block ({_e(en.design_block.rule)} rule): {_e(x)}</li>"
                  for x in en.design_block.assumptions]
    parts.append("<li>Judgement inputs not in any interval: m<sub>max</sub> and the rate share (see the sensitivity "
                 "table in section 5).</li>")
    parts += [f"<li>Default used: {_e(d)}</li>" for d in site.defaults_used]
    parts += [f"<li>Warning: {_e(w)}</li>" for w in a.warnings]
    parts.append("</ul></div></body></html>")
    return "\n".join(parts)
