"""Reading DEM rasters (GeoTIFF, ESRI ASCII) into simulation.terrain.Terrain, and profiles cut from them.

Reference values are exact: a plane z = a + b x + c y is reproduced exactly by bilinear interpolation, so
every elevation read back is known in closed form, whatever the file's row order.
"""
import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")
from affine import Affine  # noqa: E402
from rasterio.crs import CRS  # noqa: E402

from simulation.terrain import (MaterialGrid, Terrain, TerrainError, profile_from_grid,  # noqa: E402
                                read_dem, read_material_raster)

PLANE = (500.0, -0.5, 0.25)        # z = 500 - 0.5 x + 0.25 y (x, y in m from the grid origin)


def _plane(x, y):
    return PLANE[0] + PLANE[1] * (x - 2_600_000) + PLANE[2] * (y - 1_200_000)


def _write(path, z, transform, crs="EPSG:2056", nodata=None, driver="GTiff"):
    with rasterio.open(path, "w", driver=driver, height=z.shape[0], width=z.shape[1], count=1, dtype="float64",
                       crs=crs, transform=transform, nodata=nodata) as dst:
        dst.write(z, 1)
    return path


def _grid(cell=2.0, nx=30, ny=20, south_up=False):
    """A plane on a grid whose cell centres are at x = 2,600,000 + cell (j + 1/2), y = 1,200,000 + cell (i + 1/2)."""
    xs = 2_600_000 + cell * (np.arange(nx) + 0.5)
    ys = 1_200_000 + cell * (np.arange(ny) + 0.5)
    if south_up:
        X, Y = np.meshgrid(xs, ys)
        t = Affine(cell, 0, 2_600_000, 0, cell, 1_200_000)
    else:
        X, Y = np.meshgrid(xs, ys[::-1])
        t = Affine(cell, 0, 2_600_000, 0, -cell, 1_200_000 + ny * cell)
    return _plane(X, Y), t


@pytest.mark.parametrize("south_up", [False, True])
def test_geotiff_keeps_crs_transform_nodata_and_orientation(tmp_path, south_up):
    z, t = _grid(south_up=south_up)
    z[3, 4] = -9999.0
    dem = read_dem(_write(tmp_path / "dem.tif", z, t, nodata=-9999.0))
    assert dem.crs == CRS.from_epsg(2056)
    assert tuple(dem.transform)[:6] == tuple(t)[:6]
    assert dem.nodata == -9999.0 and dem.south_up is south_up
    assert np.isnan(dem.z).sum() == 1
    # Bilinear on a plane is exact: elevations anywhere away from the hole are the plane's.
    x = np.array([2_600_010.3, 2_600_040.0, 2_600_055.1])
    y = np.array([1_200_030.7, 1_200_021.0, 1_200_035.9])
    np.testing.assert_allclose(dem.elevation(x, y), _plane(x, y), rtol=0, atol=1e-9)
    gx, gy = dem.gradient(x, y)
    np.testing.assert_allclose(gx, PLANE[1], atol=1e-12)
    np.testing.assert_allclose(gy, PLANE[2], atol=1e-12)
    # the hole: the cell centre stored at file row 3, column 4
    row = 3 if south_up else z.shape[0] - 1 - 3
    xh, yh = 2_600_000 + 2.0 * 4.5, 1_200_000 + 2.0 * (row + 0.5)
    assert np.isnan(dem.elevation(xh, yh)) and not dem.contains(xh + 0.5, yh + 0.5)
    # Written back on the DEM's grid: the same array in the same order.
    out = dem.write_geotiff(tmp_path / "back.tif", dem.z)
    with rasterio.open(out) as ds:
        assert ds.crs == dem.crs and tuple(ds.transform)[:6] == tuple(t)[:6]
        back = ds.read(1)
    np.testing.assert_allclose(back, np.where(z == -9999.0, np.nan, z).astype("float32"), equal_nan=True)


def test_esri_ascii_grid_with_and_without_crs(tmp_path):
    z, t = _grid(cell=5.0, nx=6, ny=4)
    lines = ["ncols 6", "nrows 4", "xllcorner 2600000", "yllcorner 1200000", "cellsize 5", "NODATA_value -9999"]
    lines += [" ".join(f"{v:.6f}" for v in row) for row in z]
    asc = tmp_path / "dem.asc"
    asc.write_text("\n".join(lines) + "\n")
    with pytest.raises(TerrainError, match=r"dem\.asc: the DEM has no CRS .*crs"):
        read_dem(asc)
    dem = read_dem(asc, crs="EPSG:2056")
    assert dem.crs == CRS.from_epsg(2056) and dem.dx == 5.0 and not dem.south_up
    np.testing.assert_allclose(dem.elevation(2_600_012.5, 1_200_007.5), _plane(2_600_012.5, 1_200_007.5), atol=1e-5)
    # a .prj beside it gives the CRS; a different explicit one is refused
    asc.with_suffix(".prj").write_text(CRS.from_epsg(2056).to_wkt())
    assert read_dem(asc).crs == CRS.from_epsg(2056)
    with pytest.raises(TerrainError, match="file's CRS is .*EPSG:2154"):
        read_dem(asc, crs="EPSG:2154")


def test_bad_dems_are_refused_with_the_file_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.tif"):
        read_dem(tmp_path / "nope.tif")
    junk = tmp_path / "junk.tif"
    junk.write_text("not a raster")
    with pytest.raises(TerrainError, match="junk.tif"):
        read_dem(junk)
    z, _ = _grid()
    with pytest.raises(TerrainError, match="rotated"):
        Terrain.from_array(z, Affine(2, 0.1, 0, 0, -2, 0), source="rot.tif")
    with pytest.raises(TerrainError, match="every cell is nodata"):
        Terrain.from_array(np.full((3, 3), -1.0), Affine(1, 0, 0, 0, -1, 3), nodata=-1.0)


def test_profile_from_grid_matches_the_plane_and_refuses_holes_and_exits(tmp_path):
    z, t = _grid()
    dem = read_dem(_write(tmp_path / "dem.tif", z, t))
    path = [(2_600_005.0, 1_200_035.0), (2_600_050.0, 1_200_010.0)]
    prof = profile_from_grid(dem, path, spacing=1.0)
    length = np.hypot(45.0, 25.0)
    assert prof.distance_m[-1] == pytest.approx(length)
    np.testing.assert_allclose(prof.elevation_m, _plane(prof.plan_xy[:, 0], prof.plan_xy[:, 1]), atol=1e-9)
    # the section is usable by the 2-D simulator
    import simulation
    sc = simulation.scenario_from_dict({"profile": prof.to_dict(), "materials": {"talus": {"preset": "talus"}},
                                        "seeder": {"x": 1.0, "mass_kg": 1000}})
    assert sc.profile.x[-1] == pytest.approx(length, abs=1e-3)
    with pytest.raises(TerrainError, match=r"leaves the DEM .* at distance"):
        profile_from_grid(dem, path, spacing=1.0, end_m=200.0)
    z2 = z.copy()
    z2[10, 10] = np.nan
    holed = Terrain.from_array(z2, t, crs=dem.crs, source="holed.tif")
    xh, yh = 2_600_000 + 2 * 10.5, 1_200_000 + 2 * (20 - 1 - 10 + 0.5)
    with pytest.raises(TerrainError, match=r"crosses a nodata hole of the DEM holed\.tif at distance"):
        profile_from_grid(holed, [(xh - 10, yh), (xh + 10, yh)], spacing=0.5)


def test_material_raster_on_the_grid_and_on_another_grid(tmp_path):
    z, t = _grid()
    dem = read_dem(_write(tmp_path / "dem.tif", z, t))
    codes = np.ones(z.shape, dtype="int32")
    codes[:, 15:] = 2                           # east half: asphalt
    mpath = tmp_path / "mat.tif"
    with rasterio.open(mpath, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1, dtype="int32",
                       crs="EPSG:2056", transform=t) as dst:
        dst.write(codes, 1)
    grid = read_material_raster(mpath, dem, {1: "talus", 2: "asphalt"}, ["talus", "asphalt"])
    assert isinstance(grid, MaterialGrid)
    prof = profile_from_grid(dem, [(2_600_002.0, 1_200_020.0), (2_600_058.0, 1_200_020.0)], spacing=2.0,
                             materials=grid)
    assert prof.materials[0] == "talus" and prof.materials[-1] == "asphalt"
    assert prof.materials.count("talus") == 14
    other = tmp_path / "other.tif"
    with rasterio.open(other, "w", driver="GTiff", height=10, width=15, count=1, dtype="int32", crs="EPSG:2056",
                       transform=Affine(4, 0, 2_600_000, 0, -4, 1_200_040)) as dst:
        dst.write(np.ones((10, 15), dtype="int32"), 1)
    with pytest.raises(TerrainError, match=r"other\.tif: the material raster is on another grid"):
        read_material_raster(other, dem, {1: "talus"}, ["talus"])
    with pytest.raises(TerrainError, match=r"code 2 .* has no material"):
        read_material_raster(mpath, dem, {1: "talus"}, ["talus"])


def test_check_points_names_the_point_outside():
    dem = Terrain.from_function(lambda x, y: 100 - 0.5 * x, (0, 50), (0, 20), 1.0)
    dem.check_points([(10, 10)], "sources")
    with pytest.raises(TerrainError, match=r"sources: point 1 \(80.00, 5.00\) is outside the DEM"):
        dem.check_points([(10, 10), (80, 5)], "sources")


def test_hillshade_of_a_plane_is_the_cosine_of_the_sun_angle():
    # plane dipping 45 deg to the east, sun from the east at 45 deg: normal (1,0,1)/sqrt2, sun (cos45, 0, sin45)
    dem = Terrain.from_function(lambda x, y: 100 - x, (0, 20), (0, 20), 1.0)
    hs = dem.hillshade(azimuth_deg=90.0, altitude_deg=45.0)
    np.testing.assert_allclose(hs, 1.0, atol=1e-12)
    assert dem.slope_deg() == pytest.approx(np.full(dem.shape, 45.0))
