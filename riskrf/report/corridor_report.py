"""The corridor report of ``riskrf corridor``: the figure along chainage and the self-contained HTML page."""
from __future__ import annotations

from pathlib import Path

from .. import __version__
from ..core.units import M_PER_KM
from .format import Document, cell, escape


def plot_corridor(res):
    """Along chainage: RHRS score, individual risk (criterion line), deaths per year per km now and with the
    best option."""
    import matplotlib.pyplot as plt
    t = res.table.sort_values("chainage_from_m")
    x0, w = t["chainage_from_m"].to_numpy() / M_PER_KM, t["length_m"].to_numpy() / M_PER_KM
    fig, ax = plt.subplots(3, 1, figsize=(10, 7.5), sharex=True)
    ax[0].bar(x0, t["rhrs_score"], width=w, align="edge", color="#8c6d31", edgecolor="k", lw=0.3)
    ax[0].set_ylabel("RHRS score")
    ax[1].bar(x0, t["individual_risk"], width=w, align="edge", color="#d62728", alpha=0.7, edgecolor="k", lw=0.3,
              label="do nothing")
    ax[1].bar(x0, t["best_individual_risk"], width=w, align="edge", color="#2ca02c", alpha=0.8, edgecolor="k",
              lw=0.3, label="best option")
    ax[1].axhline(res.corridor.study["criteria"].individual_risk_per_year, color="k", ls="--", lw=1,
                  label="tolerable")
    ax[1].set_yscale("log")
    ax[1].set_ylabel("individual risk [1/yr]")
    ax[1].legend(fontsize=8, loc="upper right")
    km = t["length_m"].to_numpy() / M_PER_KM
    ax[2].bar(x0, t["deaths_per_year"] / km, width=w, align="edge", color="#d62728", alpha=0.7, edgecolor="k",
              lw=0.3, label="do nothing")
    ax[2].bar(x0, t["best_deaths_per_year"] / km, width=w, align="edge", color="#2ca02c", alpha=0.8,
              edgecolor="k", lw=0.3, label="best option")
    ax[2].set_yscale("log")
    ax[2].set_ylabel("deaths per year per km")
    ax[2].set_xlabel("chainage [km]")
    ax[2].legend(fontsize=8, loc="upper right")
    for i, (a, b, sid) in enumerate(zip(x0, w, t["id"])):
        ax[0].annotate(str(sid), (a + b / 2, 0), xytext=(0, 2), textcoords="offset points", ha="center",
                       fontsize=6, rotation=90)
    fig.suptitle(f"{res.corridor.name}: {len(t)} sections")
    fig.subplots_adjust(left=0.09, right=0.98, bottom=0.07, top=0.93, hspace=0.12)   # tight_layout: seconds
    return fig


def render_corridor_html(res, figure_png: Path) -> str:
    """Self-contained HTML corridor report: key figures, chainage figure, ranked table, budget curve, where the
    RHRS and the quantitative ranking disagree, rejected rows, failures and assumptions."""
    c = res.corridor
    cur = c.currency
    s = res.summary()
    b = res.budget_curve()
    t = res.table
    money_cols = ("best_option_capital", "best_option_total_cost", "expected_annual_cost_per_km", "spend",
                  "cumulative_spend")
    disagree = s[(s["rank_difference"].abs() >= max(3, len(s) // 5)).fillna(False).astype(bool)] \
        if s["rank_rhrs"].notna().any() else s.iloc[0:0]
    s = s.copy()
    for col in ("rank_rhrs", "rank_difference"):           # integer ranks; a section without RHRS attributes: blank
        s[col] = s[col].astype(object).where(s[col].notna(), "")
    disagree = disagree.astype({"rank_rhrs": object, "rank_difference": object})
    doc = Document(title=c.name)
    header = (f"<h1>{escape(c.name)}</h1>"
              f"<p>{len(t)} sections assessed on {res.workers} dask worker(s) in {res.seconds:.1f} s, "
              f"{res.n_blocks:,} simulated blocks per section, corridor seed {c.seed} (riskrf {__version__}).</p>"
              "<div class='box'><ul>"
              f"<li>Deaths per year, doing nothing: {cell(float(t['deaths_per_year'].sum()))}; with each section's "
              f"best option: {cell(float(t['best_deaths_per_year'].sum()))}</li>"
              f"<li>Capital of the best options: "
              f"{cell(float(t['best_option_capital'].sum()), money_columns=True, currency=cur)}</li><li>Rates: "
              + ("falls reaching the road (as recorded), release rate derived per section from the share reaching "
                 "the road averaged over the mass law" if c.rate_basis == "road" else "falls released (>= m_min)")
              + "</li><li>Hazard at the barrier line mass-coupled as in riskrf assess (blocks simulated across the "
                "mass law, reach and speed by mass class); the cut's own seeder only for the option effects"
              + f"</li><li>{escape(c.mass_note)}</li></ul></div>")
    doc.section("Along the chainage")
    doc.add(doc.figure(figure_png, "RHRS score, individual risk and deaths per year per km of each section, doing "
                                   "nothing and with its best option"))
    doc.section("Sections ranked by quantitative risk (RHRS rank beside)")
    doc.add(doc.table(s, "Sections ranked by risk", money_columns=money_cols, currency=cur))
    doc.section("Budget curve")
    doc.add("<p>Sections in order of deaths avoided per unit spent with their best option: what a budget buys when "
            "sections are done in this order.</p>",
            doc.table(b, "Budget curve", money_columns=money_cols, currency=cur))
    if len(disagree):
        doc.section("Where the RHRS and the risk ranking disagree")
        doc.add(f"<p>Sections whose RHRS rank and risk rank differ by at least {max(3, len(s) // 5)} places.</p>",
                doc.table(disagree[["id", "rank_risk", "rank_rhrs", "rhrs_score", "deaths_per_year",
                                    "individual_risk"]], "RHRS and risk ranks that disagree"))
    if c.errors or res.failures:
        doc.section("Rejected rows and failed sections")
        doc.add("<div class='warn'><ul>" + "".join(f"<li>{escape(e)}</li>" for e in list(c.errors) + list(res.failures))
                + "</ul></div>")
    doc.section("Inputs left at their defaults")
    doc.add("<ul>" + "".join(f"<li>{escape(d)}</li>" for d in c.defaults_used) + "</ul>")
    return doc.render(header=header)
