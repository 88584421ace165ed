"""Material presets (simulation/materials.py) and the cliff-talus-runout shadow-angle check."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import simulation
from simulation.calibration import apply_parameters, calibrate
from simulation.materials import ALIASES, PRESETS, presets_table, resolve_material
from simulation.scenario import ScenarioError

ROOT = Path(__file__).resolve().parents[1]
CLIFF = ROOT / "simulation" / "scenarios" / "cliff_talus_runout.toml"
TALUS_TOP = (15.58, 60.0)          # x, z [m] of the talus apex in cliff_talus_runout.toml
TALUS_TOE_X = 101.269


def scenario(materials, profile_material="a"):
    return {"profile": {"x": [0.0, 10.0, 40.0], "z": [10.0, 0.0, 0.0], "material": profile_material},
            "materials": materials, "seeder": {"x": 1.0, "mass_kg": 500.0}}


def material(sc, name):
    return sc.materials[sc.profile.material_names.index(name)]


# ---- presets -------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(PRESETS) + sorted(ALIASES))
def test_every_preset_and_alias_builds_a_valid_material(name):
    sc = simulation.scenario_from_dict(scenario({"a": {"preset": name}}))
    m = material(sc, "a")
    key = ALIASES.get(name, name)
    assert m.ground_friction_deg == PRESETS[key]["ground_friction_angle_deg"]
    assert m.roughness_m == PRESETS[key]["roughness_m"]


def test_fields_beside_a_preset_override_it_and_tables_merge():
    sc = simulation.scenario_from_dict(scenario({"a": {"preset": "talus", "ground_friction_angle_deg": 41.0,
                                                       "tangential": {"std": 0.05},
                                                       "normal_restitution": {"std": 0.1}}}))
    m = material(sc, "a")
    assert m.ground_friction_deg == 41.0                               # replaced
    assert (m.et_mean, m.et_std) == (0.55, 0.05)                       # merged: law and mean from the preset
    assert m.en_std == 0.1 and m.roughness_m == 0.3
    # another law replaces the preset's table
    sc = simulation.scenario_from_dict(scenario({"a": {"preset": "talus", "normal_restitution": 0.35,
                                                       "tangential": {"law": "friction", "friction_angle_deg": 33}}}))
    m = material(sc, "a")
    assert (m.en_mean, m.en_std, m.friction_deg, m.friction_std_deg) == (0.35, 0.0, 33.0, 0.0)
    # the preset library itself is never modified
    assert PRESETS["talus"]["ground_friction_angle_deg"] == 38.0 and PRESETS["talus"]["tangential"]["std"] == 0.12


def test_unknown_preset_is_an_error_with_did_you_mean_naming_file_and_material():
    with pytest.raises(ScenarioError, match=r"site\.toml: materials\.apron\.preset = 'tallus' is not a known "
                                            r"material preset; did you mean 'talus'\?"):
        simulation.scenario_from_dict(scenario({"apron": {"preset": "tallus"}}, "apron"), source="site.toml")
    with pytest.raises(ScenarioError, match=r"x\.toml: materials\.a\.preset must be a preset name"):
        simulation.scenario_from_dict(scenario({"a": {"preset": 3}}), source="x.toml")
    with pytest.raises(ScenarioError, match=r"unknown field materials\.a\.'ground_fricton_angle_deg'; did you mean"):
        simulation.scenario_from_dict(scenario({"a": {"preset": "soil", "ground_fricton_angle_deg": 30}}))


def test_wyllie_law_refuses_a_mean_it_would_ignore():
    with pytest.raises(ScenarioError, match=r"normal_restitution\.mean = 0\.4 is not used by law 'wyllie'"):
        simulation.scenario_from_dict(scenario({"a": {"preset": "talus", "normal_restitution": {"mean": 0.4}}}))


def test_talus_rolling_resistance_lets_blocks_stop_on_talus_slopes():
    """A block at rest on a 30-35 deg talus must stay (phi_g > slope), and one rolling onto it slows down."""
    phi = PRESETS["talus"]["ground_friction_angle_deg"]
    assert phi > 35.0        # steepest usual talus (Evans & Hungr 1993: 30-38 deg; Wyllie 2014 fig. 1.1)
    d = {"profile": {"x": [0.0, 60.0, 61.0], "z": [60 * math.tan(math.radians(35)), 0.0, 0.0], "material": "t"},
         "materials": {"t": {"preset": "talus", "roughness_m": 0.0}},
         "seeder": {"x": 5.0, "height_m": 0.0, "mass_kg": 1000.0, "vx_ms": 4.0 * math.cos(math.radians(35)),
                    "vz_ms": -4.0 * math.sin(math.radians(35))}}
    res = simulation.run(simulation.scenario_from_dict(d), n=20, seed=1, record_paths=0)
    # released at 4 m/s without spin, it starts rolling at 4 / (1 + 2/5) m/s (angular momentum about the contact
    # point); rolling on 35 deg with phi_g 38: a = 5/7 g (tan 38 cos 35 - sin 35), stop distance v^2 / 2a
    a = 5 / 7 * 9.81 * (math.tan(math.radians(phi)) * math.cos(math.radians(35)) - math.sin(math.radians(35)))
    travel = (res.per_block["x"] - 5.0) / math.cos(math.radians(35))
    assert np.all(res.per_block["reason"] == 1)
    assert travel == pytest.approx(np.full(20, (4.0 / 1.4) ** 2 / (2 * a)), rel=1e-6)


def test_calibration_paths_work_on_presets():
    d = scenario({"a": {"preset": "soil"}})
    out = apply_parameters(d, {"materials.a.normal_restitution.mean": 0.4, "materials.a.ground_friction_angle_deg": 30})
    m = material(simulation.scenario_from_dict(out), "a")
    assert (m.en_mean, m.en_std, m.ground_friction_deg) == (0.4, 0.03, 30.0)    # std kept from the preset
    cal = calibrate(d, np.linspace(12, 16, 12), {"materials.a.ground_friction_angle_deg": (20, 40)}, n=20,
                    maxiter=1, popsize=3, n_bootstrap=0)
    assert cal.initial_parameters["materials.a.ground_friction_angle_deg"] == PRESETS["soil"][
        "ground_friction_angle_deg"]                                  # read from the preset


def test_presets_table_lists_every_preset_with_a_source():
    t = presets_table()
    assert sorted(t.index) == sorted(PRESETS)
    assert t["sources"].str.len().min() > 20
    assert resolve_material({"a": 1}) == {"a": 1}


# ---- shadow angles (Evans & Hungr 1993) -------------------------------------------------------------------------
def shadow_angles_deg(result):
    """Shadow angle [deg] of each stopped block: from the top of the talus to the stop point (Evans & Hungr 1993)."""
    pb = result.per_block
    stopped = pb["reason"] == 1
    x, z = pb["x"][stopped], pb["z"][stopped]
    return np.degrees(np.arctan2(TALUS_TOP[1] - z, x - TALUS_TOP[0])), x


@pytest.fixture(scope="module")
def cliff_run():
    return simulation.run(simulation.load_scenario(CLIFF), n=2000, seed=1, record_paths=0)


def test_cliff_talus_runout_shadow_angles_match_evans_and_hungr(cliff_run):
    """Evans & Hungr (1993, Can. Geotech. J. 30:620-636): minimum shadow angles of about 22-30 deg (27.5 deg at most
    of their talus slopes; Wyllie 2014, fig. 1.1), most blocks on the talus or near its toe.  Measured here (n 2,000,
    seed 1): minimum 24.4 deg, 1 % 27.1, 5 % 28.8, median 32.2 deg; 1.4 % beyond the 27.5 deg line."""
    ang, x = shadow_angles_deg(cliff_run)
    assert ang.size >= 0.99 * 2000                       # (almost) every block stops
    assert 22.0 <= ang.min() <= 30.0                     # the farthest block: the minimum shadow angle
    assert 22.0 <= np.percentile(ang, 1) <= 30.0
    assert np.mean(ang >= 27.5) >= 0.9                   # the 27.5 deg rule holds for the great majority
    assert np.mean(ang >= 22.0) == 1.0
    assert np.mean(x <= TALUS_TOE_X + 20.0) >= 0.7       # most stop on the talus or within 20 m of its toe
    assert np.all(ang <= 35.0 + 1e-6)                    # nobody stops above the talus line (no crest stops)


def test_stronge_law_on_talus_runs_far_beyond_the_shadow_line():
    """The check can fail: the rough-sphere (Stronge) tangential law on talus and run-out, which keeps a rolling
    block's speed at shallow impacts, puts most blocks beyond the 22 deg line."""
    import tomllib
    with open(CLIFF, "rb") as fh:
        d = tomllib.load(fh)
    for m in ("talus", "runout"):
        d["materials"][m]["tangential"] = {"law": "friction", "friction_angle_deg": 35.0, "std_deg": 4.0}
    res = simulation.run(simulation.scenario_from_dict(d), n=500, seed=1, record_paths=0)
    ang, _ = shadow_angles_deg(res)
    assert np.mean(ang < 22.0) > 0.5
