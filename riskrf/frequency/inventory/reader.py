""":func:`read_inventory`: an inventory file and its sidecar read into an
:class:`~riskrf.frequency.inventory.record.Inventory`.

The file (CSV, Excel, Parquet; :mod:`riskrf.io.tables`) and the sidecar's ``[record]`` table (:func:`_sidecar`,
the reader options :data:`READER_OPTIONS`); the size, date, location and notes columns recognised by name and unit
(:func:`_find_column`, also used by :mod:`riskrf.hazard.design_block`); censored size cells (``<1``, ``>20``,
``~15``: :data:`CENSORING`); volumes [m³] and masses [kg] completing each other through the density; the events
table.  The checks of the events are in :mod:`riskrf.frequency.inventory.checks`.
"""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

from ...io.tables import is_blank, parse_dates, parse_numbers, read_table
from ...core.units import DEFAULT_DENSITY_KG_M3, KG_PER_TONNE
from ...core.validation import check_density, check_positive, warn
from .record import Inventory, _undated_note
from .checks import (_check_duplicates, _check_plausible_sizes, _drop_outside_period, _inventory_period,
                     _split_censored_events)


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
