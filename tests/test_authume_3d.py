"""The Authume quarry in 3-D: the shipped DEM, its scenario, and observed vs simulated stops in plan.

Observations: the 41 surveyed stop points of release P1 (Garcia et al. 2022, Engineering Geology
310:106855; data richefeu/AuthumeQuarryRockfalls_Data-in-Brief f695c933, see the raw PROVENANCE.md:
only plan positions are compared, the stop points lie 2.5-3.5 m above the terrain).  The plan runouts
(from the release point, the mean of the four drop points) are in tests/data/authume/observed_runout.csv
(``plan_runout_m``), so this test needs no raw file.
"""
import sys
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

pytest.importorskip("rasterio")
import simulation  # noqa: E402

HERE = Path(simulation.__file__).parent / "scenarios" / "authume"
SCRIPTS = Path(__file__).resolve().parents[1] / "validation" / "authume"    # not installed: run from the checkout
DATA = Path(__file__).parent / "data" / "authume" / "observed_runout.csv"


def test_the_shipped_dem_is_small_and_georeferenced():
    assert (HERE / "authume_dem.tif").stat().st_size < 1_000_000
    sc = simulation.load_terrain_scenario(HERE / "authume_3d.toml")
    dem = sc.terrain
    assert dem.dx == dem.dy == 1.0 and dem.crs is not None and "Authume" in dem.crs.to_wkt()
    # the survey spans raw Y 153.2-214.2 m (PROVENANCE.md; TIN vertices); cell centres 1 m apart sample the
    # TIN between its vertices, so the gridded extremes lie within that range, close to it
    assert 153.1 < np.nanmin(dem.z) < 156 and 210 < np.nanmax(dem.z) < 214.2
    # three substrate zones become the three materials
    assert set(np.unique(sc.material_grid.index[np.isfinite(dem.z)])) == {0, 1, 2}
    assert [m.name for m in sc.materials] == ["vegetated_slope", "hard_ground", "rocky_slope"]


def test_a_priori_run_stops_every_block_without_energy_gain():
    sc = simulation.load_terrain_scenario(HERE / "authume_3d.toml")
    r = simulation.run_terrain(sc, 300, seed=1)
    assert (r.stops()["reason"] == "stopped").all()
    assert np.all(r.energy_excess_j() <= r.blocks["mass"] * 9.81 * 1e-6)


def test_p1_calibration_transferred_to_3d_reproduces_the_observed_plan_runout():
    """The 2-D calibration on P1 applied unchanged to the 3-D kernel: the simulated plan runouts are not
    distinguishable from the 41 observed ones (KS) and their Wasserstein distance stays below 3 m."""
    sys.path.insert(0, str(SCRIPTS))
    try:
        from validate_authume_3d import APRIORI
    finally:
        sys.path.remove(str(SCRIPTS))
    with open(HERE / "authume_3d.toml", "rb") as f:
        data = tomllib.load(f)
    with open(HERE / "authume_p1_calibrated.toml", "rb") as f:
        cal = tomllib.load(f)["materials"]
    data["materials"] = {**APRIORI, **cal}
    sc = simulation.terrain_scenario_from_dict(data, source="authume_3d (P1 calibrated)", base_dir=HERE)
    r = simulation.run_terrain(sc, 1000, seed=1)
    obs = pd.read_csv(DATA)
    o = obs.loc[obs["profile"] == "P1", "plan_runout_m"].to_numpy()
    s = r.stops()["runout_m"].to_numpy()
    assert stats.ks_2samp(o, s).pvalue > 0.01
    assert stats.wasserstein_distance(o, s) < 3.0
    # and the a-priori presets do not (runout p50 7 m against 41 m observed)
    data["materials"] = APRIORI
    r0 = simulation.run_terrain(simulation.terrain_scenario_from_dict(data, base_dir=HERE), 300, seed=1)
    assert stats.ks_2samp(o, r0.stops()["runout_m"]).pvalue < 1e-6


def test_p2_calibrated_on_the_3d_kernel_fits_better_than_the_2d_calibration():
    """The 3-D calibration on P2 (results_3d_parameters.csv, written by validate_authume_3d.py) against the 2-D
    one, both on the 3-D kernel: the observed P2 plan runouts (48 blocks) are much closer with the 3-D fit
    (W1 5.6 m against 22 m at n = 2,000 in docs/validation/authume-3d.md)."""
    sys.path.insert(0, str(SCRIPTS))
    try:
        from validate_authume_3d import APRIORI
    finally:
        sys.path.remove(str(SCRIPTS))
    from simulation.calibration import apply_parameters
    obs = pd.read_csv(DATA)
    p2 = obs.loc[obs["profile"] == "P2"]
    ln = np.log(p2["mass_kg"].to_numpy())
    with open(HERE / "authume_3d.toml", "rb") as f:
        data = tomllib.load(f)
    # the P2 release point and drop height given in authume_3d.toml's comment; masses: the 48 measured ones
    data["sources"].update(points=[[-1.824, 289.859]], height_m=3.368,
                           mass_kg={"dist": "lognormal", "median": float(np.exp(ln.mean())),
                                    "sigma": float(ln.std(ddof=1)), "max": float(p2["mass_kg"].max())})
    data["collectors"] = []
    fit = pd.read_csv(HERE / "results_3d_parameters.csv")
    fit = fit[fit["calibrated on"] == "P2"].set_index("parameter")["median"].to_dict()
    assert 10.0 < fit["materials.hard_ground.ground_friction_angle_deg"] < 15.0    # 8.3 deg in the 2-D fit
    with open(HERE / "authume_p2_calibrated.toml", "rb") as f:
        cal2d = tomllib.load(f)["materials"]
    o = p2["plan_runout_m"].to_numpy()
    w1 = {}
    for name, mats in (("3-D", apply_parameters({"materials": APRIORI}, fit)["materials"]),
                       ("2-D", {**APRIORI, **cal2d})):
        data["materials"] = mats
        r = simulation.run_terrain(simulation.terrain_scenario_from_dict(data, base_dir=HERE), 1000, seed=1)
        w1[name] = stats.wasserstein_distance(o, r.stops()["runout_m"])
    assert w1["3-D"] < 8.0 < 15.0 < w1["2-D"]
