"""Writing a corridor run: :func:`write_corridor` (report, tables, figures, GIS layer, summary.json).

Everything is written into a temporary directory that appears as ``out`` only when complete; with a budget
the programme, the other objective's programme beside it and the efficient frontier are added.
Money in the corridor currency, chainage m.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from .result import BUDGET_BASES, CorridorResult, _bad_basis


#: Points of the efficient frontier written with a programme: (up to the section count given, above it).
FRONTIER_POINTS = (25, 10, 500)


#: The objective whose programme is reported beside a programme's (``other_objective``).
OTHER_OBJECTIVE = {"alarp": "risk", "risk": "alarp", "cost": "alarp"}


def programme_summary(res: CorridorResult, programme, budget_basis: str = "total") -> dict:
    """A programme as summary.json gives it: budget, objective, GDF, cost, benefit, the funded sections with their
    options and benefit/cost, the sections required by tolerability and the overrun they cause.

    Parameters
    ----------
    res : CorridorResult
        The corridor run.
    programme : Programme
        The programme.
    budget_basis : str, optional
        ``"total"`` or ``"year"``.

    Returns
    -------
    dict
        JSON-ready; money in the corridor currency, benefit/cost [-].
    """
    ch = programme.chosen
    bc = ch["benefit_cost_ratio"] if "benefit_cost_ratio" in ch else pd.Series(np.nan, index=ch.index)
    gdf = programme.gdf if programme.objective == "alarp" else None
    return {"budget": programme.budget, "basis": budget_basis, "budget_caps": BUDGET_BASES[budget_basis],
            "objective": programme.objective, "maximised": programme.benefit_column,
            "gross_disproportion_factor": gdf, "cost": programme.cost, "benefit": programme.benefit,
            "sections_funded": int(len(ch)),
            "funded": [{"id": str(r["id"]), "option": str(r["option"]), "cost": float(r[programme.cost_column]),
                        "benefit_cost_ratio": None if not np.isfinite(b) else float(b),
                        "required_by_tolerability": bool(r.get("required_by_tolerability", False))}
                       for (_, r), b in zip(ch.iterrows(), bc)],
            "median_benefit_cost_ratio": float(np.nanmedian(bc)) if bc.notna().any() else None,
            "required_by_tolerability": list(programme.required), "overrun": programme.overrun,
            "gap": programme.gap}


def write_corridor(res: CorridorResult, out: Path, *, overwrite: bool = False, budget: float | None = None,
                   budget_basis: str = "total", objective: str = "alarp", programme=None, frontier=None,
                   gdf: float | None = None, other=None) -> None:
    """Write the corridor's outputs into ``out`` (a directory that appears only when everything is written; an
    existing non-empty ``out`` is replaced whole only with ``overwrite``):

    report.html, corridor.csv (ranked), sections.csv (by chainage; with a centreline also sections.gpkg, the same
    columns on each section's line in the centreline's CRS, and map.png), budget_curve.csv, chainage.png,
    rating_sheets.html (one RHRS sheet per rated section), summary.json; with ``budget`` also programme.csv (every
    section with the option the exact programme gives it, or none, and the option of the other objective's
    programme beside it), frontier.csv and frontier.png.  The other objective's programme (:data:`OTHER_OBJECTIVE`:
    deaths avoided beside the default ``"alarp"``, ``"alarp"`` beside the others) is solved at the same budget and
    named in summary.json (``other_programme``, and ``programme.disagreement``: one line) and in the report.
    ``programme``, ``frontier`` and ``other``: already solved (:meth:`CorridorResult.programme` and ``frontier`` of
    the same budget, basis and objective), written as they are instead of solved again.

    Parameters
    ----------
    res : CorridorResult
        The corridor run.
    out : pathlib.Path
        Output directory.
    overwrite : bool, optional
        Replace an existing non-empty ``out``.
    budget : float, optional
        Budget in the corridor currency (adds the programme outputs).
    budget_basis : str, optional
        ``"total"`` or ``"year"``.
    objective : str, optional
        ``"alarp"`` (default), ``"risk"`` or ``"cost"`` (see :meth:`CorridorResult.programme`).
    programme : Programme, optional
        Already solved programme.
    frontier : Frontier, optional
        Already solved frontier.
    gdf : float, optional
        Gross-disproportion factor [-] of ``"alarp"`` (default: the corridor's ``[criteria] disproportion_factor``).
    other : Programme, optional
        Already solved programme of the other objective.
    """
    from ...io.gis import write_lines_gpkg
    from ...io.outputs import atomic_output_dir, write_json
    from ...report.corridor_report import plot_frontier, plot_map, render_corridor_html, render_rating_sheets
    from ...report.files import save_figure
    if budget_basis not in BUDGET_BASES:
        _bad_basis(budget_basis)
    if budget is None and programme is not None:
        budget = programme.budget
    if programme is not None:
        objective = programme.objective
        gdf = programme.gdf if objective == "alarp" else gdf
    if budget is not None and programme is None:
        programme = res.programme(budget, basis=budget_basis, objective=objective, gdf=gdf)
    if budget is not None and other is None:
        other = res.programme(budget, basis=budget_basis, objective=OTHER_OBJECTIVE[objective], gdf=gdf)
    if budget is not None and frontier is None:
        # every frontier point is a full programme solve: fewer points for a long corridor (see FRONTIER_POINTS)
        frontier = res.frontier(basis=budget_basis, objective=objective, gdf=gdf,
                                points=FRONTIER_POINTS[0] if len(res.table) <= FRONTIER_POINTS[2] else FRONTIER_POINTS[1])
    compared = res.compare_programmes(programme, other) if programme is not None else None
    with atomic_output_dir(out, overwrite=overwrite) as tmp:
        res.summary().to_csv(tmp / "corridor.csv", index=False)
        sections = res.sections_table(programme)
        sections.to_csv(tmp / "sections.csv", index=False)
        res.budget_curve().to_csv(tmp / "budget_curve.csv", index=False)
        figures = {"chainage": save_figure(res.figure(), tmp / "chainage.png")}
        lines = res.lines()
        if lines is not None:
            write_lines_gpkg(tmp / "sections.gpkg", sections, lines, crs=res.corridor.crs)
            figures["map"] = save_figure(plot_map(res, lines, programme), tmp / "map.png")
        if programme is not None:
            pt = res.programme_table(programme)
            och = other.chosen.set_index("id")["option"]
            pt[f"other_programme_option_{other.objective}"] = [och[i] if i in och.index else "" for i in pt["id"]]
            pt.to_csv(tmp / "programme.csv", index=False)
            frontier.summary().to_csv(tmp / "frontier.csv", index=False)
            figures["frontier"] = save_figure(plot_frontier(frontier, currency=res.corridor.currency,
                                                            chosen_budget=budget), tmp / "frontier.png")
        (tmp / "rating_sheets.html").write_text(render_rating_sheets(res), encoding="utf-8")
        (tmp / "report.html").write_text(render_corridor_html(res, figures["chainage"], figures=figures,
                                                              programme=programme, frontier=frontier,
                                                              budget_basis=budget_basis, other=other,
                                                              compared=compared), encoding="utf-8")
        summary = res.to_json()
        if programme is not None:
            summary["programme"] = programme_summary(res, programme, budget_basis)
            summary["programme"]["disagreement"] = compared["line"]
            summary["other_programme"] = programme_summary(res, other, budget_basis)
        write_json(summary, tmp / "summary.json")
