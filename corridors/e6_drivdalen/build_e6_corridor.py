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
* ``e6_centreline.gpkg``: the road centreline of main section 1 (EPSG:25833, ETRS89 / UTM 33N) from the register's
  own geometry: every feature of the extract on E6 main section 1 (any slide type) carries a ``senterlinje``
  LineString "generated from linear references to the NVDB road network" between its ``veglenkeMeterFra`` and
  ``veglenkeMeterTil``.  Its vertices, with their metre values (interpolated along the feature's line between the
  two), are the centreline's vertices in metre order (layer ``centreline``) and its calibration points (layer
  ``nvdb_metres``, field ``chainage_m``), so a chainage is the NVDB metre exactly at those points and linear in
  the distance along the drawn line between them.  Between far-apart points (e.g. metres 1,245-9,394) the drawn
  line is a straight chord of the real, winding road: positions there are interpolated, not surveyed.  Before the
  first point (metre 52) the line is extended back to metre 0 along its first segment, and it ends at metre
  19,000 on the chord towards the next point (metre 29,820): both ASSUMPTIONS, stated in PROVENANCE.md.
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
CRS = "EPSG:25833"           # the extract's srsName (ETRS89 / UTM zone 33N)


def road_points(gml: Path, main_section: str = MAIN_SECTION) -> pd.DataFrame:
    """(metre, x, y) of every vertex of the register's road geometry on E6 ``main_section``, in metre order.

    Each feature's ``senterlinje`` runs from ``veglenkeMeterFra`` to ``veglenkeMeterTil``; its vertices get metre
    values linear in the distance along it.  Repeated metres and repeated positions keep their first occurrence."""
    import numpy as np
    rows = []
    for el in ET.parse(gml).getroot().iter():
        if not el.tag.endswith("}Skred"):
            continue
        d, pos = {}, None
        for c in el.iter():
            if c.tag.endswith("}posList"):
                pos = c.text
            elif c.text and c.text.strip() and len(list(c)) == 0:
                d.setdefault(c.tag.split("}")[1], c.text.strip())
        if d.get("vegnummer") != "6" or d.get("hovedParsell") != main_section or not pos:
            continue
        xy = np.array(pos.split(), dtype=float).reshape(-1, 2)
        m0, m1 = float(d["veglenkeMeterFra"]), float(d.get("veglenkeMeterTil", d["veglenkeMeterFra"]))
        s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(xy, axis=0).T))]
        m = m0 + (m1 - m0) * (s / s[-1] if s[-1] > 0 else 0.0)
        rows += [(float(a), float(x), float(y)) for a, (x, y) in zip(m, xy)]
    pts = pd.DataFrame(rows, columns=["metre", "x", "y"]).sort_values(["metre", "x", "y"], kind="stable")
    pts = pts.drop_duplicates("metre").drop_duplicates(["x", "y"]).reset_index(drop=True)
    return pts


def write_centreline(gml: Path, path: Path, end_m: float = END_M) -> None:
    """``e6_centreline.gpkg``: the register's road points of main section 1 as a calibrated centreline from metre 0
    (extended back along the first segment) to ``end_m`` (on the chord towards the next point)."""
    import numpy as np

    from riskrf.io.gis import centreline_from_vertices, write_centreline as write_line
    pts = road_points(gml)
    first, second = pts.iloc[0], pts.iloc[1]
    u = np.array([second.x - first.x, second.y - first.y])
    u /= np.hypot(*u)
    start = np.array([first.x, first.y]) - u * first.metre          # metre 0: back along the first segment
    after = pts[pts["metre"] > end_m].iloc[0]
    before = pts[pts["metre"] <= end_m].iloc[-1]
    f = (end_m - before.metre) / (after.metre - before.metre)
    end = np.array([before.x + f * (after.x - before.x), before.y + f * (after.y - before.y)])
    inner = pts[pts["metre"] <= end_m]
    xy = np.vstack([start, inner[["x", "y"]].to_numpy(), end])
    metres = np.r_[0.0, inner["metre"].to_numpy(), end_m]
    cal = np.column_stack([metres, xy])
    line = centreline_from_vertices(xy, crs=CRS, calibration=cal, source=path.name)
    if path.exists():
        path.unlink()
    write_line(line, path, layer="centreline", calibration_layer="nvdb_metres", calibration_chainage_m=metres)


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
    write_centreline(gml, HERE / "e6_centreline.gpkg")
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
    print(f"e6_centreline.gpkg: {len(road_points(gml))} register road points on main section {MAIN_SECTION}")
    print(f"{len(falls)} rock falls ({len(vols)} with a volume); {len(sec)} sections on main section {MAIN_SECTION}, "
          f"{int(sec['recorded_falls'].sum())} falls in them")
    return 0


if __name__ == "__main__":
    sys.exit(main())
