"""A mitigation programme under a budget: one option (or none) per section, chosen exactly.

The problem is a multiple-choice knapsack.  With a binary ``x[s, o]`` for "section s gets option o",

    maximise    sum_{s,o} benefit[s, o] * x[s, o]
    subject to  sum_{s,o} cost[s, o] * x[s, o] <= budget
                sum_o x[s, o] <= 1              for every section s   (at most one option; none = do nothing)
                x[s, o] in {0, 1}

solved by branch and bound (``scipy.optimize.milp``, HiGHS) asking for a zero optimality gap, so the programme
is the best one, not a greedy ranking by benefit per cost (which can miss it: a greedy order fills the budget
with small efficient items and leaves no room for a large one that buys more in total).  The solver proves
optimality against its bound; if it stops at ``time_limit_s`` first, the programme is the best found and
:attr:`Programme.gap` states the proven relative gap to the optimum (0: proven optimal).  For problems up to
:data:`TIE_BREAK_MAX` options, among programmes of equal benefit the cheapest is returned (a second solve that
minimises cost with the benefit held at its optimum); above that the first optimum found is kept (HiGHS is
deterministic: the same table gives the same programme).

``benefit`` is what the asset manager buys: deaths avoided per year (objective ``"risk"``) or the saving
in expected total cost against doing nothing (objective ``"cost"``: maximising the saving is minimising the
corridor's expected total cost).  ``cost`` is on the budget's basis: the capital paid now (basis
``"total"``) or the equivalent annual cost (basis ``"year"``: present value of capital, renewals and
maintenance over the horizon divided by the annuity factor (1 - (1 + r)^-n) / r), both in the corridor's
currency.

Reference for the problem class: Kellerer, Pferschy & Pisinger (2004), *Knapsack Problems*, Springer,
ch. 11 (the multiple-choice knapsack problem).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

#: Largest number of candidate options for which ties in benefit are broken by the least cost (a second solve).
TIE_BREAK_MAX = 3000

#: What a programme can maximise: deaths avoided per year, or the saving in expected total cost.
OBJECTIVES = {"risk": "deaths_avoided_per_year", "cost": "expected_total_cost_saving"}


@dataclass(frozen=True)
class Programme:
    """The chosen programme: one row per section given an option (``chosen``), and the totals.

    ``cost_column``/``benefit_column`` name the columns of the option table the choice used.
    """

    chosen: pd.DataFrame = field(repr=False)
    budget: float
    cost: float
    benefit: float
    objective: str
    cost_column: str
    benefit_column: str
    n_sections: int
    gap: float = 0.0

    def summary(self) -> pd.DataFrame:
        """The chosen sections and options, with their cost and benefit (one row per funded section).

        Returns
        -------
        pandas.DataFrame
            One row per funded section: section, option, cost (in the cost column's currency, e.g. [CHF]) and benefit
            (deaths avoided [1/yr] or cost saving [currency]).
        """
        return self.chosen.reset_index(drop=True)

    def __repr__(self) -> str:
        return (f"Programme({len(self.chosen)} of {self.n_sections} sections funded, {self.cost_column} "
                f"{self.cost:,.0f} of {self.budget:,.0f}, {self.benefit_column} {self.benefit:.4g})")


@dataclass(frozen=True)
class Frontier:
    """Efficient frontier: the best benefit for each budget (``table``: budget, cost, benefit, sections)."""

    table: pd.DataFrame = field(repr=False)
    objective: str
    cost_column: str
    benefit_column: str

    def summary(self) -> pd.DataFrame:
        """One row per budget: budget, cost of the best programme, its benefit, the sections it funds and the
        proven gap (the figure: :func:`riskrf.report.corridor_report.plot_frontier`).

        Returns
        -------
        pandas.DataFrame
            Columns ``budget`` and ``cost`` [currency], ``benefit`` (deaths avoided [1/yr] or cost saving [currency]),
            ``sections`` and ``gap`` [-].
        """
        return self.table.copy()


def _check(options: pd.DataFrame, cost: str, benefit: str, section: str) -> pd.DataFrame:
    missing = [c for c in (section, "option", cost, benefit) if c not in options.columns]
    if missing:
        raise ValueError(f"option table lacks column(s) {missing}; it has {list(options.columns)}")
    t = options[[section, "option", cost, benefit]].copy()
    for c in (cost, benefit):
        v = pd.to_numeric(t[c], errors="coerce").to_numpy(dtype=float)
        bad = ~np.isfinite(v)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"option table: column {c!r} of section {t[section].iloc[i]!r}, option "
                             f"{t['option'].iloc[i]!r} is {t[c].iloc[i]!r}, not a finite number")
        t[c] = v
    neg = t[cost] < 0
    if neg.any():
        r = t[neg].iloc[0]
        raise ValueError(f"option table: {cost} of section {r[section]!r}, option {r['option']!r} is "
                         f"{r[cost]:g} < 0 (costs are what the budget pays)")
    if t.duplicated([section, "option"]).any():
        r = t[t.duplicated([section, "option"])].iloc[0]
        raise ValueError(f"option table: section {r[section]!r} lists option {r['option']!r} twice")
    return t


def _solve(cost: np.ndarray, benefit: np.ndarray, group: np.ndarray, n_groups: int, budget: float,
           time_limit_s: float = 120.0) -> tuple[np.ndarray, float]:
    """0/1 choice maximising benefit within budget, at most one per group (ties broken by the least cost up to
    :data:`TIE_BREAK_MAX` options); returns (choice, proven relative gap)."""
    from scipy.optimize import Bounds, LinearConstraint, milp
    from scipy.sparse import csr_matrix
    n = cost.size
    if n == 0:
        return np.zeros(0, bool), 0.0
    # scale to order one: HiGHS tolerances are absolute (deaths per year are ~1e-4)
    bscale = float(np.max(np.abs(benefit))) or 1.0
    cscale = float(max(np.max(cost), budget, 1e-300))
    b, c = benefit / bscale, cost / cscale
    one = csr_matrix((np.ones(n), (group, np.arange(n))), shape=(n_groups, n))
    cons = [LinearConstraint(c.reshape(1, -1), -np.inf, budget / cscale), LinearConstraint(one, -np.inf, 1.0)]
    opts = {"mip_rel_gap": 0.0, "presolve": True, "time_limit": float(time_limit_s)}
    first = milp(-b, integrality=np.ones(n), bounds=Bounds(0, 1), constraints=cons, options=opts)
    if first.x is None:
        raise RuntimeError(f"the programme optimiser found no programme: {first.message}")
    best = -float(first.fun)
    gap = float(getattr(first, "mip_gap", 0.0) or 0.0) if first.status != 0 else 0.0
    if n > TIE_BREAK_MAX or first.status != 0:
        return np.round(first.x).astype(bool), gap
    # second stage: the cheapest programme whose benefit is the optimum (to the solver's feasibility tolerance)
    tol = 1e-9 * max(abs(best), 1.0)
    cons2 = cons + [LinearConstraint(b.reshape(1, -1), best - tol, np.inf)]
    second = milp(c, integrality=np.ones(n), bounds=Bounds(0, 1), constraints=cons2, options=opts)
    x = second.x if second.status == 0 else first.x
    return np.round(x).astype(bool), gap


def optimise_programme(options: pd.DataFrame, budget: float, *, objective: str = "risk", cost_column: str = "capital",
                       section_column: str = "id", time_limit_s: float = 120.0) -> Programme:
    """The best programme within ``budget``: at most one option per section (MILP, exact).

    Parameters
    ----------
    options : DataFrame
        One row per (section, option) that could be built: ``section_column``, ``option``, ``cost_column``
        (what the budget pays, >= 0, in the corridor currency) and the benefit column of ``objective``
        (:data:`OBJECTIVES`: ``deaths_avoided_per_year`` [1/yr] or ``expected_total_cost_saving`` [currency]).
        Options with a benefit <= 0 are never worth funding and are left out.
    budget : float
        Upper limit of the summed ``cost_column`` of the chosen options (>= 0).
    objective : {"risk", "cost"}
        Maximise deaths avoided per year, or minimise the expected total cost (maximise its saving).
    time_limit_s : float
        Wall time the solver may take [s]; if it stops there, :attr:`Programme.gap` is the proven gap.

    Returns
    -------
    Programme
    """
    if objective not in OBJECTIVES:
        raise ValueError(f"objective = {objective!r} must be one of {sorted(OBJECTIVES)}")
    if isinstance(budget, bool) or not isinstance(budget, (int, float, np.floating, np.integer)) \
            or not np.isfinite(budget) or budget < 0:
        raise ValueError(f"budget = {budget!r} must be a finite number >= 0")
    benefit = OBJECTIVES[objective]
    t = _check(options, cost_column, benefit, section_column)
    sections = pd.unique(t[section_column])
    cand = t[t[benefit] > 0].reset_index(drop=True)
    codes = pd.Categorical(cand[section_column], categories=sections).codes
    pick, gap = _solve(cand[cost_column].to_numpy(), cand[benefit].to_numpy(), np.asarray(codes), len(sections),
                       float(budget), time_limit_s)
    chosen = options.merge(cand.loc[pick, [section_column, "option"]], on=[section_column, "option"])
    return Programme(chosen=chosen, budget=float(budget), cost=float(cand.loc[pick, cost_column].sum()),
                     benefit=float(cand.loc[pick, benefit].sum()), objective=objective, cost_column=cost_column,
                     benefit_column=benefit, n_sections=len(sections), gap=gap)


def efficient_frontier(options: pd.DataFrame, budgets=None, *, objective: str = "risk", cost_column: str = "capital",
                       section_column: str = "id", points: int = 25, time_limit_s: float = 20.0) -> Frontier:
    """The best benefit at each budget (each point an exact programme of :func:`optimise_programme`).

    ``budgets``: the budgets to solve at; default 0 and ``points`` - 1 budgets in geometric steps from the cheapest
    option to the cost of the programme that takes the best option of every section (beyond it more money buys
    nothing).  Between two budgets the best benefit is at least that of the lower one (a step curve).  Each point may
    take ``time_limit_s``; its proven gap is in the ``gap`` column (0: proven optimal).

    Parameters
    ----------
    options : pandas.DataFrame
        One row per (section, option) with the cost column [currency] and the objective's benefit column.
    budgets : array_like, optional
        Budgets to solve at [currency].
    objective : str, optional
        ``"risk"`` (deaths avoided per year [1/yr]) or ``"cost"`` (expected total cost saving [currency]).
    cost_column : str, optional
        The column of costs.
    section_column : str, optional
        The column naming the sections.
    points : int, optional
        Number of budgets of the default set.
    time_limit_s : float, optional
        Solver time limit per budget [s].

    Returns
    -------
    Frontier
        The best benefit at each budget.

    Raises
    ------
    ValueError
        When the objective is unknown or a column is missing or not numeric.
    """
    benefit = OBJECTIVES.get(objective)
    if benefit is None:
        raise ValueError(f"objective = {objective!r} must be one of {sorted(OBJECTIVES)}")
    t = _check(options, cost_column, benefit, section_column)
    if budgets is None:
        top = t[t[benefit] > 0]
        full = top.sort_values([benefit, cost_column], ascending=[False, True]).groupby(section_column).head(1)
        hi = float(full[cost_column].sum())
        lo = float(top.loc[top[cost_column] > 0, cost_column].min()) if (top[cost_column] > 0).any() else hi
        # 0, then geometric steps from the cheapest option to everything: the frontier rises fastest at small budgets
        budgets = np.r_[0.0, np.geomspace(lo, hi, int(points) - 1)] if hi > 0 and lo < hi else np.array([0.0, hi])
    rows = []
    for b in np.asarray(budgets, dtype=float):
        p = optimise_programme(t, float(b), objective=objective, cost_column=cost_column,
                               section_column=section_column, time_limit_s=time_limit_s)
        rows.append({"budget": float(b), "cost": p.cost, "benefit": p.benefit, "sections": len(p.chosen),
                     "gap": p.gap})
    return Frontier(table=pd.DataFrame(rows), objective=objective, cost_column=cost_column, benefit_column=benefit)
