"""simulation: Monte Carlo rock fall trajectories on 2-D slope profiles (after Wyllie 2014, ch. 3-7).

    import simulation
    scenario = simulation.load_scenario("simulation/scenarios/road_cut_barrier.toml")
    result = simulation.run(scenario, n=100_000, seed=1)
    result.collector("barrier")        # one row per crossing: velocity_ms, height_m, energy_kj, ...
"""
__version__ = "0.1.0"

from .engine import run
from .result import SimulationResult, wilson_interval
from .scenario import Scenario, ScenarioError, load_scenario, scenario_from_dict

__all__ = ["Scenario", "ScenarioError", "SimulationResult", "load_scenario", "run", "scenario_from_dict",
           "wilson_interval"]

# Calibration to observed stop points and profiles extracted from 3-D terrain (issue 9).
from .calibration import Calibration, CalibrationWarning, calibrate, read_observed  # noqa: E402
from .profile_extraction import TerrainProfile, profile_from_points, read_stl  # noqa: E402

__all__ += ["Calibration", "CalibrationWarning", "TerrainProfile", "calibrate", "profile_from_points", "read_observed",
            "read_stl"]
