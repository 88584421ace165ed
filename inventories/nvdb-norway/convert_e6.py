"""Convert the NVDB E6 Trøndelag GML extract (2000-2014) into a riskrf rock fall inventory CSV.

Reads the unmodified ``Skred_E6_Trondelag_2000_2014.gml`` from
``<raw>`` (default ``../shared/inventories-raw/nvdb-skred-norway`` beside the repository;
see PROVENANCE.md there) with the standard library's ElementTree, keeps the features with
``typeSkred = "Stein"`` (rock fall; 77 on road E6, Oppdal / Drivdalen) and writes
``nvdb_e6_rockfalls_2000_2014.csv`` and its record-period sidecar beside this script.

Road reference and chainage are kept: ``road_reference`` (e.g. ``EV6 hp1``), and
``chainage_from_m`` / ``chainage_to_m`` (metre position along the main section, NVDB
``veglenkeMeterFra/Til``).  The position is the first point of the road centre line the
NVDB generated from the linear reference (EPSG:25833).

Run from the repository root: ``python inventories/nvdb-norway/convert_e6.py [--raw DIR]``.
"""
from __future__ import annotations

import argparse
import csv
import xml.etree.ElementTree as ET
from pathlib import Path

HERE = Path(__file__).resolve().parent
RAW = HERE.parents[2] / "shared" / "inventories-raw" / "nvdb-skred-norway"
NAME = "Skred_E6_Trondelag_2000_2014.gml"
NVDB = "{https://github.com/jetgeo/NVDBGML/blob/master/XSD/}"
GML = "{http://www.opengis.net/gml/3.2}"
RECORD_START, RECORD_END = "2000-01-01", "2014-12-31"

COLUMNS = ["date", "time", "volume_m3", "volume_on_road_class", "location", "road_reference",
           "chainage_from_m", "chainage_to_m", "release_area", "closure", "easting_m", "northing_m",
           "nvdb_id", "notes"]


def _text(feature, tag: str) -> str:
    node = feature.find(f".//{NVDB}{tag}")
    return "" if node is None or node.text is None else node.text.strip()


def rock_falls(path: Path):
    """Yield one dict per rock fall feature, in file order."""
    for feature in ET.parse(path).getroot().iter(f"{NVDB}Skred"):
        if _text(feature, "typeSkred") != "Stein":
            continue
        clock = _text(feature, "skredKlokkeslett")
        pos = feature.find(f".//{GML}posList")
        east, north = (pos.text.split()[:2] if pos is not None else ("", ""))
        road = "".join(_text(feature, t) for t in ("vegkategori", "vegstatus")) + _text(feature, "vegnummer")
        road += f" hp{_text(feature, 'hovedParsell')}"
        notes = []
        if not _text(feature, "volumAvTotaleSkredmasser"):
            notes.append("total volume not registered")
        if not _text(feature, "skredDato"):
            notes.append("no date")
        yield {
            "date": _text(feature, "skredDato"),
            "time": f"{clock[:2]}:{clock[2:]}" if len(clock) == 4 else "",
            "volume_m3": _text(feature, "volumAvTotaleSkredmasser"),
            "volume_on_road_class": _text(feature, "volumAvSkredmasserPåVeg"),
            "location": _text(feature, "stedsangivelse"),
            "road_reference": road,
            "chainage_from_m": _text(feature, "veglenkeMeterFra"),
            "chainage_to_m": _text(feature, "veglenkeMeterTil"),
            "release_area": _text(feature, "løsneområde"),
            "closure": _text(feature, "stengning"),
            "easting_m": east,
            "northing_m": north,
            "nvdb_id": _text(feature, "lokalId"),
            "notes": "; ".join(notes),
        }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--raw", type=Path, default=RAW, help=f"folder of the raw GML (default {RAW})")
    args = parser.parse_args(argv)
    rows = sorted(rock_falls(args.raw / NAME), key=lambda r: (r["date"] or "9999", r["time"], r["nvdb_id"]))
    with open(HERE / "nvdb_e6_rockfalls_2000_2014.csv", "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, COLUMNS, lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
    (HERE / "nvdb_e6_rockfalls_2000_2014.toml").write_text(
        "# Record period of nvdb_e6_rockfalls_2000_2014.csv; read by riskrf.read_inventory.\n"
        "[record]\n"
        f'start = "{RECORD_START}"\n'
        f'end = "{RECORD_END}"\n'
        'site = "Road E6 in Trøndelag, Norway (NVDB object type 445, Statens vegvesen)"\n',
        encoding="utf-8")
    years = {}
    for r in rows:
        years[r["date"][:4]] = years.get(r["date"][:4], 0) + 1
    print(f"nvdb_e6_rockfalls_2000_2014.csv: {len(rows)} rock falls, "
          f"{sum(bool(r['volume_m3']) for r in rows)} with a volume; per year {dict(sorted(years.items()))}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
