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

Objective ``"alarp"`` (the corridor's default) buys net benefit at the value of a statistical life, with the
ALARP gross-disproportion factor ``gdf`` (GDF >= 1): an option's benefit ``B`` is the present value of the expected
losses it avoids (lives at the VSL, vehicle damage, closures, clean-up), ``B = saving + present_value``, and its
net benefit is ``GDF * B - present_value`` (:func:`alarp_net_benefit`).  Only options with a positive net benefit
are candidates, so every option such a programme funds is worth at least 1/GDF of its cost
(:func:`benefit_cost_ratio` >= 1/GDF), the gross-disproportion test of HSE (2001) *Reducing risks, protecting
people* (R2P2), para 140 and Appendix 3, on a programme.  At GDF = 1 it is objective ``"cost"``.

``required``: sections that must be funded whatever they cost (those above the intolerable individual-risk line;
:meth:`riskrf.app.corridor.CorridorResult.programme`), each from the options it names (those that bring it below the
line).  They are funded first: the budget is raised, where they need it, to the least cost that funds them all
(:attr:`Programme.overrun` is what they take beyond the budget), and the rest of the money buys the objective.

Reference for the problem class: Kellerer, Pferschy & Pisinger (2004), *Knapsack Problems*, Springer,
ch. 11 (the multiple-choice knapsack problem).

Solver messages (HiGHS writes a few lines straight to the process's standard output, bypassing Python) are caught
at the file-descriptor level and sent to the ``riskrf`` logger (``riskrf.risk.programme``) at DEBUG.
"""
from __future__ import annotations

import contextlib
import logging
import os
import sys
import tempfile
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

#: Largest number of candidate options for which ties in benefit are broken by the least cost (a second solve).
TIE_BREAK_MAX = 3000

#: What a programme can maximise: net benefit at the VSL with the gross-disproportion factor (``"alarp"``), deaths
#: avoided per year (``"risk"``), or the saving in expected total cost (``"cost"``).
OBJECTIVES = {"alarp": "alarp_net_benefit", "risk": "deaths_avoided_per_year", "cost": "expected_total_cost_saving"}

#: Logger receiving the solver's own output (DEBUG): a child of ``riskrf``.
log = logging.getLogger(__name__)


def alarp_net_benefit(saving, present_value, gdf: float = 1.0):
    """Net benefit of an option at the VSL with the gross-disproportion factor: ``GDF * B - C``.

    ``B = saving + C`` is the present value of the expected losses the option avoids against doing nothing (deaths
    valued at the VSL, plus the other losses) and ``C`` the present value of what it costs (capital, renewals and
    maintenance).  Positive exactly when ``B / C > 1 / GDF``: the cost is not grossly disproportionate to the
    benefit (HSE 2001, *Reducing risks, protecting people*, para 140 and Appendix 3).  At GDF = 1 it is the saving.

    Parameters
    ----------
    saving : float or array_like
        Saving in expected total cost against doing nothing [currency].
    present_value : float or array_like
        Present value of the option's capital, renewals and maintenance [currency].
    gdf : float
        Gross-disproportion factor [-], >= 1.

    Returns
    -------
    float or numpy.ndarray
        ``gdf * (saving + present_value) - present_value`` [currency].
    """
    saving, present_value = np.asarray(saving, dtype=float), np.asarray(present_value, dtype=float)
    return gdf * (saving + present_value) - present_value


def benefit_cost_ratio(saving, present_value):
    """What an option is worth per unit of its cost: ``B / C = (saving + C) / C`` (NaN where ``C`` is 0).

    Parameters
    ----------
    saving : float or array_like
        Saving in expected total cost against doing nothing [currency].
    present_value : float or array_like
        Present value of the option's capital, renewals and maintenance [currency].

    Returns
    -------
    numpy.ndarray
        Benefit over cost [-]: expected losses avoided (deaths at the VSL and the other losses, present value) over
        the option's present value.
    """
    saving, c = np.asarray(saving, dtype=float), np.asarray(present_value, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(c > 0, (saving + c) / np.where(c > 0, c, 1.0), np.nan)


def check_gdf(gdf, where: str = "gdf") -> float:
    """The gross-disproportion factor as a float, or a ValueError naming ``where`` and the value.

    Parameters
    ----------
    gdf : float
        Gross-disproportion factor [-]: finite and >= 1 (1: cost may equal benefit; HSE practice 1-10).
    where : str
        How the caller names it in the message (file and field, or the CLI argument).

    Returns
    -------
    float
        The factor.
    """
    if isinstance(gdf, bool) or not isinstance(gdf, (int, float, np.floating, np.integer)) or not np.isfinite(gdf) \
            or gdf < 1:
        raise ValueError(f"{where} = {gdf!r} must be a number >= 1 (the ALARP gross-disproportion factor: a measure "
                         "is funded while its cost is at most this factor times what it is worth; below 1 it would "
                         "refuse measures worth more than they cost)")
    return float(gdf)


@contextlib.contextmanager
def solver_output_to_log(logger: logging.Logger = log):
    """Send what native code writes to standard output (file descriptor 1) meanwhile to ``logger`` at DEBUG.

    HiGHS prints some messages with C ``printf``, which ``contextlib.redirect_stdout`` cannot catch; descriptor 1 is
    pointed at a temporary file for the duration and its lines are logged afterwards.  Falls back to doing nothing
    where descriptor 1 cannot be duplicated.

    Parameters
    ----------
    logger : logging.Logger
        Receives each non-empty line at DEBUG.
    """
    try:
        fd = sys.__stdout__.fileno() if sys.__stdout__ is not None else 1
        saved = os.dup(fd)
    except (OSError, ValueError, AttributeError):
        yield
        return
    try:
        import ctypes
        libc_flush = ctypes.CDLL(None).fflush
    except (OSError, AttributeError):           # no C runtime to flush (e.g. some Windows builds)
        libc_flush = None
    for stream in (sys.stdout, sys.__stdout__):
        with contextlib.suppress(Exception):
            stream.flush()
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), fd)
        try:
            yield
        finally:
            if libc_flush is not None:
                libc_flush(None)
            os.dup2(saved, fd)
            os.close(saved)
            tmp.seek(0)
            for line in tmp.read().decode("utf-8", errors="replace").splitlines():
                if line.strip():
                    logger.debug("HiGHS: %s", line.rstrip())


@dataclass(frozen=True)
class Programme:
    """The chosen programme: one row per section given an option (``chosen``), and the totals.

    ``cost_column``/``benefit_column`` name the columns of the option table the choice used.  ``required``: the
    sections funded whatever they cost (above the intolerable individual-risk line); ``chosen`` marks them in its
    column ``required_by_tolerability``.  ``overrun``: what the programme costs beyond ``budget`` because of them
    [currency] (0 when they fit).  ``gdf``: the gross-disproportion factor of objective ``"alarp"`` [-].
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
    required: tuple = ()
    overrun: float = 0.0
    gdf: float = 1.0

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
           time_limit_s: float = 120.0, must=None) -> tuple[np.ndarray, float]:
    """0/1 choice maximising benefit within budget, at most one per group (exactly one for the groups flagged in
    ``must``; ties broken by the least cost up to :data:`TIE_BREAK_MAX` options); returns (choice, proven relative
    gap).  The solver's own output goes to the log (:func:`solver_output_to_log`)."""
    from scipy.optimize import LinearConstraint, milp
    from scipy.sparse import csr_matrix
    n = cost.size
    if n == 0:
        return np.zeros(0, bool), 0.0
    # scale to order one: HiGHS tolerances are absolute (deaths per year are ~1e-4)
    bscale = float(np.max(np.abs(benefit))) or 1.0
    cscale = float(max(np.max(cost), budget, 1e-300))
    b, c = benefit / bscale, cost / cscale
    one = csr_matrix((np.ones(n), (group, np.arange(n))), shape=(n_groups, n))
    low = np.where(np.asarray(must, dtype=bool), 1.0, -np.inf) if must is not None else -np.inf
    cons = [LinearConstraint(c.reshape(1, -1), -np.inf, budget / cscale), LinearConstraint(one, low, 1.0)]
    opts = {"mip_rel_gap": 0.0, "presolve": True, "time_limit": float(time_limit_s), "disp": False}
    with solver_output_to_log():
        return _solve_two_stage(milp, b, c, cons, opts, n)


def _solve_two_stage(milp, b, c, cons, opts, n):
    """The two solves of :func:`_solve` (the best benefit, then the least cost at it), on scaled ``b`` and ``c``."""
    from scipy.optimize import Bounds, LinearConstraint
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


def _with_objective(options: pd.DataFrame, objective: str, gdf: float, cost: str, section: str,
                    value_column: str = "present_value") -> tuple[pd.DataFrame, str]:
    """The checked option table with the objective's benefit column (computed for ``"alarp"``)."""
    if objective not in OBJECTIVES:
        raise ValueError(f"objective = {objective!r} must be one of {sorted(OBJECTIVES)} ('alarp': net benefit at "
                         "the VSL with the gross-disproportion factor; 'risk': deaths avoided per year; 'cost': "
                         "expected total cost saving)")
    benefit = OBJECTIVES[objective]
    if objective != "alarp":
        return _check(options, cost, benefit, section), benefit
    # always from the saving and the present value at this GDF (a column of another GDF is not reused)
    gdf = check_gdf(gdf)
    t = _check(options, cost, "expected_total_cost_saving", section)
    if value_column != cost:
        t[value_column] = _check(options, value_column, "expected_total_cost_saving", section)[value_column]
    t[benefit] = alarp_net_benefit(t["expected_total_cost_saving"].to_numpy(), t[value_column].to_numpy(), gdf)
    return t, benefit


def _required_mask(t: pd.DataFrame, required, section: str) -> np.ndarray:
    """True for the rows of ``t`` that are allowed options of a required section (ValueError naming a bad one)."""
    allowed = np.zeros(len(t), bool)
    for sid, names in (required or {}).items():
        rows = (t[section] == sid).to_numpy()
        if not rows.any():
            raise ValueError(f"required = {{{sid!r}: ...}}: section {sid!r} has no option in the option table")
        names = [names] if isinstance(names, str) else list(names)
        ok = rows & t["option"].isin(names).to_numpy()
        if not ok.any():
            raise ValueError(f"required = {{{sid!r}: {names!r}}}: none of these is an option of section {sid!r} "
                             f"(it has {list(t.loc[rows, 'option'])})")
        allowed |= ok
    return allowed


def optimise_programme(options: pd.DataFrame, budget: float, *, objective: str = "risk", cost_column: str = "capital",
                       section_column: str = "id", time_limit_s: float = 120.0, gdf: float = 1.0,
                       required=None, value_column: str = "present_value") -> Programme:
    """The best programme within ``budget``: at most one option per section (MILP, exact).

    Parameters
    ----------
    options : DataFrame
        One row per (section, option) that could be built: ``section_column``, ``option``, ``cost_column``
        (what the budget pays, >= 0, in the corridor currency) and the benefit column of ``objective``
        (:data:`OBJECTIVES`: ``deaths_avoided_per_year`` [1/yr] or ``expected_total_cost_saving`` [currency]; for
        ``"alarp"`` ``expected_total_cost_saving`` and ``value_column``, from which ``alarp_net_benefit`` is
        computed at ``gdf``).  Options with a benefit <= 0 are never worth funding and are left out (but on a required section).
    budget : float
        Upper limit of the summed ``cost_column`` of the chosen options (>= 0), in the corridor currency; raised to
        the least cost of the ``required`` sections where they need more (:attr:`Programme.overrun`).
    objective : {"risk", "cost", "alarp"}
        Maximise deaths avoided per year, minimise the expected total cost (maximise its saving), or maximise the
        net benefit at the VSL with the gross-disproportion factor (:func:`alarp_net_benefit`).  The default stays
        ``"risk"`` here; the corridor's programme defaults to ``"alarp"``.
    time_limit_s : float
        Wall time the solver may take [s]; if it stops there, :attr:`Programme.gap` is the proven gap.
    gdf : float
        Gross-disproportion factor of ``"alarp"`` [-], >= 1 (ignored by the other objectives).
    required : dict, optional
        ``{section: option names}``: sections funded whatever they cost, each by one of the named options.
    value_column : str
        Present value of each option's capital, renewals and maintenance [currency] (objective ``"alarp"``).

    Returns
    -------
    Programme

    Raises
    ------
    ValueError
        An unknown objective, a negative or non-finite budget, a GDF below 1, a missing or non-numeric column, or
        a required section or option that the table does not have.

    References
    ----------
    Kellerer, H., Pferschy, U. & Pisinger, D. (2004) Knapsack Problems. Springer, ch. 11.  HSE (2001) Reducing
    risks, protecting people. HSE Books, para 140 and Appendix 3 (gross disproportion).
    """
    if isinstance(budget, bool) or not isinstance(budget, (int, float, np.floating, np.integer)) \
            or not np.isfinite(budget) or budget < 0:
        raise ValueError(f"budget = {budget!r} must be a finite number >= 0")
    if objective == "alarp":
        gdf = check_gdf(gdf)
    t, benefit = _with_objective(options, objective, gdf, cost_column, section_column, value_column)
    sections = pd.unique(t[section_column])
    req = [sid for sid in sections if sid in set(required or {})]
    allowed = _required_mask(t, required, section_column)
    # candidates: options worth funding, and on a required section only the options named for it
    on_req = t[section_column].isin(req).to_numpy()
    keep_rows = np.where(on_req, allowed, (t[benefit] > 0).to_numpy())
    cand = t[keep_rows].reset_index(drop=True)
    codes = np.asarray(pd.Categorical(cand[section_column], categories=sections).codes)
    must = np.isin(sections, req)
    # the required sections are funded whatever they cost: at least their least cost is available
    least = float(cand.loc[cand[section_column].isin(req)].groupby(section_column)[cost_column].min().sum())
    cap = max(float(budget), least * (1 + 1e-12))
    pick, gap = _solve(cand[cost_column].to_numpy(), cand[benefit].to_numpy(), codes, len(sections), cap,
                       time_limit_s, must=must)
    got = cand.loc[pick, [section_column, "option"] + ([] if benefit in options.columns and objective != "alarp"
                                                       else [benefit])]
    chosen = options.drop(columns=[c for c in ("required_by_tolerability",) if c in options]
                          + ([benefit] if objective == "alarp" and benefit in options else [])).merge(
        got, on=[section_column, "option"])
    chosen["required_by_tolerability"] = chosen[section_column].isin(req).to_numpy()
    spent = float(cand.loc[pick, cost_column].sum())
    return Programme(chosen=chosen, budget=float(budget), cost=spent,
                     benefit=float(cand.loc[pick, benefit].sum()), objective=objective, cost_column=cost_column,
                     benefit_column=benefit, n_sections=len(sections), gap=gap, required=tuple(req),
                     overrun=max(0.0, spent - float(budget)), gdf=float(gdf) if objective == "alarp" else 1.0)


def efficient_frontier(options: pd.DataFrame, budgets=None, *, objective: str = "risk", cost_column: str = "capital",
                       section_column: str = "id", points: int = 25, time_limit_s: float = 20.0, gdf: float = 1.0,
                       required=None, value_column: str = "present_value") -> Frontier:
    """The best benefit at each budget (each point an exact programme of :func:`optimise_programme`).

    ``budgets``: the budgets to solve at; default 0 and ``points`` - 1 budgets in geometric steps from the cheapest
    option to the cost of the programme that takes the best option of every section (beyond it more money buys
    nothing).  Between two budgets the best benefit is at least that of the lower one (a step curve).  Each point may
    take ``time_limit_s``; its proven gap is in the ``gap`` column (0: proven optimal).  With ``required`` sections
    every point funds them (below their least cost the points are that same programme, ``overrun`` > 0).

    Parameters
    ----------
    options : pandas.DataFrame
        One row per (section, option) with the cost column [currency] and the objective's benefit column.
    budgets : array_like, optional
        Budgets to solve at [currency].
    objective : str, optional
        ``"risk"`` (deaths avoided per year [1/yr]), ``"cost"`` (expected total cost saving [currency]) or
        ``"alarp"`` (net benefit at the VSL with ``gdf`` [currency]).
    cost_column : str, optional
        The column of costs.
    section_column : str, optional
        The column naming the sections.
    points : int, optional
        Number of budgets of the default set.
    time_limit_s : float, optional
        Solver time limit per budget [s].
    gdf : float, optional
        Gross-disproportion factor of ``"alarp"`` [-], >= 1.
    required : dict, optional
        ``{section: option names}`` funded at every budget (see :func:`optimise_programme`).
    value_column : str, optional
        Present value of each option's costs [currency] (``"alarp"``).

    Returns
    -------
    Frontier
        The best benefit at each budget.

    Raises
    ------
    ValueError
        When the objective is unknown, the GDF below 1, or a column is missing or not numeric.
    """
    if objective == "alarp":
        gdf = check_gdf(gdf)
    t, benefit = _with_objective(options, objective, gdf, cost_column, section_column, value_column)
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
                               section_column=section_column, time_limit_s=time_limit_s, gdf=gdf, required=required,
                               value_column=value_column)
        rows.append({"budget": float(b), "cost": p.cost, "benefit": p.benefit, "sections": len(p.chosen),
                     "gap": p.gap})
    return Frontier(table=pd.DataFrame(rows), objective=objective, cost_column=cost_column, benefit_column=benefit)
