"""simulation: Monte Carlo rock fall trajectories on 2-D slope profiles (after Wyllie 2014, ch. 3-7).

    import simulation
    scenario = simulation.load_scenario("simulation/scenarios/road_cut_barrier.toml")
    result = simulation.run(scenario, n=100_000, seed=1)
    result.collector("barrier")        # one row per crossing: velocity_ms, height_m, energy_kj, ...
"""
__version__ = "0.1.0"

from ._lazy import lazy_exports as _lazy_exports

#: Public name -> the module that holds it, imported on first use (PEP 562): ``simulation.units`` and
#: ``simulation.precompile`` can then be imported without numpy or numba.
_EXPORTS = {
    "run": "engine",
    "SimulationResult": "result", "wilson_interval": "result",
    **dict.fromkeys(["Scenario", "ScenarioError", "load_scenario", "scenario_from_dict"], "scenario"),
    # Calibration to observed stop points and profiles extracted from 3-D terrain.
    **dict.fromkeys(["Calibration", "CalibrationWarning", "calibrate", "read_observed"], "calibration"),
    # Calibration pooled over many releases, with a posterior sample.
    **dict.fromkeys(["Release", "read_releases", "ReachConstraint"], "pooled.releases"),
    **dict.fromkeys(["PooledCalibration", "read_posterior"], "pooled.result"),
    "PooledCalibrationWarning": "pooled.posterior", "calibrate_pooled": "pooled.fit",
    "stop_density": "pooled.likelihood",
    # The trajectory model's uncertainty as material draws: a posterior's rows or the presets' spread.
    **dict.fromkeys(["material_draws", "preset_spread", "scenario_with_values"], "material_uncertainty"),
    **dict.fromkeys(["TerrainProfile", "profile_from_points", "read_stl"], "profile_extraction"),
    # 3-D terrain: DEM rasters, profiles cut from them, 3-D scenarios and the 3-D kernel's runs.
    **dict.fromkeys(["Terrain", "TerrainError", "read_dem", "read_material_raster", "profile_from_grid"], "terrain"),
    **dict.fromkeys(["TerrainScenario", "is_terrain_scenario_file", "load_terrain_scenario",
                     "terrain_scenario_from_dict"], "scenario3d"),
    **dict.fromkeys(["run_terrain", "TerrainResult"], "engine3d"),
}

__all__ = sorted(_EXPORTS)

_lazy_exports(__name__, _EXPORTS)
