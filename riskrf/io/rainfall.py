"""Daily rainfall records: reading, checking for gaps, antecedent totals.

Two file formats are read by :func:`read_rainfall`:

* **Hong Kong Observatory** daily totals as downloaded ("Daily Total Rainfall
  (mm) at the Hong Kong Observatory"): two title lines, the header
  ``年/Year,月/Month,日/Day,數值/Value,數據完整性/data Completeness`` and one row
  per day; ``Trace`` (less than 0.05 mm) is read as 0 mm and flagged ``trace``,
  ``***`` (unavailable) and values marked ``#`` (incomplete) are missing.
* **Generic table** for any other gauge: a ``date`` column (one row per day) and a
  ``rainfall_mm`` column (daily total in mm, >= 0; an empty cell, ``-``, ``***`` or
  ``NA`` is a missing day; ``trace`` is read as 0 mm), optionally a ``note`` column.
  Other columns are ignored.  Read by the rules of :mod:`riskrf.io.tables` shared by every
  table riskrf reads: CSV with any separator, Excel, Parquet, decimal commas, UTF-8 or
  cp1252, ``YYYY-MM-DD`` / ``DD.MM.YYYY`` dates (``NN/NN/YYYY`` by the whole-file rule).

Missing days are never filled: they stay NaN and are listed in
:attr:`Rainfall.gaps`; anything that needs rainfall on a missing day (a rate
model over a period that includes it or its antecedent window) stops with an
error naming the file, the rows around the gap and its dates.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .tables import sniff_delimiter  # noqa: F401 (re-exported: public before)
from ..core.validation import warn
from simulation._display import Displayed, short_repr


@dataclass(frozen=True, repr=False)
class Rainfall(Displayed):
    """A daily rainfall record on a complete calendar (missing days are NaN, never filled).

    Attributes
    ----------
    daily : pandas.Series
        Daily total rainfall [mm], indexed by every calendar day from the first
        to the last day of the file; NaN on missing days.
    flags : pandas.Series
        Per day: ``""``, ``"trace"`` (read as 0 mm), ``"missing"`` or ``"incomplete"``.
    rows : pandas.Series
        Line number in the file of each day (0 for days absent from the file).
    gaps : pandas.DataFrame
        One row per run of missing days: ``start``, ``end``, ``n_days``,
        ``row_before``, ``row_after`` (file lines around the gap).
    source : str
        The file read (or ``"<series>"``).
    file_format : str
        ``"HKO"`` or ``"generic"``.
    notes : tuple of str
        Every warning raised while reading.
    """

    daily: pd.Series
    flags: pd.Series
    rows: pd.Series
    gaps: pd.DataFrame
    source: str = "<series>"
    file_format: str = "generic"
    notes: tuple = field(default_factory=tuple)

    @property
    def first_day(self) -> pd.Timestamp:
        """First day of the daily record."""
        return self.daily.index[0]

    @property
    def last_day(self) -> pd.Timestamp:
        """Last day of the daily record."""
        return self.daily.index[-1]

    def summary(self) -> pd.DataFrame:
        """Key figures of the record (one-column table): source, format, first and last day, days, missing days,
        gaps, trace days, mean annual rainfall [mm] and the wettest day [mm].

        Returns
        -------
        pandas.DataFrame
            Index: quantity; column ``value``.
        """
        d = self.daily
        years = d.groupby(d.index.year).sum(min_count=300)
        rows = {
            "source": self.source,
            "format": self.file_format,
            "first day": self.first_day.date().isoformat(),
            "last day": self.last_day.date().isoformat(),
            "days": len(d),
            "missing days": int(d.isna().sum()),
            "gaps": len(self.gaps),
            "trace days (read as 0 mm)": int((self.flags == "trace").sum()),
            "mean annual rainfall [mm]": round(float(years.mean()), 1),
            "wettest day [mm]": f"{d.max():.1f} on {d.idxmax().date()}",
        }
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    def __repr__(self) -> str:
        return short_repr(self, repr(Path(str(self.source)).name),
                          f"{self.first_day.date()} to {self.last_day.date()}", f"{len(self.daily)} days",
                          f"{int(self.daily.isna().sum())} missing")

    def plot(self, ax=None, **kwargs):
        """Daily rainfall [mm] against date (drawn by :func:`riskrf.io.figures.plot_rainfall`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).
        **kwargs
            Passed to the drawing function.

        Returns
        -------
        matplotlib.axes.Axes
        """
        from .figures import plot_rainfall
        return plot_rainfall(self, ax=ax, **kwargs)

    def _row_label(self, day) -> str:
        r = int(self.rows.get(day, 0))
        return f"row {r}" if r else "no row"

    def check_covers(self, start, end, what: str) -> None:
        """Raise ``ValueError`` unless every day from ``start`` to ``end`` has rainfall.

        Parameters
        ----------
        start, end : date-like
            First and last day needed.
        what : str
            The caller's need (e.g. ``"inventory X, row 12, date 1984-01-02 (with its 30-day antecedent
            window)"``), in the message.

        Raises
        ------
        ValueError
            Naming the record, the missing days and the rows around them.
        """
        start, end = pd.Timestamp(start).normalize(), pd.Timestamp(end).normalize()
        if start < self.first_day:
            raise ValueError(f"{what}: needs rainfall from {start.date()}, before the rainfall record {self.source} "
                             f"begins ({self.first_day.date()}, {self._row_label(self.first_day)})")
        if end > self.last_day:
            raise ValueError(f"{what}: needs rainfall to {end.date()}, after the rainfall record {self.source} "
                             f"ends ({self.last_day.date()}, {self._row_label(self.last_day)})")
        for g in self.gaps.itertuples():
            if g.start <= end and g.end >= start:
                raise ValueError(
                    f"{self.source}: no rainfall from {g.start.date()} to {g.end.date()} ({g.n_days} days missing, "
                    f"between rows {g.row_before} and {g.row_after}), but {what} needs rainfall from {start.date()} "
                    f"to {end.date()}; gaps are never filled: choose a period outside the gap or supply the "
                    "missing days")

    def window_total(self, days: int, lag: int = 0) -> pd.Series:
        """Rainfall [mm] summed over ``days`` days ending ``lag`` days before each day.

        ``window_total(1)`` is the day's own rainfall; ``window_total(14, lag=1)``
        the 14 days before it.  NaN where any day of the window is missing.

        Parameters
        ----------
        days : int
            Window length [days], >= 1.
        lag : int
            Days between the window's last day and the day it is reported on, >= 0.

        Returns
        -------
        pandas.Series
            Rainfall total [mm] per calendar day.
        """
        if days < 1 or lag < 0:
            raise ValueError(f"days = {days!r} must be >= 1 and lag = {lag!r} >= 0")
        return self.daily.rolling(days, min_periods=days).sum().shift(lag)


def _gaps(daily: pd.Series, rows: pd.Series) -> pd.DataFrame:
    miss = daily.isna().to_numpy()
    out = []
    if miss.any():
        idx = daily.index
        edges = np.flatnonzero(np.diff(np.r_[0, miss.astype(int), 0]))
        for a, b in zip(edges[::2], edges[1::2]):
            before = int(rows.iloc[a - 1]) if a > 0 else 0
            after = int(rows.iloc[b]) if b < len(rows) else 0
            out.append({"start": idx[a], "end": idx[b - 1], "n_days": int(b - a),
                        "row_before": before, "row_after": after})
    return pd.DataFrame(out, columns=["start", "end", "n_days", "row_before", "row_after"])


#: Largest daily rainfall ever measured [mm]: 1,825 mm in 24 h at Foc-Foc, La Réunion, 7-8 January 1966
#: (WMO World Weather and Climate Extremes Archive).  A larger daily total is a unit or typing error.
MAX_DAILY_RAINFALL_MM = 1825.0


def _build(dates, values, flags, lines, path, fmt, notes) -> Rainfall:
    big = np.asarray(values, float) > MAX_DAILY_RAINFALL_MM
    if big.any():
        i = int(np.argmax(big))
        where = f"row {lines[i]}, " if lines[i] else ""
        raise ValueError(f"{path}: {where}{pd.Timestamp(dates[i]).date()}: daily rainfall {values[i]:g} mm is above "
                         f"the largest ever measured ({MAX_DAILY_RAINFALL_MM:g} mm in 24 h, La Réunion 1966); "
                         "check the unit (the column is mm per day)")
    frame = pd.DataFrame({"value": values, "flag": flags, "row": lines}, index=pd.DatetimeIndex(dates))
    dup = frame.index.duplicated(keep=False)
    if dup.any():
        d = frame.index[dup][0]
        rows = frame.loc[d, "row"].tolist()
        raise ValueError(f"{path}: rows {rows}: date {d.date()} appears more than once")
    frame = frame.sort_index()
    calendar = pd.date_range(frame.index[0], frame.index[-1], freq="D")
    frame = frame.reindex(calendar)
    absent = frame["row"].isna()
    frame["flag"] = frame["flag"].where(~absent, "missing")
    frame["row"] = frame["row"].fillna(0).astype(int)
    daily = frame["value"].astype(float).rename("rainfall_mm")
    gaps = _gaps(daily, frame["row"])
    if not gaps.empty:
        listed = "; ".join(f"{g.start.date()} to {g.end.date()} ({g.n_days} days, between rows {g.row_before} and "
                           f"{g.row_after})" for g in gaps.head(6).itertuples())
        msg = (f"{path}: {len(gaps)} gap(s), {int(gaps['n_days'].sum())} missing days in the rainfall record: "
               f"{listed}{' ...' if len(gaps) > 6 else ''}; they are not filled, and a rate model needing them stops")
        notes.append(msg)
        warn(msg)
    n_trace = int((frame["flag"] == "trace").sum())
    if n_trace:
        notes.append(f"{path}: {n_trace} days with a trace of rain (< 0.05 mm) read as 0 mm")
    return Rainfall(daily=daily, flags=frame["flag"].astype(str), rows=frame["row"], gaps=gaps, source=str(path),
                    file_format=fmt, notes=tuple(notes))


def _value(text: str, path, line: int, column: str):
    """(value in mm or NaN, flag) for one cell."""
    s = text.strip()
    if s.lower() == "trace":
        return 0.0, "trace"
    if s in ("", "***", "-", "NA", "NaN", "nan"):
        return np.nan, "missing"
    try:
        v = float(s)
    except ValueError:
        raise ValueError(f"{path}: row {line}, column {column!r}: {text!r} is not a rainfall in mm "
                         "(a number >= 0, 'Trace', or empty when missing)") from None
    if not np.isfinite(v) or v < 0:
        raise ValueError(f"{path}: row {line}, column {column!r}: rainfall {text!r} must be a finite number >= 0")
    return v, ""


def _read_hko(path: Path, lines: list[str]) -> Rainfall:
    header = next((i for i, line in enumerate(lines) if "Year" in line and "Value" in line), None)
    if header is None:
        raise ValueError(f"{path}: no header line with Year, Month, Day, Value found in the first lines")
    dates, values, flags, rows, impossible = [], [], [], [], []
    for i in range(header + 1, len(lines)):
        line = lines[i].strip()
        if not line:
            break                                   # the legend follows a blank line
        parts = [p.strip() for p in line.split(",")]
        if len(parts) < 4:
            raise ValueError(f"{path}: row {i + 1}: {line!r} does not have Year, Month, Day, Value")
        try:
            y, m, d = int(parts[0]), int(parts[1]), int(parts[2])
        except ValueError:
            raise ValueError(f"{path}: row {i + 1}: {','.join(parts[:3])!r} is not a year, month, day") from None
        v, flag = _value(parts[3], path, i + 1, "Value")
        try:
            day = pd.Timestamp(y, m, d)
        except ValueError:
            if 1 <= m <= 12 and 1 <= d <= 31:       # e.g. 1900-02-29 in the Observatory file: not a calendar day
                impossible.append(f"row {i + 1} ({y}-{m:02d}-{d:02d}, value {parts[3]!r})")
                continue
            raise ValueError(f"{path}: row {i + 1}: {','.join(parts[:3])!r} is not a valid year, month, day") from None
        if len(parts) > 4 and parts[4] == "#":
            v, flag = np.nan, "incomplete"
        dates.append(day), values.append(v), flags.append(flag), rows.append(i + 1)
    if not dates:
        raise ValueError(f"{path}: no daily rows after the header")
    notes = []
    if impossible:
        msg = (f"{path}: {len(impossible)} row(s) name a day that does not exist in the calendar and are left out: "
               + ", ".join(impossible))
        notes.append(msg)
        warn(msg)
    n_inc = flags.count("incomplete")
    if n_inc:
        notes.append(f"{path}: {n_inc} days marked '#' (data incomplete) are treated as missing")
    return _build(dates, values, flags, rows, path, "HKO", notes)


_MISSING = ("", "***", "-", "NA", "NaN", "nan", "n/a", "N/A")


def _read_generic(path: Path, reader: dict) -> Rainfall:
    """The generic layout through the shared table reader (:mod:`riskrf.io.tables`)."""
    from .tables import is_blank, parse_dates, parse_numbers, read_table
    reader = dict(reader)
    decimal, date_format = reader.pop("decimal", None), reader.pop("date_format", None)
    table, first, notes = read_table(path, what="rainfall", **reader)
    cols = {c.strip().lower(): c for c in table.columns}
    if "date" not in cols or "rainfall_mm" not in cols:
        raise ValueError(f"{path}: a rainfall file needs columns 'date' (YYYY-MM-DD) and 'rainfall_mm' (daily total, "
                         f"mm), or the Hong Kong Observatory layout; found {list(table.columns)}")
    rows = np.arange(len(table)) + first
    sub = table[[cols["date"], cols["rainfall_mm"]]]
    keep = ~is_blank(sub).to_numpy() if len(sub) else np.ones(0, bool)
    sub, rows = sub[keep].reset_index(drop=True), rows[keep]
    if sub.empty:
        raise ValueError(f"{path}: no daily rows")
    dcol, rcol = cols["date"], cols["rainfall_mm"]
    empty_date = sub[dcol].astype(str).str.strip() == ""
    if empty_date.any():
        i = int(np.argmax(empty_date.to_numpy()))
        raise ValueError(f"{path}: row {rows[i]}, column {dcol!r}: the date is empty (rainfall "
                         f"{sub[rcol].iloc[i]!r})")
    try:
        dates, _ = parse_dates(sub[dcol], path, dcol, rows, date_format=date_format)
    except ValueError as exc:      # the rainfall reader's wording: "'2001-13-02' is not a date (...)"
        raise ValueError(re.sub(r"cannot read date ('.*?') ", r"\1 is not a date ", str(exc))) from None
    year_only = dates.isna().to_numpy()
    if year_only.any():
        i = int(np.argmax(year_only))
        raise ValueError(f"{path}: row {rows[i]}, column {dcol!r}: {sub[dcol].iloc[i]!r} is not a date: daily "
                         "rainfall needs a day (YYYY-MM-DD, DD.MM.YYYY, ...)")
    raw = sub[rcol]
    text = raw.astype(str).str.strip()
    trace = text.str.lower() == "trace"
    missing = text.isin(_MISSING)
    values = parse_numbers(raw.where(~(trace | missing), ""), path, rcol, rows, decimal=decimal)
    bad = ~(trace | missing).to_numpy() & ~(np.isfinite(values.to_numpy()) & (values.to_numpy() >= 0))
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{path}: row {rows[i]}, column {rcol!r}: rainfall {raw.iloc[i]!r} must be a finite "
                         "number >= 0")
    values = values.where(~trace, 0.0).where(~missing, np.nan)
    flags = np.where(trace, "trace", np.where(missing, "missing", ""))
    return _build(list(dates.dt.normalize()), list(values.to_numpy()), list(flags), list(rows), path, "generic",
                  list(notes))


def read_rainfall(path, *, sheet=None, header_row: int | None = None, decimal: str | None = None,
                  encoding: str | None = None, date_format: str | None = None) -> Rainfall:
    """Read a daily rainfall record (Hong Kong Observatory layout or the generic table).

    Parameters
    ----------
    path : str or Path
        The file; the layout is recognised from its header (see the module
        docstring for both formats).
    sheet, header_row, decimal, encoding, date_format
        For the generic layout, the rules of :mod:`riskrf.io.tables` as for
        inventories: CSV with any separator, Excel (``sheet``, ``header_row``)
        or Parquet; decimal commas; UTF-8 or cp1252; ``DD.MM.YYYY`` dates and
        ``NN/NN/YYYY`` by the whole-file rule (``date_format`` when ambiguous).

    Returns
    -------
    Rainfall
        Daily totals [mm] on a complete calendar; missing days NaN, listed in
        ``gaps`` and in a warning (never filled).

    Raises
    ------
    ValueError
        Naming the file, row, column and value: a malformed date, a negative
        or non-numeric rainfall, a date given twice, missing columns.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"rainfall file not found: {path}")
    reader = {"sheet": sheet, "header_row": header_row, "decimal": decimal, "encoding": encoding,
              "date_format": date_format}
    if path.suffix.lower() in (".xlsx", ".xlsm", ".parquet"):
        return _read_generic(path, reader)
    text = path.read_bytes().decode("utf-8-sig", errors="replace")
    lines = text.splitlines()
    head = "\n".join(lines[:5])
    if "Hong Kong Observatory" in head or ("Year" in head and "Value" in head and "Completeness" in head):
        return _read_hko(path, lines)
    return _read_generic(path, reader)


def rainfall_from_series(daily: pd.Series, source: str = "<series>") -> Rainfall:
    """A :class:`Rainfall` from a pandas Series of daily totals [mm] indexed by date.

    Parameters
    ----------
    daily : pandas.Series
        Daily totals [mm] (NaN for missing days), on a DatetimeIndex.
    source : str
        Name used in messages.

    Returns
    -------
    Rainfall
    """
    if not isinstance(daily, pd.Series) or not isinstance(daily.index, pd.DatetimeIndex):
        raise TypeError(f"{source}: daily rainfall must be a pandas Series indexed by dates")
    values = daily.to_numpy(dtype=float)
    bad = np.isfinite(values) & (values < 0)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{source}: rainfall on {daily.index[i].date()} is {values[i]!r}; must be >= 0")
    flags = np.where(np.isnan(values), "missing", "")
    return _build(daily.index.normalize(), values, flags, np.zeros(len(values), int), source, "generic", [])
