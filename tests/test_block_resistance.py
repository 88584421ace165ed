"""Per-block variability of the rolling resistance: a material's ``ground_friction_std_deg`` gives each block its own
phi_g = phi_g + z_b sd (z_b one standard normal deviate per block, the same on every material), in the 2-D and the
3-D kernel (:func:`simulation.contact.block_ground_resistance`).

Exact case: a block sliding on flat ground at u0 with friction tan(phi) stops after u0^2 / (2 g tan(phi)); with a
spread, each block stops where its own phi_b = phi + z_b sd says.
"""
import math

import numpy as np
import pytest

import simulation
from simulation import ScenarioError
from simulation.contact import block_ground_resistance
from simulation.engine3d import run_terrain
from simulation.scenario3d import terrain_scenario_from_dict
from simulation.terrain import Terrain

from .test_simulation_physics import G, scenario

PHI, SD, U0 = 30.0, 5.0, 6.0


def _expected(z_b):
    phi_b = np.clip(PHI + z_b * SD, 0.0, 89.0)
    return U0 * U0 / (2 * G * np.tan(np.radians(phi_b)))


def _flat_2d(sd):
    return scenario([0, 200], [0, 0], material={"ground_friction_angle_deg": PHI, "ground_friction_std_deg": sd},
                    seeder={"x": 1.0, "height_m": 0.0, "vx_ms": U0}, settings={"stop_velocity_ms": 0.0})


def test_each_block_slides_as_far_as_its_own_friction_says_2d():
    res = simulation.run(_flat_2d(SD), n=200, seed=4, record_paths=0)
    z_b = res.blocks["resistance_deviate"]
    assert z_b.std() > 0.8 and abs(z_b.mean()) < 0.25           # one standard normal deviate per block
    np.testing.assert_allclose(res.per_block["x"] - 1.0, _expected(z_b), rtol=1e-9)


def test_each_block_slides_as_far_as_its_own_friction_says_3d():
    flat = Terrain.from_function(lambda x, y: 0 * x + 10.0, (0, 80), (0, 20), 1.0)
    mats = {"m": {"normal_restitution": 0.3, "roughness_m": 0.0, "ground_motion": "slide",
                  "ground_friction_angle_deg": PHI, "ground_friction_std_deg": SD}}
    sc = terrain_scenario_from_dict({"terrain": {}, "materials": mats, "collectors": [],
                                     "sources": {"points": [[10.0, 10.0]], "height_m": 0.0, "mass_kg": 1000,
                                                 "speed_ms": U0}}, terrain=flat)
    r = run_terrain(sc, 50, seed=2)
    # the 3-D kernel steps the contact cell by cell on the bilinear surface: a rounding-level difference
    np.testing.assert_allclose(r.per_block["x"] - 10.0, _expected(r.blocks["resistance_deviate"]), rtol=1e-6)


def _spread_run(**material):
    sc = scenario([0, 200], [0, 0], material={"ground_friction_angle_deg": PHI, **material},
                  seeder={"type": "line", "x": [1.0, 5.0], "height_m": 0.0,
                          "vx_ms": {"dist": "uniform", "low": 2.0, "high": 8.0}})
    return simulation.run(sc, n=100, seed=7, record_paths=0)


def test_no_spread_is_the_former_model_and_the_other_draws_do_not_move():
    """With sd 0 no deviate is drawn and the run is the one without the field; with a spread, every other
    quantity of the blocks is drawn as without it (its own stream)."""
    base, zero = _spread_run(), _spread_run(ground_friction_std_deg=0.0)
    spread = _spread_run(ground_friction_std_deg=SD)
    assert np.array_equal(base.per_block["x"], zero.per_block["x"])
    assert not zero.blocks["resistance_deviate"].any()
    for k in ("x", "vx", "mass", "radius"):
        assert np.array_equal(base.blocks[k], spread.blocks[k]), k
    assert not np.array_equal(base.per_block["x"], spread.per_block["x"])


def test_block_ground_resistance_clips_to_a_physical_angle():
    mu = math.tan(math.radians(PHI))
    assert block_ground_resistance(mu, PHI, 0.0, 2.0) == mu
    assert block_ground_resistance(mu, PHI, SD, 0.0) == mu
    assert block_ground_resistance(mu, PHI, SD, 1.0) == pytest.approx(math.tan(math.radians(PHI + SD)))
    assert block_ground_resistance(mu, PHI, SD, -100.0) == 0.0
    assert block_ground_resistance(mu, PHI, SD, 100.0) == pytest.approx(math.tan(math.radians(89.0)))


@pytest.mark.parametrize("value", [-1.0, 25.0, "wide"])
def test_bad_spread_names_the_file_material_and_field(value):
    with pytest.raises(ScenarioError, match=r"test: .*materials\.m\.ground_friction_std_deg"):
        scenario([0, 200], [0, 0], material={"ground_friction_std_deg": value})
