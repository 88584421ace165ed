"""Build the Authume quarry scenarios and observed runouts from the raw experiment files.

    python validation/authume/build_authume.py [RAW_DIR]

RAW_DIR defaults to ``<repo>/../shared/experiments-raw/authume-quarry`` (or
``<repo>/../../shared/...`` from a git worktree) (the
files of Garcia et al. 2022 / the Data in Brief repository
richefeu/AuthumeQuarryRockfalls_Data-in-Brief, commit f695c933; see its
PROVENANCE.md).  Writes, deterministically (no randomness):

* ``simulation/scenarios/authume/authume_p1.toml`` and ``authume_p2.toml``:
  the 2-D profiles extracted every 0.5 m from the zoned STL terrain along each
  profile's path, one material per substrate zone;
* ``tests/data/authume/observed_runout.csv``: per block, the profile, the stop
  point's distance along the path (``x_stop_m``, the 2-D model's runout), its
  lateral offset, the straight plan runout, fall height and mass.

The path of each profile is a plan polyline from the release point (mean of
the four drop points) through the median stop point of the nearest, middle
and farthest third of the blocks (sorted by plan distance from the release),
extended along its last leg to 15 m beyond the farthest projected stop or to
the edge of the terrain.  It follows the corridor (P2 bends) without using
anything but the observations and the terrain.  The vertical axis of the raw
files is Y; plan coordinates are (X, Z).
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
DATA = REPO / "simulation" / "scenarios" / "authume"   # the quarry's scenarios, DEM and results
sys.path.insert(0, str(REPO))

from simulation.profile_extraction import profile_from_points, read_stl  # noqa: E402
from simulation.units import DEFAULT_DENSITY_KG_M3  # noqa: E402

#: Substrate zones of the source (SOURCE_README "Digital Terrain Model") -> scenario material names.
ZONES = {"Blue": "vegetated_slope", "Gray": "hard_ground", "Red": "rocky_slope"}

#: A-priori materials before calibration: the presets of simulation/materials.py (published ranges; see the
#: README "Material presets").  The blue zone is a vegetated soil slope ("soil"), the red zone a rocky slope
#: ("talus").  The gray zone is "vertical rock walls and horizontal sturdy soil": the "bedrock" preset, with
#: Wyllie's tangential coefficient of natural ground (e_T 0.3-0.8, as the other natural-ground presets) because
#: its benches are compacted soil.  ASSUMPTIONS, labelled as such in the scenario description;
#: ``riskrf calibrate`` fits them to the observed stops.
MATERIALS = {
    "vegetated_slope": {"preset": "soil"},
    "hard_ground": {"preset": "bedrock", "tangential": {"law": "constant", "mean": 0.55, "std": 0.12}},
    "rocky_slope": {"preset": "talus"},
}
CITATION = ("Garcia, Villard, Richefeu, Daudon (2022) Engineering Geology 310:106855; data: "
            "richefeu/AuthumeQuarryRockfalls_Data-in-Brief f695c933 (no licence file; derived profile and "
            "runouts used with the citation)")


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace('\\', '\\\\').replace('"', '\\"') + '"'
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(v)


def load_terrain(raw: Path):
    tris, labels = [], []
    for zone in ZONES:
        t = read_stl(raw / f"DTM_{zone}_zone.stl")
        tris.append(t)
        labels += [ZONES[zone]] * len(t)
    return np.concatenate(tris), labels


def build(raw: Path, out_dir: Path = DATA, data_dir: Path = REPO / "tests" / "data" / "authume"):
    tri, labels = load_terrain(raw)
    rows = []
    for prof_name in ("P1", "P2"):
        ends = np.loadtxt(raw / f"Endpoints_{prof_name}.txt", ndmin=2)
        drops = np.loadtxt(raw / f"positions_{prof_name}.xyz", ndmin=2)
        release = drops.mean(axis=0)                       # X, Y (up), Z
        r_xy = release[[0, 2]]
        stops_xy = ends[:, [0, 2]]
        order = np.argsort(np.hypot(*(stops_xy - r_xy).T))
        spine = [r_xy] + [np.median(stops_xy[g], axis=0) for g in np.array_split(order, 3)]
        start = -2.5                                        # behind the drop square's back edge (2 m)
        probe = profile_from_points(tri, spine, spacing=0.5, vertical_axis=1, start_m=start, end_m=300.0,
                                    trim=True)
        proj = probe.project(stops_xy)
        end = min(float(proj["distance_m"].max()) + 15.0, float(probe.distance_m[-1]))
        prof = profile_from_points(tri, spine, spacing=0.5, labels=labels, vertical_axis=1, start_m=start,
                                   end_m=end)
        proj = prof.project(stops_xy)
        ground0 = float(np.interp(0.0, prof.distance_m, prof.elevation_m))
        drop_h = float(release[1]) - ground0
        masses = ends[:, 3]
        ln = np.log(masses)
        used = sorted(set(prof.materials), key=list(ZONES.values()).index)
        lo_name = prof_name.lower()
        for i in range(len(ends)):
            rows.append({"profile": prof_name, "block": i + 1, "x_stop_m": round(float(proj["distance_m"][i]), 3),
                         "offset_m": round(float(proj["offset_m"][i]), 3),
                         "plan_runout_m": round(float(np.hypot(*(stops_xy[i] - r_xy))), 3),
                         "fall_height_m": round(float(release[1] - ends[i, 1]), 3),
                         "mass_kg": float(masses[i]), "l1_m": ends[i, 4], "l2_m": ends[i, 5], "l3_m": ends[i, 6]})
        desc = (f"Authume quarry profile {prof_name}: 2-D section every 0.5 m along the blocks' path through the "
                f"zoned 0.5 m TIN ({len(ends)} real blocks released; observed stops in "
                f"tests/data/authume/observed_runout.csv). Release at x = 0, {drop_h:.2f} m above the ground "
                f"(drop height of the shovel, Y = {release[1]:.2f} m). Masses: lognormal fitted to the "
                f"{len(ends)} measured masses. Materials are A-PRIORI ASSUMPTIONS from published ranges, "
                f"not fitted (see README 'Calibration'). Built by build_authume.py. {CITATION}")
        lines = [f'name = "authume_{lo_name}"', f"description = {_toml_value(desc)}", "", "[profile]",
                 f"# {len(prof.distance_m)} vertices; x = distance along the path from the release point [m], "
                 f"z = terrain elevation (raw Y) [m]"]
        d = prof.to_dict()
        lines += [f"x = {_toml_value(d['x'])}", f"z = {_toml_value(d['z'])}",
                  f"materials = {_toml_value(d['materials'])}", ""]
        for m in used:
            lines.append(f"[materials.{m}]   # zone {[k for k, v in ZONES.items() if v == m][0]}; a-priori: preset")
            lines += [f"{k} = {_toml_value(v)}" for k, v in MATERIALS[m].items()]
            lines.append("")
        lines += ["[seeder]", 'type = "point"', "x = 0.0", f"height_m = {drop_h:.3f}",
                  f"mass_kg = {{ dist = \"lognormal\", median = {float(np.exp(ln.mean())):.1f}, "
                  f"sigma = {float(ln.std(ddof=1)):.4f}, max = {float(masses.max()):.1f} }}",
                  f"density_kg_m3 = {DEFAULT_DENSITY_KG_M3!r}", "", "[settings]", "envelope_bins = 0", ""]
        (out_dir / f"authume_{lo_name}.toml").write_text("\n".join(lines))
    data_dir.mkdir(parents=True, exist_ok=True)
    df = pd.DataFrame(rows)
    df.to_csv(data_dir / "observed_runout.csv", index=False)
    return df


if __name__ == "__main__":
    candidates = [Path(sys.argv[1])] if len(sys.argv) > 1 else \
        [base / "shared" / "experiments-raw" / "authume-quarry" for base in (REPO.parent, REPO.parent.parent)]
    raw = next((c for c in candidates if (c / "Endpoints_P1.txt").exists()), candidates[0])
    if not (raw / "Endpoints_P1.txt").exists():
        sys.exit(f"raw Authume files not found in {raw}; pass the directory holding Endpoints_P1.txt")
    table = build(raw.resolve())
    print(table.groupby("profile")[["x_stop_m", "offset_m", "plan_runout_m", "fall_height_m", "mass_kg"]]
          .describe().T.round(2).to_string())
