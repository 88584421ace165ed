"""Printable and written results of a mitigation study: ranking, break-even, tornado, figures."""
from __future__ import annotations

import numpy as np
import pandas as pd


def study_report(study) -> dict:
    """Ranking, tornado, break-even and a printable text of a mitigation study."""
    ranking = study.ranking()
    tornado = study.tornado()
    be = study.break_even_table()
    cur = study.currency
    show = ranking.copy()
    for c in ("capital", "pv_maintenance", "pv_expected_loss", "expected_total_cost"):
        show[c] = show[c].map(lambda v: f"{v:,.0f}")
    show["individual_risk"] = show["individual_risk"].map(lambda v: f"{v:.2e}")
    show["road_falls_per_year"] = show["road_falls_per_year"].map(lambda v: f"{v:.3g}")
    show["deaths_per_year"] = show["deaths_per_year"].map(lambda v: f"{v:.2e}")
    show["benefit_cost_ratio"] = show["benefit_cost_ratio"].map(lambda v: "" if pd.isna(v) else f"{v:.2f}")
    a, b = ranking["option"].iloc[0], ranking["option"].iloc[1]
    lines = [f"Mitigation ranking by expected total cost ({cur}, present values over "
             f"{study.economics.horizon_years:g} years at {study.economics.discount_rate:.1%}):",
             show.drop(columns=["kind"]).to_string(index=False), "",
             f"Best: {a}.  What would make {b!r} as good (break-even, other inputs unchanged):"]
    for r in be.itertuples():
        if np.isfinite(r.break_even):
            lines.append(f"  {r.parameter}: {r.current:,.4g} -> {r.break_even:,.4g} (x{r.factor:.3g})")
        else:
            lines.append(f"  {r.parameter}: {r.note}")
    voi = study.value_of_information()
    lines += ["", f"Value of perfect information about the fall rate (x0.5 / x1 / x2 with probabilities "
                  f"1/4, 1/2, 1/4): {voi['evpi']:,.0f} {cur}; best option by rate: "
                  + ", ".join(f"{k}: {v}" for k, v in voi["best_by_rate"].items())]
    lines += ["", "Tornado (best option's expected total cost with each input halved / doubled):"]
    for r in tornado.itertuples():
        lines.append(f"  {r.parameter:<40} {r.cost_at_low:>14,.0f} .. {r.cost_at_high:>14,.0f}   "
                     f"best: {r.best_at_low} / {r.best_at_high}")
    if study.defaults_used:
        lines += ["", "Defaults used: " + "; ".join(study.defaults_used)]
    return {"ranking": ranking, "tornado": tornado, "break_even": be, "value_of_information": voi,
            "text": "\n".join(lines)}


def write_mitigation_outputs(study, report, tmp) -> None:
    from ..outputs import write_json
    from .decision_figures import plot_fn, plot_tornado, plot_tree
    from .files import save_figure
    report["ranking"].to_csv(tmp / "ranking.csv", index=False)
    report["tornado"].to_csv(tmp / "tornado.csv", index=False)
    report["break_even"].to_csv(tmp / "break_even.csv", index=False)
    tree = study.to_tree()
    write_json({"currency": study.currency, "ranking": report["ranking"], "break_even": report["break_even"],
                "tornado": report["tornado"], "tree_value": tree.rollback().value,
                "value_of_information": report["value_of_information"],
                "defaults_used": list(study.defaults_used)}, tmp / "decision.json")
    ax = plot_tree(tree)
    save_figure(ax.figure, tmp / "tree.png")
    ax = plot_tornado(report["tornado"], currency=study.currency)
    save_figure(ax.figure, tmp / "tornado.png")
    curves = {o.name: study.fn_curve(o.name) for o in study.options if o.kind != "realignment"}
    ax = plot_fn(curves)
    save_figure(ax.figure, tmp / "fn_curve.png")
