"""Benchmark: calibration of two parameters on 50 observed stop points.

Run: python tests/benchmarks/bench_calibration.py [--authume]

Issue 9 target: "calibration of two parameters on 50 stop points finishes in under a minute on 2 cores".
Times ``simulation.calibrate`` with its defaults (1,000 simulated blocks per evaluation, differential
evolution with 20 generations at most, 200 bootstrap replicates) fitting two parameters to 50 stop
points on the Authume P1 profile (real terrain, 180 segments).  The two parameters are the ones the P1
runout constrains (README "Validation: the Authume quarry", results.md): the vegetated slope's
tangential coefficient e_T (whether blocks cross the slope at all) and the hard ground's
rolling-resistance angle (where they stop beyond it); the vegetated slope's friction angle, the third
parameter of that study, is the one P1 leaves unconstrained (another seed fits 3.8 deg instead of 33).
The 50 observations are synthesised from known values of the two (printed beside the fit) so that
there are exactly 50; with --authume the real 41 P1 stops are calibrated as well.  One process (the
simulator is single-threaded); the kernel is compiled before timing.  Prints the wall time beside the
target with PASS/FAIL and the load average (the machine may be shared).
"""
from __future__ import annotations

import argparse
import os
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

import simulation
from simulation.calibration import apply_parameters, scenario_dict

ROOT = Path(__file__).resolve().parents[2]
P1 = ROOT / "simulation" / "scenarios" / "authume" / "authume_p1.toml"
PARAMS = {"materials.vegetated_slope.tangential.mean": (0.2, 1.0),
          "materials.hard_ground.ground_friction_angle_deg": (5.0, 50.0)}
TRUTH = {"materials.vegetated_slope.tangential.mean": 0.9,          # blocks cross the vegetated slope, as observed
         "materials.hard_ground.ground_friction_angle_deg": 35.0}
TARGET_S = 60.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--authume", action="store_true", help="also calibrate on the 41 real P1 stops")
    args = ap.parse_args()
    data, _ = scenario_dict(P1)
    truth = TRUTH
    sc_truth = simulation.scenario_from_dict(apply_parameters(data, truth), source=str(P1))
    obs = simulation.run(sc_truth, n=50, seed=777, record_paths=0).per_block["x"]      # 50 stop points
    simulation.run(sc_truth, n=10, seed=1)                                                 # compile, untimed
    print(f"cores available: {os.cpu_count()}; load average {os.getloadavg()[0]:.1f}; scenario {P1.name} "
          f"({sc_truth.profile.n_segments} segments); observed p10/p50/p90 "
          + "/".join(f"{q:.1f}" for q in np.percentile(obs, [10, 50, 90])) + " m")
    failed = False
    cases = [("50 synthetic stops (known parameters)", obs)]
    if args.authume:
        df = pd.read_csv(ROOT / "tests" / "data" / "authume" / "observed_runout.csv")
        cases.append(("41 real P1 stops", df.loc[df.profile == "P1", "x_stop_m"].to_numpy()))
    for label, x in cases:
        t0, c0 = time.perf_counter(), time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = simulation.calibrate(P1, x, PARAMS, seed=1)
        dt, cpu = time.perf_counter() - t0, time.process_time() - c0
        print(f"{label}: {dt:.1f} s, {len(cal.evaluations)} evaluations of 1,000 blocks "
              f"({dt / len(cal.evaluations) * 1000:.0f} ms each); fitted "
              + ", ".join(f"{k.split('.')[-2]}.{k.split('.')[-1]} = {v:.3g}" for k, v in cal.parameters.items())
              + ("; truth " + ", ".join(f"{v:.3g}" for v in truth.values()) if "synthetic" in label else ""))
        ci = cal.summary()
        print("  95 % bootstrap intervals: " + ", ".join(f"{k.split('.')[-2]}.{k.split('.')[-1]} "
                                                       f"{ci.loc[k, 'ci95_low']:.3g}-{ci.loc[k, 'ci95_high']:.3g}"
                                                       for k in PARAMS))
        ok = dt < TARGET_S
        failed |= not ok
        print(f"  wall time {dt:.1f} s (must be < {TARGET_S:.0f} s): {'PASS' if ok else 'FAIL'}; CPU time {cpu:.1f} s "
              f"(what a quiet machine would take, about); load average now {os.getloadavg()[0]:.1f}")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
