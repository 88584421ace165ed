"""Rain-triggered road closure as a mitigation option, from a fitted daily rate model.

A closure rule closes the road while rainfall over a window exceeds a
threshold (``closure_rule``) or while a rainstorm warning of a given level is
in force (``warning_closure``).  Its **effectiveness** is the share of falls
that occur while the road is closed: the rate model's expected falls on the
closed time divided by its expected falls on all days of the record,

.. math::  e = \\frac{\\sum_t \\mu_t c_t}{\\sum_t \\mu_t},

with :math:`\\mu_t` the fitted expected count on day t (at the record's
rainfall) and :math:`c_t` the share of day t the road is closed (1 for a
closed day under a rainfall rule; hours of warning / 24 under a warning rule).
Its **cost** is the closure hours per year times the cost per hour.  The
share of *recorded* falls on closed days is reported beside it as a check.

Assumptions (stated in every output): daily resolution, so a rainfall rule
closes the whole day on which the window total (ending that day) reaches the
threshold, an idealisation of closing when a real-time gauge crosses it;
within a day the rate is uniform (warning rule); a closure protects road users
(no vehicle can be hit), not the road itself (falls still need clearing).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..frequency.rates.result import RateModel


@dataclass(frozen=True)
class ClosureRule:
    """A closure rule evaluated on a daily rate model and its rainfall record.

    Attributes
    ----------
    rule : str
        The rule in words.
    effectiveness : float
        Share of expected falls that occur while the road is closed (model).
    observed_share : float
        Share of recorded falls dated on closed time (closed days, or days
        weighted by their closed hours for a warning rule).
    closure_hours_per_year : float
        Mean hours closed per year over the evaluation period [h/yr].
    closures_per_year : float
        Closure episodes (runs of closed days, or warnings) per year.
    cost_per_hour : float
        Cost of one hour of closure (detours, delay; currency of the study).
    start, end : pandas.Timestamp
        Period over which the rule was evaluated.
    closed_share_of_time : pandas.Series
        Per day of the period, the share of the day the road is closed.
    """

    rule: str
    effectiveness: float
    observed_share: float
    closure_hours_per_year: float
    closures_per_year: float
    cost_per_hour: float
    start: pd.Timestamp
    end: pd.Timestamp
    model_preferred: str
    n_events: int
    expected_falls_per_year: float
    closed_share_of_time: pd.Series

    @property
    def annual_cost(self) -> float:
        """Closure hours per year times the cost per hour [currency/yr]."""
        return self.closure_hours_per_year * self.cost_per_hour

    def summary(self) -> pd.DataFrame:
        """Key figures of the rule (one-column table): period evaluated, effectiveness (share of falls while closed,
        model and recorded), falls per year [1/yr] in all and while closed, hours closed per year.

        Returns
        -------
        pandas.DataFrame
            One column ``value`` indexed by the figure's name (units in the names).
        """
        rows = {
            "rule": self.rule,
            "evaluated over": f"{self.start.date()} to {self.end.date()}",
            "effectiveness (share of falls while closed, model)": round(self.effectiveness, 4),
            "share of recorded falls while closed": round(self.observed_share, 4),
            "falls per year (model, all days)": round(self.expected_falls_per_year, 3),
            "falls per year while closed (model)": round(self.effectiveness * self.expected_falls_per_year, 3),
            "closure hours per year": round(self.closure_hours_per_year, 1),
            "closures per year": round(self.closures_per_year, 2),
            "cost per hour": self.cost_per_hour,
            "annual cost": round(self.annual_cost, 2),
            "model": self.model_preferred,
            "assumptions": ("daily resolution (a rainfall rule closes the whole day); uniform rate within a day; "
                            "closure protects road users, not the road"),
        }
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    def option_spec(self, name: str, *, capital_cost: float = 0.0, life_years: float | None = None) -> dict:
        """The closure as an option table for a mitigation file (``[[options]]``, kind ``closure``) with the share and
        hours TYPED from this evaluation: the outputs label such an option an assumption.  In a site file give the
        rule instead (``threshold_mm`` + ``window_days`` or ``warning_levels``, with a ``[rates]`` table): the share
        and hours are then computed in the run (:mod:`riskrf.risk.site_rates`).

        Parameters
        ----------
        name : str
            The option's name.
        capital_cost : float, optional
            Capital cost [currency], e.g. [CHF].
        life_years : float, optional
            Life of the option [yr].

        Returns
        -------
        dict
            The ``[[options]]`` table: share while closed [-], closure hours per year [h/yr], cost per closure hour
            [currency/h].
        """
        spec = {"name": name, "kind": "closure", "capital_cost": float(capital_cost),
                "share_while_closed": float(self.effectiveness),
                "closure_hours_per_year": float(self.closure_hours_per_year),
                "cost_per_closure_hour": float(self.cost_per_hour),
                "description": f"{self.rule} (rate model, {self.start.year}-{self.end.year})"}
        if life_years is not None:
            spec["life_years"] = float(life_years)
        return spec


def _daily_model(model: RateModel, what: str):
    if not isinstance(model, RateModel):
        raise TypeError(f"{what}: model must be a RateModel from riskrf.frequency.rates; got {type(model).__name__}")
    if model.period != "day":
        raise ValueError(f"{what}: needs a daily rate model (period='day'); this one counts per {model.period}")
    if model.rainfall is None:
        raise ValueError(f"{what}: the rate model was fitted without rainfall")
    mu = model.fitted()
    counts = pd.Series(model.design["count"].to_numpy(), index=mu.index)
    return mu, counts


def _evaluate(model, mu, counts, share, rule, cost_per_hour, episodes) -> ClosureRule:
    if not (np.isfinite(cost_per_hour) and cost_per_hour >= 0):
        raise ValueError(f"cost_per_hour = {cost_per_hour!r} must be a number >= 0")
    years = len(mu) / 365.25
    eff = float((mu * share).sum() / mu.sum())
    n = int(counts.sum())
    obs = float((counts * share).sum() / n) if n else float("nan")
    return ClosureRule(rule=rule, effectiveness=eff, observed_share=obs,
                       closure_hours_per_year=float(share.sum() * 24 / years), closures_per_year=episodes / years,
                       cost_per_hour=float(cost_per_hour), start=mu.index[0], end=mu.index[-1],
                       model_preferred=model.preferred, n_events=n, expected_falls_per_year=float(mu.sum() / years),
                       closed_share_of_time=share.rename("closed_share"))


def closure_rule(model: RateModel, threshold_mm: float, *, window_days: int = 1,
                 cost_per_hour: float = 0.0) -> ClosureRule:
    """Close the road on days when rainfall over ``window_days`` (ending that day) reaches ``threshold_mm``.

    Parameters
    ----------
    model : RateModel
        A daily rate model fitted with rainfall (:func:`riskrf.frequency.rates`).
    threshold_mm : float
        Rainfall total over the window that triggers the closure [mm].
    window_days : int
        Window length [days], 1 = the day's rainfall.
    cost_per_hour : float
        Cost of one closure hour (detours and delay), in the study's currency.

    Returns
    -------
    ClosureRule
        Effectiveness (share of falls while closed) [-], closure hours per year [h/yr], closures per year [1/yr] and
        cost per hour [currency/h].

    Raises
    ------
    ValueError
        When an input is out of range or the model is not a daily model fitted with rainfall.
    """
    what = "closure_rule"
    if not (np.isfinite(threshold_mm) and threshold_mm > 0):
        raise ValueError(f"{what}: threshold_mm = {threshold_mm!r} must be > 0")
    if int(window_days) != window_days or window_days < 1:
        raise ValueError(f"{what}: window_days = {window_days!r} must be a whole number of days >= 1")
    mu, counts = _daily_model(model, what)
    total = model.rainfall.window_total(int(window_days)).reindex(mu.index)
    if total.isna().any():
        d = total.index[total.isna().to_numpy()][0]
        raise ValueError(f"{what}: no {window_days}-day rainfall total for {d.date()} in {model.rainfall.source}")
    closed = (total >= threshold_mm).astype(float)
    episodes = int(((closed.diff().fillna(closed.iloc[0])) > 0).sum())
    rule = f"close while the {window_days}-day rainfall reaches {threshold_mm:g} mm (whole day)"
    return _evaluate(model, mu, counts, closed, rule, cost_per_hour, episodes)


_TIME = re.compile(r"^(\d{1,2}):(\d{2})(?::00)?$")


def read_rainstorm_warnings(path) -> pd.DataFrame:
    """Read the Hong Kong Observatory's rainstorm warning list (``color, start time, start date, end time,
    end date, duration``; dates like ``12-Apr-98``): one row per signal with ``level``, ``start``, ``end``.

    Raises ``ValueError`` naming the row and value for an unreadable time or date, or an end before the start.

    Parameters
    ----------
    path : str or pathlib.Path
        The CSV file.

    Returns
    -------
    pandas.DataFrame
        Columns ``level``, ``start``, ``end`` (timestamps) and ``row`` (file line).

    Raises
    ------
    FileNotFoundError
        When the file does not exist.
    ValueError
        Naming the row and value of an unreadable time or date, a missing column, or an end before the start.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"rainstorm warning file not found: {path}")
    table = pd.read_csv(path, dtype=str, keep_default_na=False, encoding="utf-8-sig")
    cols = {c.strip().lower(): c for c in table.columns}
    need = ("color", "start time", "start date", "end time", "end date")
    missing = [c for c in need if c not in cols]
    if missing:
        raise ValueError(f"{path}: column(s) {missing} missing; found {list(table.columns)}")
    rows = []
    for i, r in enumerate(table.to_dict(orient="records")):
        line = i + 2
        stamps = []
        for d, t in (("start date", "start time"), ("end date", "end time")):
            text = f"{r[cols[d]].strip()} {r[cols[t]].strip()}"
            m = _TIME.match(r[cols[t]].strip())
            try:
                if m is None or int(m.group(1)) > 24 or int(m.group(2)) > 59:
                    raise ValueError
                day = pd.to_datetime(r[cols[d]].strip(), format="%d-%b-%y")
                # "24:00" (also written 24:00:00) is the end of the day
                stamps.append(day + pd.Timedelta(hours=int(m.group(1)), minutes=int(m.group(2))))
            except ValueError:
                raise ValueError(f"{path}: row {line}, columns {d!r}/{t!r}: {text!r} is not a date dd-Mon-yy "
                                 "and a time HH:MM") from None
        if stamps[1] < stamps[0]:
            raise ValueError(f"{path}: row {line}: the signal ends ({stamps[1]}) before it starts ({stamps[0]})")
        rows.append({"level": r[cols["color"]].strip().capitalize(), "start": stamps[0], "end": stamps[1],
                     "row": line})
    return pd.DataFrame(rows)


def warning_closure(model: RateModel, warnings, *, levels=("Red", "Black"), cost_per_hour: float = 0.0) -> ClosureRule:
    """Close the road while a rainstorm warning of one of ``levels`` is in force.

    ``warnings`` is a DataFrame from :func:`read_rainstorm_warnings` or its file.
    The rule is evaluated over the days both the rate model and the warning
    record cover (the first to the last warning's year); hours of closure per
    day come from the signals (overlapping signals counted once).

    Parameters
    ----------
    model : RateModel
        A daily rate model fitted with rainfall (:func:`riskrf.frequency.rates`).
    warnings : pandas.DataFrame or str or pathlib.Path
        The warning list (:func:`read_rainstorm_warnings`) or its file.
    levels : sequence of str, optional
        Warning levels that close the road.
    cost_per_hour : float, optional
        Cost of one closure hour [currency/h].

    Returns
    -------
    ClosureRule
        Effectiveness (share of falls while closed) [-], closure hours per year [h/yr], closures per year [1/yr] and
        cost per hour [currency/h].

    Raises
    ------
    ValueError
        When an input is out of range or the model is not a daily model fitted with rainfall.
    """
    what = "warning_closure"
    if not isinstance(warnings, pd.DataFrame):
        warnings = read_rainstorm_warnings(warnings)
    levels = tuple(str(v).capitalize() for v in levels)
    known = set(warnings["level"])
    bad = [v for v in levels if v not in known]
    if bad:
        raise ValueError(f"{what}: level(s) {bad} do not occur in the warning record (levels: {sorted(known)})")
    mu, counts = _daily_model(model, what)
    sel = warnings[warnings["level"].isin(levels)].sort_values("start")
    first = pd.Timestamp(warnings["start"].min().year, 1, 1)
    last = pd.Timestamp(warnings["end"].max().year, 12, 31)
    lo, hi = max(first, mu.index[0]), min(last, mu.index[-1])
    if hi <= lo:
        raise ValueError(f"{what}: the warning record ({first.date()} to {last.date()}) does not overlap the rate "
                         f"model's period ({mu.index[0].date()} to {mu.index[-1].date()})")
    mu, counts = mu.loc[lo:hi], counts.loc[lo:hi]
    # merge overlapping signals, then spread their hours over days
    merged = []
    for s, e in zip(sel["start"], sel["end"]):
        if merged and s <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], e)
        else:
            merged.append([s, e])
    hours = pd.Series(0.0, index=mu.index)
    episodes = 0
    for s, e in merged:
        s, e = max(s, lo), min(e, hi + pd.Timedelta(days=1))
        if e <= s:
            continue
        episodes += 1
        day = s.normalize()
        while day < e:
            nxt = day + pd.Timedelta(days=1)
            overlap = (min(e, nxt) - max(s, day)).total_seconds() / 3600.0
            if day in hours.index:
                hours[day] += overlap
            day = nxt
    share = (hours / 24.0).clip(upper=1.0)
    rule = f"close while a {' or '.join(levels)} rainstorm warning is in force"
    return _evaluate(model, mu, counts, share, rule, cost_per_hour, episodes)
