"""The result of a corridor run: :class:`CorridorResult`, its tables, budget curve and budget programmes.

One row per section (``table``, plain numbers from :func:`riskrf.app.corridor.assess_section`); the ranked
corridor table, every buildable option, the sections the tolerability line requires, the exact budget
programme and its efficient frontier (:mod:`riskrf.risk.programme`), the chainage figure and the run summary.
Chainage m, rates per year, risks deaths per year, money in the corridor currency.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ...core.units import M_PER_KM
from .model import Corridor, _check_corridor_gdf


@dataclass(frozen=True)
class CorridorResult:
    """Results of a corridor run: one row per section (``table``), the failures, and how it ran."""

    corridor: Corridor
    table: pd.DataFrame = field(repr=False)
    failures: tuple = ()
    workers: int = 0
    seconds: float = 0.0
    n_blocks: int = 0

    def summary(self) -> pd.DataFrame:
        """Sections ranked by quantitative risk (deaths per year of doing nothing) with the RHRS rank beside it,
        the best option and its cost; ``rank_difference`` = RHRS rank - risk rank (large: they disagree).

        Returns
        -------
        pandas.DataFrame
            One row per section, ranked by risk [deaths/yr], with ``rank_rhrs``, ``rank_risk`` and ``rank_difference``.
        """
        t = self.table.copy()
        # ranks of values rounded to 12 significant digits: risks equal but for float noise share a rank, stably
        t["rank_risk"] = _sig12(t["deaths_per_year"]).rank(ascending=False, method="min").astype(int)
        t["rank_rhrs"] = _sig12(t["rhrs_score"]).rank(ascending=False, method="min").astype("Int64")
        t["rank_difference"] = t["rank_rhrs"] - t["rank_risk"]
        t["expected_annual_cost_per_km"] = t["expected_annual_loss_pv"] / _pv(self.corridor) / (t["length_m"] / M_PER_KM)
        cols = ["rank_risk", "rank_rhrs", "rank_difference", "id", "chainage_from_m", "chainage_to_m", "rhrs_score",
                "rhrs_total",
                "road_falls_per_year", "deaths_per_year", "individual_risk", "expected_annual_cost_per_km",
                "best_option", "best_option_capital", "best_option_total_cost", "best_individual_risk",
                "deaths_avoided_per_million", "meets_criteria", "note"]
        return t.sort_values(["rank_risk", "id"])[[c for c in cols if c in t]].reset_index(drop=True)

    def budget_curve(self) -> pd.DataFrame:
        """Sections in order of deaths avoided per unit spent (best option of each): cumulative spend and
        cumulative deaths avoided per year (how much risk a budget buys).

        Returns
        -------
        pandas.DataFrame
            One row per section: ``id``, ``option``, cumulative spend (corridor currency) and cumulative deaths avoided
            [1/yr].
        """
        t = self.table[self.table["best_option_spend"] > 0].copy() if "best_option_spend" in self.table else \
            self.table.iloc[0:0].copy()
        t["avoided_per_spend"] = t["deaths_avoided_per_year"] / t["best_option_spend"]
        t = t.sort_values(["avoided_per_spend", "id"], ascending=[False, True])
        return pd.DataFrame({"id": t["id"].to_numpy(), "option": t["best_option"].to_numpy(),
                             "spend": t["best_option_spend"].to_numpy(),
                             "cumulative_spend": t["best_option_spend"].cumsum().to_numpy(),
                             "deaths_avoided_per_year": t["deaths_avoided_per_year"].to_numpy(),
                             "cumulative_deaths_avoided_per_year": t["deaths_avoided_per_year"].cumsum().to_numpy()})

    def figure(self):
        """Along chainage: RHRS score, individual risk and deaths per year per km (see
        :func:`riskrf.report.corridor_report.plot_corridor`).

        Returns
        -------
        matplotlib.figure.Figure
            The chainage figure.
        """
        from ...report.corridor_report import plot_corridor
        return plot_corridor(self)

    def options_table(self) -> pd.DataFrame:
        """Every option that could be built on every section (one row each; "do nothing" left out: not funding a
        section is doing nothing there), with what it costs and what it buys against doing nothing.

        Money in the corridor currency: ``capital`` (paid now), ``present_value`` (capital + renewals +
        maintenance discounted at the corridor's rate over its horizon), ``equivalent_annual_cost``
        (present_value / annuity factor (1 - (1 + r)^-n) / r: the same money as a level cost per year);
        ``deaths_avoided_per_year`` and ``expected_total_cost_saving`` against the section's do-nothing option;
        ``loss_avoided`` (present value of the expected losses avoided, deaths at the VSL included: saving +
        present_value) and ``benefit_cost_ratio`` (loss_avoided / present_value [-],
        :func:`riskrf.risk.programme.benefit_cost_ratio`).

        Returns
        -------
        pandas.DataFrame
            One row per (section, option), with the columns above.
        """
        import json
        pv = _pv(self.corridor)
        rows = []
        for _, r in self.table.iterrows():
            for o in json.loads(r.get("options_json", "[]") or "[]"):
                if o["kind"] == "none":
                    continue
                present = o["capital"] + o["pv_renewals"] + o["pv_maintenance"]
                rows.append({"id": r["id"], "option": o["option"], "kind": o["kind"], "capital": o["capital"],
                             "present_value": present, "equivalent_annual_cost": present / pv,
                             "deaths_per_year": o["deaths_per_year"],
                             "deaths_avoided_per_year": r["deaths_per_year"] - o["deaths_per_year"],
                             "expected_total_cost": o["expected_total_cost"],
                             "expected_total_cost_saving": r["do_nothing_total_cost"] - o["expected_total_cost"],
                             "individual_risk": o["individual_risk"], "meets_criteria": o["meets_criteria"]})
        cols = ["id", "option", "kind", "capital", "present_value", "equivalent_annual_cost", "deaths_per_year",
                "deaths_avoided_per_year", "expected_total_cost", "expected_total_cost_saving", "individual_risk",
                "meets_criteria"]
        t = pd.DataFrame(rows, columns=cols)
        from ...risk.programme import benefit_cost_ratio
        t["loss_avoided"] = t["expected_total_cost_saving"] + t["present_value"]
        t["benefit_cost_ratio"] = benefit_cost_ratio(t["expected_total_cost_saving"], t["present_value"])
        return t

    @property
    def gdf(self) -> float:
        """The corridor's ALARP gross-disproportion factor [-] (``[criteria] disproportion_factor``, default 1)."""
        return float(self.corridor.study["criteria"].disproportion_factor)

    def required_sections(self) -> dict:
        """Sections above the intolerable individual-risk line, and the options that bring each below it.

        The line is the criteria's ``individual_risk_per_year`` (the limit in force, e.g. 1e-4 /yr for an existing
        slope under Hong Kong GEO Report 75 (1998)).  A section whose do-nothing individual risk exceeds it must be
        funded whatever it costs, by an option whose individual risk is at most the limit; where no option reaches
        it, by the options of least individual risk (the best it can be made).

        Returns
        -------
        dict
            ``{section id: [option names]}``, by chainage.
        """
        lim = float(self.corridor.study["criteria"].individual_risk_per_year)
        opts = self.options_table()
        out = {}
        for _, r in self.table.iterrows():
            if not float(r.get("individual_risk", 0.0) or 0.0) > lim:
                continue
            o = opts[opts["id"] == r["id"]]
            if not len(o):
                continue
            ok = o[o["individual_risk"] <= lim]
            if not len(ok):
                ok = o[o["individual_risk"] <= o["individual_risk"].min() * (1 + 1e-12)]
            out[r["id"]] = list(ok["option"])
        return out

    def programme(self, budget: float, *, basis: str = "total", objective: str = "alarp", gdf: float | None = None):
        """The best programme within ``budget`` (:func:`riskrf.risk.programme.optimise_programme`, exact MILP).

        ``basis``: ``"total"`` -- the budget caps the summed capital of the chosen options (money paid now);
        ``"year"`` -- it caps their summed equivalent annual cost (present value of capital, renewals and
        maintenance spread as a level yearly cost at the discount rate).

        ``objective``: ``"alarp"`` (default) first funds the sections above the intolerable individual-risk line
        whatever they cost (:meth:`required_sections`), then maximises the net benefit at the corridor's VSL with
        the gross-disproportion factor ``gdf`` (:func:`riskrf.risk.programme.alarp_net_benefit`): every other
        funded option is worth at least 1/GDF of its present value.  ``"risk"`` maximises deaths avoided per year
        and ``"cost"`` minimises the corridor's expected total cost (both as before, without the tolerability step).

        Parameters
        ----------
        budget : float
            Budget in the corridor currency.
        basis : str, optional
            ``"total"`` (capital) or ``"year"`` (equivalent annual cost).
        objective : str, optional
            ``"alarp"``, ``"risk"`` or ``"cost"``.
        gdf : float, optional
            Gross-disproportion factor [-], >= 1 (default: the corridor's, :attr:`gdf`).

        Returns
        -------
        Programme
            The chosen option of each funded section and the programme's cost and benefit.

        References
        ----------
        HSE (2001) Reducing risks, protecting people. HSE Books, para 140 and Appendix 3.
        """
        from ...risk.programme import optimise_programme
        gdf = self.gdf if gdf is None else _check_corridor_gdf(gdf, "gdf")
        return optimise_programme(self.options_table(), budget, objective=objective,
                                  cost_column=BUDGET_BASES[basis] if basis in BUDGET_BASES else _bad_basis(basis),
                                  gdf=gdf, required=self.required_sections() if objective == "alarp" else None)

    def frontier(self, *, basis: str = "total", objective: str = "alarp", points: int = 25, budgets=None,
                 gdf: float | None = None):
        """Efficient frontier: the best programme's benefit at each budget (exact at every point).

        Parameters
        ----------
        basis : str, optional
            ``"total"`` (capital) or ``"year"`` (equivalent annual cost).
        objective : str, optional
            ``"alarp"``, ``"risk"`` or ``"cost"`` (see :meth:`programme`).
        points : int, optional
            Number of budgets (when ``budgets`` is not given).
        budgets : sequence of float, optional
            Budgets to solve at, in the corridor currency.
        gdf : float, optional
            Gross-disproportion factor [-] of ``"alarp"`` (default: the corridor's).

        Returns
        -------
        Frontier
            The best benefit at each budget.
        """
        from ...risk.programme import efficient_frontier
        gdf = self.gdf if gdf is None else _check_corridor_gdf(gdf, "gdf")
        return efficient_frontier(self.options_table(), budgets, objective=objective, points=points,
                                  cost_column=BUDGET_BASES[basis] if basis in BUDGET_BASES else _bad_basis(basis),
                                  gdf=gdf, required=self.required_sections() if objective == "alarp" else None)

    def compare_programmes(self, programme, other) -> dict:
        """Where two programmes of the same budget differ, in numbers and in one line.

        Parameters
        ----------
        programme : Programme
            The programme recommended (e.g. objective ``"alarp"``).
        other : Programme
            The other objective's programme.

        Returns
        -------
        dict
            ``only_programme``, ``only_other`` and ``other_option`` (section ids funded by one only, or by both
            with different options), the median benefit/cost [-] of each programme's funded options, and
            ``line``: one sentence saying where they disagree.
        """
        a = programme.chosen.set_index("id")["option"]
        b = other.chosen.set_index("id")["option"]
        only_a = [i for i in self.table["id"] if i in a.index and i not in b.index]
        only_b = [i for i in self.table["id"] if i in b.index and i not in a.index]
        diff = [i for i in self.table["id"] if i in a.index and i in b.index and a[i] != b[i]]
        name = {"alarp": f"net benefit at the VSL (GDF {programme.gdf:g})", "risk": "deaths avoided",
                "cost": "expected total cost"}

        def median_bc(p):
            v = p.chosen["benefit_cost_ratio"] if "benefit_cost_ratio" in p.chosen else pd.Series(dtype=float)
            return float(np.nanmedian(v)) if len(v.dropna()) else float("nan")

        def ids(x):
            return ", ".join(x[:6]) + (f" and {len(x) - 6} more" if len(x) > 6 else "")
        bc_b = other.chosen.set_index("id")["benefit_cost_ratio"] if "benefit_cost_ratio" in other.chosen else {}
        parts = []
        if only_b:
            worth = np.nanmedian([bc_b[i] for i in only_b]) if len(bc_b) else float("nan")
            parts.append(f"the {name[other.objective]} programme also funds {len(only_b)} section(s) ({ids(only_b)}) "
                         f"worth a median {worth:.2g} of their cost")
        if only_a:
            parts.append(f"only the {name[programme.objective]} programme funds {ids(only_a)}")
        if diff:
            parts.append(f"they choose different options on {ids(diff)}")
        line = ("The two programmes agree." if not parts else
                f"Where they disagree: {'; '.join(parts)}.")
        return {"only_programme": only_a, "only_other": only_b, "other_option": diff,
                "median_benefit_cost": median_bc(programme), "other_median_benefit_cost": median_bc(other),
                "line": line}

    def programme_table(self, programme) -> pd.DataFrame:
        """Every section with the programme's choice: ``programme_option`` ("" = not funded: do nothing), its
        capital, present value and equivalent annual cost, deaths per year before and after.

        Parameters
        ----------
        programme : Programme
            A programme from :meth:`programme`.

        Returns
        -------
        pandas.DataFrame
            One row per section with the programme's choice, its costs and deaths per year before and after.
        """
        t = self.table[["id", "chainage_from_m", "chainage_to_m", "rhrs_total", "deaths_per_year",
                        "do_nothing_total_cost"]].copy()
        ch = programme.chosen.set_index("id")
        t["programme_option"] = [ch.loc[i, "option"] if i in ch.index else "" for i in t["id"]]
        for c in ("capital", "present_value", "equivalent_annual_cost"):
            t[f"programme_{c}"] = [float(ch.loc[i, c]) if i in ch.index else 0.0 for i in t["id"]]
        t["programme_deaths_per_year"] = [float(ch.loc[i, "deaths_per_year"]) if i in ch.index else d
                                          for i, d in zip(t["id"], t["deaths_per_year"])]
        t["programme_expected_total_cost"] = [float(ch.loc[i, "expected_total_cost"]) if i in ch.index else d
                                              for i, d in zip(t["id"], t["do_nothing_total_cost"])]
        if "benefit_cost_ratio" in ch:
            t["programme_benefit_cost_ratio"] = [float(ch.loc[i, "benefit_cost_ratio"]) if i in ch.index else np.nan
                                                 for i in t["id"]]
        req = set(getattr(programme, "required", ()))
        t["programme_required_by_tolerability"] = [i in req for i in t["id"]]
        return t

    def sections_table(self, programme=None) -> pd.DataFrame:
        """The result rows by chainage as written to sections.csv and sections.gpkg (same columns): everything
        but the per-option list (the text ``geometry`` of the cut renamed ``cut_geometry``), with the programme's
        choice when one is given.

        Parameters
        ----------
        programme : Programme, optional
            Add the programme's choice of each section.

        Returns
        -------
        pandas.DataFrame
            One row per section by chainage [m].
        """
        t = self.table.drop(columns=[c for c in ("options_json",) if c in self.table]).rename(
            columns={"geometry": "cut_geometry"})          # text: a GIS reserves "geometry" for the line itself
        if programme is not None:
            p = self.programme_table(programme)
            t = t.merge(p[["id"] + [c for c in p.columns if c.startswith("programme_")]], on="id", how="left")
        return t

    def lines(self) -> list | None:
        """Line geometry (k x 2 vertices, metres in :attr:`Corridor.crs`) of every row of :attr:`table`, or None
        when the corridor has no centreline.

        Returns
        -------
        list of numpy.ndarray or None
            One (k, 2) vertex array [m] per row of :attr:`table`.
        """
        if self.corridor.centreline is None:
            return None
        return self.corridor.centreline.cuts(self.table["chainage_from_m"], self.table["chainage_to_m"])

    def to_json(self) -> dict:
        """The run as a JSON-ready dict (``corridor_summary.json``): counts, failures, rejected rows, seed, blocks,
        workers, seconds, units (chainage m, rates 1/yr, money in the corridor's currency) and totals.

        Returns
        -------
        dict
            The run summary.
        """
        s = self.summary()
        return {"corridor": self.corridor.name, "sections": int(len(self.table)), "failures": list(self.failures),
                "rejected_rows": list(self.corridor.errors), "seed": self.corridor.seed, "n_blocks": self.n_blocks,
                "workers": self.workers, "seconds": round(self.seconds, 2), "rate_basis": self.corridor.rate_basis,
                "mass_law": self.corridor.mass_note, "currency": self.corridor.currency,
                "units": {"chainage": "m", "rate": "1/yr", "individual_risk": "1/yr", "money": self.corridor.currency},
                "total_deaths_per_year_do_nothing": float(self.table["deaths_per_year"].sum()),
                "total_deaths_per_year_best_options": float(self.table["best_deaths_per_year"].sum()),
                "total_capital_best_options": float(self.table["best_option_capital"].sum()),
                "top": s.head(10).replace({np.nan: None}).to_dict(orient="records"),
                "defaults_used": list(self.corridor.defaults_used)}


#: What a budget caps, by ``--budget-basis``: capital paid now, or the equivalent annual cost.
BUDGET_BASES = {"total": "capital", "year": "equivalent_annual_cost"}


def _bad_basis(basis):
    raise ValueError(f"budget basis = {basis!r} must be 'total' (capital paid now) or 'year' (equivalent annual "
                     "cost: present value of capital, renewals and maintenance as a level yearly cost)")


def _sig12(values: pd.Series) -> pd.Series:
    """Values rounded to 12 significant digits (NaN kept), for ranking without float-noise ties."""
    x = values.to_numpy(dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        digits = np.where(np.isfinite(x) & (x != 0), 11 - np.floor(np.log10(np.abs(x))), 0)
    return pd.Series([round(v, int(d)) if np.isfinite(v) else v for v, d in zip(x, digits)], index=values.index)


def _pv(corridor) -> float:
    from ...risk.economics import pv_factor
    e = corridor.study["economics"]
    return float(pv_factor(e.discount_rate, e.horizon_years))
