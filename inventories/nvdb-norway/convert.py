"""Convert the NVDB "Skred" GML extract into a riskrf rock fall inventory CSV.

Reads the unmodified ``../shared/inventories-raw/nvdb-skred-norway/Skred.gml``
(see PROVENANCE.md there) with the standard library's ElementTree, keeps the
features with ``typeSkred = "Stein"`` (rock fall) and writes
``nvdb_rockfalls_2015.csv`` and its record-period sidecar beside this script.

Run from the repository root: ``python inventories/nvdb-norway/convert.py``.
"""
from __future__ import annotations

import csv
import xml.etree.ElementTree as ET
from pathlib import Path

HERE = Path(__file__).resolve().parent
RAW = HERE.parents[2] / "shared" / "inventories-raw" / "nvdb-skred-norway" / "Skred.gml"
NVDB = "{https://raw.githubusercontent.com/jetgeo/NVDBGML/master/XSD/}"
GML = "{http://www.opengis.net/gml/3.2}"

#: Start and end of the record period written to the sidecar.  258 of the 267
#: rock falls fall between September 2014 and the extraction in May 2015
#: (PROVENANCE.md); events outside it are kept in the CSV with a note and are
#: excluded by riskrf.read_inventory with a warning.
RECORD_START = "2014-09-01"
RECORD_END = "2015-05-18"

COLUMNS = ["date", "time", "volume_m3", "volume_on_road_class", "location", "road_reference",
           "release_area", "easting_m", "northing_m", "nvdb_id", "notes"]


def _text(feature, tag: str) -> str:
    node = feature.find(f".//{NVDB}{tag}")
    return "" if node is None or node.text is None else node.text.strip()


def rock_falls():
    """Yield one dict per rock fall feature, in file order."""
    for feature in ET.parse(RAW).getroot().iter(f"{NVDB}Skred"):
        if _text(feature, "typeSkred") != "Stein":
            continue
        date = _text(feature, "skredDato")
        clock = _text(feature, "skredKlokkeslett")
        pos = feature.find(f"{NVDB}posisjon/{GML}Point/{GML}pos")
        east, north = (pos.text.split() if pos is not None else ("", ""))
        road = "".join(_text(feature, t) for t in ("vegkategori", "vegstatus"))
        road += f"{_text(feature, 'vegnummer')} hp{_text(feature, 'hovedParsell')} " \
                f"m{_text(feature, 'veglenkeMeterFra')}-{_text(feature, 'veglenkeMeterTil')}"
        notes = []
        if date and not (RECORD_START <= date <= RECORD_END):
            notes.append("date outside the 2014-09..2015-05 registration period")
        if not _text(feature, "volumAvTotaleSkredmasser"):
            notes.append("total volume not registered")
        yield {
            "date": date,
            "time": f"{clock[:2]}:{clock[2:]}" if len(clock) == 4 else "",
            "volume_m3": _text(feature, "volumAvTotaleSkredmasser"),
            "volume_on_road_class": _text(feature, "volumAvSkredmasserPåVeg"),
            "location": _text(feature, "stedsangivelse"),
            "road_reference": road,
            "release_area": _text(feature, "løsneområde"),
            "easting_m": east,
            "northing_m": north,
            "nvdb_id": _text(feature, "lokalId"),
            "notes": "; ".join(notes),
        }


if __name__ == "__main__":
    rows = sorted(rock_falls(), key=lambda r: (r["date"] or "9999", r["time"]))
    with open(HERE / "nvdb_rockfalls_2015.csv", "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    (HERE / "nvdb_rockfalls_2015.toml").write_text(
        "# Record period of nvdb_rockfalls_2015.csv; read by riskrf.read_inventory.\n"
        "[record]\n"
        f'start = "{RECORD_START}"\n'
        f'end = "{RECORD_END}"\n'
        'site = "Norwegian public roads (NVDB object type 445, Statens vegvesen)"\n'
    )
    print(f"nvdb_rockfalls_2015.csv: {len(rows)} rock falls, "
          f"{sum(bool(r['volume_m3']) for r in rows)} with a volume")
