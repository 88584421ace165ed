"""Rock fall inventories: reading, validating and summarising a record of falls.

An inventory is a list of rock falls with a size (volume in m³ or mass in kg),
optionally a date (full date or year only) and a location, together with the
length of the period over which falls were recorded.  The record period turns
counts into annual rates (Wyllie 2014, section 8.4), so it is never guessed
silently: it is given as an argument, read from a sidecar TOML file beside the
inventory (``<name>.toml`` with a ``[record]`` table), or inferred from the dates
with a warning.

Years with no recorded fall are kept in :meth:`Inventory.annual_maxima` as
missing values (NaN), never dropped and never set to zero: the extreme-value
fits then use the mixed model that gives such years their own probability
(see :func:`riskrf.fit_gumbel`).

Censored sizes.  Agency registers often give a size only as a bound or an
estimate.  In a size column a value may be written ``<1`` (the size is below
1: an upper bound), ``>20`` (above 20: a lower bound) or ``~15`` (about 15: an
approximate estimate); an empty size means "not recorded".  Such events are
never dropped and never given a made-up size: they are kept in
:attr:`Inventory.censored` (column ``censoring`` = ``below``, ``above``,
``approximate`` or ``unknown``, with the bound or estimate in ``volume_m3`` /
``mass_kg``), left out of the size fits (power law, annual maxima) with a
warning that counts them, and counted by rate models through
:meth:`Inventory.all_events`.
"""
from __future__ import annotations

import datetime as _dt
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..io.tables import is_blank, parse_dates, parse_numbers, read_table, sniff_delimiter  # noqa: F401 (re-exported)
from ..core.format import sig
from ..core.units import DEFAULT_DENSITY_KG_M3, KG_PER_TONNE
from ..core.validation import check_density, check_positive, warn
from simulation._display import Displayed, short_repr

#: Rock density used when none is given [kg/m³] (a typical value for granite
#: and limestone; Wyllie 2014 uses 2.6-2.7 t/m³).

_VOLUME_NAMES = {"volume", "vol", "v", "volume_m3", "vol_m3", "v_m3", "volum", "volumen"}
_MASS_NAMES = {"mass", "masse", "m", "weight", "block_mass"}
_DATE_NAMES = {"date", "datum", "event_date", "date_time", "datetime", "skreddato", "dato", "year", "jahr", "ar"}
_LOCATION_NAMES = {"location", "chainage", "chainage_m", "station", "place", "site", "km", "stedsangivelse"}
_NOTES_NAMES = {"notes", "note", "comment", "comments", "remarks", "bemerkung"}
_MASS_UNITS = {"kg": 1.0, "t": KG_PER_TONNE, "tonne": KG_PER_TONNE, "tonnes": KG_PER_TONNE, "tons": KG_PER_TONNE}
_VOLUME_UNITS = {"m3": 1.0, "dm3": 1e-3, "l": 1e-3, "litre": 1e-3, "cm3": 1e-6}


#: Prefix of a censored size -> the value of the ``censoring`` column.
CENSORING = {"<": "below", "<=": "below", "≤": "below", ">": "above", ">=": "above", "≥": "above",
             "~": "approximate", "≈": "approximate", "ca.": "approximate", "ca": "approximate"}
_CENSORED_RE = re.compile(r"^\s*(<=|>=|<|>|≤|≥|~|≈|ca\.?)\s*([0-9.,eE+-]+)\s*$")
_EVENT_COLUMNS = ["date", "year", "volume_m3", "mass_kg", "location", "notes", "source_row"]


def _empty_censored() -> pd.DataFrame:
    return pd.DataFrame({"date": pd.Series(dtype="datetime64[ns]"), "year": pd.Series(dtype="Int64"),
                         "volume_m3": pd.Series(dtype=float), "mass_kg": pd.Series(dtype=float),
                         "location": pd.Series(dtype=object), "notes": pd.Series(dtype=object),
                         "source_row": pd.Series(dtype=int), "censoring": pd.Series(dtype=object),
                         "size_text": pd.Series(dtype=object)})


def _normalise(name: str) -> str:
    """Lower-case a column name and turn brackets, units and spaces into ``root_unit``."""
    s = str(name).strip().lower().replace("³", "3").replace("^3", "3")
    s = re.sub(r"[\[\]\(\)\{\}]", " ", s)
    s = re.sub(r"[^0-9a-zæøåäöüß]+", "_", s).strip("_")
    return s


def _split_unit(norm: str, units: dict) -> tuple[str, str | None]:
    """Split ``mass_kg`` into (``mass``, ``kg``); the unit is None when absent."""
    for unit in sorted(units, key=len, reverse=True):
        if norm.endswith("_" + unit):
            return norm[: -len(unit) - 1], unit
    return norm, None


def _find_column(columns, roots: set, units: dict | None = None):
    """Return (original column, unit) for the first column whose root is in ``roots``."""
    for col in columns:
        norm = _normalise(col)
        root, unit = _split_unit(norm, units) if units else (norm, None)
        if root in roots or norm in roots:
            return col, unit
    return None, None


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
        """Empirical magnitude-frequency curve: falls of at least m per year [1/yr] against m [kg], log-log (drawn by :func:`riskrf.report.fit_figures.plot_inventory`).

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
        from ..core.figures import draw
        return draw("inventory", self, ax=ax, **kwargs)

#: What an inventory's sizes can be: detached event volumes (laser scanning, registers) or individual block sizes.
SIZES = ("event_volumes", "blocks")

#: Reader options a sidecar ``[record]`` table (or a site file's ``[inventory]``) may give.
READER_OPTIONS = ("sheet", "header_row", "encoding", "decimal", "date_format", "volume_unit", "mass_unit",
                  "duplicates", "volume_column", "mass_column", "date_column", "location_column")


def _sidecar(path: Path) -> tuple[dict, Path | None, str | None]:
    """The ``[record]`` table of ``<stem>.toml`` beside the inventory: (fields, path, note)."""
    side = path.with_suffix(".toml")
    if not side.exists():
        return {}, None, None
    try:
        with open(side, "rb") as fh:
            data = tomllib.load(fh)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:   # a binary file: named, not a bare codec error
        raise ValueError(f"{side}: not valid TOML: {exc}") from exc
    if "record" not in data and any(k in data for k in ("inventory", "hazard", "site", "options")):
        return {}, None, (f"{side} is a site file, not a [record] sidecar of {path.name}; it is not read as "
                          "the inventory's sidecar (the site file's [inventory] fields apply)")
    record = data.get("record", data)
    known = {"start", "end", "duration_years", "density_kg_m3", "site", "sizes", *READER_OPTIONS}
    unknown = set(record) - known
    if unknown:
        raise ValueError(f"{side}: unknown field(s) {sorted(unknown)} in [record]; expected {sorted(known)}")
    if "sizes" in record and record["sizes"] not in SIZES:
        raise ValueError(f"{side}: [record] sizes = {record['sizes']!r} must be one of {list(SIZES)} (what the "
                         "inventory's sizes are: detached event volumes, or individual block sizes)")
    return record, side, None


def _as_date(value, what: str) -> _dt.date:
    if isinstance(value, _dt.datetime):
        return value.date()
    if isinstance(value, _dt.date):
        return value
    try:
        return _dt.date.fromisoformat(str(value))
    except ValueError as exc:
        raise ValueError(f"{what} = {value!r} is not a date (use YYYY-MM-DD)") from exc


def _split_censored(raw: pd.Series) -> tuple[pd.Series, pd.Series]:
    """Strip a censoring prefix (``<1``, ``>20``, ``~15``) from size cells.

    Returns (text without the prefix, censoring): censoring is ``""`` (exact),
    ``"below"``, ``"above"``, ``"approximate"`` or ``"unknown"`` (empty cell).
    """
    text = raw.astype(str).str.strip()
    censoring = pd.Series("", index=raw.index, dtype=object)
    censoring[text == ""] = "unknown"
    # Only cells starting with a prefix character go through the (slow) extraction.
    candidates = text.str.match(r"^(<|>|≤|≥|~|≈|ca)", case=False)
    match = text[candidates].str.extract(_CENSORED_RE)
    has_prefix = pd.Series(False, index=raw.index)
    has_prefix[match.index] = match[0].notna()
    if has_prefix.any():
        hit = match[match[0].notna()]
        censoring[hit.index] = hit[0].str.lower().map(CENSORING)
        text = text.where(~has_prefix, match[1].reindex(text.index))
    text = text.astype(object)
    if raw.dtype == object and pd.api.types.infer_dtype(raw, skipna=True) not in ("string", "empty"):
        # Excel number cells stay numbers: their decimal point is not text to interpret (riskrf.io.tables)
        is_num = raw.map(lambda v: isinstance(v, (float, int, np.floating, np.integer)) and not isinstance(v, bool))
        text[is_num] = raw[is_num]
    return text, censoring


def _parse_sizes(raw: pd.Series, path, col: str, rows: np.ndarray, decimal=None) -> pd.Series:
    values = parse_numbers(raw, path, col, rows, decimal=decimal)
    nonpos = values.notna() & ~(values > 0)
    if nonpos.any():
        i = nonpos.idxmax()
        raise ValueError(f"{path}: row {rows[i]}, column {col!r}: size {raw[i]!r} must be > 0")
    inf = values.notna() & ~np.isfinite(values)
    if inf.any():
        i = inf.idxmax()
        raise ValueError(f"{path}: row {rows[i]}, column {col!r}: size {raw[i]!r} is not finite")
    return values


def read_inventory(path, *, start=None, end=None, duration_years=None, density_kg_m3=None,
                   volume_column=None, mass_column=None, date_column=None, location_column=None,
                   mass_unit=None, volume_unit=None, sheet=None, header_row=None, encoding=None, decimal=None,
                   date_format=None, duplicates=None) -> Inventory:
    """Read a rock fall inventory from CSV, Excel (.xlsx) or Parquet.

    Parameters
    ----------
    path : str or Path
        The inventory file.  Never modified.
    start, end : date or str, optional
        Record period (inclusive).  Overrides the sidecar file.
    duration_years : float, optional
        Length of the record [yr] when there are no dates (e.g. a laser-scanning
        campaign).  Overrides the sidecar file.
    density_kg_m3 : float, optional
        Rock density [kg/m³]; default :data:`DEFAULT_DENSITY_KG_M3` (reported).
    volume_column, mass_column, date_column, location_column : str, optional
        Column names when they cannot be recognised.  By default names are
        matched case-insensitively: ``volume``/``vol``/``volume_m3``/``Volume [m³]``,
        ``mass``/``masse``/``mass_kg``/``Mass [t]``, ``date``/``datum``/``year``, ...
    mass_unit : {"kg", "t"}, optional
        Unit of the mass column when its name does not say (default kg).
    volume_unit : {"m3", "dm3", "l", "litre", "cm3"}, optional
        Unit of the volume column when its name does not say (default m³).  Giving it
        also confirms volumes that look implausibly large for m³ (see Notes).
    sheet, header_row : optional
        Excel sheet (name, or number counting from 1) and the 1-based row holding
        the column names (also for text files with title lines above the header).
    encoding : str, optional
        Text encoding; default UTF-8 (with or without BOM), else cp1252 with a note.
    decimal : {".", ","}, optional
        Decimal mark; default decided per column (:mod:`riskrf.io.tables`).
    date_format : str, optional
        ``strftime`` pattern of every date, e.g. ``"%d/%m/%Y"``; needed only when
        the dates are ambiguous (:mod:`riskrf.io.tables`).
    duplicates : {"warn", "drop", "keep", "error"}, optional
        What to do with dated rows that repeat an earlier row exactly.  Default
        ``"warn"``: kept with a warning, but refused when every dated row has an
        exact copy (a file appended twice doubles the rate).

    Returns
    -------
    Inventory

    Notes
    -----
    The record period is taken, in this order, from ``start``/``end`` or
    ``duration_years``; from ``<path stem>.toml`` beside the file
    (``[record]`` with ``start``, ``end`` or ``duration_years``, and optionally
    ``density_kg_m3`` and ``site``); or from the first and last dates, with a
    warning (this underestimates the period by the waiting time to the first
    and after the last fall).  Rows with an empty size are dropped with a
    warning that lists them; events dated outside the record period are
    excluded with a warning.

    Every reader option (``sheet`` ... ``duplicates``, the column names and units)
    may also be given in the sidecar's ``[record]`` table; arguments win.  Numbers
    with decimal commas, dates and encodings follow the rules of
    :mod:`riskrf.io.tables` (documentation: File formats, "Input formats").

    Plausibility: when the volume unit was not declared (``volume_unit`` or a unit
    in the column name such as ``Volume [l]``), volumes whose median exceeds
    100 m³, or with more than one fall of 10⁵ m³ or more per decade of record,
    are refused as probable litres or cm³ entered as m³ (declare
    ``volume_unit="m3"`` to confirm them).
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"inventory file not found: {path}")
    if path.is_dir():
        raise ValueError(f"{path} is a directory, not an inventory file")
    notes: list[str] = []

    def note(msg):
        notes.append(msg)
        warn(msg)

    sidecar, side_path, side_note = _sidecar(path)
    if side_note:
        note(side_note)
    opts = _reader_options(sidecar, volume_column=volume_column, mass_column=mass_column, date_column=date_column,
                           location_column=location_column, mass_unit=mass_unit, volume_unit=volume_unit,
                           sheet=sheet, header_row=header_row, encoding=encoding, decimal=decimal,
                           date_format=date_format, duplicates=duplicates)
    events, density, density_is_default, size_column, size_spec = _read_events(path, opts, density_kg_m3, sidecar,
                                                                               side_path, note)
    start, end, duration_years, period_source = _inventory_period(path, events, sidecar, side_path, start, end,
                                                                  duration_years, note)
    if start is not None:
        events = _drop_outside_period(path, events, start, end, note)
    duration_years = check_positive(duration_years, "duration_years")
    events, censored = _split_censored_events(path, events, note)
    if _undated_note(str(path), events):
        note(_undated_note(str(path), events))
    _check_plausible_sizes(events, path, *size_spec, duration_years, note)
    return Inventory(events=events, duration_years=duration_years, start=start, end=end, density_kg_m3=density,
                     density_is_default=density_is_default, source=str(path), period_source=period_source,
                     size_column=size_column, site=str(sidecar.get("site", "")), notes=tuple(notes),
                     censored=censored, sizes=sidecar.get("sizes"))


def _reader_options(sidecar: dict, **given) -> dict:
    """The reader options: each argument, else the sidecar's ``[record]`` value; checks duplicates and decimal.

    Parameters
    ----------
    sidecar : dict
        The sidecar's ``[record]`` table.
    **given
        The options :data:`READER_OPTIONS` as passed to :func:`read_inventory` (None when not given).

    Returns
    -------
    dict
        The options, ``duplicates`` defaulting to ``"warn"``.

    Raises
    ------
    ValueError
        ``duplicates`` or ``decimal`` is not one of its values.
    """
    for key in READER_OPTIONS:
        if given[key] is None and key in sidecar:
            given[key] = sidecar[key]
    given["duplicates"] = given["duplicates"] or "warn"
    if given["duplicates"] not in ("warn", "drop", "keep", "error"):
        raise ValueError(f"duplicates = {given['duplicates']!r} is not one of 'warn', 'drop', 'keep', 'error'")
    if given["decimal"] not in (None, ".", ","):
        raise ValueError(f"decimal = {given['decimal']!r} is not '.' or ','")
    return given


def _read_events(path: Path, opts: dict, density_kg_m3, sidecar: dict, side_path, note) -> tuple:
    """Read the inventory's rows into a table of events with volumes [m³] and masses [kg], duplicates handled.

    Parameters
    ----------
    path : Path
        The inventory file.
    opts : dict
        The reader options (:func:`_reader_options`).
    density_kg_m3 : float or None
        Rock density given as an argument [kg/m³].
    sidecar : dict
        The sidecar's ``[record]`` table.
    side_path : Path or None
        The sidecar file.
    note : callable
        Records and warns one note of the reading.

    Returns
    -------
    tuple
        ``(events, density, density_is_default, size_column, size_spec)``: every row as an event (censored
        and unsized ones included), the density [kg/m³], whether it is the default, the column the sizes were
        given in (``"volume"`` or ``"mass"``) and the arguments ``(column, is_volume, declared_unit)`` of
        :func:`_check_plausible_sizes`.
    """
    table, rows = _read_inventory_table(path, opts["sheet"], opts["header_row"], opts["encoding"], note)
    vcol, vunit, mcol, munit, dcol, lcol, ncol = _inventory_columns(
        path, table, opts["volume_column"], opts["mass_column"], opts["date_column"], opts["location_column"])
    density, density_is_default = _inventory_density(density_kg_m3, sidecar, side_path)
    volume_unit, mass_unit = opts["volume_unit"], opts["mass_unit"]
    volume, mass, size_column, censoring, size_raw = _inventory_sizes(
        path, table, rows, vcol, vunit, mcol, munit, volume_unit, mass_unit, opts["decimal"], density)
    if density_is_default:
        note(f"{path}: density not given; the default {DEFAULT_DENSITY_KG_M3:g} kg/m3 converts "
             f"{'volume to mass' if size_column == 'volume' else 'mass to volume'}")
    events = _inventory_events(path, table, rows, volume, mass, censoring, size_raw, dcol, lcol, ncol,
                               opts["date_format"], note)
    events = _check_duplicates(events, table, path, opts["duplicates"], note)
    # a unit in the column name counts as declared unless it is the default one:
    # litres typed into a 'volume_m3' column are exactly the mistake to catch
    declared = ((volume_unit or (vunit if vunit != "m3" else None)) if vcol is not None
                else (mass_unit or (munit if munit != "kg" else None)))
    size_spec = (vcol if vcol is not None else mcol, vcol is not None, declared)
    return events, density, density_is_default, size_column, size_spec


def _read_inventory_table(path: Path, sheet, header_row, encoding, note) -> tuple[pd.DataFrame, np.ndarray]:
    """Read the inventory's table and drop its blank rows.

    Parameters
    ----------
    path : Path
        The inventory file.
    sheet, header_row, encoding : optional
        Reader options of :func:`riskrf.io.tables.read_table`.
    note : callable
        Records and warns one note of the reading.

    Returns
    -------
    table : pandas.DataFrame
        The non-blank rows, indexed from 0.
    rows : numpy.ndarray
        The 1-based file row of each row of ``table``.
    """
    table, first_row, read_notes = read_table(path, sheet=sheet, header_row=header_row, encoding=encoding,
                                              what="inventory")
    for msg in read_notes:
        note(msg)
    blank = is_blank(table)
    rows = np.arange(len(table)) + first_row
    table = table.loc[~blank]
    rows = rows[~blank.to_numpy()]
    table.index = range(len(table))
    return table, rows


def _inventory_columns(path: Path, table: pd.DataFrame, volume_column, mass_column, date_column,
                       location_column) -> tuple:
    """Find the size, date, location and notes columns of the inventory's table, checking the named ones.

    Parameters
    ----------
    path : Path
        The inventory file (named in errors).
    table : pandas.DataFrame
        The inventory's rows.
    volume_column, mass_column, date_column, location_column : str or None
        Column names given by the user or the sidecar; None to recognise them by name.

    Returns
    -------
    tuple
        ``(vcol, vunit, mcol, munit, dcol, lcol, ncol)``: the volume and mass columns with the units their
        names state (None when absent or unstated), the date, location and notes columns (None when absent).

    Raises
    ------
    ValueError
        A named column that is not in the table, neither a volume nor a mass column, or no rows.
    """
    columns = [c for c in table.columns if not str(c).startswith("Unnamed")]
    vcol, vunit = (volume_column, None) if volume_column else _find_column(columns, _VOLUME_NAMES, _VOLUME_UNITS)
    mcol, munit = (mass_column, None) if mass_column else _find_column(columns, _MASS_NAMES, _MASS_UNITS)
    for given, what in ((volume_column, "volume_column"), (mass_column, "mass_column"),
                        (date_column, "date_column"), (location_column, "location_column")):
        if given is not None and given not in table.columns:
            raise ValueError(f"{path}: {what} = {given!r} is not a column; columns are {columns}")
    if vcol is None and mcol is None:
        hint = (" (is the header on another row or sheet? pass header_row=/sheet=, CLI --header-row/--sheet)"
                if path.suffix.lower() in (".xlsx", ".xlsm", ".csv", ".txt", ".tsv") else "")
        raise ValueError(f"{path}: no volume or mass column found among {columns}; name one 'volume_m3' or "
                         f"'mass_kg', or pass volume_column=/mass_column={hint}")
    if table.empty:
        raise ValueError(f"{path}: the inventory has no rows")
    dcol = date_column or _find_column(columns, _DATE_NAMES)[0]
    lcol = location_column or _find_column(columns, _LOCATION_NAMES)[0]
    ncol = _find_column(columns, _NOTES_NAMES)[0]
    return vcol, vunit, mcol, munit, dcol, lcol, ncol


def _inventory_density(density_kg_m3, sidecar: dict, side_path) -> tuple[float, bool]:
    """The rock density converting volumes and masses: the argument, else the sidecar's, else the default.

    Parameters
    ----------
    density_kg_m3 : float or None
        Density given as an argument [kg/m³].
    sidecar : dict
        The sidecar's ``[record]`` table.
    side_path : Path or None
        The sidecar file (named in errors).

    Returns
    -------
    density : float
        Density [kg/m³].
    density_is_default : bool
        True when neither the argument nor the sidecar gave it.
    """
    density_from_argument = density_kg_m3 is not None
    if density_kg_m3 is None and "density_kg_m3" in sidecar:
        density_kg_m3 = sidecar["density_kg_m3"]
    density_is_default = density_kg_m3 is None
    density = DEFAULT_DENSITY_KG_M3 if density_is_default else check_density(
        density_kg_m3, "density_kg_m3" if density_from_argument else f"{side_path}: [record] density_kg_m3")
    return density, density_is_default


def _inventory_sizes(path: Path, table: pd.DataFrame, rows: np.ndarray, vcol, vunit, mcol, munit, volume_unit,
                     mass_unit, decimal, density: float) -> tuple:
    """Parse the size columns into volumes [m³] and masses [kg], each completing the other through the density.

    Parameters
    ----------
    path : Path
        The inventory file (named in errors).
    table : pandas.DataFrame
        The inventory's rows.
    rows : numpy.ndarray
        The file row of each table row (named in errors).
    vcol, vunit, mcol, munit : str or None
        Volume and mass columns and the units their names state (:func:`_inventory_columns`).
    volume_unit, mass_unit : str or None
        Units declared by the user or the sidecar; they win over the names' units.
    decimal : {".", ","} or None
        Decimal mark.
    density : float
        Rock density [kg/m³].

    Returns
    -------
    tuple
        ``(volume, mass, size_column, censoring, size_raw)``: volumes [m³] and masses [kg] as Series, the
        column the sizes were given in (``"volume"`` or ``"mass"``), the censoring of each size and its text.
    """
    if vcol is not None:
        unit = volume_unit or vunit or "m3"
        if unit not in _VOLUME_UNITS:
            raise ValueError(f"volume_unit = {volume_unit!r} is not one of {sorted(_VOLUME_UNITS)}")
        vtext, vcens = _split_censored(table[vcol])
        volume = _parse_sizes(vtext, path, vcol, rows, decimal) * _VOLUME_UNITS[unit]
    if mcol is not None:
        unit = mass_unit or munit or "kg"
        if unit not in _MASS_UNITS:
            raise ValueError(f"mass_unit = {mass_unit!r} is not one of {sorted(_MASS_UNITS)}")
        mtext, mcens = _split_censored(table[mcol])
        mass = _parse_sizes(mtext, path, mcol, rows, decimal) * _MASS_UNITS[unit]
    if vcol is None:
        volume = mass / density
        size_column, censoring, size_raw = "mass", mcens, table[mcol]
    elif mcol is None:
        mass = volume * density
        size_column, censoring, size_raw = "volume", vcens, table[vcol]
    else:
        size_column = "mass"
        volume = volume.fillna(mass / density)
        mass = mass.fillna(volume * density)
        use_mass = mcens != "unknown"
        censoring = mcens.where(use_mass, vcens)
        size_raw = table[mcol].where(use_mass, table[vcol])
    return volume, mass, size_column, censoring, size_raw


def _inventory_events(path: Path, table: pd.DataFrame, rows: np.ndarray, volume, mass, censoring, size_raw,
                      dcol, lcol, ncol, date_format, note) -> pd.DataFrame:
    """The table of events: dates, sizes, location, notes, file row and censoring; notes rows without a size.

    Parameters
    ----------
    path : Path
        The inventory file (named in errors and notes).
    table : pandas.DataFrame
        The inventory's rows.
    rows : numpy.ndarray
        The file row of each table row.
    volume, mass : pandas.Series
        Volumes [m³] and masses [kg] (:func:`_inventory_sizes`).
    censoring, size_raw : pandas.Series
        Censoring of each size and the size as written.
    dcol, lcol, ncol : str or None
        Date, location and notes columns.
    date_format : str or None
        ``strftime`` pattern of the dates.
    note : callable
        Records and warns one note of the reading.

    Returns
    -------
    pandas.DataFrame
        One row per table row, censored and unsized ones included.
    """
    if dcol is not None:
        dates, years = parse_dates(table[dcol].astype(str), path, dcol, rows, date_format=date_format)
    else:
        dates = pd.Series(pd.NaT, index=table.index, dtype="datetime64[ns]")
        years = pd.Series(pd.NA, index=table.index, dtype="Int64")
    events = pd.DataFrame({
        "date": dates, "year": years, "volume_m3": volume.astype(float), "mass_kg": mass.astype(float),
        "location": table[lcol].astype(str) if lcol else "",
        "notes": table[ncol].astype(str) if ncol else "",
        "source_row": rows,
        "censoring": censoring.to_numpy(dtype=object),
        "size_text": size_raw.astype(str).str.strip().to_numpy(dtype=object),
    })
    missing = events["mass_kg"].isna()
    if missing.any():
        lines = events.loc[missing, "source_row"].tolist()
        note(f"{path}: {len(lines)} row(s) have no size and are left out of the size fits (rows "
             f"{', '.join(map(str, lines[:12]))}{' ...' if len(lines) > 12 else ''}); they are kept in "
             "Inventory.censored and counted by rate models")
    return events


def _inventory_period(path: Path, events: pd.DataFrame, sidecar: dict, side_path, start, end, duration_years,
                   note) -> tuple:
    """The record period: from the arguments, else the sidecar, else inferred from the dates with a note.

    Parameters
    ----------
    path : Path
        The inventory file (named in errors and notes).
    events : pandas.DataFrame
        The events (:func:`_inventory_events`).
    sidecar : dict
        The sidecar's ``[record]`` table.
    side_path : Path or None
        The sidecar file.
    start, end : date or str or None
        Record period given as arguments (inclusive).
    duration_years : float or None
        Record length given as an argument [yr].
    note : callable
        Records and warns one note of the reading.

    Returns
    -------
    tuple
        ``(start, end, duration_years, period_source)``: the period's first and last days (None when only a
        length is known), its length [yr] (computed from ``start`` and ``end`` when they are known) and where
        it came from.
    """
    if start is not None or end is not None:
        if start is None or end is None:
            raise ValueError(f"start = {start!r}, end = {end!r}: give both start and end of the record period, "
                             "or duration_years")
        start, end = _as_date(start, "start"), _as_date(end, "end")
        period_source = "argument"
    elif duration_years is not None:
        period_source = "argument"
    elif "start" in sidecar or "end" in sidecar or "duration_years" in sidecar:
        if "duration_years" in sidecar:
            duration_years = sidecar["duration_years"]
        else:
            if "start" not in sidecar or "end" not in sidecar:
                raise ValueError(f"{side_path}: [record] needs both start and end, or duration_years")
            start = _as_date(sidecar["start"], f"{side_path}: start")
            end = _as_date(sidecar["end"], f"{side_path}: end")
        period_source = str(side_path)
    else:
        if events["year"].isna().all():
            raise ValueError(f"{path}: the record period is unknown: the events are undated, so pass "
                             f"duration_years= or start=/end=, or write {path.with_suffix('.toml')} "
                             "with [record] duration_years = ...")
        first, last = events["date"].min(), events["date"].max()
        if pd.isna(first):
            start = _dt.date(int(events["year"].min()), 1, 1)
            end = _dt.date(int(events["year"].max()), 12, 31)
        else:
            start, end = first.date(), last.date()
        period_source = "inferred from the dates"
        note(f"{path}: record period not given; inferred {start} to {end} from the dates. "
             "Give start/end (or a sidecar .toml) if the record was longer")
    if start is not None:
        if end < start:
            raise ValueError(f"record period ends ({end}) before it starts ({start})")
        duration_years = ((end - start).days + 1) / 365.25
    return start, end, duration_years, period_source


def _drop_outside_period(path: Path, events: pd.DataFrame, start: _dt.date, end: _dt.date,
                         note) -> pd.DataFrame:
    """Leave out, with a note naming their rows, the events dated outside the record period.

    Parameters
    ----------
    path : Path
        The inventory file (named in the note).
    events : pandas.DataFrame
        The events.
    start, end : datetime.date
        The record period (inclusive).
    note : callable
        Records and warns one note of the reading.

    Returns
    -------
    pandas.DataFrame
        The events inside the period or undated.
    """
    outside = events["date"].notna() & ((events["date"] < pd.Timestamp(start)) |
                                        (events["date"] > pd.Timestamp(end)))
    outside |= events["date"].isna() & events["year"].notna() & (
        (events["year"] < start.year) | (events["year"] > end.year))
    if outside.any():
        lines = events.loc[outside, "source_row"].tolist()
        note(f"{path}: {len(lines)} event(s) dated outside the record period {start} to {end} are left "
             f"out (rows {', '.join(map(str, lines[:12]))}{' ...' if len(lines) > 12 else ''})")
        events = events.loc[~outside]
    return events


def _split_censored_events(path: Path, events: pd.DataFrame, note) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Set the censored and unsized events apart from the exact ones, with a note on the bounded ones.

    Parameters
    ----------
    path : Path
        The inventory file (named in the note and error).
    events : pandas.DataFrame
        The events inside the record period.
    note : callable
        Records and warns one note of the reading.

    Returns
    -------
    events : pandas.DataFrame
        The events with an exact size, columns :data:`_EVENT_COLUMNS`, indexed from 0.
    censored : pandas.DataFrame
        The censored and unsized events, indexed from 0.

    Raises
    ------
    ValueError
        When no event has an exact size.
    """
    is_cens = events["censoring"] != ""
    censored = events.loc[is_cens].reset_index(drop=True)
    bounded = censored[censored["censoring"] != "unknown"]
    if not bounded.empty:
        kinds = bounded["censoring"].value_counts()
        lines = bounded["source_row"].tolist()
        note(f"{path}: {len(bounded)} censored size(s) kept as censored, not used by the size fits (power law, "
             f"annual maxima) but counted by rate models: "
             + ", ".join(f"{int(kinds[k])} {k}" for k in ("below", "above", "approximate") if k in kinds)
             + f" (rows {', '.join(map(str, lines[:12]))}{' ...' if len(lines) > 12 else ''})")
    events = events.loc[~is_cens, _EVENT_COLUMNS]
    if events.empty:
        raise ValueError(f"{path}: no usable events (every row lacked an exact size or lay outside the record "
                         "period)")
    return events.reset_index(drop=True), censored


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


def _check_duplicates(events, table, path, policy, note):
    """Dated rows repeating an earlier row exactly: counted; kept, dropped or refused by ``policy``."""
    dated = events["date"].notna()
    if policy == "keep" or not dated.any():
        return events
    dup = table.loc[events.index].duplicated(keep="first") & dated
    k = int(dup.sum())
    if k == 0:
        return events
    lines = events.loc[dup, "source_row"].tolist()
    what = (f"{path}: {k} of {int(dated.sum())} rows repeat an earlier row exactly (duplicate "
            f"{'row' if k == 1 else 'rows'} {_line_list(lines)})")
    if policy == "drop":
        note(f"{what}; the {k} duplicate rows are dropped as asked (duplicates='drop')")
        return events.loc[~dup]
    copied = table.loc[events.index].duplicated(keep=False)
    if policy == "error" or bool(copied[dated].all()):
        raise ValueError(f"{what}: a file appended twice doubles the rate of falls.  Pass duplicates='drop' "
                         "(CLI --duplicates drop) to remove them, or duplicates='keep' if they are distinct falls")
    note(f"{what}; they are kept as distinct falls (pass duplicates='drop' to remove them)")
    return events


#: Above these, sizes given "in m3" are probably litres or cm3 (or grams given as kg).
PLAUSIBLE_MEDIAN_M3 = 100.0
#: A median above this (and up to PLAUSIBLE_MEDIAN_M3) is possible for m3 but also what litres give: a warning.
SUSPECT_MEDIAN_M3 = 10.0
PLAUSIBLE_LARGE_M3 = 1e5
PLAUSIBLE_LARGE_PER_YEAR = 0.1


#: No single fall may exceed this volume [m³]: the largest known rock avalanches are Seymareh (Saidmarreh),
#: Iran, about 4.4e10 m³ (Roberts & Evans 2013, Journal of the Geological Society 170, 685-700) and Flims,
#: Switzerland, about 1e10 m³ (von Poschinger et al. 2006, Geomorphology 74, 17-31).  A larger value is a unit
#: or typing mistake, whatever unit is declared.
LARGEST_FALL_M3 = 1e11
#: A median volume below this [m³] (1 litre, a 2.7 kg stone) is implausibly small for a rock fall inventory.
SMALLEST_MEDIAN_M3 = 1e-3


def _check_plausible_sizes(events, path, col, is_volume, declared_unit, duration_years, note):
    """Refuse sizes that look like a unit mistake unless the unit was declared (see :func:`read_inventory`);
    refuse any single fall larger than every rock avalanche recorded (:data:`LARGEST_FALL_M3`), declared unit or
    not; warn about sizes implausibly small for the stated unit."""
    v = events["volume_m3"].to_numpy(dtype=float)
    huge = v > LARGEST_FALL_M3
    if huge.any():
        i = int(np.argmax(huge))
        row = int(events["source_row"].iloc[i])
        raise ValueError(f"{path}: row {row}, column {col!r}: a fall of "
                         f"{v[i]:.3g} m3, larger than any rock fall or rock avalanche ever recorded (Seymareh, Iran, "
                         f"about 4.4e10 m3; Flims, Switzerland, about 1e10 m3); check the value and its unit")
    if is_volume and float(np.median(v)) < SMALLEST_MEDIAN_M3:
        note(f"{path}: column {col!r}: median volume {float(np.median(v)):.3g} m3 is below one litre, implausibly "
             f"small for a rock fall inventory; if the column holds m3 but a smaller unit was declared, fix "
             "volume_unit (CLI --volume-unit, sidecar volume_unit)")
    med = float(np.median(v))
    large = int((v >= PLAUSIBLE_LARGE_M3).sum())
    rate = large / duration_years
    if is_volume:
        if declared_unit is not None:
            return
        if med > PLAUSIBLE_MEDIAN_M3 or rate > PLAUSIBLE_LARGE_PER_YEAR:
            raise ValueError(
                f"{path}: column {col!r}: median {med:.3g} m3 and {large} fall(s) of 10^5 m3 or more "
                f"({rate:.2g} a year) look like litres or cm3 entered as m3 (a rock fall inventory's median is "
                "usually below 10 m3, and a 10^5 m3 fall is a rock avalanche).  Declare the unit: "
                "volume_unit='l', 'cm3' or, if the volumes are right, 'm3' (CLI --volume-unit, sidecar "
                "volume_unit)")
        if med > SUSPECT_MEDIAN_M3:
            note(f"{path}: column {col!r}: median volume {med:.3g} m3 is unusually large for a rock fall inventory "
                 f"(usually below {SUSPECT_MEDIAN_M3:g} m3) and is what litres entered as m3 would give (largest "
                 f"{v.max():.4g} m3).  If the volumes are in litres or cm3, declare volume_unit='l' or 'cm3'; if "
                 "they are right, declare volume_unit='m3' to silence this (CLI --volume-unit, sidecar volume_unit)")
        return
    m = events["mass_kg"].to_numpy(dtype=float)
    if declared_unit is None and (med > PLAUSIBLE_MEDIAN_M3 or rate > PLAUSIBLE_LARGE_PER_YEAR):
        raise ValueError(
            f"{path}: column {col!r}: median mass {np.median(m):.3g} kg ({med:.3g} m3) looks like grams entered "
            "as kg.  Declare the unit: mass_unit='kg' if the masses are right (CLI --mass-unit, sidecar mass_unit)")
    if np.median(m) < 1.0:
        note(f"{path}: column {col!r}: median mass {np.median(m):.3g} kg is below 1 kg, implausibly small for a "
             "rock fall inventory; if the masses are in tonnes, declare mass_unit='t' (CLI --mass-unit, sidecar "
             "mass_unit)")
