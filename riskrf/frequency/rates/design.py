"""The count design of a rate model: one row per day, month or year of the record.

The arguments checked before any work; the events that can be counted per period and each period's exposure
[days]; the covariate columns (antecedent rainfall bands [mm] checked to cover every event and day, the user's daily
covariates summed or averaged per period, the season terms, the centred year of the trend); the counts; and the
table of terms with the unit each rate ratio refers to.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..inventory.record import Inventory
from ...io.rainfall import Rainfall, read_rainfall
from ...core.validation import warn
from .result import _TRANSFORMS, _season_frame


#: Fewest periods a count model is fitted to.
MIN_PERIODS = 20
#: Default antecedent rainfall bands for daily counts [days]: the day itself,
#: the two days before, and days 3-14 before.
DEFAULT_WINDOWS_DAYS = (1, 3, 15)
_PERIODS = {"day": "D", "month": "MS", "year": "YS"}
_SEASONS = ("harmonic", "wet", "month", None)


def _band_name(lo: int, hi: int) -> tuple[str, str]:
    if lo == hi == 0:
        return "rain_d0_mm", "rainfall on the day"
    if lo == hi:
        return f"rain_d{lo}_mm", f"rainfall {lo} day{'s' if lo > 1 else ''} before"
    return f"rain_d{lo}_{hi}_mm", f"rainfall {lo}-{hi} days before"


def _as_rainfall(obj, what: str) -> Rainfall | None:
    if obj is None or isinstance(obj, Rainfall):
        return obj
    if isinstance(obj, (str, Path)):
        return read_rainfall(obj)
    raise TypeError(f"{what} must be a Rainfall, a rainfall file path or None; got {type(obj).__name__}")


def _note(notes: list, msg: str) -> None:
    """Keep ``msg`` among the model's notes and warn with it (:func:`riskrf.core.validation.warn`)."""
    notes.append(msg)
    warn(msg)


def _check_rate_arguments(inventory, period: str, season, level: float, rain_per_mm: float,
                          rain_transform: str) -> None:
    """Check the arguments of :func:`rate_model` that need no data, before any work.

    Parameters
    ----------
    inventory, period, season, level, rain_per_mm, rain_transform
        As :func:`rate_model` (``rain_per_mm`` in mm).

    Raises
    ------
    TypeError
        ``inventory`` is not an :class:`~riskrf.frequency.inventory.Inventory`.
    ValueError
        Naming the argument and its value.
    """
    if not isinstance(inventory, Inventory):
        raise TypeError(f"inventory must be a riskrf Inventory (read_inventory); got {type(inventory).__name__}")
    if period not in _PERIODS:
        raise ValueError(f"period = {period!r} is not one of {list(_PERIODS)}")
    if season not in _SEASONS:
        raise ValueError(f"season = {season!r} is not one of {list(_SEASONS)}")
    if not (0 < level < 1):
        raise ValueError(f"level = {level!r} must be between 0 and 1")
    if not (np.isfinite(rain_per_mm) and rain_per_mm > 0):
        raise ValueError(f"rain_per_mm = {rain_per_mm!r} must be > 0")
    if rain_transform not in _TRANSFORMS:
        raise ValueError(f"rain_transform = {rain_transform!r} is not one of {list(_TRANSFORMS)}")


def _counted_events(inventory: Inventory, period: str, notes: list) -> pd.DataFrame:
    """The inventory's events that can be counted per ``period`` (a full date, or a year for yearly counts).

    Parameters
    ----------
    inventory : Inventory
        The dated inventory (all events, censored sizes included).
    period : {"day", "month", "year"}
        Counting period.
    notes : list of str
        The model's notes; extended (and warned) with the events left out and those with a censored size.

    Returns
    -------
    pandas.DataFrame
        :meth:`Inventory.all_events` without the undated events.
    """
    src = inventory.source
    events = inventory.all_events()
    if period == "year":
        undated = events["year"].isna()
    else:
        undated = events["date"].isna()
    if undated.any():
        rows = events.loc[undated, "source_row"].tolist()
        _note(notes, f"{src}: {len(rows)} event(s) without a {'year' if period == 'year' else 'full date'} are not "
                     f"counted (rows {', '.join(map(str, rows[:12]))}{' ...' if len(rows) > 12 else ''})")
        events = events.loc[~undated]
    n_cens = int((events["censoring"] != "").sum())
    if n_cens:
        notes.append(f"{src}: {n_cens} event(s) with a censored or missing size are counted (the rate model "
                     "counts events of any size)")
    return events


def _record_periods(start: pd.Timestamp, end: pd.Timestamp, period: str, min_periods: int, src: str):
    """The days and counting periods of the record, with each period's exposure [days].

    Parameters
    ----------
    start, end : pandas.Timestamp
        First and last day of the record period.
    period : {"day", "month", "year"}
        Counting period.
    min_periods : int
        Fewest periods allowed.
    src : str
        The inventory's source for messages.

    Returns
    -------
    days : pandas.DatetimeIndex
        Every day of the record.
    starts : pandas.DatetimeIndex
        First day of each period.
    exposure : numpy.ndarray
        Days of each period inside the record.
    key : pandas.DatetimeIndex
        Each day's period start.
    """
    days = pd.date_range(start, end, freq="D")
    if period == "day":
        starts = days
        exposure = np.ones(len(days))
        key = days
    else:
        key = days.to_period("M" if period == "month" else "Y").to_timestamp()
        starts = pd.DatetimeIndex(pd.unique(key))
        exposure = pd.Series(1.0, index=days).groupby(key).sum().reindex(starts).to_numpy()
    if len(starts) < min_periods:
        raise ValueError(f"{src}: {len(starts)} {period} period(s) from {start.date()} to {end.date()}; a count model "
                         f"needs at least {min_periods} (count per month or per day instead)")
    return days, starts, exposure, key


def _add_rainfall_columns(design: pd.DataFrame, rain: Rainfall, events: pd.DataFrame, period: str, windows: tuple,
                          start: pd.Timestamp, end: pd.Timestamp, days, key, starts, src: str) -> list:
    """Check that the rainfall covers every event and day (with its antecedent window) and add its columns.

    Parameters
    ----------
    design : pandas.DataFrame
        The model frame, one row per period; rainfall columns [mm] are added in place.
    rain : Rainfall
        Daily rainfall.
    events : pandas.DataFrame
        The counted events (:func:`_counted_events`).
    period : {"day", "month", "year"}
        Counting period.
    windows : tuple of int
        Antecedent rainfall bands of daily counts [days].
    start, end : pandas.Timestamp
        The record period.
    days, key, starts
        As :func:`_record_periods`.
    src : str
        The inventory's source for messages.

    Returns
    -------
    list of (str, str)
        Name and label of each rainfall column added.
    """
    rain_cols: list[tuple[str, str]] = []
    lead = max(windows) - 1 if period == "day" else 0
    first_needed = start - pd.Timedelta(days=lead)
    for r in events.itertuples():
        d = r.date if period != "year" or pd.notna(r.date) else pd.Timestamp(int(r.year), 1, 1)
        if pd.isna(d):
            continue
        if d - pd.Timedelta(days=lead) < rain.first_day or d > rain.last_day:
            raise ValueError(f"{src}: row {r.source_row}, date {d.date()}: outside the rainfall record "
                             f"{rain.source} ({rain.first_day.date()} to {rain.last_day.date()}"
                             + (f", and the {max(windows)}-day antecedent window needs rainfall from "
                                f"{(d - pd.Timedelta(days=lead)).date()}" if lead else "") + ")")
    rain.check_covers(first_needed, end, f"{src}: the record period {start.date()} to {end.date()}"
                      + (f" with its {max(windows)}-day antecedent window" if lead else ""))
    if period == "day":
        lo = 0
        for w in windows:
            name, label = _band_name(lo, w - 1)
            total = rain.window_total(w - lo, lag=lo).reindex(days)
            design[name] = total.to_numpy()
            rain_cols.append((name, label))
            lo = w
    else:
        total = rain.daily.reindex(days).groupby(key).sum(min_count=1).reindex(starts)
        design[f"rain_{period}_mm"] = total.to_numpy()
        rain_cols.append((f"rain_{period}_mm", f"rainfall in the {period}"))
    return rain_cols


def _add_covariate_columns(design: pd.DataFrame, extra: pd.DataFrame, period: str, start: pd.Timestamp,
                           end: pd.Timestamp, days, key, starts, src: str) -> list:
    """Check the user's daily covariates and add them per period (summed or averaged) to the model frame.

    Parameters
    ----------
    design : pandas.DataFrame
        The model frame, one row per period; a column per covariate is added in place.
    extra : pandas.DataFrame
        Daily covariates indexed by date.  ``*_mm``, ``*_days`` and ``freeze_thaw`` are summed over a month or
        year, the others averaged.
    period : {"day", "month", "year"}
        Counting period.
    start, end : pandas.Timestamp
        The record period.
    days, key, starts
        As :func:`_record_periods`.
    src : str
        The inventory's source for messages.

    Returns
    -------
    list of str
        The covariate columns added.
    """
    extra_cols = []
    if not isinstance(extra.index, pd.DatetimeIndex):
        raise TypeError("covariates: a DataFrame of covariates must be indexed by date (DatetimeIndex)")
    for col in extra.columns:
        values = pd.to_numeric(extra[col], errors="coerce")
        bad = values.isna() & extra[col].notna()
        if bad.any():
            d = extra.index[bad.to_numpy()][0]
            raise ValueError(f"covariates: column {col!r}, date {d.date()}: {extra[col][d]!r} is not a number")
        series = values.groupby(extra.index.normalize()).mean()
        daily = series.reindex(days)
        if daily.isna().any():
            d = days[daily.isna().to_numpy()][0]
            raise ValueError(f"covariates: column {col!r} has no value for {d.date()}, but the inventory "
                             f"{src} covers {start.date()} to {end.date()}: covariates must cover every day "
                             f"of the period (given {series.index.min().date()} to {series.index.max().date()})")
        if period == "day":
            design[col] = daily.to_numpy()
        else:
            how = "sum" if (col.endswith(("_mm", "_days")) or col == "freeze_thaw") else "mean"
            design[col] = daily.groupby(key).agg(how).reindex(starts).to_numpy()
        extra_cols.append(col)
    return extra_cols


def _add_season_trend_columns(design: pd.DataFrame, period: str, season, trend: bool, start: pd.Timestamp,
                              end: pd.Timestamp, notes: list):
    """Add the season terms and the centred year [yr] of the trend to the model frame.

    Parameters
    ----------
    design : pandas.DataFrame
        The model frame (``period_start``, ``exposure_days``); columns are added in place.
    period : {"day", "month", "year"}
        Counting period (the middle of a month or year dates it).
    season : {"harmonic", "wet", "month", None}
        Season terms (none for yearly counts; a note says so).
    trend : bool
        Add ``year_c``, the decimal year minus ``year_ref``.
    start, end : pandas.Timestamp
        The record period.
    notes : list of str
        The model's notes.

    Returns
    -------
    season_frame : pandas.DataFrame
        The season columns added.
    season_used : str or None
        The season terms used.
    year_ref : float
        Reference year of the trend [yr]: the middle of the record, to 0.1 yr.
    """
    mid = design["period_start"] + pd.to_timedelta(design["exposure_days"] / 2, unit="D") \
        if period != "day" else design["period_start"]
    season_used = season if period != "year" else None
    if season is not None and period == "year":
        notes.append("season terms are not used for yearly counts")
    season_frame = _season_frame(pd.DatetimeIndex(mid), season_used)
    for c in season_frame.columns:
        design[c] = season_frame[c].to_numpy()
    decimal_year = mid.dt.year + (mid.dt.day_of_year - 0.5) / 365.25 if period != "day" else \
        design["period_start"].dt.year + (design["period_start"].dt.day_of_year - 0.5) / 365.25
    year_ref = float(np.round((start.year + end.year + 1) / 2, 1))
    if trend:
        design["year_c"] = decimal_year.to_numpy() - year_ref
    return season_frame, season_used, year_ref


def _add_counts(design: pd.DataFrame, events: pd.DataFrame, period: str, start: pd.Timestamp, end: pd.Timestamp,
                src: str) -> None:
    """Insert the count of events per period as the model frame's column ``count`` (raises when all are 0)."""
    ev_key = events["date"].dt.normalize() if period == "day" else (
        events["date"].dt.to_period("M").dt.to_timestamp() if period == "month"
        else pd.to_datetime(events["year"].astype(int).astype(str) + "-01-01"))
    counts = ev_key.value_counts()
    design.insert(1, "count", counts.reindex(design["period_start"]).fillna(0).astype(int).to_numpy())
    n_counted = int(design["count"].sum())
    if n_counted == 0:
        raise ValueError(f"{src}: no event falls inside the record period {start.date()} to {end.date()}")


def _term_table(design: pd.DataFrame, rain_cols: list, season_frame: pd.DataFrame, trend: bool, extra_cols: list,
                rain_per_mm: float, rain_transform: str) -> pd.DataFrame:
    """The model's terms: column, label, unit of the rate ratio, scale and transform; each must vary.

    Parameters
    ----------
    design : pandas.DataFrame
        The model frame.
    rain_cols : list of (str, str)
        Rainfall columns and labels.
    season_frame : pandas.DataFrame
        The season columns.
    trend : bool
        Whether ``year_c`` is a term.
    extra_cols : list of str
        The user's covariates.
    rain_per_mm : float
        Rainfall [mm] that a rainfall rate ratio refers to.
    rain_transform : {"linear", "sqrt", "log1p"}
        How rainfall enters the linear predictor.

    Returns
    -------
    pandas.DataFrame
        Columns ``term``, ``label``, ``unit``, ``scale``, ``transform``.
    """
    terms = []
    rain_unit = f"{rain_per_mm:g} mm" if rain_transform == "linear" else f"{rain_per_mm:g} mm vs none"
    for name, label in rain_cols:
        if rain_transform != "linear":
            label = f"{label} ({'square root' if rain_transform == 'sqrt' else 'log(1 + mm)'})"
        terms.append((name, label, rain_unit, rain_per_mm, rain_transform))
    for c in season_frame.columns:
        terms.append((c, {"season_sin": "season (sine of the day of year)",
                          "season_cos": "season (cosine of the day of year)",
                          "wet_season": "wet season (April-September)"}.get(c, f"calendar month {c[-2:]}"),
                      "unit", 1.0, "linear"))
    if trend:
        terms.append(("year_c", "trend", "year", 1.0, "linear"))
    for c in extra_cols:
        terms.append((c, c, "unit", 1.0, "linear"))
    terms = pd.DataFrame(terms, columns=["term", "label", "unit", "scale", "transform"])
    const_like = [t for t in terms["term"] if np.ptp(design[t].to_numpy(float)) == 0]
    if const_like:
        raise ValueError(f"covariate(s) {const_like} do not vary over the record period; they cannot be estimated")
    return terms


def _covariate_inputs(covariates, rainfall, windows_days):
    """Sort :func:`rate_model`'s ``covariates`` and ``rainfall`` into a covariate frame and daily rainfall.

    Parameters
    ----------
    covariates, rainfall, windows_days
        As :func:`rate_model`.

    Returns
    -------
    extra : pandas.DataFrame or None
        The user's daily covariates.
    rain : Rainfall or None
        Daily rainfall (a file is read).
    windows : tuple of int
        The antecedent rainfall bands [days], checked increasing and >= 1.
    """
    extra = None
    if isinstance(covariates, pd.DataFrame):
        extra = covariates
    elif covariates is not None:
        if rainfall is not None:
            raise ValueError("give rainfall either as covariates= or as rainfall=, not both")
        rainfall = covariates
    rain = _as_rainfall(rainfall, "rainfall")
    windows = tuple(int(w) for w in windows_days)
    if not windows or any(w < 1 for w in windows) or list(windows) != sorted(set(windows)):
        raise ValueError(f"windows_days = {windows_days!r} must be increasing whole numbers of days >= 1")
    return extra, rain, windows
