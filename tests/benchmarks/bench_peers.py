"""Optional side-by-side benchmark against PyRockfall on the same profile.

The profile, release and materials are those of simulation/scenarios/peer_benchmark_profile.toml
(shared/research/rockfall-simulation.md, section 3.1).  Each engine is timed in the interpreter
that runs this script, so a peer can live in a throwaway environment and is never a dependency:

    python tests/benchmarks/bench_peers.py                         # riskrf's simulation package
    python3 -m venv /tmp/rfvenv && /tmp/rfvenv/bin/pip install pyrockfall==0.1.2   # (GPL-3, ~4 GB)
    /tmp/rfvenv/bin/python tests/benchmarks/bench_peers.py --engine pyrockfall

Prints trajectories per second for 1,000 and 10,000 blocks.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

NODES = np.array([[0, 60], [10, 60], [40, 10], [45, 0], [60, 0], [150, -5]], dtype=float)


def run_riskrf(n):
    import simulation
    sc = simulation.load_scenario(Path(simulation.__file__).parent / "scenarios" / "peer_benchmark_profile.toml")
    simulation.run(sc, n=100, seed=1)                       # compile / load the kernel
    t = time.perf_counter()
    res = simulation.run(sc, n=n, seed=1)
    dt = time.perf_counter() - t
    v = res.collector("x50", first_only=True)["velocity_ms"]
    return dt, f"x = 50 m: v mean {v.mean():.2f}, p95 {np.percentile(v, 95):.2f} m/s"


def run_pyrockfall(n):
    import pyrockfall as pr
    mat = pr.Material("rock", normalRestitution=0.35, tangentialRestitution=0.85, frictionAngle=30.0)
    slope = pr.Slope(pr.Geometry(NODES), mat)
    seeder = pr.LineSeeder(np.array([[11.0, 12.0], [61.5, 61.5]]), [pr.Rock("r", mass=1000.0, density=2650.0)])
    seeder.translationalVelocity = [1.0, 0.0]
    seeder.numberOfRocks = n
    an = pr.Analysis()
    an.slope, an.seeders, an.useSpecificSeed = slope, [seeder], True
    t = time.perf_counter()
    an.run()
    return time.perf_counter() - t, "(collector post-processing not timed)"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--engine", choices=("riskrf", "pyrockfall"), default="riskrf")
    args = ap.parse_args()
    fn = run_riskrf if args.engine == "riskrf" else run_pyrockfall
    for n in (1_000, 10_000):
        dt, note = fn(n)
        print(f"{args.engine}: {n:,} blocks in {dt:.3f} s -> {n / dt:,.0f} trajectories/s  {note}")


if __name__ == "__main__":
    main()
