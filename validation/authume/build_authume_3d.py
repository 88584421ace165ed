"""Build the Authume quarry 3-D terrain (a 1 m DEM and a substrate-zone raster) and its ``[terrain]`` scenario.

    python validation/authume/build_authume_3d.py [RAW_DIR]

RAW_DIR defaults as in ``build_authume.py`` (the files of Garcia et al. 2022 / the Data in Brief repository
richefeu/AuthumeQuarryRockfalls_Data-in-Brief, commit f695c933; read its PROVENANCE.md).  Writes into
``simulation/scenarios/authume/``, deterministically:

* ``authume_dem.tif``: elevations [m] (the raw vertical axis Y) on a 1 m grid, the zoned TIN
  (``DTM_{Blue,Gray,Red}_zone.stl``, the same terrain as the vertices in ``Terrain.xyz``) interpolated
  linearly in the triangle containing each cell centre; cells outside the TIN are nodata;
* ``authume_zones.tif``: the substrate zone of that triangle, 1 Blue (vegetated slope), 2 Gray (hard rock
  walls and benches), 3 Red (rocky slope), 0 nodata;
* ``authume_3d.toml``: the scenario users start from: this DEM, the zones as materials (the a-priori
  presets of the 2-D Authume scenarios), the P1 release point, a collector across the lower bench.

Plan axes: the raster's x is the raw X and its y the raw Z (the raw frame is y-up), in a local engineering
CRS (metres; orientation to north not given by the source).  Caveats carried from PROVENANCE.md: the stop
points lie a steady 2.5-3.5 m above the nearest terrain vertex (a datum or frame offset), so only plan
positions are compared; no licence file came with the data: the rasters are derived products used here
with the citation and are kept out of the installed package (``pyproject.toml`` package data lists no
``.tif``).
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
DATA = REPO / "simulation" / "scenarios" / "authume"   # the quarry's scenarios, DEM and results
sys.path.insert(0, str(REPO))

from simulation.profile_extraction import _TriangleLocator, read_stl  # noqa: E402

ZONE_CODES = {"Blue": 1, "Gray": 2, "Red": 3}
ZONE_MATERIALS = {1: "vegetated_slope", 2: "hard_ground", 3: "rocky_slope"}
CELL_M = 1.0
#: A local engineering CRS: the quarry's frame is not georeferenced in the source.
LOCAL_CRS_WKT = ('LOCAL_CS["Authume quarry local frame (raw X, Z; metres)",LOCAL_DATUM["Authume survey",32767],'
                 'UNIT["metre",1],AXIS["X",EAST],AXIS["Y",NORTH]]')
CITATION = ("Garcia, Villard, Richefeu, Daudon (2022) Engineering Geology 310:106855; data: "
            "richefeu/AuthumeQuarryRockfalls_Data-in-Brief f695c933 (no licence file; derived rasters used with "
            "the citation, not installed with the package)")


def _raw_dir(argv) -> Path:
    if len(argv) > 1:
        return Path(argv[1])
    for base in (REPO.parent, REPO.parent.parent):
        cand = base / "shared" / "experiments-raw" / "authume-quarry"
        if cand.exists():
            return cand
    raise SystemExit("raw Authume directory not found; pass it as the first argument")


def grid_terrain(raw: Path):
    """(z, zone, transform) of the 1 m north-up grid (rows from high raw Z to low) over the zoned TIN."""
    from affine import Affine
    tris, codes = [], []
    for zone, code in ZONE_CODES.items():
        t = read_stl(raw / f"DTM_{zone}_zone.stl")
        tris.append(t)
        codes.append(np.full(len(t), code, dtype=np.uint8))
    tri = np.concatenate(tris)
    code = np.concatenate(codes)
    plan = tri[:, :, [0, 2]]
    lo = np.floor(plan.reshape(-1, 2).min(axis=0))
    hi = np.ceil(plan.reshape(-1, 2).max(axis=0))
    nx, ny = int((hi[0] - lo[0]) / CELL_M), int((hi[1] - lo[1]) / CELL_M)
    xs = lo[0] + CELL_M * (np.arange(nx) + 0.5)
    ys = lo[1] + CELL_M * (np.arange(ny) + 0.5)[::-1]              # north-up: first row at the largest y
    X, Y = np.meshgrid(xs, ys)
    q = np.column_stack([X.ravel(), Y.ravel()])
    idx, bary = _TriangleLocator(plan).locate(q)
    z = np.full(len(q), np.nan)
    zone = np.zeros(len(q), dtype=np.uint8)
    ok = idx >= 0
    z[ok] = np.sum(tri[idx[ok], :, 1] * bary[ok], axis=1)
    zone[ok] = code[idx[ok]]
    transform = Affine(CELL_M, 0.0, lo[0], 0.0, -CELL_M, lo[1] + ny * CELL_M)
    return z.reshape(ny, nx), zone.reshape(ny, nx), transform


def release_point(raw: Path, profile: str):
    """Mean of the four drop points of a profile: plan (X, Z) and drop elevation Y [m]."""
    drops = np.loadtxt(raw / f"positions_{profile}.xyz", ndmin=2)
    m = drops.mean(axis=0)
    return float(m[0]), float(m[2]), float(m[1])


def build(raw: Path, out_dir: Path = DATA) -> None:
    import rasterio
    z, zone, t = grid_terrain(raw)
    common = dict(driver="GTiff", height=z.shape[0], width=z.shape[1], count=1, crs=LOCAL_CRS_WKT, transform=t,
                  compress="deflate")
    with rasterio.open(out_dir / "authume_dem.tif", "w", dtype="float32", nodata=-9999.0, predictor=3,
                       **common) as dst:
        dst.write(np.where(np.isnan(z), -9999.0, z).astype("float32"), 1)
    with rasterio.open(out_dir / "authume_zones.tif", "w", dtype="uint8", nodata=0, **common) as dst:
        dst.write(zone, 1)
    # the scenario users start from (release P1; the masses of the 2-D scenario authume_p1.toml)
    import simulation
    dem = simulation.read_dem(out_dir / "authume_dem.tif")
    x1, y1, drop1 = release_point(raw, "P1")
    x2, y2, drop2 = release_point(raw, "P2")
    h1 = drop1 - float(dem.elevation(x1, y1))
    h2 = drop2 - float(dem.elevation(x2, y2))
    ends = np.loadtxt(raw / "Endpoints_P1.txt", ndmin=2)
    ln = np.log(ends[:, 3])
    text = f'''name = "authume_3d"
description = """Authume open-pit quarry (France): 3-D terrain of the full-scale block releases of Garcia et al. \\
(2022), a 1 m DEM gridded from the zoned TIN, release P1 (41 real blocks; their stop points are in the raw data, \\
compared in docs/validation/authume-3d.md).  Materials are the A-PRIORI presets of the 2-D Authume scenarios \\
(published ranges, not fitted).  Local engineering frame (raw X, Z), not georeferenced.  Caveat: the surveyed \\
stop points lie 2.5-3.5 m above the terrain (a datum offset): compare plan positions only.  \\
Built by build_authume_3d.py.  {CITATION}"""

[terrain]
dem = "authume_dem.tif"            # in the repository, not in the installed package (no licence file)
material_raster = "authume_zones.tif"
material_codes = {{ 1 = "vegetated_slope", 2 = "hard_ground", 3 = "rocky_slope" }}

[materials.vegetated_slope]        # zone Blue; a-priori: preset
preset = "soil"

[materials.hard_ground]            # zone Gray (rock walls, compacted benches); a-priori: preset
preset = "bedrock"
tangential = {{ law = "constant", mean = 0.55, std = 0.12 }}

[materials.rocky_slope]            # zone Red; a-priori: preset
preset = "talus"

[sources]
# P1 release: mean of the four drop points, {h1:.2f} m above the DEM (shovel drop elevation Y = {drop1:.2f} m).
# For P2 use points = [[{x2:.3f}, {y2:.3f}]] and height_m = {h2:.3f}.
points = [[{x1:.3f}, {y1:.3f}]]
height_m = {h1:.3f}
mass_kg = {{ dist = "lognormal", median = {float(np.exp(ln.mean())):.1f}, sigma = {float(ln.std(ddof=1)):.4f}, max = {float(ends[:, 3].max()):.1f} }}
density_kg_m3 = 2650.0
speed_ms = 0.0

[[collectors]]
name = "lower_bench"               # a plan line across the P1 corridor, 50 m from the release (raw X)
line = [[{x1 + 50:.1f}, {y1 - 40:.1f}], [{x1 + 50:.1f}, {y1 + 40:.1f}]]
'''
    (out_dir / "authume_3d.toml").write_text(text)


if __name__ == "__main__":
    build(_raw_dir(sys.argv))
