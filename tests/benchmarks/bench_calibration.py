"""Benchmark: calibration of two parameters on 50 observed stop points (issue 9).

Run: python tests/benchmarks/bench_calibration.py [--authume]

Times ``simulation.calibrate`` with its defaults (1,000 simulated blocks per
evaluation, differential evolution with 20 generations at most, 200 bootstrap
replicates) fitting two parameters to 50 stop points, on the Authume P1 profile
(real terrain, 180 segments, observations synthesised from known parameters so
that there are exactly 50) and, with --authume, on the real 41 (P1) stops.
One process (the simulator is single-threaded); the kernel is compiled before timing.
"""
from __future__ import annotations

import argparse
import os
import time
import warnings
from pathlib import Path

import pandas as pd

import simulation
from simulation.calibration import apply_parameters, scenario_dict

ROOT = Path(__file__).resolve().parents[2]
P1 = ROOT / "simulation" / "scenarios" / "authume" / "authume_p1.toml"
PARAMS = {"materials.hard_ground.ground_friction_angle_deg": (10.0, 45.0),
          "materials.hard_ground.normal_restitution.mean": (0.05, 0.7)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--authume", action="store_true", help="also calibrate on the 41 real P1 stops")
    args = ap.parse_args()
    data, _ = scenario_dict(P1)
    truth = {k: lo + 0.4 * (hi - lo) for k, (lo, hi) in PARAMS.items()}
    sc_truth = simulation.scenario_from_dict(apply_parameters(data, truth), source=str(P1))
    obs = simulation.run(sc_truth, n=50, seed=777, record_paths=0).per_block["x"]      # 50 stop points
    simulation.run(sc_truth, n=10, seed=1)                                                 # compile, untimed
    print(f"cores available: {os.cpu_count()}; scenario {P1.name} ({sc_truth.profile.n_segments} segments)")
    cases = [("50 synthetic stops (known parameters)", obs)]
    if args.authume:
        df = pd.read_csv(ROOT / "tests" / "data" / "authume" / "observed_runout.csv")
        cases.append(("41 real P1 stops", df.loc[df.profile == "P1", "x_stop_m"].to_numpy()))
    for label, x in cases:
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = simulation.calibrate(P1, x, PARAMS, seed=1)
        dt = time.perf_counter() - t0
        print(f"{label}: {dt:.1f} s, {len(cal.evaluations)} evaluations of 1,000 blocks "
              f"({dt / len(cal.evaluations) * 1000:.0f} ms each); fitted "
              + ", ".join(f"{k.split('.')[-2]}.{k.split('.')[-1]} = {v:.3g}" for k, v in cal.parameters.items())
              + ("; truth " + ", ".join(f"{v:.3g}" for v in truth.values()) if "synthetic" in label else ""))
        assert dt < 60, f"calibration took {dt:.1f} s (> 60 s)"


if __name__ == "__main__":
    main()
