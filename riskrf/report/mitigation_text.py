"""Printable and written results of a mitigation study: ranking, recommendation, break-even, tornado, figures."""
from __future__ import annotations

import numpy as np
import pandas as pd

from .format import money, probability   # money for a manager: "1,250,000 CHF"; 3 figures when uncertain


def option_entries(study, ranking: pd.DataFrame) -> list:
    """The ``options`` entries of summary.json: one dict per option, ranked.

    Parameters
    ----------
    study : MitigationStudy
        The study.
    ranking : pandas.DataFrame
        Its ranking (:meth:`MitigationStudy.ranking`).

    Returns
    -------
    list of dict
        Name, kind, rank, description and the option's costs [currency] and risks.
    """
    out = []
    table = study.options_table().set_index("option")
    for _, r in ranking.iterrows():
        e = {"name": r["option"], "kind": r["kind"], "rank": int(r["rank"]),
             "description": table.loc[r["option"], "what it is and assumes"],
             "expected_total_cost": float(r["expected_total_cost"]), "cost_p05": float(r["cost_p05"]),
             "cost_p95": float(r["cost_p95"]), "cost_at_central_values": float(r["cost_at_central_values"]),
             "probability_best": float(r["probability_best"]), "expected_regret": float(r["expected_regret"]),
             "capital_cost": float(r["capital"]), "pv_renewals": float(r["pv_renewals"]),
             "pv_maintenance_repairs_replacements": float(r["pv_maintenance"]),
             "pv_expected_loss": float(r["pv_expected_loss"]),
             "road_falls_per_year": float(r["road_falls_per_year"]),
             "individual_risk_per_year": float(r["individual_risk"]),
             "deaths_per_year": float(r["deaths_per_year"]), "fn_zone": r["fn_zone"],
             "meets_criteria": bool(r["meets_criteria"]),
             "probability_meets_criteria": float(r["probability_meets_criteria"]),
             "effectiveness": float(r["effectiveness"]),
             "effect_basis": r["effect_basis"],
             "repairs_per_year": float(r["repairs_per_year"]),
             "replacements_per_year": float(r["replacements_per_year"])}
        if r["retention"] is not None and not pd.isna(r["retention"]):
            e["retention"] = float(r["retention"])
        out.append(e)
    return out


def study_report(study, *, tornado=None, campaign=None) -> dict:
    """Ranking, recommendation, tornado, break-even, value of information and a printable text.

    Parameters
    ----------
    study : MitigationStudy
        The study.
    tornado : pandas.DataFrame, optional
        ``study.tornado()`` when it was computed already (it is then not computed again).
    campaign : object with ``result()``, optional
        The value of a release campaign being computed elsewhere (``runner.beside`` of
        :func:`riskrf.risk.campaign.release_campaign_value`), taken once the rest of the report is computed; by
        default it is computed here.

    Returns
    -------
    dict
        ``ranking``, ``tornado``, ``break_even``, ``options_table`` (DataFrames), ``value_of_information``,
        ``release_campaign`` (the value of a release campaign priced from the study's material draws,
        :func:`riskrf.risk.campaign.release_campaign_value`: a JSON-ready dict, or None without material draws),
        ``recommendation``, ``options``, ``uncertainty`` and ``text``.
    """
    from ..risk.campaign import release_campaign_value
    ranking = study.ranking()
    tornado = study.tornado() if tornado is None else tornado
    be = study.break_even_table()
    rec = study.recommendation(ranking)
    voi = study.value_of_information()
    campaign = release_campaign_value(study) if campaign is None else campaign.result()
    cur = study.currency
    u = study.uncertainty
    ranges = study.parameter_ranges()
    show = pd.DataFrame({
        "rank": ranking["rank"], "option": ranking["option"],
        f"expected total cost [{cur}]": ranking["expected_total_cost"].map(lambda v: money(v, sig=3)),
        "5-95 %": [f"{money(a, sig=3)}-{money(b, sig=3)}" for a, b in zip(ranking["cost_p05"], ranking["cost_p95"])],
        "P(cheapest)": ranking["probability_best"].map(lambda v: f"{v:.1%}"),
        "capital": ranking["capital"].map(lambda v: f"{v:,.0f}"),
        "PV renewals": ranking["pv_renewals"].map(lambda v: money(v, sig=3)),
        "road falls/yr": ranking["road_falls_per_year"].map(lambda v: f"{v:.3g}"),
        "retention": ranking["retention"].map(lambda v: "" if v is None or pd.isna(v) else f"{v:.1%}"),
        "deaths/yr": ranking["deaths_per_year"].map(probability),
        "indiv. risk/yr": ranking["individual_risk"].map(probability),
        "F-N zone": ranking["fn_zone"]})
    lines = [f"Mitigation ranking by expected total cost ({cur}, present values over "
             f"{study.economics.horizon_years:g} years at {study.economics.discount_rate:.1%}; mean and 5-95 % over "
             f"{u.samples:,} joint samples of the uncertain inputs, seed {u.seed}):",
             show.to_string(index=False), "",
             "What each option is and assumes:"]
    for _, r in study.options_table().iterrows():
        lines.append(f"  {r['option']}: {r['what it is and assumes']} [{r['effect_basis']}]")
    lines += ["", f"RECOMMENDATION: {rec['option'] or 'none'} ({rec['basis']}).", "  " + rec["reason"], "",
              "Uncertain inputs sampled jointly: " + "; ".join(f"{k} {lo:.4g}-{hi:.4g} ({how})"
                                                                for k, (lo, hi, how) in ranges.items())]
    r0 = study._central_result
    order = np.argsort(r0.total[0], kind="stable")
    ca, cb = r0.names[order[0]], r0.names[order[1]]
    lines += ["", f"Break-even (at central values {ca!r} is cheapest, then {cb!r}; value at which they tie, "
                  "other inputs unchanged):"]
    for r in be.itertuples():
        if np.isfinite(r.break_even):
            flag = "  <- INSIDE the stated range" if r.within_stated_range else ""
            lines.append(f"  {r.parameter}: {r.current:,.4g} -> {r.break_even:,.4g}{flag}")
    n_none = int((~np.isfinite(be["break_even"])).sum())
    if n_none:
        lines.append(f"  ({n_none} inputs cannot make them tie within the searched range)")
    lines += ["", f"Value of perfect information: about the fall rate (x0.5 / x1 / x2 with probabilities 1/4, 1/2, "
                  f"1/4) {money(voi['evpi'], cur, sig=3)}; about all sampled inputs "
                  f"{money(voi['evpi_all_sampled_inputs'], cur, sig=3)}."]
    if campaign is not None:
        lines.append(f"Value of a release campaign (from the {campaign.n_draws} material draws): "
                     + campaign.verdict() + ".")
    lines += ["", "Tornado (lowest expected total cost at central values as each input moves over its range; "
                  "inputs that change the best option first):"]
    for r in tornado.itertuples():
        lines.append(f"  {r.parameter:<38} {r.low:>12,.4g} .. {r.high:<12,.4g} "
                     f"cost {money(r.cost_at_low, sig=3):>14} .. "
                     f"{money(r.cost_at_high, sig=3):>14}   best: {r.best_at_low} / {r.best_at_high}"
                     + ("  CHANGES THE BEST" if r.changes_best else "  changes the order" if r.changes_order
                        else ""))
    if study.defaults_used:
        lines += ["", "Defaults used: " + "; ".join(study.defaults_used)]
    not_sampled = [] if u.fractal_dimension else [
        ("fragmentation: the loss engine takes every event volume as one intact block (conservative for fence and "
         "shed loads, since one block carries the event's whole energy; the more numerous smaller fragments a road "
         "user might meet are not modelled; give uncertainty.fractal_dimension to break events up); stated "
         "fragmentation parameters of the design block are used only for the design block")]
    if not any(k.startswith("material:") for k in ranges):
        not_sampled.insert(0, "slope material parameters (no [uncertainty.materials] ranges given)")
    uncertainty = {"samples": u.samples, "seed": u.seed,
                   "inputs": {k: {"low": lo, "high": hi, "law": how} for k, (lo, hi, how) in ranges.items()},
                   "not_sampled": not_sampled}
    return {"ranking": ranking, "tornado": tornado, "break_even": be, "value_of_information": voi,
            "release_campaign": None if campaign is None else campaign.to_dict(), "recommendation": rec, "options": option_entries(study, ranking), "uncertainty": uncertainty,
            "options_table": study.options_table(), "text": "\n".join(lines)}


def write_tree_figure(study, tmp) -> None:
    """The decision tree of the options (``tree.png``).

    Parameters
    ----------
    study : MitigationStudy
        The study.
    tmp : pathlib.Path
        Folder the figure is written into.
    """
    from ..risk.figures import plot_tree
    from .files import save_figure
    ax = plot_tree(study.to_tree())
    save_figure(ax.figure, tmp / "tree.png")


def write_mitigation_outputs(study, report, tmp, *, tree_figure: bool = True, figures: bool = True) -> None:
    """Ranking, tornado, break-even and decision tables, and the tree (unless ``tree_figure`` is False: drawn
    apart by :func:`write_tree_figure`), tornado and F-N figures (unless ``figures`` is False: drawn apart by
    :func:`write_mitigation_figures`).

    Parameters
    ----------
    study : MitigationStudy
        The study.
    report : dict
        Its :func:`study_report`.
    tmp : pathlib.Path
        Folder written into.
    tree_figure : bool
        Draw the tree here.
    figures : bool
        Draw the tornado and F-N figures here.
    """
    from ..io.outputs import write_json
    report["ranking"].to_csv(tmp / "ranking.csv", index=False)
    report["tornado"].to_csv(tmp / "tornado.csv", index=False)
    report["break_even"].to_csv(tmp / "break_even.csv", index=False)
    tree = study.to_tree()
    write_json({"currency": study.currency, "recommendation": report["recommendation"],
                "options": report["options"], "ranking": report["ranking"], "break_even": report["break_even"],
                "tornado": report["tornado"], "tree_value": tree.rollback().value,
                "value_of_information": report["value_of_information"],
                "release_campaign": report["release_campaign"], "uncertainty": report["uncertainty"],
                "defaults_used": list(study.defaults_used)}, tmp / "decision.json")
    if tree_figure:
        write_tree_figure(study, tmp)
    if figures:
        write_mitigation_figures(study, report, tmp)


def write_mitigation_figures(study, report, tmp) -> None:
    """The tornado (tornado.png) and F-N (fn_curve.png) figures of a mitigation study.

    Parameters
    ----------
    study : MitigationStudy
        The study.
    report : dict
        Its :func:`study_report` (only its ``tornado`` is read).
    tmp : pathlib.Path
        Folder written into.
    """
    from ..risk.figures import plot_tornado
    from .decision_figures import plot_fn
    from .files import save_figure
    ax = plot_tornado(report["tornado"].head(15), currency=study.currency,   # the 15 inputs that matter most
                      xlabel=f"lowest cost of the options at central values [{study.currency}]")
    ax.xaxis.set_major_formatter(lambda v, _pos: f"{v:,.0f}")
    save_figure(ax.figure, tmp / "tornado.png")
    curves = {o.name: study.fn_curve(o.name) for o in study.options}
    ax = plot_fn(curves)
    save_figure(ax.figure, tmp / "fn_curve.png")
