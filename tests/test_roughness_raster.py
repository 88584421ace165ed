"""Roughness as a property of the terrain: ``terrain.roughness_raster``, the roughness height of each DEM cell [m]
(as Rockyfor3D's mean obstacle height), replaces the material's ``roughness_m`` in the 3-D kernel where it has a
value (:func:`simulation.terrain.read_roughness_raster`, :func:`simulation.kernel3d_surface.cell_roughness`).

Exact checks: a raster equal to the material's roughness everywhere, or of nodata everywhere, gives the run without
it bit for bit; a rougher raster scatters the blocks more.  Bad rasters (another grid, another CRS, a negative
height) are refused before any simulation, naming the file.
"""
import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")
from affine import Affine  # noqa: E402

from simulation import ScenarioError  # noqa: E402
from simulation.engine3d import run_terrain  # noqa: E402
from simulation.scenario3d import terrain_scenario_from_dict  # noqa: E402

CELL, NX, NY = 2.0, 60, 30
T = Affine(CELL, 0, 0.0, 0, -CELL, NY * CELL)
ROUGH = 0.2


def _write(path, values, transform=T, crs="EPSG:2056", nodata=None):
    with rasterio.open(path, "w", driver="GTiff", height=values.shape[0], width=values.shape[1], count=1,
                       dtype="float64", crs=crs, transform=transform, nodata=nodata) as dst:
        dst.write(values, 1)
    return path.name


@pytest.fixture()
def site(tmp_path):
    """A 35 deg slope over 60 m down to a flat runout, 2 m cells, rows north to south."""
    x = CELL * (np.arange(NX) + 0.5)
    z = np.where(x < 60.0, 200.0 - np.tan(np.radians(35.0)) * x, 200.0 - np.tan(np.radians(35.0)) * 60.0)
    _write(tmp_path / "dem.tif", np.tile(z, (NY, 1)))
    return tmp_path


def _scenario(base, **terrain):
    data = {"terrain": {"dem": "dem.tif", **terrain},
            "materials": {"m": {"normal_restitution": 0.35, "tangential": {"law": "constant", "mean": 0.8},
                                "roughness_m": ROUGH, "ground_motion": "roll", "ground_friction_angle_deg": 30.0}},
            "sources": {"points": [[4.0, 30.0]], "height_m": 2.0, "mass_kg": 500, "speed_ms": 1.0}}
    return terrain_scenario_from_dict(data, source=str(base / "site.toml"), base_dir=base)


def _stops(sc):
    r = run_terrain(sc, 200, seed=3, record_paths=0)
    return np.column_stack([r.per_block["x"], r.per_block["y"]])


def test_a_raster_of_the_materials_roughness_or_of_nodata_is_the_run_without_it(site):
    without = _stops(_scenario(site))
    same = _write(site / "same.tif", np.full((NY, NX), ROUGH))
    empty = _write(site / "empty.tif", np.full((NY, NX), -9999.0), nodata=-9999.0)
    assert np.array_equal(_stops(_scenario(site, roughness_raster=same)), without)
    sc = _scenario(site, roughness_raster=empty)
    assert np.isnan(sc.roughness_grid).all()
    assert np.array_equal(_stops(sc), without)


def test_a_rougher_terrain_scatters_the_blocks_more(site):
    smooth = _write(site / "smooth.tif", np.zeros((NY, NX)))
    rough = _write(site / "rough.tif", np.full((NY, NX), 0.6))
    sd_smooth = _stops(_scenario(site, roughness_raster=smooth))[:, 1].std()
    sd_rough = _stops(_scenario(site, roughness_raster=rough))[:, 1].std()
    assert sd_smooth < 1e-6 < sd_rough           # no tilt on smooth ground: every block stays on its fall line


def test_bad_roughness_rasters_are_refused_naming_the_file(site):
    other_grid = _write(site / "coarse.tif", np.zeros((NY // 2, NX // 2)), transform=Affine(4.0, 0, 0, 0, -4.0, 60))
    other_crs = _write(site / "lv03.tif", np.zeros((NY, NX)), crs="EPSG:21781")
    negative = np.zeros((NY, NX))
    negative[3, 7] = -0.5
    neg = _write(site / "negative.tif", negative)
    with pytest.raises(ScenarioError, match=r"coarse\.tif: the roughness raster is on another grid than the DEM"):
        _scenario(site, roughness_raster=other_grid)
    with pytest.raises(ScenarioError, match=r"lv03\.tif: the roughness raster's CRS EPSG:21781 is not the DEM's"):
        _scenario(site, roughness_raster=other_crs)
    with pytest.raises(ScenarioError, match=r"negative\.tif: roughness -0\.5 m \(cell row 3, column 7\) is outside"):
        _scenario(site, roughness_raster=neg)
    with pytest.raises(FileNotFoundError, match="roughness raster not found"):
        _scenario(site, roughness_raster="missing.tif")
