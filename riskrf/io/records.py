"""Readers for agency incident registers, turning them into riskrf inventory tables.

:func:`read_cedd_incidents` reads the Hong Kong slope incident register of the
Civil Engineering and Development Department, Geotechnical Engineering Office
(CEDD/GEO; DATA.GOV.HK dataset ``hk-cedd-csu-cedd-incident``) as published in
CSV, and returns the incidents on one kind of feature (by default man-made
rock cuts) in riskrf's inventory format (``date``, ``volume_m3``, ``location``
... ; see :func:`riskrf.read_inventory`).  Nothing is repaired silently: rows
with bytes that are not valid UTF-8 are decoded with U+FFFD and listed, sizes
written as bounds or estimates (``<1``, ``~15``) stay censored, text sizes
(``Minor``, ``-``) become "no size" with a note, and the failure date is used
where given, else the date of the call, with a flag saying which.

Source and terms: Civil Engineering and Development Department (GEO), Hong
Kong SAR Government, via DATA.GOV.HK, Terms and Conditions of Use (free reuse
with acknowledgement, data reproduced accurately).  The SCALE field is read as
the failure volume in m³; the data dictionary that would confirm the unit was
not available, so this is an assumption stated wherever the data are used.
"""
from __future__ import annotations

import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

#: Columns of the CEDD register that the reader needs (file header spelling).
CEDD_REQUIRED = ("INCID", "CALLDATE", "FAILDATE", "EASTING", "NORTHING", "LOCATION", "SLOPENUM", "FEATTYPE",
                 "SCALE", "FACAFF", "CONSEC", "CONSEC - ROADCLOSED")

#: Columns of the inventory table written by :func:`read_cedd_incidents`.
CEDD_COLUMNS = ["date", "date_source", "volume_m3", "scale_as_recorded", "location", "easting_m", "northing_m",
                "incident_id", "slope_number", "call_date", "fail_date", "facility_affected", "consequence",
                "lanes_closed", "notes"]

_NUMBER = re.compile(r"^\d+(\.\d+)?$")
_CENSORED = re.compile(r"^(<|~)\s*(\d+(\.\d+)?)$")
_DATE = re.compile(r"^\d{2}/\d{2}/\d{4}$")


@dataclass(frozen=True)
class RegisterExtract:
    """Incidents taken from an agency register, in riskrf's inventory format.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per incident, columns :data:`CEDD_COLUMNS`; ``volume_m3`` holds
        the size as text: a number [m³], a censored size (``<1``, ``~15``) or
        empty when the register gives none.
    source : str
        The register file.
    n_rows : int
        Incidents of every kind in the file.
    bad_byte_rows : tuple of str
        ``"INCID (feature type)"`` of the rows holding bytes that are not valid
        UTF-8 (decoded as U+FFFD), whether or not they were selected.
    notes : tuple of str
        What was converted and flagged, for reports.
    """

    table: pd.DataFrame
    source: str
    n_rows: int
    bad_byte_rows: tuple = ()
    notes: tuple = field(default_factory=tuple)

    def summary(self) -> pd.DataFrame:
        """Key figures of the extract (one-column table): source, incidents in the file, selected, with a numeric,
        censored or no size, dated by FAILDATE or CALLDATE, and rows with invalid UTF-8.

        Returns
        -------
        pandas.DataFrame
            Index: quantity; column ``value``.
        """
        t = self.table
        sized = t["volume_m3"].str.fullmatch(r"\d+(\.\d+)?")
        rows = {
            "source": self.source,
            "incidents in file": self.n_rows,
            "selected": len(t),
            "numeric size": int(sized.sum()),
            "censored size (<, ~)": int(t["volume_m3"].str.match(r"[<~]").sum()),
            "no size": int((t["volume_m3"] == "").sum()),
            "dated by FAILDATE": int((t["date_source"] == "FAILDATE").sum()),
            "dated by CALLDATE": int((t["date_source"] == "CALLDATE").sum()),
            "rows with invalid UTF-8 (whole file)": len(self.bad_byte_rows),
        }
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})


def _iso(text: str, path, incid: str, column: str) -> str:
    text = text.strip()
    if text in ("", "-"):
        return ""
    if not _DATE.match(text):
        raise ValueError(f"{path}: incident {incid!r}, column {column!r}: {text!r} is not a date dd/mm/yyyy")
    day, month, year = text.split("/")
    try:
        return pd.Timestamp(int(year), int(month), int(day)).date().isoformat()
    except ValueError as exc:
        raise ValueError(f"{path}: incident {incid!r}, column {column!r}: {text!r} is not a valid date") from exc


def read_cedd_incidents(path, *, feature_type: str = "rock cut") -> RegisterExtract:
    """Read the CEDD/GEO slope incident register (CSV) and keep one feature type.

    Parameters
    ----------
    path : str or Path
        The register as published (``1984 - 2020 landslide data for public ...csv``):
        columns INCID, CALLDATE and FAILDATE (dd/mm/yyyy, ``-`` when unknown),
        EASTING/NORTHING (Hong Kong 1980 Grid, m), LOCATION, SLOPENUM,
        FEATTYPE, SCALE (failure volume, read as m³), FACAFF, CONSEC, ...
    feature_type : str
        FEATTYPE to keep, compared case-insensitively after trimming (the file
        spells it both "Rock Cut" and "Rock cut").  Default ``"rock cut"``.

    Returns
    -------
    RegisterExtract

    Raises
    ------
    ValueError
        A required column is missing, or a date is malformed (naming the
        incident, the column and the value).
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"register file not found: {path}")
    raw = path.read_bytes()
    text = raw.decode("utf-8-sig", errors="replace")
    table = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False)
    missing = [c for c in CEDD_REQUIRED if c not in table.columns]
    if missing:
        raise ValueError(f"{path}: column(s) {missing} missing; found {list(table.columns)[:20]}")
    table = table.apply(lambda c: c.astype(str).str.strip())
    bad = table.apply(lambda c: c.str.contains("\ufffd", regex=False)).any(axis=1)
    bad_rows = tuple(f"{r.INCID} ({r.FEATTYPE})" for r in table.loc[bad].itertuples())
    notes = []
    if bad_rows:
        notes.append(f"{path}: {len(bad_rows)} row(s) hold bytes that are not valid UTF-8, kept as U+FFFD: "
                     + ", ".join(bad_rows))
    keep = table["FEATTYPE"].str.lower() == feature_type.strip().lower()
    sel = table.loc[keep]
    out = []
    counts = {"CALLDATE": 0, "no date": 0, "text size": 0, "call before failure": 0}
    for r in sel.to_dict(orient="records"):
        incid = r["INCID"]
        call = _iso(r["CALLDATE"], path, incid, "CALLDATE")
        fail = _iso(r["FAILDATE"], path, incid, "FAILDATE")
        flags = []
        if fail:
            date, source = fail, "FAILDATE"
            if call and call < fail:
                flags.append("CALLDATE before FAILDATE")
                counts["call before failure"] += 1
        elif call:
            date, source = call, "CALLDATE"
            flags.append("failure date not given: date of the call")
            counts["CALLDATE"] += 1
        else:
            date, source = "", ""
            flags.append("no date")
            counts["no date"] += 1
        scale = r["SCALE"]
        if _NUMBER.match(scale):
            volume = scale
        elif (m := _CENSORED.match(scale)):
            volume = f"{m.group(1)}{m.group(2)}"
            flags.append(f"SCALE {scale!r} censored")
        else:
            volume = ""
            flags.append(f"SCALE {scale!r}: no numeric size")
            counts["text size"] += 1
        if "\ufffd" in "".join(r.values()):
            flags.append("invalid UTF-8 bytes in the source row (shown as U+FFFD)")
        lanes = r["CONSEC - ROADCLOSED"]
        out.append({
            "date": date, "date_source": source, "volume_m3": volume, "scale_as_recorded": scale,
            "location": r["LOCATION"], "easting_m": r["EASTING"], "northing_m": r["NORTHING"],
            "incident_id": incid, "slope_number": "" if r["SLOPENUM"] == "-" else r["SLOPENUM"],
            "call_date": call, "fail_date": fail, "facility_affected": r["FACAFF"],
            "consequence": "" if r["CONSEC"] == "-" else r["CONSEC"],
            "lanes_closed": "" if lanes == "-" else lanes, "notes": "; ".join(flags),
        })
    frame = pd.DataFrame(out, columns=CEDD_COLUMNS)
    frame = frame.sort_values(["date", "incident_id"], kind="stable").reset_index(drop=True)
    notes.append(f"{path}: {len(frame)} of {len(table)} incidents have FEATTYPE {feature_type!r}; "
                 f"{counts['CALLDATE']} dated by the call (no FAILDATE), {counts['no date']} without any date, "
                 f"{counts['call before failure']} with the call before the failure date, "
                 f"{counts['text size']} with a text SCALE and no numeric size")
    return RegisterExtract(table=frame, source=str(path), n_rows=len(table), bad_byte_rows=bad_rows,
                           notes=tuple(notes))
