""":class:`Inventory`: a validated record of falls and what is derived from it.

The exact sizes are in ``events``, the censored and unsized ones in ``censored`` (see
:mod:`riskrf.frequency.inventory`); the object gives the counts, the events of any size
(:meth:`Inventory.all_events`), the annual maxima with the years without a fall kept as NaN, the completeness by
year, the summary table and the plot.  The sentence every output carries for a partly dated inventory
(:func:`_undated_note`) lives here too, as the reader and the object both write it.
"""
from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ...core.format import sig
from ...core.units import DEFAULT_DENSITY_KG_M3
from ...core.validation import warn
from simulation._display import Displayed, short_repr


_EVENT_COLUMNS = ["date", "year", "volume_m3", "mass_kg", "location", "notes", "source_row"]


def _empty_censored() -> pd.DataFrame:
    return pd.DataFrame({"date": pd.Series(dtype="datetime64[ns]"), "year": pd.Series(dtype="Int64"),
                         "volume_m3": pd.Series(dtype=float), "mass_kg": pd.Series(dtype=float),
                         "location": pd.Series(dtype=object), "notes": pd.Series(dtype=object),
                         "source_row": pd.Series(dtype=int), "censoring": pd.Series(dtype=object),
                         "size_text": pd.Series(dtype=object)})


@dataclass(frozen=True, repr=False)
class Inventory(Displayed):
    """A validated rock fall inventory.

    Attributes
    ----------
    events : pandas.DataFrame
        One row per fall, columns ``date`` (datetime64, NaT when unknown),
        ``year`` (Int64, missing when unknown), ``volume_m3``, ``mass_kg``,
        ``location``, ``notes`` and ``source_row`` (line number in the file).
    duration_years : float
        Length of the record [yr].
    start, end : datetime.date or None
        Record period, when known.
    density_kg_m3 : float
        Density used to convert between volume and mass [kg/m³].
    density_is_default : bool
        True when no density was given and :data:`DEFAULT_DENSITY_KG_M3` was used.
    source : str
        File the inventory was read from (or ``"<array>"``).
    period_source : str
        Where the record period came from: ``"argument"``, the sidecar path, or
        ``"inferred from the dates"``.
    size_column : str
        ``"volume"`` or ``"mass"``: which size was recorded (the other is derived).
    notes : tuple of str
        Every warning raised while reading, kept for reports.
    censored : pandas.DataFrame
        Events of the record period whose size is censored or missing: the
        columns of ``events`` plus ``censoring`` (``below``: the true size is
        below ``volume_m3``/``mass_kg``; ``above``: above it; ``approximate``:
        about it; ``unknown``: no size, NaN) and ``size_text`` (as written).
        They are not in ``events`` (the size fits use exact sizes only) but are
        counted by :meth:`all_events` and the rate models.
    sizes : str or None
        What the sizes are, from the sidecar's ``sizes``: ``"event_volumes"`` or ``"blocks"``; None when it does
        not say (a site file's ``inventory.sizes`` or ``--inventory-sizes`` wins; else event volumes are assumed).
    """

    events: pd.DataFrame
    duration_years: float
    start: _dt.date | None = None
    end: _dt.date | None = None
    density_kg_m3: float = DEFAULT_DENSITY_KG_M3
    density_is_default: bool = True
    source: str = "<array>"
    period_source: str = "argument"
    size_column: str = "volume"
    site: str = ""
    notes: tuple = field(default_factory=tuple)
    censored: pd.DataFrame = field(default_factory=_empty_censored)
    sizes: str | None = None

    def all_events(self) -> pd.DataFrame:
        """Every event of the record period, exact and censored sizes alike, in date order.

        The columns of :attr:`events` plus ``censoring`` (``""`` for an exact
        size) and ``size_text``.  Use it to count events (rate models); use
        :attr:`events` or :attr:`masses` for size statistics.

        Returns
        -------
        pandas.DataFrame
            One row per event (sizes in m³ and kg), dates ascending.
        """
        exact = self.events.assign(censoring="", size_text="")
        if self.censored.empty:
            return exact.reset_index(drop=True)
        both = pd.concat([exact, self.censored[exact.columns]], ignore_index=True)
        return both.sort_values(["date", "year", "source_row"], kind="stable").reset_index(drop=True)

    @property
    def n_censored(self) -> int:
        """Number of events with a censored or missing size (in :attr:`censored`)."""
        return len(self.censored)

    @property
    def masses(self) -> np.ndarray:
        """Block masses [kg], in record order."""
        return self.events["mass_kg"].to_numpy(dtype=float)

    @property
    def volumes(self) -> np.ndarray:
        """Block volumes [m³], in record order."""
        return self.events["volume_m3"].to_numpy(dtype=float)

    @property
    def n_events(self) -> int:
        """Number of events in the inventory."""
        return len(self.events)

    @property
    def is_dated(self) -> bool:
        """True when every event has at least a year."""
        return bool(self.events["year"].notna().all()) and self.n_events > 0

    @property
    def has_dates(self) -> bool:
        """True when at least one event has a date or year (annual maxima can be formed from the dated ones)."""
        return bool(self.events["year"].notna().any())

    @property
    def undated_rows(self) -> list[int]:
        """File rows of the events that have no date or year (left out of the annual maxima)."""
        return [int(r) for r in self.events.loc[self.events["year"].isna(), "source_row"]]

    @property
    def n_undated(self) -> int:
        """Number of events without a date or year."""
        return int(self.events["year"].isna().sum())

    def undated_note(self) -> str:
        """The sentence every output carries for a partly dated inventory ("" when all or none are dated).

        Returns
        -------
        str
        """
        return _undated_note(self.source, self.events)

    def record_years(self) -> list[int]:
        """Calendar years covered (wholly or partly) by the record period.

        Returns
        -------
        list of int
            The years, ascending (from the dated events when the period is not known; empty when none is dated).
        """
        if self.start is None or self.end is None:
            years = self.events["year"].dropna()
            if years.empty:
                return []
            return list(range(int(years.min()), int(years.max()) + 1))
        return list(range(self.start.year, self.end.year + 1))

    def annual_maxima(self, *, unit: str = "kg") -> pd.Series:
        """Largest fall of each calendar year of the record [kg, or m³ with ``unit="m3"``].

        Every year of the record period appears, except the years whose falls
        all lack an exact size (censored such as "<1" or no size at all): their
        maximum is unknown, not zero, so they are left out and named in a
        warning, and listed in ``series.attrs["years_without_exact_size"]`` (the
        Gumbel/GEV fits count them as years with a fall when they estimate the
        share of empty years p0).  A year with no recorded fall at all (exact,
        censored or missing size) has NaN (not zero, not dropped), and a
        warning says how many such years there are.  Partly covered first and
        last years are kept and named in a warning.  Raises ``ValueError`` for
        an inventory without any date; events without a date are left out with a warning listing their rows.

        Parameters
        ----------
        unit : {"kg", "m3"}
            Mass [kg] (default) or volume [m³].

        Returns
        -------
        pandas.Series
            Largest exact size of each year [kg or m³], indexed by year; NaN for a year without a fall.
        """
        if not self.has_dates:
            raise ValueError(
                f"{self.source}: annual maxima need a date or year for at least one event; none of the {self.n_events} "
                "events has one")
        col = {"kg": "mass_kg", "m3": "volume_m3"}.get(unit)
        if col is None:
            raise ValueError(f"unit = {unit!r} is not one of 'kg', 'm3'")
        if self.n_undated and self.undated_note() not in self.notes:
            warn(self.undated_note())
        years = self.record_years()
        dated = self.events[self.events["year"].notna()]
        maxima = dated.groupby(dated["year"].astype(int))[col].max()
        series = maxima.reindex(years)
        series.index.name = "year"
        series.name = f"annual_max_{col}"
        cens = self.censored
        with_falls = set() if cens.empty else {int(y) for y in cens["year"].dropna()}
        unknown = [y for y in series.index[series.isna()] if y in with_falls]
        if unknown:
            series = series.drop(unknown)
            warn(f"{self.source}: {len(unknown)} of {len(years)} years have falls but no exact size "
                 f"({_line_list(unknown, 10)}); their maximum is "
                 "unknown (not zero), so they are left out of the annual maxima and counted as years with a fall")
        series.attrs["years_without_exact_size"] = [int(y) for y in unknown]
        empty = series.index[series.isna()].tolist()
        if empty:
            warn(f"{self.source}: {len(empty)} of {len(years)} years have no recorded fall "
                 f"({_line_list(empty, 10)}); they are kept "
                 "as NaN and the Gumbel/GEV fits treat them with the mixed (zero-year) model")
        self._warn_censored_maxima(series, col)
        partial = [y for y in (years[:1] + years[-1:]) if self._coverage(y) < 0.999]
        if partial:
            warn(f"{self.source}: year(s) {sorted(set(partial))} are only partly covered by the record "
                 f"period {self.start} to {self.end}; their maxima may be low")
        return series

    def _warn_censored_maxima(self, series: pd.Series, col: str) -> None:
        """Warn about censored sizes that could set or change a year's maximum."""
        cens = self.censored
        if cens.empty:
            return
        cens = cens[cens["year"].notna()]
        affected = []
        for _, row in cens.iterrows():
            year, value, kind = int(row["year"]), row[col], row["censoring"]
            if year not in series.index:
                continue
            top = series.loc[year]          # exact: years with falls but no exact size were left out above
            if kind == "unknown":
                changes = False                     # no size recorded: nothing to compare
            else:
                changes = value > top or (kind == "above" and value >= top)
            if changes:
                affected.append(f"{year} ({row['size_text'] or 'no size'}, row {row['source_row']})")
        if affected:
            warn(f"{self.source}: {len(affected)} censored or missing size(s) could set or change their year's "
                 f"maximum, which uses exact sizes only: {', '.join(affected[:8])}"
                 f"{' ...' if len(affected) > 8 else ''}")

    def _coverage(self, year: int) -> float:
        if self.start is None or self.end is None:
            return 1.0
        lo = max(self.start, _dt.date(year, 1, 1))
        hi = min(self.end, _dt.date(year, 12, 31))
        return max((hi - lo).days + 1, 0) / (366 if year % 4 == 0 else 365)

    def completeness(self) -> pd.DataFrame:
        """Events per year and the smallest, median and largest recorded size per year.

        A rising smallest size or a falling count over time shows a change in
        recording practice (completeness), which the magnitude-frequency fit
        must respect.  Undated inventories give one row for the whole record.

        Returns
        -------
        pandas.DataFrame
            Indexed by year (or ``"all"``): ``n_events``, ``smallest_m3``, ``median_m3``, ``largest_m3``,
            ``smallest_kg``, ``largest_kg``.
        """
        ev = self.events
        key = ev["year"].astype("Int64") if self.is_dated else pd.Series("all", index=ev.index)
        g = ev.groupby(key)
        table = pd.DataFrame({
            "n_events": g.size(),
            "smallest_m3": g["volume_m3"].min(),
            "median_m3": g["volume_m3"].median(),
            "largest_m3": g["volume_m3"].max(),
            "smallest_kg": g["mass_kg"].min(),
            "largest_kg": g["mass_kg"].max(),
        })
        if self.is_dated:
            table = table.reindex(self.record_years())
            table["n_events"] = table["n_events"].fillna(0).astype(int)
        table.index.name = "year" if self.is_dated else "record"
        return table

    def summary(self) -> pd.DataFrame:
        """One-column table describing the inventory (sizes, period, density and its origin).

        Returns
        -------
        pandas.DataFrame
            Index: quantity (units in brackets: yr, kg/m3, m3, kg); column ``value``.
        """
        v, m = self.volumes, self.masses
        rows = {
            "source": self.source,
            "site": self.site,
            "events": self.n_events,
            "recorded size": self.size_column,
            "record start": self.start.isoformat() if self.start else "",
            "record end": self.end.isoformat() if self.end else "",
            "duration [yr]": round(self.duration_years, 3),
            "record period from": self.period_source,
            "events per year": round(self.n_events / self.duration_years, 3),
            "density [kg/m3]": f"{self.density_kg_m3:g}" + (" (default)" if self.density_is_default else ""),
            "volume min / median / max [m3]": " / ".join(sig(x) for x in (v.min(), np.median(v), v.max())),
            "mass min / median / max [kg]": " / ".join(sig(x) for x in (m.min(), np.median(m), m.max())),
            "dated": self.is_dated,
            "events without a date (not in the annual maxima)": self.n_undated,
            "censored or no size (not in the size fits)": self.n_censored,
        }
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    def __repr__(self) -> str:
        m = self.masses
        return short_repr(self, repr(Path(str(self.source)).name), f"{self.n_events} events",
                          f"{self.duration_years:.4g} yr", f"mass {sig(m.min())}-{sig(m.max())} kg" if m.size else "")

    def plot(self, ax=None, **kwargs):
        """Empirical magnitude-frequency curve: falls of at least m per year [1/yr] against m [kg], log-log (drawn by :func:`riskrf.frequency.figures.plot_inventory`).

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
        from ..figures import plot_inventory
        return plot_inventory(self, ax=ax, **kwargs)


def _undated_note(source: str, events: pd.DataFrame) -> str:
    """"k of n events have no date (rows ...)" for a partly dated inventory; "" when all or none are dated."""
    undated = events["year"].isna()
    k, n = int(undated.sum()), len(events)
    if k == 0 or k == n:
        return ""
    return (f"{source}: {k} of {n} events have no date (rows {_line_list(events.loc[undated, 'source_row'].tolist())}"
            f"); they count in the power law (sizes and rate) but are left out of the annual maxima, which use the "
            f"{n - k} dated events")


def _line_list(lines, limit=12) -> str:
    return ", ".join(map(str, lines[:limit])) + (" ..." if len(lines) > limit else "")
