"""Hazard maps aggregated chunk by chunk and rasters a GIS user can trust:
streamed rasters equal the unchunked ones, nodata on DEM holes, quantity and unit in each band, and the
intensity-frequency layers on cases with a known answer."""
import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")
from affine import Affine  # noqa: E402

import simulation  # noqa: E402
from riskrf.app.hazard_map import DESCRIPTIONS, FREQUENCY_RASTERS, RASTERS, hazard_map  # noqa: E402
from riskrf.cli import main  # noqa: E402
from simulation.engine3d import aggregate_passages  # noqa: E402
from simulation.hazard_grids import (ENERGY_QUANTILES, HazardGridError, PassageAggregator,  # noqa: E402
                                     frequency_rank)

SCENARIO = """
name = "test_slope"
[terrain]
dem = "dem.tif"
material = "talus"
[materials.talus]
preset = "talus"
[sources]
polygon = [[900003, 6600030], [900012, 6600030], [900012, 6600050], [900003, 6600050]]
height_m = 1.0
mass_kg = { dist = "lognormal", median = 1000, sigma = 0.5, max = 20000 }
speed_ms = 1.0
[settings]
contact_velocity_ms = 0.5
"""


def _dem(path, hole=False):
    """A 35 deg slope easing to 8 deg (down +x), 2 m cells, 80 x 40; ``hole``: a NaN square far from the path
    of the blocks (rows 0-4, columns 60-69 of the file) and the file's nodata value in another (rows 35-39,
    columns 0-4)."""
    nx, ny, cell = 80, 40, 2.0
    xs = 900_000 + cell * (np.arange(nx) + 0.5)
    ys = 6_600_000 + cell * (np.arange(ny) + 0.5)
    X, Y = np.meshgrid(xs, ys[::-1])
    u = X - 900_000
    z = 400 - np.where(u < 70, np.tan(np.radians(35)) * u, np.tan(np.radians(35)) * 70
                       + np.tan(np.radians(8)) * (u - 70)) + 0.1 * np.abs(Y - 6_600_040)
    if hole:
        z[0:5, 60:70] = np.nan
        z[35:40, 0:5] = -9999.0
    t = Affine(cell, 0, 900_000, 0, -cell, 6_600_000 + ny * cell)
    with rasterio.open(path, "w", driver="GTiff", height=ny, width=nx, count=1, dtype="float32", crs="EPSG:2154",
                       transform=t, nodata=-9999.0) as dst:
        dst.write(z.astype("float32"), 1)
    return t


@pytest.fixture(scope="module")
def slope(tmp_path_factory):
    d = tmp_path_factory.mktemp("slope")
    _dem(d / "dem.tif")
    (d / "slope.toml").write_text(SCENARIO)
    return d


def test_streamed_rasters_equal_the_unchunked_ones_for_any_chunks_and_threads(slope, tmp_path):
    sc = simulation.load_terrain_scenario(slope / "slope.toml")
    ref = simulation.run_terrain(sc, 400, seed=7, hazard=True, chunk_size=400).hazard_grids()
    for chunk, workers in ((400, 1), (37, 1), (50, 2)):
        hm = hazard_map(sc, n=400, seed=7, chunk_size=chunk, workers=workers, record_paths=5,
                        scratch_dir=tmp_path)
        assert hm.result.passages is None                    # nothing kept beyond the chunks
        for k, g in ref.items():
            np.testing.assert_array_equal(hm.grids[k], g, err_msg=f"{k}, chunk {chunk}, workers {workers}")
        assert list(tmp_path.iterdir()) == []                # scratch files removed
    assert np.nansum(hm.grids["passage_count"]) > 400
    ok = np.isfinite(hm.grids["energy_p99_kj"])
    assert np.all(hm.grids["energy_max_kj"][ok] >= hm.grids["energy_p99_kj"][ok] - 1e-4)


def test_aggregator_equals_aggregate_passages_in_any_chunk_order():
    """Random passages with revisits, fed in shuffled groups of whole blocks: the same rasters exactly."""
    rng = np.random.default_rng(3)
    ny, nx, n = 70, 150, 600                                  # 2 x 3 tiles of 64 pixels, partly filled
    parts, blocks = [], []
    for b in range(n):
        m = rng.integers(0, 60)
        cell = rng.integers(0, 40, m) * nx + rng.integers(0, 150, m)
        parts.append({"block": np.full(m, b, np.int32), "cell": cell.astype(np.int32),
                      "e": rng.lognormal(2, 1, m).astype(np.float32), "h": rng.uniform(0, 5, m).astype(np.float32)})
        blocks.append(b)
    cat = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    count, eq, hq = aggregate_passages(cat["cell"], cat["block"], cat["e"], cat["h"], ny * nx,
                                       np.array(ENERGY_QUANTILES), 0.95)
    groups = np.array_split(rng.permutation(n), 17)
    with PassageAggregator((ny, nx)) as agg:
        for g in groups:
            agg.add({k: np.concatenate([parts[b][k] for b in np.sort(g)]) for k in parts[0]})
        st = agg.rasters(n)
    np.testing.assert_array_equal(st["count"].ravel(), count)
    np.testing.assert_array_equal(st["energy_q"].reshape(3, -1), eq)
    np.testing.assert_array_equal(st["height_q"].ravel(), hq)


@pytest.mark.parametrize("rate, expected", [(10.0, (997.0, 1000.0, 1000.0)),      # k = 4, 1, 1
                                            (0.02, (np.nan, 501.0, 834.0)),       # k = 1667 > 1000, 500, 167
                                            (1 / 30, (1.0, 701.0, 901.0))])      # k = 1000 exactly, 300, 100
def test_energy_at_annual_frequency_is_the_k_th_largest_or_nodata(rate, expected):
    """1,000 blocks pass one pixel with energies 1, 2, ..., 1000 kJ (each block twice: its largest counts);
    each stands for rate / 1000 releases a year, so energy >= e is reached (1001 - e) rate / 1000 times a year."""
    n = 1000
    e = np.arange(1, n + 1, dtype=np.float32)
    with PassageAggregator((3, 3)) as agg:
        agg.add({"block": np.repeat(np.arange(n), 2), "cell": np.full(2 * n, 4),
                 "e": np.column_stack([e / 2, e]).ravel(), "h": np.ones(2 * n, np.float32)})
        st = agg.rasters(n, rate_per_year=rate, frequencies=tuple(FREQUENCY_RASTERS.values()))
    got = st["energy_at_frequency"][:, 1, 1]
    np.testing.assert_array_equal(got, np.array(expected))
    assert np.all(np.isnan(np.delete(st["energy_at_frequency"].reshape(3, -1), 4, axis=1)))
    assert frequency_rank(1 / 100, 1000, 10.0) == 1 and frequency_rank(1 / 30, 1000, 1 / 30) == 1000


def test_same_energy_at_a_known_rate_and_an_unknown_rate_is_refused():
    """Every block reaches the pixel with 250 kJ: at 0.05 releases a year all three frequencies are reached
    (250 kJ); at 0.02 a year only 1/100 and 1/300 (1/30 is nodata, not 0)."""
    n = 200
    for rate, want in ((0.05, [250.0, 250.0, 250.0]), (0.02, [np.nan, 250.0, 250.0])):
        with PassageAggregator((1, 2)) as agg:
            agg.add({"block": np.arange(n), "cell": np.zeros(n, np.int64), "e": np.full(n, 250.0, np.float32),
                     "h": np.full(n, 0.5, np.float32)})
            st = agg.rasters(n, rate_per_year=rate, frequencies=tuple(FREQUENCY_RASTERS.values()))
        np.testing.assert_array_equal(st["energy_at_frequency"][:, 0, 0], want)
        assert np.all(np.isnan(st["energy_at_frequency"][:, 0, 1]))
    with PassageAggregator((1, 2)) as agg, pytest.raises(HazardGridError, match="rate_per_year"):
        agg.rasters(n, frequencies=(0.01,))


def test_hazard_map_frequency_layers_follow_the_counts(slope):
    n, rate = 300, 3.0
    hm = hazard_map(slope / "slope.toml", n=n, seed=2, rate_per_year=rate, record_paths=2)
    count = hm.grids["passage_count"]
    for name, f in FREQUENCY_RASTERS.items():
        k = frequency_rank(f, n, rate)                          # 4, 1, 1
        g = hm.grids[name]
        np.testing.assert_array_equal(np.isfinite(g), count >= k)
    a, b = hm.grids["energy_1in30_kj"], hm.grids["energy_1in300_kj"]
    ok = np.isfinite(a)
    assert ok.any() and np.all(b[ok] >= a[ok])                  # a rarer frequency: a larger energy
    np.testing.assert_array_equal(b, hm.grids["energy_max_kj"])  # k = 1: the largest


def test_rasters_have_nodata_on_dem_holes_and_units_in_each_band(tmp_path):
    _dem(tmp_path / "dem.tif", hole=True)
    (tmp_path / "slope.toml").write_text(SCENARIO)
    out = tmp_path / "maps"
    assert main(["hazard-map", str(tmp_path / "slope.toml"), "-n", "150", "--seed", "4", "--rate-per-year", "2",
                 "--out", str(out)]) == 0
    with rasterio.open(tmp_path / "dem.tif") as dem:
        hole = dem.read(1, masked=True).mask | ~np.isfinite(dem.read(1))
    assert hole.sum() == 75
    for name in {**RASTERS, **FREQUENCY_RASTERS}:
        with rasterio.open(out / f"{name}.tif") as ds:
            band = ds.read(1, masked=True)
            assert np.isnan(ds.nodata)
            assert np.all(band.mask[hole]), name                   # nodata on every hole, never 0
            assert ds.descriptions[0] == DESCRIPTIONS[name] and ds.units[0]
            assert ds.tags(1)["unit"] == ds.units[0] == (RASTERS.get(name) or "kJ")
            assert ds.tags(1)["quantity"] == DESCRIPTIONS[name]
            assert ds.tags()["riskrf_blocks"] == "150" and ds.tags()["riskrf_rate_per_year"] == "2.0"
            if name in ("passage_count", "reach_probability", "deposition_density"):
                assert np.all(~band.mask[~hole]) and np.nanmin(band.filled(np.nan)) == 0   # 0: valid, not reached
    with rasterio.open(out / "energy_p95_kj.tif") as ds:
        assert ds.descriptions[0] == "passing energy p95" and ds.units[0] == "kJ"


def test_bad_rate_is_refused_before_work_naming_the_option(slope, tmp_path, capsys):
    out = tmp_path / "maps"
    for bad in ("0", "-1", "nan", "inf"):
        assert main(["hazard-map", str(slope / "slope.toml"), "-n", "20", "--rate-per-year", bad, "--out",
                     str(out)]) == 2
        err = capsys.readouterr().err
        assert "--rate-per-year" in err and "> 0 [1/year]" in err and not out.exists()
    with pytest.raises(HazardGridError, match=r"rate_per_year .*got 'two'"):
        hazard_map(slope / "slope.toml", n=10, rate_per_year="two")


def test_streamed_dask_tiles_give_the_same_rasters(slope):
    """Tiles by source on dask, each tile's passages aggregated as it arrives: the unchunked rasters exactly."""
    distributed = pytest.importorskip("distributed")
    sc = simulation.load_terrain_scenario(slope / "slope.toml")
    ref = simulation.run_terrain(sc, 240, seed=9, hazard=True).hazard_grids()
    with distributed.Client(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as client:
        hm = hazard_map(sc, n=240, seed=9, client=client, tile_m=4.0, max_tile_blocks=30, record_paths=3)
    assert hm.result.passages is None and hm.result.workers == 2
    for k, g in ref.items():
        np.testing.assert_array_equal(hm.grids[k], g, err_msg=k)
