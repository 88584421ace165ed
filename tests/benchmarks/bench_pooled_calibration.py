"""Benchmark: a pooled calibration of 3 parameters on 80 releases (target: under 5 minutes on 2 cores).

Run: python tests/benchmarks/bench_pooled_calibration.py [--n-per-release 200]

The 80 releases are real: the 41 Authume P1 blocks and the first 39 P2 blocks (tests/data/authume/
observed_runout.csv; Garcia et al. 2022, Engineering Geology 310:106855), each a release on its profile's 2-D
section (simulation/scenarios/authume/authume_p1.toml, authume_p2.toml) with its measured mass.  The three
shared parameters are those of tests/test_pooled_calibration.py (the vegetated slope's rolling-resistance angle
and tangential coefficient, the hard ground's rolling-resistance angle).  ``simulation.calibrate_pooled`` runs
with its defaults (200 blocks per release and parameter set, a 256-point Sobol design, 3 adaptive rounds of 96,
40 posterior-predictive draws).  The kernel is compiled before timing; the simulator is single-threaded, so one
process uses one of the 2 cores.  Prints the wall and CPU time beside the target with PASS/FAIL and the load
average (the machine may be shared).
"""
from __future__ import annotations

import argparse
import os
import time
import warnings
from pathlib import Path

import pandas as pd

import simulation
from simulation.pooled import Release, calibrate_pooled

ROOT = Path(__file__).resolve().parents[2]
AUTHUME = ROOT / "simulation" / "scenarios" / "authume"
PARAMETERS = {"materials.vegetated_slope.ground_friction_angle_deg": (3.0, 45.0),
              "materials.vegetated_slope.tangential.mean": (0.2, 1.0),
              "materials.hard_ground.ground_friction_angle_deg": (5.0, 50.0)}
TARGET_S = 300.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-per-release", type=int, default=200)
    args = ap.parse_args()
    obs = pd.read_csv(ROOT / "tests" / "data" / "authume" / "observed_runout.csv")
    rows = pd.concat([obs[obs.profile == "P1"], obs[obs.profile == "P2"].head(39)])
    releases = [Release(name=f"{r.profile}-{r.block}", scenario=AUTHUME / f"authume_{r.profile.lower()}.toml",
                        x_stop_m=[r.x_stop_m], mass_kg=r.mass_kg, source="observed_runout.csv")
                for r in rows.itertuples()]
    assert len(releases) == 80
    simulation.run(simulation.load_scenario(AUTHUME / "authume_p1.toml"), n=10, seed=1)     # compile, untimed
    print(f"cores available: {os.cpu_count()}; load average {os.getloadavg()[0]:.1f}; 80 releases "
          f"(41 P1 + 39 P2), 3 parameters, {args.n_per_release} blocks per release and parameter set")
    t0, c0 = time.perf_counter(), time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_pooled(releases, PARAMETERS, n_per_release=args.n_per_release, seed=1, obs_error_m=2.0)
    dt, cpu = time.perf_counter() - t0, time.process_time() - c0
    n_eval = len(cal.evaluations)
    print(f"{n_eval} parameter sets x 80 releases x {args.n_per_release} blocks "
          f"({n_eval * 80 * args.n_per_release:,} trajectories) + 40 predictive draws")
    print(cal.summary()[["median", "q05", "q95", "sd_ratio"]].round(3).to_string())
    print(f"posterior-predictive: {cal.coverage().round(3).to_dict()}")
    ok = dt < TARGET_S
    print(f"wall time {dt:.1f} s (must be < {TARGET_S:.0f} s): {'PASS' if ok else 'FAIL'}; CPU time {cpu:.1f} s; "
          f"load average now {os.getloadavg()[0]:.1f}")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
