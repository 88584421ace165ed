"""The corridor report of ``riskrf corridor``: the figure along chainage and the self-contained HTML page."""
from __future__ import annotations

from pathlib import Path

from .. import __version__
from ..core.units import M_PER_KM
from .format import Document, cell, escape


#: Above this many sections the chainage figure draws binned step curves (one artist per curve, no labels), so
#: that it costs O(sections) with a small constant; at or below it, one bar and one label per section.
AGGREGATE_ABOVE = 300
#: Number of chainage bins of the aggregated figure.
CHAINAGE_BINS = 300
#: Rows of the ranked and budget tables shown in the HTML report (all rows are in the CSV files).
HTML_ROWS = 100


def _binned(t, bins):
    """Per chainage bin (sections assigned by their start): max RHRS, max individual risk now and with the best
    option, and deaths per year per km now and after (sums over the bin's section length)."""
    import numpy as np
    x0 = t["chainage_from_m"].to_numpy() / M_PER_KM
    edges = np.linspace(x0.min(), (t["chainage_to_m"].to_numpy() / M_PER_KM).max(), bins + 1)
    k = np.clip(np.searchsorted(edges, x0, side="right") - 1, 0, bins - 1)
    out = {}
    for name, col, how in (("rhrs", "rhrs_score", "max"), ("ir", "individual_risk", "max"),
                           ("ir_best", "best_individual_risk", "max"), ("d", "deaths_per_year", "sum"),
                           ("d_best", "best_deaths_per_year", "sum"), ("km", "length_m", "sum")):
        v = t[col].to_numpy(dtype=float)
        acc = np.full(bins, -np.inf if how == "max" else 0.0)
        (np.maximum if how == "max" else np.add).at(acc, k, np.nan_to_num(v, nan=-np.inf if how == "max" else 0.0))
        out[name] = np.where(np.isfinite(acc), acc, np.nan)
    out["km"] = out["km"] / M_PER_KM
    with np.errstate(divide="ignore", invalid="ignore"):
        out["d"], out["d_best"] = out["d"] / out["km"], out["d_best"] / out["km"]
    return edges, out


def plot_corridor(res):
    """Along chainage: RHRS score, individual risk (criterion line), deaths per year per km now and with the
    best option.  Above :data:`AGGREGATE_ABOVE` sections the curves are binned (:data:`CHAINAGE_BINS` bins; RHRS
    and individual risk the bin's maximum, deaths per km the bin's total over its length).

    Parameters
    ----------
    res : CorridorResult
        The corridor's results.

    Returns
    -------
    matplotlib.figure.Figure
        Panels against chainage [m].
    """
    import matplotlib.pyplot as plt
    t = res.table.sort_values("chainage_from_m")
    fig, ax = plt.subplots(3, 1, figsize=(10, 7.5), sharex=True)
    crit = res.corridor.study["criteria"].individual_risk_per_year
    if len(t) > AGGREGATE_ABOVE:
        edges, b = _binned(t, CHAINAGE_BINS)
        ax[0].stairs(b["rhrs"], edges, color="#8c6d31", fill=True, alpha=0.8)
        ax[0].set_ylabel("RHRS score (bin max)")
        ax[1].stairs(b["ir"], edges, color="#d62728", label="do nothing")
        ax[1].stairs(b["ir_best"], edges, color="#2ca02c", label="best option")
        ax[1].set_ylabel("individual risk [1/yr]\n(bin max)")
        ax[2].stairs(b["d"], edges, color="#d62728", label="do nothing")
        ax[2].stairs(b["d_best"], edges, color="#2ca02c", label="best option")
        title = f"{res.corridor.name}: {len(t):,} sections in {CHAINAGE_BINS} chainage bins"
    else:
        x0, w = t["chainage_from_m"].to_numpy() / M_PER_KM, t["length_m"].to_numpy() / M_PER_KM
        ax[0].bar(x0, t["rhrs_score"], width=w, align="edge", color="#8c6d31", edgecolor="k", lw=0.3)
        ax[0].set_ylabel("RHRS score")
        ax[1].bar(x0, t["individual_risk"], width=w, align="edge", color="#d62728", alpha=0.7, edgecolor="k",
                  lw=0.3, label="do nothing")
        ax[1].bar(x0, t["best_individual_risk"], width=w, align="edge", color="#2ca02c", alpha=0.8, edgecolor="k",
                  lw=0.3, label="best option")
        ax[1].set_ylabel("individual risk [1/yr]")
        km = t["length_m"].to_numpy() / M_PER_KM
        ax[2].bar(x0, t["deaths_per_year"] / km, width=w, align="edge", color="#d62728", alpha=0.7, edgecolor="k",
                  lw=0.3, label="do nothing")
        ax[2].bar(x0, t["best_deaths_per_year"] / km, width=w, align="edge", color="#2ca02c", alpha=0.8,
                  edgecolor="k", lw=0.3, label="best option")
        if len(t) <= 60:
            for a, b_, sid in zip(x0, w, t["id"]):
                ax[0].annotate(str(sid), (a + b_ / 2, 0), xytext=(0, 2), textcoords="offset points", ha="center",
                               fontsize=6, rotation=90)
        title = f"{res.corridor.name}: {len(t)} sections"
    ax[1].axhline(crit, color="k", ls="--", lw=1, label="tolerable")
    ax[1].set_yscale("log")
    ax[1].legend(fontsize=8, loc="upper right")
    ax[2].set_yscale("log")
    ax[2].set_ylabel("deaths per year per km")
    ax[2].set_xlabel("chainage [km]")
    ax[2].legend(fontsize=8, loc="upper right")
    fig.suptitle(title)
    fig.subplots_adjust(left=0.09, right=0.98, bottom=0.07, top=0.93, hspace=0.12)   # tight_layout: seconds
    return fig


def plot_map(res, lines, programme=None):
    """Map of the sections on the road (projected CRS, metres): each section's line coloured by deaths per year
    per km of doing nothing (log scale); sections the programme funds drawn wide with a black casing.

    Parameters
    ----------
    res : CorridorResult
        The corridor's results.
    lines : sequence of numpy.ndarray
        Each section's (k, 2) vertices [m].
    programme : Programme, optional
        The funded programme.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.collections import LineCollection
    from matplotlib.colors import LogNorm
    t = res.table
    km = t["length_m"].to_numpy() / M_PER_KM
    dens = t["deaths_per_year"].to_numpy(dtype=float) / km
    pos = dens[dens > 0]
    norm = LogNorm(vmin=pos.min(), vmax=max(pos.max(), pos.min() * 10)) if pos.size else None
    fig, ax = plt.subplots(figsize=(8, 8))
    funded = set(programme.chosen["id"]) if programme is not None else set()
    if funded:
        sel = [ln for ln, i in zip(lines, t["id"]) if i in funded]
        ax.add_collection(LineCollection(sel, colors="k", linewidths=7, zorder=1, label="funded by the programme"))
    lc = LineCollection(lines, array=np.where(dens > 0, dens, np.nan), cmap="inferno_r", norm=norm, linewidths=3.5,
                        zorder=2)
    ax.add_collection(lc)
    allxy = np.vstack(lines)
    pad = 0.05 * max(np.ptp(allxy[:, 0]), np.ptp(allxy[:, 1]), 100.0)
    ax.set_xlim(allxy[:, 0].min() - pad, allxy[:, 0].max() + pad)
    ax.set_ylim(allxy[:, 1].min() - pad, allxy[:, 1].max() + pad)
    ax.set_aspect("equal")
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.set_xlabel(f"easting [m] ({res.corridor.crs})")
    ax.set_ylabel(f"northing [m] ({res.corridor.crs})")
    if norm is not None:
        fig.colorbar(lc, ax=ax, shrink=0.7, label="deaths per year per km, doing nothing")
    if len(t) <= 60:
        for ln, sid in zip(lines, t["id"]):
            mid = ln[len(ln) // 2]
            ax.annotate(str(sid), tuple(mid), xytext=(4, 0), textcoords="offset points", fontsize=6)
    if funded:
        ax.legend(loc="lower right", fontsize=8)
    ax.set_title(f"{res.corridor.name}: sections on the road" + (f", {len(funded)} funded" if funded else ""))
    return fig


def plot_frontier(frontier, ax=None, *, currency: str = "", chosen_budget: float | None = None):
    """The efficient frontier: benefit of the best programme against the budget (steps: each point exact).

    Parameters
    ----------
    frontier : Frontier
        Its ``table`` (``budget``, ``benefit``) and the cost and benefit columns.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    currency : str
        Currency label.
    chosen_budget : float, optional
        Budget marked [currency].

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt
    t = frontier.table
    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(8, 5))
    else:
        fig = ax.figure
    scale = 1e6 if t["budget"].max() >= 1e6 else 1.0
    unit = f"million {currency}" if scale == 1e6 else currency
    ax.step(t["budget"] / scale, t["benefit"], where="post", color="#1f77b4", lw=1.5)
    ax.plot(t["budget"] / scale, t["benefit"], "o", color="#1f77b4", ms=3)
    if chosen_budget is not None:
        ax.axvline(chosen_budget / scale, color="k", ls="--", lw=1, label=f"budget {chosen_budget / scale:,.3g} {unit}")
        ax.legend(fontsize=8, loc="lower right")
    what = {"capital": "capital paid now", "equivalent_annual_cost": "equivalent annual cost per year"}
    ax.set_xlabel(f"budget: {what.get(frontier.cost_column, frontier.cost_column)} [{unit}]")
    ax.set_ylabel({"deaths_avoided_per_year": "deaths avoided per year",
                   "expected_total_cost_saving": f"expected total cost saved [{currency}]",
                   "alarp_net_benefit": f"net benefit at the VSL, GDF x benefit - cost [{currency}]"}.get(
        frontier.benefit_column, frontier.benefit_column))
    ax.set_title("Efficient frontier: the best programme at each budget (exact, one option per section)")
    ax.grid(alpha=0.3)
    return fig


def render_rating_sheets(res) -> str:
    """One RHRS rating sheet per rated section (HTML): category, rated value, level x, score and whole points,
    the total as a sheet prints it; built as plain strings so that it costs O(sections).

    Parameters
    ----------
    res : CorridorResult
        The corridor's results.

    Returns
    -------
    str
        A complete HTML document.

    References
    ----------
    Pierson, L. A. & Van Vickle, R. (1993). Rockfall Hazard Rating System: Participant's Manual. Federal Highway
    Administration, FHWA-SA-93-057.
    """
    c = res.corridor
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>RHRS rating sheets: "
             f"{escape(c.name)}</title><style>body{{font-family:Georgia,serif;max-width:900px;margin:2em auto}}"
             "table{border-collapse:collapse;margin-bottom:1.5em}td,th{border:1px solid #999;padding:2px 6px}"
             "td.n{text-align:right}section{page-break-inside:avoid}</style></head><body>",
             f"<h1>RHRS rating sheets: {escape(c.name)}</h1><p>Variant: {escape(c.rhrs_variant)} "
             f"({escape(_variant_text(c.rhrs_variant))})"
             + (f"; each category capped at {c.sections[0].rating.cap_points:g} points"
                if c.sections and c.sections[0].rating is not None and c.sections[0].rating.cap_points else "")
             + ". Points are the category scores 3<sup>x</sup> to the nearest whole point (halves up), the total "
               "their sum, as a rating sheet prints them.</p>"]
    for sec in c.sections:
        if sec.rating is None:
            continue
        rows = "".join(f"<tr><td>{escape(r['category'])}</td><td>{escape(r['rated_value'])}</td>"
                       f"<td class='n'>{'' if r['category'] == 'total' else format(r['x'], '.3f')}</td>"
                       f"<td class='n'>{r['score']:.2f}</td><td class='n'><b>{r['points']}</b></td></tr>"
                       for r in sec.rating.sheet_rows())
        parts.append(f"<section id='{escape(sec.id)}'><h2>{escape(sec.id)}: chainage {sec.chainage_from_m:,.0f}-"
                     f"{sec.chainage_to_m:,.0f} m</h2><table><thead><tr><th>category</th><th>rated value (SI)</th>"
                     f"<th>x</th><th>score 3<sup>x</sup></th><th>points</th></tr></thead><tbody>{rows}</tbody>"
                     "</table></section>")
    parts.append("</body></html>")
    return "\n".join(parts)


def _variant_text(name):
    from ..risk.rhrs import VARIANTS
    return VARIANTS.get(name, name)


#: Money columns of the ranked and budget-curve tables of the HTML report.
_RANKED_MONEY_COLUMNS = ("best_option_capital", "best_option_total_cost", "expected_annual_cost_per_km", "spend",
                         "cumulative_spend")


def _caption_rows(caption: str, n: int, csv: str) -> str:
    """A table caption that says when only the first :data:`HTML_ROWS` of ``n`` rows are shown.

    Parameters
    ----------
    caption, csv : str
        The caption, and the file that holds every row.
    n : int
        Rows of the whole table.

    Returns
    -------
    str
        The caption, with "(first ... of n; all in csv)" when ``n`` exceeds :data:`HTML_ROWS`.
    """
    return caption + (f" (first {HTML_ROWS} of {n}; all in {csv})" if n > HTML_ROWS else "")


def _ranked_tables(s):
    """The ranked summary as the report shows it, and the sections whose RHRS and risk ranks disagree.

    Parameters
    ----------
    s : pandas.DataFrame
        :meth:`CorridorResult.summary`.

    Returns
    -------
    s : pandas.DataFrame
        Whole-point RHRS total only; integer ranks, blank for a section without RHRS attributes.
    disagree : pandas.DataFrame
        Sections whose ranks differ by at least ``places``.
    places : int
        The rank difference that counts as a disagreement.
    """
    places = max(3, len(s) // 5)
    disagree = s[(s["rank_difference"].abs() >= places).fillna(False).astype(bool)] \
        if s["rank_rhrs"].notna().any() else s.iloc[0:0]
    s = s.drop(columns=["rhrs_score"]) if "rhrs_total" in s and "rhrs_score" in s else s.copy()   # whole points
    for col in ("rank_rhrs", "rank_difference"):           # integer ranks; a section without RHRS attributes: blank
        s[col] = s[col].astype(object).where(s[col].notna(), "")
    disagree = disagree.astype({"rank_rhrs": object, "rank_difference": object})
    return s, disagree, places


def _report_header(res) -> str:
    """The title block of the corridor report: how the run went and the corridor's key figures.

    Parameters
    ----------
    res : CorridorResult
        The corridor run: its corridor, table, workers, seconds and blocks per section.

    Returns
    -------
    str
        HTML: title, run line and the key-figures box (deaths per year, capital, rates, hazard, mass law).
    """
    c, t = res.corridor, res.table
    return (f"<h1>{escape(c.name)}</h1>"
            f"<p>{len(t)} sections assessed on {res.workers} dask worker(s) in {res.seconds:.1f} s, "
            f"{res.n_blocks:,} simulated blocks per section, corridor seed {c.seed} (riskrf {__version__}).</p>"
            "<div class='box'><ul>"
            f"<li>Deaths per year, doing nothing: {cell(float(t['deaths_per_year'].sum()))}; with each section's "
            f"best option: {cell(float(t['best_deaths_per_year'].sum()))}</li>"
            f"<li>Capital of the best options: "
            f"{cell(float(t['best_option_capital'].sum()), money_columns=True, currency=c.currency)}</li><li>Rates: "
            + ("falls reaching the road (as recorded), release rate derived per section from the share reaching "
               "the road averaged over the mass law" if c.rate_basis == "road" else "falls released (>= m_min)")
            + "</li><li>Hazard at the barrier line mass-coupled as in riskrf assess (blocks simulated across the "
              "mass law, reach and speed by mass class); the cut's own seeder only for the option effects"
            + f"</li><li>{escape(c.mass_note)}</li></ul></div>")


def _chainage_section(doc: Document, n: int, figure_png: Path) -> None:
    """Add the section "Along the chainage" with the chainage figure.

    Parameters
    ----------
    doc : Document
        The report.
    n : int
        Number of sections (above :data:`AGGREGATE_ABOVE` the figure is binned).
    figure_png : pathlib.Path
        The chainage figure.
    """
    doc.section("Along the chainage")
    doc.add(doc.figure(figure_png, "RHRS score, individual risk and deaths per year per km of each section, doing "
                                   "nothing and with its best option"
                       + (f" (binned: {n:,} sections in {CHAINAGE_BINS} bins of chainage)"
                          if n > AGGREGATE_ABOVE else "")))


def _map_section(doc: Document, c, figures: dict, funded: bool) -> None:
    """Add the section "On the road" with the map of the sections on the centreline.

    Parameters
    ----------
    doc : Document
        The report.
    c : Corridor
        The corridor (its centreline and CRS).
    figures : dict
        Figures by name (the map under ``map``).
    funded : bool
        Whether the map marks the sections a programme funds.
    """
    doc.section("On the road")
    doc.add(f"<p>Each section's line on the road centreline ({escape(c.centreline.source)}, {escape(c.crs)}); "
            "the same lines with every column of sections.csv are in <code>sections.gpkg</code> for a GIS.</p>",
            doc.figure(figures["map"], "Sections on the road, coloured by deaths per year per km of doing "
                                       "nothing" + ("; wide black casing: funded by the programme" if funded else "")))


def _programme_box(c, programme, budget_basis: str) -> str:
    """What the budget caps, what the programme maximises and buys, and how capital and present value differ.

    Parameters
    ----------
    c : Corridor
        The corridor (currency, economics).
    programme : Programme
        The budget programme.
    budget_basis : str
        ``"total"`` or ``"year"``.

    Returns
    -------
    str
        HTML box.
    """
    cur = c.currency
    caps = {"total": "the capital of the chosen options (money paid now)",
            "year": "the equivalent annual cost of the chosen options (present value of capital, renewals and "
                    "maintenance, spread as a level cost per year at the discount rate)"}[budget_basis]
    buys = {"deaths_avoided_per_year": "the deaths avoided per year",
            "expected_total_cost_saving": "the saving in expected total cost (capital + discounted "
                                          "maintenance, renewals and expected losses) against doing nothing",
            "alarp_net_benefit": f"the net benefit at the value of a statistical life "
                                 f"({cell(c.study['consequences'].value_of_statistical_life, money_columns=True, currency=cur)}"
                                 f") with the gross-disproportion factor GDF = {programme.gdf:g}: GDF times the "
                                 "expected losses an option avoids (present value, lives at the VSL) less its present "
                                 "value, so that every option it funds is worth at least 1/GDF of its cost"}
    got = {"deaths_avoided_per_year": " deaths avoided per year",
           "expected_total_cost_saving": f" {escape(cur)} of expected total cost saved",
           "alarp_net_benefit": f" {escape(cur)} of net benefit"}
    e = c.study["economics"]
    lim = c.study["criteria"].individual_risk_per_year
    req = getattr(programme, "required", ())
    first = ""
    if programme.objective == "alarp":
        first = (f"First, the sections above the intolerable individual-risk line ({lim:.0e}/yr) are funded whatever "
                 "they cost, with an option that brings them below it: "
                 + (f"{len(req)} section(s), {escape(', '.join(req))}"
                    + (f", taking {cell(programme.overrun, money_columns=True, currency=cur)} beyond the budget"
                       if programme.overrun > 0 else "") if req else "none here") + ". Then ")
    return (f"<div class='box'><p>Budget {cell(programme.budget, money_columns=True, currency=cur)} caps "
            f"{caps}. {first}The programme gives each section at most one option and maximises "
            f"{buys.get(programme.benefit_column, programme.benefit_column)}; it is solved as a mixed-integer "
            "programme, not by a greedy order, "
            + ("and proven optimal. " if programme.gap == 0 else
               f"which stopped at its time limit: the programme is within {programme.gap:.2g} (relative) of the "
               "optimum. ")
            + f"It funds {len(programme.chosen)} of {programme.n_sections} sections for "
            f"{cell(programme.cost, money_columns=True, currency=cur)} and buys {cell(programme.benefit)}"
            + got.get(programme.benefit_column, "") + ".</p>"
            f"<p><b>Capital</b> is what the works cost when built. <b>Present value</b> adds renewals at the end "
            f"of each option's life and yearly maintenance over {e.horizon_years:g} years, discounted at "
            f"{e.discount_rate:.1%}. Per-metre costs are paid on each section's cut length. <b>Benefit/cost</b> is "
            "the present value of the expected losses an option avoids (lives at the VSL, damage, closures, "
            "clean-up) over its present value.</p></div>")


def _other_box(c, programme, other, compared) -> str:
    """The other objective's programme beside the recommended one, and one line on where they disagree.

    Parameters
    ----------
    c : Corridor
        The corridor (currency).
    programme : Programme
        The recommended programme.
    other : Programme
        The other objective's programme at the same budget.
    compared : dict
        :meth:`riskrf.app.corridor.CorridorResult.compare_programmes` of the two.

    Returns
    -------
    str
        HTML box.
    """
    cur = c.currency
    name = {"alarp": f"net benefit at the VSL (GDF {other.gdf:g}, tolerability first)",
            "risk": "deaths avoided per year", "cost": "expected total cost"}

    def bc(x):
        return "n/a" if x is None or x != x else f"{x:.2g}"
    return (f"<div class='box'><p><b>Beside it, objective '{escape(other.objective)}'</b> "
            f"({escape(name[other.objective])}) at the same budget funds {len(other.chosen)} of {other.n_sections} "
            f"sections for {cell(other.cost, money_columns=True, currency=cur)} (median benefit/cost "
            f"{bc(compared['other_median_benefit_cost'])}, against {bc(compared['median_benefit_cost'])} for the "
            f"programme above; programme.csv column other_programme_option_{escape(other.objective)}).</p>"
            f"<p>{escape(compared['line'])}</p></div>")


def _programme_section(doc: Document, res, programme, figures: dict, budget_basis: str, other=None,
                       compared=None) -> None:
    """Add the section "Programme within the budget": its explanation, the funded sections and the frontier.

    Parameters
    ----------
    doc : Document
        The report.
    res : CorridorResult
        The corridor's results.
    programme : Programme
        The budget programme.
    figures : dict
        Figures by name (``frontier`` is shown when present).
    budget_basis : str
        ``"total"`` or ``"year"``.
    other : Programme, optional
        The other objective's programme at the same budget.
    compared : dict, optional
        Where the two differ (:meth:`riskrf.app.corridor.CorridorResult.compare_programmes`).
    """
    box = _programme_box(res.corridor, programme, budget_basis)
    doc.section("Programme within the budget")
    doc.add(box)
    if other is not None and compared is not None:
        doc.add(_other_box(res.corridor, programme, other, compared))
    pt = res.programme_table(programme)
    funded = pt[pt["programme_option"] != ""]
    doc.add(doc.table(funded.head(HTML_ROWS), _caption_rows("Sections the programme funds", len(funded),
                                                            "programme.csv"),
                      money_columns=("do_nothing_total_cost", "programme_capital", "programme_present_value",
                                     "programme_equivalent_annual_cost", "programme_expected_total_cost"),
                      currency=res.corridor.currency))
    if "frontier" in figures:
        doc.add(doc.figure(figures["frontier"], "Efficient frontier: what the best programme buys at each "
                                                "budget (each point an exact programme; frontier.csv)"))


def _ranking_sections(doc: Document, s, b, disagree, places: int, cur: str) -> None:
    """Add the sections of the ranked table, the budget curve and, if any, the sections whose ranks disagree.

    Parameters
    ----------
    doc : Document
        The report.
    s : pandas.DataFrame
        The ranked summary as shown (:func:`_ranked_tables`).
    b : pandas.DataFrame
        :meth:`CorridorResult.budget_curve`.
    disagree : pandas.DataFrame
        Sections whose RHRS and risk ranks differ by at least ``places``.
    places : int
        That rank difference.
    cur : str
        Currency.
    """
    doc.section("Sections ranked by quantitative risk (RHRS rank beside)")
    doc.add("<p>Whole-point RHRS category scores and totals of every section are in sections.csv; one rating sheet "
            "per section is in <code>rating_sheets.html</code>.</p>",
            doc.table(s.head(HTML_ROWS), _caption_rows("Sections ranked by risk", len(s), "corridor.csv"),
                      money_columns=_RANKED_MONEY_COLUMNS, currency=cur))
    doc.section("Budget curve")
    doc.add("<p>Sections in order of deaths avoided per unit spent with their best option: what a budget buys when "
            "sections are done in this order (a greedy order; the programme above is the exact choice). Spend is "
            "the present value (capital + renewals + maintenance) above doing nothing.</p>",
            doc.table(b.head(HTML_ROWS), _caption_rows("Budget curve", len(b), "budget_curve.csv"),
                      money_columns=_RANKED_MONEY_COLUMNS, currency=cur))
    if len(disagree):
        doc.section("Where the RHRS and the risk ranking disagree")
        doc.add(f"<p>Sections whose RHRS rank and risk rank differ by at least {places} places.</p>",
                doc.table(disagree[["id", "rank_risk", "rank_rhrs", "rhrs_total" if "rhrs_total" in disagree else
                                    "rhrs_score", "deaths_per_year", "individual_risk"]].head(HTML_ROWS),
                          "RHRS and risk ranks that disagree"))


def _closing_sections(doc: Document, res) -> None:
    """Add the closing sections: rejected rows and failed sections (if any) and the inputs left at their defaults.

    Parameters
    ----------
    doc : Document
        The report.
    res : CorridorResult
        The corridor run: its failures, and its corridor's rejected rows and defaults used.
    """
    c = res.corridor
    if c.errors or res.failures:
        doc.section("Rejected rows and failed sections")
        doc.add("<div class='warn'><ul>" + "".join(f"<li>{escape(e)}</li>" for e in list(c.errors) + list(res.failures))
                + "</ul></div>")
    doc.section("Inputs left at their defaults")
    doc.add("<ul>" + "".join(f"<li>{escape(d)}</li>" for d in c.defaults_used) + "</ul>")


def render_corridor_html(res, figure_png: Path, *, figures: dict | None = None, programme=None, frontier=None,
                         budget_basis: str = "total", other=None, compared=None) -> str:
    """Self-contained HTML corridor report: key figures, chainage figure, map, the budget programme and its
    efficient frontier, ranked table (first :data:`HTML_ROWS` rows), budget curve, where the RHRS and the
    quantitative ranking disagree, rejected rows, failures and assumptions.

    Parameters
    ----------
    res : CorridorResult
        The corridor's results.
    figure_png : pathlib.Path
        The chainage figure.
    figures : dict, optional
        Other figures by name (``map``, ``frontier`` ...).
    programme : Programme, optional
        The budget programme.
    frontier : Frontier, optional
        Its efficient frontier.
    budget_basis : str
        What the budget counts: ``"total"`` (capital paid now) or ``"year"`` (equivalent annual cost).
    other : Programme, optional
        The other objective's programme at the same budget, shown beside ``programme``.
    compared : dict, optional
        Where the two differ (:meth:`riskrf.app.corridor.CorridorResult.compare_programmes`).

    Returns
    -------
    str
        A complete HTML document.
    """
    figures = figures or {}
    c = res.corridor
    s = res.summary()
    b = res.budget_curve()
    s, disagree, places = _ranked_tables(s)
    doc = Document(title=c.name)
    header = _report_header(res)
    _chainage_section(doc, len(res.table), figure_png)
    if "map" in figures:
        _map_section(doc, c, figures, programme is not None)
    if programme is not None:
        _programme_section(doc, res, programme, figures, budget_basis, other, compared)
    _ranking_sections(doc, s, b, disagree, places, c.currency)
    _closing_sections(doc, res)
    return doc.render(header=header)
