"""``riskrf hazard-map``: hazard GeoTIFFs on the DEM's grid and CRS, stop points as a GeoPackage, a figure."""
import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")
pyogrio = pytest.importorskip("pyogrio")
from affine import Affine  # noqa: E402

from riskrf.app.hazard_map import RASTERS, hazard_map  # noqa: E402
from riskrf.cli import main  # noqa: E402


def _dem(path, south_up=False, crs="EPSG:2154"):
    """A 35 deg slope easing to 8 deg (down +x) with a shallow gully, 2 m cells, origin at (900000, 6600000)."""
    nx, ny, cell = 80, 40, 2.0
    xs = 900_000 + cell * (np.arange(nx) + 0.5)
    ys = 6_600_000 + cell * (np.arange(ny) + 0.5)
    rows = ys if south_up else ys[::-1]
    X, Y = np.meshgrid(xs, rows)
    u = X - 900_000
    z = 400 - np.where(u < 70, np.tan(np.radians(35)) * u, np.tan(np.radians(35)) * 70
                       + np.tan(np.radians(8)) * (u - 70)) + 0.1 * np.abs(Y - 6_600_040)
    t = (Affine(cell, 0, 900_000, 0, cell, 6_600_000) if south_up
         else Affine(cell, 0, 900_000, 0, -cell, 6_600_000 + ny * cell))
    with rasterio.open(path, "w", driver="GTiff", height=ny, width=nx, count=1, dtype="float32", crs=crs,
                       transform=t, nodata=-9999.0) as dst:
        dst.write(z.astype("float32"), 1)
    return t


SCENARIO = """
name = "test_slope"
[terrain]
dem = "dem.tif"
material = "talus"
[materials.talus]
preset = "talus"
[sources]
points = [[900005.0, 6600041.0]]
height_m = 1.0
mass_kg = { dist = "lognormal", median = 1000, sigma = 0.5, max = 20000 }
speed_ms = 1.0
[[collectors]]
name = "track"
line = [[900100.0, 6600000.0], [900100.0, 6600080.0]]
[settings]
contact_velocity_ms = 0.5
"""


@pytest.mark.parametrize("south_up", [False, True])
def test_hazard_map_writes_geotiffs_on_the_dem_grid_and_crs(tmp_path, south_up):
    t = _dem(tmp_path / "dem.tif", south_up=south_up)
    (tmp_path / "slope.toml").write_text(SCENARIO)
    out = tmp_path / "maps"
    assert main(["hazard-map", str(tmp_path / "slope.toml"), "-n", "400", "--seed", "3", "--out", str(out)]) == 0
    with rasterio.open(tmp_path / "dem.tif") as dem:
        dem_crs, dem_shape, dem_z = dem.crs, dem.shape, dem.read(1)
    grids = {}
    for name in RASTERS:
        with rasterio.open(out / f"{name}.tif") as ds:
            assert ds.crs == dem_crs and ds.shape == dem_shape
            assert tuple(ds.transform)[:6] == tuple(t)[:6]
            grids[name] = ds.read(1).astype(float)
    reach, count = grids["reach_probability"], grids["passage_count"]
    assert np.nanmax(reach) == pytest.approx(1.0) and np.nanmin(reach) >= 0
    np.testing.assert_allclose(reach, count / 400, rtol=1e-6)
    # every block passes the release pixel: in file order, its row depends on the orientation
    row = int((6_600_041 - 6_600_000) // 2)
    row = row if south_up else dem_shape[0] - 1 - row
    assert count[row, 2] == 400
    # blocks run down +x: the reach probability falls with distance from the source along the fall line
    centre = dem_shape[0] // 2
    assert np.nanmean(reach[centre - 3:centre + 3, 10:20]) > np.nanmean(reach[centre - 3:centre + 3, 60:70])
    e50, e95, e99 = grids["energy_p50_kj"], grids["energy_p95_kj"], grids["energy_p99_kj"]
    ok = np.isfinite(e50)
    assert np.all(e50[ok] <= e95[ok] + 1e-3) and np.all(e95[ok] <= e99[ok] + 1e-3)
    # the deposition density integrates to the share of blocks that stopped on the DEM
    info = pyogrio.read_info(out / "hazard_map.gpkg", layer="stop_points")
    assert info["features"] == 400 and "EPSG:2154" in str(info["crs"])
    _, _, geom, fields = pyogrio.raw.read(out / "hazard_map.gpkg", layer="stop_points")
    reasons = fields[1]
    n_stopped = int(np.sum(reasons == "stopped"))
    assert np.nansum(grids["deposition_density"]) * 4.0 == pytest.approx(n_stopped / 400, rel=1e-5)
    assert pyogrio.read_info(out / "hazard_map.gpkg", layer="trajectories")["features"] > 0
    assert (out / "hillshade.png").stat().st_size > 10_000
    assert np.all(np.isfinite(dem_z))
    # the talus preset is not fitted to this slope: the map says so beside the rasters and in their tags
    assert (out / "trajectory_model.txt").read_text().startswith("UNCALIBRATED trajectory model")
    with rasterio.open(out / "reach_probability.tif") as ds:
        assert ds.tags()["riskrf_trajectory_model"] == "uncalibrated"


def test_a_dem_without_crs_needs_crs(tmp_path, capsys):
    _dem(tmp_path / "dem.tif", crs=None)
    (tmp_path / "slope.toml").write_text(SCENARIO)
    out = tmp_path / "maps"
    assert main(["hazard-map", str(tmp_path / "slope.toml"), "-n", "20", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "dem.tif: the DEM has no CRS" in err and not out.exists()
    assert main(["hazard-map", str(tmp_path / "slope.toml"), "-n", "20", "--out", str(out), "--crs",
                 "EPSG:2154"]) == 0
    with rasterio.open(out / "reach_probability.tif") as ds:
        assert ds.crs.to_epsg() == 2154


def test_sources_outside_the_dem_are_refused_before_work(tmp_path, capsys):
    _dem(tmp_path / "dem.tif")
    (tmp_path / "slope.toml").write_text(SCENARIO.replace("[[900005.0, 6600041.0]]", "[[800005.0, 6600041.0]]"))
    out = tmp_path / "maps"
    assert main(["hazard-map", str(tmp_path / "slope.toml"), "-n", "20", "--out", str(out)]) == 2
    assert "sources.points: point 0 (800005.00, 6600041.00) is outside the DEM" in capsys.readouterr().err


def test_hazard_map_is_identical_for_one_and_two_workers(tmp_path):
    _dem(tmp_path / "dem.tif")
    (tmp_path / "slope.toml").write_text(SCENARIO)
    a = hazard_map(tmp_path / "slope.toml", n=300, seed=5, workers=1, chunk_size=300)
    b = hazard_map(tmp_path / "slope.toml", n=300, seed=5, workers=2, chunk_size=40)
    for k in a.grids:
        np.testing.assert_array_equal(a.grids[k], b.grids[k])
    assert set(a.summary()["layer"]) == set(RASTERS)


def test_cli_profile_cuts_a_section_from_the_dem(tmp_path, capsys):
    import tomllib

    import simulation
    _dem(tmp_path / "dem.tif")
    out = tmp_path / "section.toml"
    assert main(["profile", str(tmp_path / "dem.tif"), "--path", "900002,6600040", "900150,6600040",
                 "--spacing", "2", "--out", str(out)]) == 0
    prof = tomllib.loads(out.read_text())["profile"]
    assert prof["x"][0] == 0 and prof["x"][-1] == pytest.approx(148.0) and len(prof["x"]) == 75
    # bilinear on the DEM: the first sample lies on the 35 deg plane 2 m from the grid's west edge, plus the
    # cross-slope V term 0.1 |y - 6600040| = 0.1 m at the centres of the two rows either side (y = 39, 41)
    assert prof["z"][0] == pytest.approx(400 - np.tan(np.radians(35)) * 2.0 + 0.1, abs=1e-3)
    sc = simulation.scenario_from_dict({**tomllib.loads(out.read_text()),
                                        "materials": {"talus": {"preset": "talus"}},
                                        "seeder": {"x": 1.0, "mass_kg": 1000}})
    assert sc.profile.x[-1] == pytest.approx(148.0)
    assert main(["profile", str(tmp_path / "dem.tif"), "--path", "900002,6600040", "900300,6600040",
                 "--out", str(tmp_path / "far.toml")]) == 2
    assert "leaves the DEM" in capsys.readouterr().err


def test_tiled_by_source_on_dask_gives_the_same_rasters_for_one_and_two_workers(tmp_path):
    """Tiles by source on dask.distributed (threads: the kernel releases the GIL) give the rasters of the
    one-machine run exactly, for 1 and 2 workers and any tile size."""
    distributed = pytest.importorskip("distributed")
    import simulation
    from riskrf.app.hazard_map import run_tiled
    _dem(tmp_path / "dem.tif")
    (tmp_path / "slope.toml").write_text(SCENARIO.replace('points = [[900005.0, 6600041.0]]',
                                                          'polygon = [[900003, 6600005], [900030, 6600005], '
                                                          '[900030, 6600075], [900003, 6600075]]')
                                         + '[[collectors]]\nname = "net"\nline = [[900012, 6600001], '
                                           '[900012, 6600079]]\nheight_m = 2.0\ncapacity_kj = 100\n')
    sc = simulation.load_terrain_scenario(tmp_path / "slope.toml")
    ref = simulation.run_terrain(sc, 300, seed=5, hazard=True, record_paths=10)
    ga = ref.hazard_grids()
    for n_workers, tile_m in ((1, 20.0), (2, 12.0)):
        with distributed.Client(n_workers=n_workers, threads_per_worker=1, processes=False,
                                dashboard_address=":0") as client:
            res = run_tiled(sc, 300, seed=5, client=client, tile_m=tile_m, max_tile_blocks=40, record_paths=10)
        assert res.workers == n_workers
        for k in ref.per_block:
            np.testing.assert_array_equal(ref.per_block[k], res.per_block[k])
        for k in ref.crossings:
            np.testing.assert_array_equal(ref.crossings[k], res.crossings[k])
        gb = res.hazard_grids()
        for k in ga:
            np.testing.assert_array_equal(ga[k], gb[k])
        for k in ref.paths:
            np.testing.assert_array_equal(ref.paths[k], res.paths[k])
    from riskrf.app.hazard_map import HazardMap
    out = HazardMap(result=res, grids=gb).write(tmp_path / "maps")
    import pandas as pd
    bars = pd.read_csv(out / "barriers.csv")
    assert list(bars["outcome"]) == ["caught", "through", "over"] and set(bars["barrier"]) == {"net"}
    assert bars["blocks"].sum() == res.barrier("net").shape[0] > 0
