"""Calibration pooled over many releases (simulation.pooled; ``simulation.calibrate(releases, parameters=...)``).

* Synthetic releases drawn from the simulator with known parameters: over seeded repeats the 90 % posterior
  intervals cover the truth at about their nominal rate.
* The Authume quarry releases (Garcia et al. 2022, Engineering Geology 310:106855; data
  richefeu/AuthumeQuarryRockfalls_Data-in-Brief f695c933, no licence file: derived runouts used with the
  citation), split into two halves by block number: the two posteriors overlap.
* Bad input: a release outside its profile, masses missing for some releases, a posterior file that does not
  match the scenario's materials -- each a clear error naming file, release and field.
"""
import warnings

import numpy as np
import pandas as pd
import pytest

import simulation
from simulation.pooled import PooledCalibration, Release, calibrate_pooled, read_posterior, read_releases

from .conftest import ROOT, digest

AUTHUME = ROOT / "simulation" / "scenarios" / "authume"
OBSERVED = pd.read_csv(ROOT / "tests" / "data" / "authume" / "observed_runout.csv")
COULOMB = {"law": "coulomb", "mean": 0.6, "std": 0.1, "friction_angle_deg": 35.0, "std_deg": 3.0}
TRUTH = {"materials.ground.ground_friction_angle_deg": 30.0, "materials.ground.tangential.mean": 0.6}
BOUNDS = {"materials.ground.ground_friction_angle_deg": (15.0, 45.0), "materials.ground.tangential.mean": (0.2, 1.0)}
FAST = dict(n_per_release=50, n_initial=64, n_per_iteration=32, iterations=4, n_predictive=10)


def _profile(kind):
    x, z = ([0, 30, 60, 90, 250], [60, 35, 18, 8, 0]) if kind == "A" else \
        ([0, 20, 50, 80, 110, 250], [70, 52, 30, 17, 9, 0])
    return {"name": f"synthetic_{kind}", "profile": {"x": x, "z": z, "material": "ground"},
            "materials": {"ground": {"preset": "soil", "tangential": dict(COULOMB), "ground_friction_angle_deg": 30.0,
                                     "roughness_m": 0.3, "rolling_size_coefficient": 0.5,
                                     # the size term active over the whole prior box of phi_g (15-45 deg): with the
                                     # default 38 deg cap it vanishes for phi_g >= 38 and the 90 % intervals held
                                     # the truth 11 times of 16
                                     "rolling_resistance_cap_deg": 60.0}},
            "seeder": {"x": 1.0, "height_m": 2.0, "mass_kg": 500.0, "vx_ms": 1.0}, "settings": {"envelope_bins": 0}}


def synthetic_releases(rep, n_releases=20):
    """Releases on two profiles with masses of 100-3,000 kg; one stop each, simulated with the true values."""
    rng = np.random.default_rng(1000 + rep)
    scen = {k: _profile(k) for k in "AB"}
    out = []
    for i in range(n_releases):
        k = "AB"[i % 2]
        m = float(rng.uniform(100.0, 3000.0))
        res = simulation.run(simulation.scenario_from_dict(scen[k]), seed=[rep, i, 99], masses_kg=[m],
                             record_paths=0)
        out.append(Release(name=f"r{i}", scenario=scen[k], x_stop_m=res.per_block["x"].copy(), mass_kg=m,
                           source="synthetic"))
    return out


def test_posterior_intervals_cover_known_parameters_at_about_the_nominal_rate():
    """8 seeded repeats x 2 parameters: the 90 % intervals hold the truth 14-16 times of 16 (nominal 14.4)."""
    hits, widths = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", simulation.PooledCalibrationWarning)
        for rep in range(8):
            cal = calibrate_pooled(synthetic_releases(rep), BOUNDS, seed=rep + 1, **FAST)
            for k, v in TRUTH.items():
                lo, hi = cal.interval(k, 0.9)
                hits.append(lo <= v <= hi)
                widths.append((hi - lo) / (BOUNDS[k][1] - BOUNDS[k][0]))
    assert 0.75 <= np.mean(hits) <= 1.0
    assert np.median(widths) < 0.3                    # the data constrain both parameters well inside the prior


@pytest.fixture(scope="module")
def synthetic_fit():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", simulation.PooledCalibrationWarning)
        return simulation.calibrate(synthetic_releases(0), parameters=BOUNDS, seed=1, **FAST)


def test_result_tables(synthetic_fit, tmp_path):
    cal = synthetic_fit
    assert isinstance(cal, PooledCalibration)
    s = cal.summary()
    assert list(s.index) == list(BOUNDS)
    assert (s["sd_ratio"] < 1.0).all() and (s["q05"] <= s["median"]).all() and (s["median"] <= s["q95"]).all()
    corr = cal.correlations()
    assert corr.shape == (2, 2) and np.allclose(np.diag(corr), 1.0)
    cov = cal.coverage()
    assert 0.0 <= cov["inside_90"] <= cov["inside_99"] <= 1.0 and cov["observed_stops"] == 20
    assert set(cal.coverage_table.columns) >= {"p05", "p95", "p995", "inside_90", "inside_99"}
    # the posterior file round-trips and is checked against a scenario's materials
    path = cal.write(tmp_path / "posterior.csv")
    back = read_posterior(path, _profile("A"))
    pd.testing.assert_frame_equal(back, cal.posterior, check_exact=False, rtol=1e-12)
    ax = cal.plot()                              # the pairs: the lower-left panel of a 2 x 2 grid
    assert len(ax.figure.axes) == 4
    np.testing.assert_allclose(ax.lines[0].get_xdata(), cal.posterior[list(BOUNDS)[0]])
    ax = cal.plot("coverage")                    # one 90 % bar per release at the coverage table's quantiles
    np.testing.assert_allclose(ax.collections[1].get_segments()[0][:, 0],
                               cal.coverage_table[["p05", "p95"]].iloc[0].to_numpy())
    with pytest.raises(ValueError, match="'pie'"):
        cal.plot("pie")


def test_posterior_file_that_does_not_match_the_scenario(synthetic_fit, tmp_path):
    path = synthetic_fit.write(tmp_path / "posterior.csv")
    other = _profile("A")
    other["materials"] = {"rock": other["materials"]["ground"]}
    other["profile"]["material"] = "rock"
    with pytest.raises(ValueError, match=r"posterior.csv: field 'materials.ground.ground_friction_angle_deg' names "
                                         r"material 'ground', which <dict> does not define \(materials: \['rock'\]\)"):
        read_posterior(path, other)


def test_single_scenario_calibration_keeps_its_signature():
    with pytest.raises(TypeError, match="only a pooled calibration"):
        simulation.calibrate(_profile("A"), [50.0] * 12, BOUNDS, n_per_release=10)
    with pytest.raises(TypeError, match="observed stops and parameters are required"):
        simulation.calibrate(_profile("A"))


# ---- bad input ------------------------------------------------------------------------------------------------------
def test_a_release_outside_its_profile_is_named():
    rel = [Release("r1", _profile("A"), [100.0], mass_kg=500.0, source="site.csv"),
           Release("r2", _profile("A"), [260.0], mass_kg=500.0, source="site.csv")]
    with pytest.raises(ValueError, match=r"site.csv: release 'r2': x_stop_m = 260 m is outside the profile of "
                                         r"<dict> \[0, 250\] m"):
        calibrate_pooled(rel, BOUNDS)
    rel = [Release("r1", _profile("A"), [100.0], mass_kg=500.0, x_m=-5.0, source="site.csv")]
    with pytest.raises(ValueError, match=r"site.csv: release 'r1': x_m = -5 m \(the release point\) is outside"):
        calibrate_pooled(rel, BOUNDS)


def test_masses_or_radii_missing_for_some_releases_are_named():
    rel = [Release("r1", _profile("A"), [100.0], mass_kg=500.0, source="site.csv"),
           Release("r2", _profile("A"), [90.0], source="site.csv")]
    with pytest.raises(ValueError, match=r"site.csv: field mass_kg is given for 1 releases and missing for 1: \['r2'\]"):
        calibrate_pooled(rel, BOUNDS)
    rel = [Release("r1", _profile("A"), [100.0], mass_kg=500.0, radius_m=0.4, source="site.csv"),
           Release("r2", _profile("A"), [90.0], mass_kg=500.0, source="site.csv")]
    with pytest.raises(ValueError, match=r"field radius_m is given for 1 releases and missing for 1: \['r2'\]"):
        calibrate_pooled(rel, BOUNDS)
    rel = [Release("r1", _profile("A"), [100.0], mass_kg=500.0, radius_m=2.0, source="site.csv")]
    with pytest.raises(ValueError, match=r"release 'r1': mass_kg = 500 and radius_m = 2 give a density of 15 kg/m"):
        calibrate_pooled(rel, BOUNDS)


def test_releases_file_errors_name_file_release_line_and_field(tmp_path):
    p = tmp_path / "releases.csv"
    p.write_text("release,scenario,x_stop_m,mass_kg\nr1,A,100,500\nr1,A,x,500\n")
    with pytest.raises(ValueError, match=r"releases.csv: release 'r1' \(line 3\): x_stop_m = 'x' is not a number"):
        read_releases(p, {"A": _profile("A")})
    p.write_text("release,scenario,x_stop_m,mass_kg\nr1,A,100,500\nr2,A,90,\n")
    with pytest.raises(ValueError, match=r"releases.csv: field mass_kg is given for 1 releases and missing for 1"):
        read_releases(p, {"A": _profile("A")})
    p.write_text("release,scenario,x_stop_m\nr1,C,100\n")
    with pytest.raises(ValueError, match=r"release 'r1' \(line 2\): scenario = 'C' is not one of \['A'\]"):
        read_releases(p, {"A": _profile("A")})
    p.write_text("release,scenario,x_stop_m,mass_kg\nr1,A,100,500\nr1,A,110,600\n")
    with pytest.raises(ValueError, match=r"release 'r1': field mass_kg differs between its rows"):
        read_releases(p, {"A": _profile("A")})
    p.write_text("release,scenario,x_stop_m,mass_kg\nr1,A,100,500\nr2,B,110,600\n")
    rel = read_releases(p, {"A": _profile("A"), "B": _profile("B")})
    assert [r.name for r in rel] == ["r1", "r2"] and rel[1].mass_kg == 600.0
    p.write_text("profile,block,sc,x_stop_m\nP1,1,1,100\nP1,,1,90\n")                   # an empty name cell
    with pytest.raises(ValueError, match=r"releases.csv: line 3: column 'block' is empty"):
        read_releases(p, {"1": _profile("A")}, release_column=["profile", "block"], scenario_column="sc")
    p.write_text("profile,block,sc,x_stop_m\nP1,1,1,100\nP1,02,1,90\n")      # numeric names, as written
    rel = read_releases(p, {"1": _profile("A")}, release_column=["profile", "block"], scenario_column="sc")
    assert [r.name for r in rel] == ["P1-1", "P1-02"]


def test_bad_parameters_are_named():
    rel = [Release("r1", _profile("A"), [100.0], mass_kg=500.0)]
    with pytest.raises(ValueError, match="no release's scenario defines material 'talus'"):
        calibrate_pooled(rel, {"materials.talus.roughness_m": (0.0, 1.0)})
    with pytest.raises(ValueError, match="a pooled calibration fits material fields"):
        calibrate_pooled(rel, {"settings.contact_velocity_ms": (0.1, 1.0)})
    with pytest.raises(ValueError, match=r"materials.ground.tangential.mean' = 2 \(a bound\)"):
        calibrate_pooled(rel, {"materials.ground.tangential.mean": (0.2, 2.0)})


def test_a_parameter_shared_by_two_materials(tmp_path):
    """'materials.A+B.FIELD' puts one value into the same field of every listed material a scenario defines: profile
    A's material is 'ground', profile B's 'meadow' (its file value 45 deg, the truth 30 deg); fitted as one shared
    parameter, the posterior covers the truth, which it cannot if B's releases kept their file value."""
    from simulation.calibration import set_parameter
    from simulation.pooled import _Pool
    scen = {"A": _profile("A"), "B": _profile("B")}
    scen["B"]["materials"] = {"meadow": {**scen["B"]["materials"]["ground"], "ground_friction_angle_deg": 45.0}}
    scen["B"]["profile"]["material"] = "meadow"
    rels = []
    for i in range(20):
        k = "AB"[i % 2]
        m = 300.0 + 100.0 * i
        truth = simulation.scenario_from_dict({**scen[k], "materials": {
            mat: {**spec, "ground_friction_angle_deg": 30.0} for mat, spec in scen[k]["materials"].items()}})
        res = simulation.run(truth, seed=[7, i], masses_kg=[m], record_paths=0)
        rels.append(Release(name=f"r{i}", scenario=scen[k], x_stop_m=res.per_block["x"].copy(), mass_kg=m))
    name = "materials.ground+meadow.ground_friction_angle_deg"
    pool = _Pool(rels, {name: (15.0, 45.0)})
    for sc in pool.scenarios({name: 22.0}).values():
        assert [m.ground_friction_deg for m in sc.materials] == [22.0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", simulation.PooledCalibrationWarning)
        cal = calibrate_pooled(rels, {name: (15.0, 45.0)}, seed=3, **FAST)
    q05, q95 = cal.posterior[name].quantile([0.05, 0.95])
    assert q05 < 30.0 < q95 and q95 - q05 < 10.0
    # the posterior applies to a scenario with either material, and is refused by one with neither
    path = cal.write(tmp_path / "posterior.csv")
    assert list(read_posterior(path, scen["B"]).columns) == [name]
    other = _profile("A")
    other["materials"] = {"rock": other["materials"]["ground"]}
    other["profile"]["material"] = "rock"
    with pytest.raises(ValueError, match=r"names material 'ground' or 'meadow', which <dict> does not define"):
        read_posterior(path, other)
    data = {"materials": {"ground": {"ground_friction_angle_deg": 30.0}}}
    set_parameter(data, name, 25.0)
    assert data == {"materials": {"ground": {"ground_friction_angle_deg": 25.0}}}
    with pytest.raises(ValueError, match=r"defines none of the materials \['talus', 'scree'\]"):
        set_parameter(data, "materials.talus+scree.roughness_m", 0.2)
    # refused by name: a misspelt member (it would be dropped), a field set twice, an empty member
    with pytest.raises(ValueError, match=r"'materials.ground\+medow.ground_friction_angle_deg': no release's scenario "
                                         r"defines material 'medow'"):
        _Pool(rels, {"materials.ground+medow.ground_friction_angle_deg": (15.0, 45.0)})
    with pytest.raises(ValueError, match=r"parameters 'materials.ground\+meadow.ground_friction_angle_deg' and "
                                         r"'materials.ground.ground_friction_angle_deg' both set"):
        _Pool(rels, {name: (15.0, 45.0), "materials.ground.ground_friction_angle_deg": (15.0, 45.0)})
    with pytest.raises(ValueError, match=r"an empty material name in 'ground\+'"):
        _Pool(rels, {"materials.ground+.ground_friction_angle_deg": (15.0, 45.0)})
    with pytest.raises(ValueError, match=r"parameter 'materials.ground\+meadow.ground_friction_angle_deg': the "
                                         r"scenario defines no material 'meadow'"):
        simulation.calibrate(scen["A"], pd.DataFrame({"x_stop_m": [60.0, 70.0]}), {name: (15.0, 45.0)}, n=50)
    # a reach constraint on a scenario with one of the materials takes the shared parameter too
    from simulation.pooled import ReachConstraint, _ConstraintPool
    c = ReachConstraint(name="reach", scenario=scen["B"], apex_x_m=0.0, apex_z_m=70.0, shadow_angle_deg=30.0,
                        sd_deg=2.0)
    assert list(_ConstraintPool([c], {name: (15.0, 45.0)}).pools[0][1]) == [name]
    # the assumed site-to-site spread of a shared field: the widest of its presets' (talus 4 deg, soil 6 deg)
    from simulation.material_uncertainty import site_spread_half_width
    assert site_spread_half_width("materials.talus+soil.ground_friction_angle_deg") == 6.0


# ---- a real data set: the two halves of the Authume releases --------------------------------------------------------
PARAMETERS = {"materials.vegetated_slope.ground_friction_angle_deg": (3.0, 45.0),
              "materials.vegetated_slope.tangential.mean": (0.2, 1.0),
              "materials.hard_ground.ground_friction_angle_deg": (5.0, 50.0)}


def authume_releases(half):
    """Every observed Authume block as a release on its profile's section with its measured mass; the half by
    block number parity (P1: 41 blocks, P2: 48)."""
    return [Release(name=f"{row.profile}-{row.block}", scenario=AUTHUME / f"authume_{row.profile.lower()}.toml",
                    x_stop_m=[row.x_stop_m], mass_kg=row.mass_kg, source="tests/data/authume/observed_runout.csv")
            for row in OBSERVED.itertuples() if row.block % 2 == half]


def test_the_two_halves_of_the_authume_releases_give_overlapping_posteriors():
    """Each half (44 and 45 releases on both profiles, the a-priori materials of authume_p1/p2.toml, 3 shared
    parameters) is fitted on its own; their 95 % posterior intervals overlap for every parameter, and at most
    10 % of each half's observed stops lie beyond their release's predictive p99.  The kernel width floor is 2 m:
    the observed stops lie up to 10 m to the side of the 2-D section they are projected on (column offset_m)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", simulation.PooledCalibrationWarning)
        fits = [calibrate_pooled(authume_releases(h), PARAMETERS, seed=1, n_per_release=50, n_initial=128,
                                 n_per_iteration=48, iterations=3, n_predictive=20, obs_error_m=2.0)
                for h in (0, 1)]
    for k in PARAMETERS:
        (a_lo, a_hi), (b_lo, b_hi) = fits[0].interval(k, 0.95), fits[1].interval(k, 0.95)
        assert a_lo <= b_hi and b_lo <= a_hi, (k, (a_lo, a_hi), (b_lo, b_hi))
    for cal in fits:
        assert cal.coverage()["beyond_p99"] <= 0.1          # at most 10 % of stops beyond their release's p99


def test_coverage_without_a_predictive_check_says_so():
    """A calibration run with n_predictive=0 has no posterior-predictive check: coverage() says why instead of
    dividing by zero."""
    fast = {**FAST, "n_predictive": 0, "n_initial": 32, "iterations": 1}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", simulation.PooledCalibrationWarning)
        cal = calibrate_pooled(synthetic_releases(0, n_releases=4), BOUNDS, seed=1, **fast)
    with pytest.raises(ValueError, match="n_predictive=0"):
        cal.coverage()


def test_box_rolling_cylinder_from_measured_sizes():
    from simulation.units import block_radius, box_rolling_cylinder
    # a 1.0 x 0.8 x 0.6 m block rolls about its 1.0 m axis: r = (0.8 + 0.6) / 4, length 1.0 = 2 r x aspect
    assert box_rolling_cylinder(1.0, 0.8, 0.6) == pytest.approx((0.35, 1.0 / 0.7), rel=1e-12)
    assert box_rolling_cylinder(0.6, 1.0, 0.8) == box_rolling_cylinder(1.0, 0.8, 0.6)     # any order
    r, a = box_rolling_cylinder(1.0, 1.0, 1.0)                                             # a cube: r = L / 2
    assert (r, a) == (0.5, 1.0)
    # the cylinder and the seeder's radius law agree: a cylinder of that r and aspect at 2,650 kg/m^3
    mass = 2650.0 * np.pi * 0.35 ** 2 * 1.0
    assert float(block_radius(mass, 2650.0, "cylinder", 1.0 / 0.7)) == pytest.approx(0.35, rel=1e-12)
    for bad in (0.0, -1.0, float("nan"), "a"):
        with pytest.raises(ValueError, match=r"l2_m = .* block size"):
            box_rolling_cylinder(1.0, bad, 0.5)


def test_release_shape_and_aspect_ratio_set_the_simulated_radius():
    from simulation.pooled import _Pool, _with_release_state
    from simulation.units import box_rolling_cylinder
    r, a = box_rolling_cylinder(1.1, 0.8, 0.5)
    rel = Release("r1", _profile("A"), [100.0], mass_kg=900.0, radius_m=r, shape="cylinder", aspect_ratio=a,
                  source="site.csv")
    pool = _Pool([rel], BOUNDS)
    sc = _with_release_state(next(iter(pool.bases.values()))[2], rel)
    assert sc.seeder.shape == "cylinder" and sc.seeder.aspect_ratio == pytest.approx(a)
    assert float(sc.seeder.radius(900.0)) == pytest.approx(r, rel=1e-12)
    assert sc.seeder.inertia_factor == 0.5
    assert rel.summary()["aspect_ratio"].iloc[0] == pytest.approx(a)
    # the density check uses the release's aspect ratio, and says so
    bad = Release("r1", _profile("A"), [100.0], mass_kg=900.0, radius_m=0.2, shape="cylinder", aspect_ratio=0.5,
                  source="site.csv")
    with pytest.raises(ValueError, match=r"site.csv: release 'r1': mass_kg = 900 and radius_m = 0.2 give a density "
                                         r"of 35,810 kg/m\^3 for a cylinder of aspect ratio 0.5, outside"):
        calibrate_pooled([bad], BOUNDS)
    bad = Release("r1", _profile("A"), [100.0], mass_kg=900.0, radius_m=r, shape="cylinder", aspect_ratio=-1.0,
                  source="site.csv")
    with pytest.raises(ValueError, match=r"site.csv: release 'r1': aspect_ratio = -1.0 must be a finite number > 0"):
        calibrate_pooled([bad], BOUNDS)


def test_releases_file_reads_shape_and_aspect_ratio(tmp_path):
    p = tmp_path / "releases.csv"
    p.write_text("release,scenario,x_stop_m,mass_kg,radius_m,shape,aspect_ratio\n"
                 "r1,A,100,900,0.325,cylinder,1.6923\nr1,A,104,900,0.325,cylinder,1.6923\n"
                 "r2,A,90,500,0.33,sphere,1\n")
    rel = read_releases(p, {"A": _profile("A")})
    assert (rel[0].shape, rel[0].aspect_ratio, rel[1].shape) == ("cylinder", 1.6923, "sphere")
    p.write_text("release,scenario,x_stop_m,mass_kg,radius_m,shape,aspect_ratio\n"
                 "r1,A,100,900,0.325,cylinder,1.6923\nr1,A,104,900,0.325,cylinder,2\n")
    with pytest.raises(ValueError, match=r"release 'r1': field aspect_ratio differs between its rows"):
        read_releases(p, {"A": _profile("A")})


def test_command_line_pooled_calibration(tmp_path, capsys):
    """``riskrf calibrate-pooled`` on 12 real Authume blocks (each its own release, named by profile and block):
    the posterior file reads back, the coverage table has one row per release; a scenario name without its
    ``--scenario`` is an error naming the file, release, line, column and value, before any simulation."""
    from riskrf.cli import main
    stops = tmp_path / "stops.csv"
    OBSERVED.groupby("profile").head(6).to_csv(stops, index=False)
    common = [str(stops), "--release-column", "profile,block", "--scenario-column", "profile",
              "--scenario", f"P1={AUTHUME / 'authume_p1.toml'}",
              "--parameter", "materials.vegetated_slope.ground_friction_angle_deg=3:45"]
    rc = main(["calibrate-pooled", *common, "--scenario", f"P2={AUTHUME / 'authume_p2.toml'}", "--n-per-release",
               "10", "--iterations", "1", "--posterior", "200", "--predictive", "5", "--out", str(tmp_path / "out")])
    assert rc == 0, capsys.readouterr().err
    out = tmp_path / "out"
    post = read_posterior(out / "posterior.csv")
    assert len(post) == 200 and list(post.columns) == ["materials.vegetated_slope.ground_friction_angle_deg"]
    assert len(pd.read_csv(out / "coverage.csv")) == 12 and (out / "posterior_pairs.png").is_file()
    assert "Predictive check" in capsys.readouterr().out
    rc = main(["calibrate-pooled", *common, "--out", str(tmp_path / "bad")])
    err = capsys.readouterr().err
    assert rc == 2 and "release 'P2-1' (line 8): profile = 'P2' is not one of ['P1']" in err and "stops.csv" in err
    assert not (tmp_path / "bad").exists()
    rc = main(["calibrate-pooled", *common, "--n-per-release", "5"])
    assert rc == 2 and "--n-per-release 5: must be a whole number >= 10" in capsys.readouterr().err
    rc = main(["calibrate-pooled", *common, "--scenario", f"P1={AUTHUME / 'authume_p2.toml'}"])
    assert rc == 2 and "--scenario 'P1=" in (err := capsys.readouterr().err) and "already given" in err
    folder = tmp_path / "sc"                                 # a 3-D scenario and the rasters it names
    folder.mkdir()
    for f in ("authume_3d.toml", "authume_dem.tif", "authume_zones.tif"):
        (folder / f).write_bytes((AUTHUME / f).read_bytes())
    before = digest(folder)
    rc = main(["calibrate-pooled", str(stops), "--release-column", "profile,block", "--scenario-column", "profile",
               "--scenario", f"P1={folder / 'authume_3d.toml'}", "--parameter",
               "materials.soil.ground_friction_angle_deg=3:40", "--out", str(folder), "--overwrite"])
    assert rc == 2 and "would delete it" in capsys.readouterr().err and digest(folder) == before
