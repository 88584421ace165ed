"""Build the E6 Drivdalen example corridor from the real NVDB slide register (run from this directory).

    python build_e6_corridor.py [path/to/Skred_E6_Trondelag_2000_2014.gml]

Input: ``Skred_E6_Trondelag_2000_2014.gml`` (NVDB object type 445 "Skred", Statens vegvesen, NLOD 2.0; copied
unmodified from jetgeo/NVDBGML, blob f8012b95; see shared/inventories-raw/nvdb-skred-norway/PROVENANCE.md).
Writes:

* ``e6_rockfalls.csv``: the 77 rock falls (typeSkred = "Stein") with NVDB id, date, road reference
  (main section ``hovedParsell`` and metre), release area, height class and volume (m3; empty if not recorded);
  the 34 with a volume make the inventory of the corridor's mass law (``e6_volumes.csv`` + sidecar TOML).
* ``e6_sections.csv``: main road section (hovedParsell) 1 of the E6, metres 0-19,000, cut into 1-km sections.
  ``falls_per_year`` = (recorded falls in the section + 0.5) / 15 years (2000-2014): the recorded count plus
  one half (the Jeffreys-prior mean of a Poisson rate, so a section without a recorded fall is not rated
  at zero) -- a stated estimator choice.  Geometry (cut height from the record's height-difference class:
  "0 - 50 m" -> 25 m, "50 - 200 m" -> 60 m; face angle, ditch, road width) and the RHRS descriptive classes
  are ILLUSTRATIVE, not surveyed.
"""
from __future__ import annotations

import collections
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pandas as pd

HERE = Path(__file__).resolve().parent
DEFAULT_GML = HERE.parents[1] / ".." / "shared" / "inventories-raw" / "nvdb-skred-norway" / \
    "Skred_E6_Trondelag_2000_2014.gml"
YEARS = 15.0                 # 2000-01-01 .. 2014-12-31
MAIN_SECTION = "1"
SECTION_M = 1000.0
END_M = 19000.0
HEIGHT_CLASS_M = {"0 - 50 m": 25.0, "50 - 200 m": 60.0}     # ILLUSTRATIVE cut height per recorded class


def read_rockfalls(gml: Path) -> pd.DataFrame:
    rows = []
    for el in ET.parse(gml).getroot().iter():
        if not el.tag.endswith("}Skred"):
            continue
        d = {}
        for c in el.iter():
            if c.text and c.text.strip() and len(list(c)) == 0:
                d.setdefault(c.tag.split("}")[1], c.text.strip())
        if d.get("typeSkred") != "Stein":
            continue
        rows.append({"nvdb_id": d["lokalId"], "date": d.get("skredDato", ""), "road": "E" + d.get("vegnummer", ""),
                     "main_section": d.get("hovedParsell", ""), "metre": int(d["veglenkeMeterFra"]),
                     "release_area": d.get("løsneområde", ""), "height_class": d.get("høydeforskjellVegUtløsningssted", ""),
                     "volume_m3": d.get("volumAvTotaleSkredmasser", ""), "place": d.get("stedsangivelse", "")})
    return pd.DataFrame(rows).sort_values(["main_section", "metre", "date"]).reset_index(drop=True)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    gml = Path(argv[0]) if argv else DEFAULT_GML
    falls = read_rockfalls(gml)
    falls.to_csv(HERE / "e6_rockfalls.csv", index=False)
    vols = falls[falls["volume_m3"] != ""][["date", "volume_m3", "nvdb_id"]]
    vols.to_csv(HERE / "e6_volumes.csv", index=False)
    (HERE / "e6_volumes.toml").write_text(
        "# Real NVDB record (Statens vegvesen / NVDB, NLOD 2.0): rock falls on the E6 in Trondelag with a recorded\n"
        "# total volume (integer m3 estimates), 2000-2014.  Built by build_e6_corridor.py.\n"
        "[record]\nstart = \"2000-01-01\"\nend = \"2014-12-31\"\ndensity_kg_m3 = 2650\n"
        "site = \"E6 Oppdal / Drivdalen (NVDB object type 445), rock falls with a volume\"\n", encoding="utf-8")
    main_falls = falls[falls["main_section"] == MAIN_SECTION]
    rows = []
    start = 0.0
    k = 1
    while start < END_M:
        end = start + SECTION_M
        here = main_falls[(main_falls["metre"] >= start) & (main_falls["metre"] < end)]
        cls = collections.Counter(here["height_class"]).most_common(1)
        height = HEIGHT_CLASS_M.get(cls[0][0], 25.0) if cls else 25.0
        history = "few" if len(here) == 0 else "occasional" if len(here) <= 2 else "many"
        rows.append({"id": f"E6-1-{k:02d}", "chainage_from": start, "chainage_to": end,
                     "falls_per_year": round((len(here) + 0.5) / YEARS, 6), "recorded_falls": len(here),
                     "cut_height_m": height, "rhrs_rockfall_history": history,
                     "notes": "; ".join(sorted({p for p in here["place"] if p}))})
        start, k = end, k + 1
    sec = pd.DataFrame(rows)
    with open(HERE / "e6_sections.csv", "w", encoding="utf-8") as fh:
        fh.write("# E6 hovedParsell 1, 1-km sections.  falls_per_year: (recorded NVDB rock falls 2000-2014 + 0.5) / 15 yr"
                 " (real record; +0.5 = Jeffreys-prior mean).  cut_height_m and RHRS classes ILLUSTRATIVE.\n")
        sec.drop(columns=["recorded_falls"]).to_csv(fh, index=False)
    print(f"{len(falls)} rock falls ({len(vols)} with a volume); {len(sec)} sections on main section {MAIN_SECTION}, "
          f"{int(sec['recorded_falls'].sum())} falls in them")
    return 0


if __name__ == "__main__":
    sys.exit(main())
