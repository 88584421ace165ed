"""``riskrf assess`` on a 3-D terrain site: mass-coupled energy hazard at a barrier line, road per metre."""
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

rasterio = pytest.importorskip("rasterio")
from affine import Affine  # noqa: E402

from riskrf.app.site import SiteError, load_site  # noqa: E402
from riskrf.cli import main  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "riskrf" / "data"


def _dem(path):
    """A 38 deg slope down +x to x = 60 m, then a 6 deg runout to x = 160 m; 2 m cells, 100 m wide."""
    nx, ny, cell = 80, 50, 2.0
    xs = cell * (np.arange(nx) + 0.5)
    ys = cell * (np.arange(ny) + 0.5)
    X, Y = np.meshgrid(xs, ys[::-1])
    z = 200 - np.where(X < 60, np.tan(np.radians(38)) * X,
                       np.tan(np.radians(38)) * 60 + np.tan(np.radians(6)) * (X - 60))
    with rasterio.open(path, "w", driver="GTiff", height=ny, width=nx, count=1, dtype="float32", crs="EPSG:2056",
                       transform=Affine(cell, 0, 0, 0, -cell, ny * cell), nodata=-9999.0) as dst:
        dst.write(z.astype("float32"), 1)


SCENARIO = """
name = "plane_3d"
[terrain]
dem = "dem.tif"
material = "talus"
[materials.talus]
preset = "talus"
[sources]
polygon = [[4, 20], [12, 20], [12, 80], [4, 80]]
height_m = 1.0
mass_kg = 1000
speed_ms = 1.0
[[collectors]]
name = "barrier"
line = [[50, 1.5], [50, 98.5]]
[[collectors]]
name = "road"
line = [[64, 1.5], [64, 98.5]]
"""

SITE = f"""
[site]
name = "3-D plane test"
[inventory]
path = "{(DATA / 'lauterbrunnen_tls_2018.csv').as_posix()}"
m_max_kg = 2.0e6
rate_scale = 0.05
[hazard]
scenario = "slope3d.toml"
collector = "barrier"
road_collector = "road"
n_blocks = 1200
fences_kj = [2000]
fence_height_m = 5.0
bootstrap = 30
seed = 3
[traffic]
vehicles_per_day = 6000
"""


@pytest.fixture(scope="module")
def site3d(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("site3d")
    _dem(tmp / "dem.tif")
    (tmp / "slope3d.toml").write_text(SCENARIO)
    (tmp / "site.toml").write_text(SITE)
    return tmp


@pytest.fixture(scope="module")
def assessed3d(site3d):
    out = site3d / "out"
    assert main(["assess", str(site3d / "site.toml"), "--out", str(out)]) == 0
    return out


def test_a_terrain_site_is_recognised_and_checked(site3d):
    site = load_site(site3d / "site.toml")
    assert site.three_d
    text = SITE + '\n[[options]]\nname = "fence"\nkind = "fence"\ncost = 1000\ncapacity_kj = 2000\nheight_m = 5\n'
    (site3d / "bad.toml").write_text(text)
    with pytest.raises(SiteError, match=r"\[options\] is given, but hazard.scenario 'slope3d.toml' is a 3-D "
                                        "terrain scenario"):
        load_site(site3d / "bad.toml")
    (site3d / "bad2.toml").write_text(SITE.replace('collector = "barrier"', 'collector = "fence"'))
    with pytest.raises(SiteError, match="no collector named 'fence'"):
        load_site(site3d / "bad2.toml")


def test_assess_on_terrain_writes_hazard_energy_and_road_outputs(assessed3d):
    out = assessed3d
    for name in ("summary.json", "design_energies.csv", "fence_checks.csv", "barrier_crossings.csv",
                 "road_per_metre.csv", "road_per_metre.png", "plan.png", "stops.csv"):
        assert (out / name).exists(), name
    s = json.loads((out / "summary.json").read_text())
    assert s["terrain"] is True and 0 < s["hazard"]["reach_probability"] <= 1
    bc = pd.read_csv(out / "barrier_crossings.csv")
    # crossings lie on the barrier line x = 50 m, positions measured from its first vertex (y = 1.5 m)
    np.testing.assert_allclose(bc["x_m"], 50.0, atol=1e-6)
    np.testing.assert_allclose(bc["position_m"], bc["y_m"] - 1.5, atol=1e-6)
    road = pd.read_csv(out / "road_per_metre.csv")
    assert len(road) == 97 and (road["end_m"] - road["start_m"]).max() <= 1.0 + 1e-9
    # the per-metre falls add up to the whole-road total, and deaths follow the falls
    assert (road["falls_per_year_per_m"] * (road["end_m"] - road["start_m"])).sum() == pytest.approx(
        s["road"]["falls_per_year"], rel=1e-9)
    assert s["road"]["falls_per_year"] <= s["hazard"]["arrival_rate_per_year"] * (1 + 1e-9)
    assert s["road"]["deaths_per_year"] > 0
    # the sources span y 20-80 m on a plane: blocks reach the road there, hardly at its ends
    mid = road[(road["start_m"] > 25) & (road["end_m"] < 75)]["falls_per_year_per_m"].mean()
    ends = road[(road["end_m"] < 10) | (road["start_m"] > 87)]["falls_per_year_per_m"].mean()
    assert mid > 5 * ends
    assert "ranking of mitigation options" in s["not_done_on_3d_terrain"]


def test_the_mass_coupled_hazard_on_a_plane_matches_the_2d_section():
    """On a plane slope (nothing varies across it) the 3-D mass-coupled hazard at a line equals the 2-D one on
    the section through the release point, within Monte Carlo error and the 3-D kernel's half-cell steps."""
    from scipy import stats

    import simulation
    from riskrf.hazard.simulated import simulate_energy_hazard
    from simulation import Terrain, profile_from_grid, terrain_scenario_from_dict
    t40, t15 = np.tan(np.radians(40)), np.tan(np.radians(15))
    dem = Terrain.from_function(lambda x, y: np.where(x < 60, 200 - t40 * x, 200 - t40 * 60 - t15 * (x - 60)),
                                (0, 200), (0, 100), 1.0)
    mats = {"soil": {"preset": "soil"}}
    sc3 = terrain_scenario_from_dict({"terrain": {}, "materials": mats,
                                      "sources": {"points": [[5.0, 50.0]], "mass_kg": 1000, "speed_ms": 1.0},
                                      "collectors": [{"name": "line", "line": [[55.0, 0.0], [55.0, 100.0]]}]},
                                     terrain=dem)
    prof = profile_from_grid(dem, [(0.0, 50.0), (200.0, 50.0)], spacing=1.0)
    sc2 = simulation.scenario_from_dict({"profile": prof.to_dict(), "materials": mats,
                                         "seeder": {"x": 5.0, "height_m": 1.0, "mass_kg": 1000, "vx_ms": 1.0},
                                         "collectors": [{"name": "line", "x": 55.0}]})
    law = stats.truncpareto(b=0.7, c=1000.0, scale=10.0)        # 10 kg - 10 t
    h3, _ = simulate_energy_hazard(law, sc3, "line", rate_per_year=2.0, n=1500, seed=1)
    h2, _ = simulate_energy_hazard(law, sc2, "line", rate_per_year=2.0, n=1500, seed=2)
    assert h3.reach_probability == pytest.approx(h2.reach_probability, abs=0.02)
    for m in (30.0, 300.0, 3000.0):
        for q in (0.5, 0.95):
            assert h3.velocity_percentile(q, mass_kg=m) == pytest.approx(h2.velocity_percentile(q, mass_kg=m),
                                                                          rel=0.03), (m, q)
    for e in (20.0, 200.0):
        assert h3.annual_frequency(e) == pytest.approx(h2.annual_frequency(e), rel=0.02), e


def test_the_3d_chain_fits_the_inventory_with_the_2d_fits_stage(site3d, monkeypatch):
    """One chain: the 3-D assessment differs from the 2-D one only in the hazard stage; its fits are
    riskrf.app.assess.site_inputs.fit_site_inventory (the same m_min and bootstrap sizes), not a copy of its own."""
    import riskrf.app.assess.site_inputs as site_inputs
    from riskrf.app.assess3d import run_terrain_assessment

    seen = []

    def fits(site, seed):
        seen.append(seed)
        raise RuntimeError("the shared fits stage was called")

    monkeypatch.setattr(site_inputs, "fit_site_inventory", fits)
    with pytest.raises(RuntimeError, match="shared fits stage"):
        run_terrain_assessment(load_site(site3d / "site.toml"), seed=7, log=lambda *_: None)
    assert seen == [7]
