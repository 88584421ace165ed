"""What the mitigation study recommends and how sure it is: the resolution of the two cheapest options (with the
error budget of :mod:`riskrf.risk.error_budget`), and the recommendation in plain words, among the options that
pass their design checks (:class:`RecommendationMixin`, a part of
:class:`~riskrf.risk.mitigation.MitigationStudy`).  Money in the study currency, risks per year.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..core.format import money, probability
from .error_budget import clustered_se, combined_se


class RecommendationMixin:
    """The resolution and recommendation methods of :class:`~riskrf.risk.mitigation.MitigationStudy` (they use its
    ranking, joint samples, criteria, ensemble and required barrier)."""

    def resolution(self, ranking: pd.DataFrame | None = None) -> dict:
        """Can the joint samples tell the two cheapest options apart?

        Paired over the joint samples: the difference of their total costs and P(best) of the cheapest, each with
        its standard error over every Monte Carlo source (:mod:`riskrf.risk.error_budget`): the joint samples
        clustered by the material re-simulation they share (``material_draws``), and the trajectory ensembles'
        variance from repeated ensembles (``ensemble``; without them the text says it is not included).  They are
        "distinguishable" (the ranking is resolved) when the lead, the mean difference, exceeds twice its standard
        error; P(best) is stated with its two standard errors.  More draws and samples (``[uncertainty]``, or the
        adaptive effort of :func:`riskrf.risk.error_budget.adapt_effort`) narrow both.

        Parameters
        ----------
        ranking : pandas.DataFrame, optional
            A table from :meth:`ranking` (computed when None).

        Returns
        -------
        dict
            ``first`` and ``second`` (option names), ``difference`` and ``difference_se`` [study currency],
            ``probability_best`` and ``probability_best_se`` [-], ``distinguishable`` (bool) and ``text``.
        """
        t = self.ranking() if ranking is None else ranking
        u = self.uncertain
        names = u["names"]
        if len(t) < 2:                        # e.g. the only option that passes its design checks
            a = t["option"].iloc[0]
            return {"first": a, "second": None, "difference": float("nan"), "difference_se": float("nan"),
                    "probability_best": float(u["probability_best"][names.index(a)]),
                    "probability_best_se": float("nan"), "distinguishable": True,
                    "text": f"{a} is the only option left to compare."}
        a, b = t["option"].iloc[0], t["option"].iloc[1]
        d = u["total"][:, names.index(b)] - u["total"][:, names.index(a)]
        ens = self.ensemble
        g = u["clusters"]
        se = combined_se(clustered_se(d, g, u["design"]), None if ens is None else ens.difference_variance(a, b))
        p = float(u["probability_best"][names.index(a)])
        se_p = combined_se(clustered_se((u["best"] == names.index(a)).astype(float), g, u["design"]),
                           None if ens is None else ens.probability_variance(a))
        ok = bool(abs(d.mean()) > 2 * se)
        text = (f"{a} and {b} {'are' if ok else 'are NOT'} distinguishable at the stated effort ({u['error_sources']}"
                + f"): {b} costs "
                f"{money(d.mean(), self.currency, sig=3)} more in expectation (+- {money(2 * se, sig=2)}, two "
                f"standard errors); P({a} cheapest) = {p:.2f} +- {2 * se_p:.2f}")
        if not ok:
            text += "; more samples and re-simulations, or better information, are needed to separate them"
        return {"first": a, "second": b, "difference": float(d.mean()), "difference_se": se,
                "probability_best": p, "probability_best_se": se_p, "distinguishable": ok,
                "error_sources": u["error_sources"], "text": text + "."}

    def best(self) -> str:
        """Name of the first option of :meth:`ranking` (the lowest expected total cost over the joint samples).

        Returns
        -------
        str
            Name of the option ranked first.
        """
        return self.ranking()["option"].iloc[0]

    def recommendation(self, ranking: pd.DataFrame | None = None) -> dict:
        """The cheapest option meeting the tolerability criteria, else the one reducing risk most per unit cost,
        among the options that pass their design checks, with the reasoning in plain words.

        An option whose design checks fail ("NOT ADEQUATE" in ``design_check``) stays in the ranking, marked, and is
        never recommended: the reason names each such option that would otherwise have been chosen, and says when
        no adequate option exists.  The required barrier (``required_barrier``) is reported: where it is ranked, or
        why none can be placed and what would work instead.

        Parameters
        ----------
        ranking : pandas.DataFrame, optional
            A table from :meth:`ranking` (computed when None).

        Returns
        -------
        dict
            ``option`` (name; None when no option passes its design checks), ``basis`` (the rule that chose it),
            ``reason`` (plain words), ``resolution`` (:meth:`resolution`), ``expected_total_cost`` [study currency],
            ``probability_best`` [-], ``design_check`` (the chosen option's verdict), ``not_recommended`` (option
            name -> its failed design checks) and ``required_barrier`` (its sentence, or None).
        """
        t_all = self.ranking() if ranking is None else ranking
        cur = self.currency
        lim = self.criteria.individual_risk_per_year
        bad = ~t_all["design_adequate"].astype(bool) if "design_adequate" in t_all \
            else pd.Series(False, index=t_all.index)
        rejected = t_all[bad]
        t = t_all[~bad]
        rb = self.required_barrier
        rb_text = rb.text(cur) if rb is not None else None
        excluded = ""
        if len(rejected):
            tolerable_bad = rejected[rejected["meets_criteria"]]
            excluded = (" Not recommended, whatever their cost, because they fail their design checks: "
                        + "; ".join(f"{r['option']} ({r['design_check']})" for _, r in rejected.iterrows()) + ".")
            best_ok = t.loc[t["meets_criteria"], "expected_total_cost"].min() if t["meets_criteria"].any() \
                else np.inf
            if len(tolerable_bad) and tolerable_bad["expected_total_cost"].iloc[0] < best_ok:
                excluded += (f" {tolerable_bad['option'].iloc[0]} would be the cheapest tolerable option but is "
                             "not adequate.")
        if t.empty:
            why = ("NO ADEQUATE OPTION: every option fails its design checks, so none is recommended."
                   + excluded + (" " + rb_text if rb_text else ""))
            res = self.resolution(t_all)
            return {"option": None, "basis": "no option passes its design checks", "reason": why, "resolution": res,
                    "expected_total_cost": float("nan"), "probability_best": float("nan"), "design_check": None,
                    "not_recommended": dict(zip(rejected["option"], rejected["design_check"])),
                    "required_barrier": rb_text}
        ok = t[t["meets_criteria"]]
        cheapest = t.iloc[0]
        if len(ok):
            rec = ok.iloc[0]
            why = (f"{rec['option']} is the cheapest option that meets the tolerability criteria (individual risk "
                   f"{probability(rec['individual_risk'])}/yr against {probability(lim)}/yr; societal risk "
                   f"{rec['fn_zone']} on the "
                   f"{self.criteria.fn_diagram} F-N diagram). Its expected total cost is "
                   f"{money(rec['expected_total_cost'], cur, sig=3)} (5-95 %: {money(rec['cost_p05'], sig=3)} to "
                   f"{money(rec['cost_p95'], cur, sig=3)}); it meets them in "
                   f"{rec['probability_meets_criteria']:.0%} of the "
                   "joint samples of the uncertain inputs.")
            if rec["option"] != cheapest["option"]:
                intolerable = t[(t["expected_total_cost"] < rec["expected_total_cost"])]
                why += (f" Cheaper options leave the risk intolerable: {cheapest['option']} costs least "
                        f"({money(cheapest['expected_total_cost'], cur, sig=3)}, the cheapest in "
                        f"{cheapest['probability_best']:.0%} of the joint samples) but leaves individual risk "
                        f"{probability(cheapest['individual_risk'])}/yr and societal risk {cheapest['fn_zone']}"
                        + (f"; so do {', '.join(intolerable['option'].iloc[1:])}" if len(intolerable) > 1 else "")
                        + f". Meeting the criteria costs "
                        f"{money(rec['expected_total_cost'] - cheapest['expected_total_cost'], cur, sig=3)} more in "
                        "expectation.")
            else:
                most = t.loc[t["probability_best"].idxmax()]
                why += " It also has the lowest expected total cost of all options" + (
                    f", though it is the cheapest in only {rec['probability_best']:.0%} of the joint samples "
                    f"({most['option']}: {most['probability_best']:.0%})." if most["option"] != rec["option"]
                    else f", and is the cheapest in {rec['probability_best']:.0%} of the joint samples.")
            basis = "cheapest tolerable option"
            if "alarp" in rec and str(rec["alarp"]).startswith("not ALARP"):
                why += f" ALARP test: {rec['alarp']}."
        else:
            crit = self.criteria.describe()
            safest = t.sort_values(["individual_risk", "deaths_per_year"], kind="stable").iloc[0]
            ir_factor = safest["individual_risk"] / lim if lim > 0 else np.inf
            fn_factor = float(safest.get("fn_ratio_to_limit", 0.0))
            factor = max(ir_factor, fn_factor, 1.0)
            need = (f"NO OPTION IS TOLERABLE under {crit}. What would be needed: the safest option, "
                    f"{safest['option']}, leaves individual risk {probability(safest['individual_risk'])}/yr "
                    f"(limit {probability(lim)}/yr)"
                    + (f" and an F-N curve up to {fn_factor:.3g} times the unacceptable line" if fn_factor > 1 else "")
                    + f"; its risk would have to fall by a factor of {factor:.3g} (a further measure removing "
                    f"{1 - 1 / factor:.1%} of the falls that still reach the road, or fewer people exposed). ")
            cand = t[t["kind"] != "none"].dropna(subset=["deaths_avoided_per_million"])
            cand = cand[cand["deaths_avoided_per_million"] > 0]
            if len(cand) == 0:
                rec, basis = cheapest, "no option is tolerable; lowest expected total cost (no option reduces the risk)"
                why = need + f"No option reduces the risk; {rec['option']} costs least."
            else:
                rec = cand.sort_values("deaths_avoided_per_million", ascending=False).iloc[0]
                basis = "no option is tolerable; largest risk reduction per unit cost"
                why = need + (f"Among the options given, {rec['option']} reduces the risk most per unit cost: "
                              f"{rec['deaths_avoided_per_million']:.3g} statistical lives saved over "
                              f"{self.economics.horizon_years:g} years per million {cur} spent; residual individual "
                              f"risk {probability(rec['individual_risk'])}/yr. It is not tolerable either.")
        if not len(ok) and len(t) < len(t_all):
            basis = basis.replace("no option is tolerable", "no adequate option is tolerable")
        why += excluded
        if rb is not None and rb.placeable and rb.option.name in list(t_all["option"]) \
                and rb.option.name != rec["option"]:
            row = t_all[t_all["option"] == rb.option.name].iloc[0]
            why += (f" {rb_text} It is ranked {int(row['rank'])} of {len(t_all)} at "
                    f"{money(row['expected_total_cost'], cur, sig=3)}"
                    + ("" if row["meets_criteria"] else " and does not meet the tolerability criteria") + ".")
        elif rb is not None and not rb.placeable:
            why += " " + rb_text
        check = str(rec.get("design_check", "-"))
        if check.startswith("adequate") and "not checked" in check:
            why += f" Its design check: {check}; complete it before signing."
        elif check == "not checked":
            why += " Its design checks were not run (no requirement at its line); check it before signing."
        if "ASSUMED" in str(rec["effect_basis"]):
            why += f" Note: its effect is partly assumed ({rec['effect_basis']})."
        elif "ASSUMPTION" in str(rec["effect_basis"]):
            why += f" Note: its effectiveness is typed, not derived ({rec['effect_basis']})."
        res = self.resolution(t)
        why += " " + res["text"][0].upper() + res["text"][1:]
        return {"option": str(rec["option"]), "basis": basis, "reason": why, "resolution": res,
                "expected_total_cost": float(rec["expected_total_cost"]),
                "probability_best": float(rec["probability_best"]), "design_check": check,
                "not_recommended": dict(zip(rejected["option"], rejected["design_check"])),
                "required_barrier": rb_text}


__all__ = ["RecommendationMixin"]
