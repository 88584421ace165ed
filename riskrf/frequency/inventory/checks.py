"""Checks of an inventory's events while it is read (:func:`~riskrf.frequency.inventory.reader.read_inventory`).

The record period (from the arguments, the sidecar, or inferred from the dates with a note) and the events dated
outside it; the censored and unsized events set apart from the exact ones; dated rows repeating an earlier row;
and sizes that look like a unit mistake, with the plausibility limits they are checked against
(:data:`PLAUSIBLE_MEDIAN_M3`, :data:`LARGEST_FALL_M3`, ...).
"""
from __future__ import annotations

import datetime as _dt
from pathlib import Path

import numpy as np
import pandas as pd

from .record import _EVENT_COLUMNS, _line_list


def _as_date(value, what: str) -> _dt.date:
    if isinstance(value, _dt.datetime):
        return value.date()
    if isinstance(value, _dt.date):
        return value
    try:
        return _dt.date.fromisoformat(str(value))
    except ValueError as exc:
        raise ValueError(f"{what} = {value!r} is not a date (use YYYY-MM-DD)") from exc


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
