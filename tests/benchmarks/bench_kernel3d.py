"""Benchmark: 3-D trajectories per second per core on a 1 m DEM of 1 km^2, and peak memory.

Run: python tests/benchmarks/bench_kernel3d.py [-n 20000] [--million] [--hazard]

The DEM is synthetic (1,001 x 1,001 cells of 1 m, in EPSG:2056): a 600 m high mountainside whose slope
eases from about 40 deg at the top to 10 deg at the foot, with gullies and ridges (sines across the slope)
and 0.3 m of random roughness at the cell scale; bedrock above 60 % of the height, talus below, sources a
band along the top.  The goal printed beside the figure: >= 20,000 trajectories per second per core
(10^6 trajectories on 2 cores in under 2 minutes, with --million).  The 2-D kernel's figure on the
bundled road_cut_barrier scenario is printed beside it.  CPU time of this process is used for the single
thread figure (time.process_time); the kernel is compiled (and cached) before timing.
"""
from __future__ import annotations

import argparse
import resource
import time
from pathlib import Path

import numpy as np

import simulation
from simulation.engine3d import run_terrain
from simulation.scenario3d import terrain_scenario_from_dict
from simulation.terrain import MaterialGrid, Terrain


def mountainside(seed: int = 0) -> Terrain:
    """The 1 km^2, 1 m benchmark DEM (see the module docstring)."""
    rng = np.random.default_rng(seed)
    noise = rng.normal(0, 0.3, (1001, 1001))

    def f(x, y):
        s = x / 1000.0
        base = 600.0 * (1 - s) ** 1.6                     # slope 0.96 (44 deg) at the top, flattening below
        gullies = 8.0 * np.sin(2 * np.pi * y / 120.0) * (1 - s) + 3.0 * np.sin(2 * np.pi * y / 37.0 + 3 * s)
        return base + gullies + noise
    return Terrain.from_function(f, (0, 1000), (0, 1000), 1.0)


def scenario(terrain: Terrain):
    """Bedrock on the upper 40 % of the height, talus below; sources along the top band."""
    sc = terrain_scenario_from_dict(
        {"terrain": {}, "materials": {"bedrock": {"preset": "bedrock"}, "talus": {"preset": "talus"}},
         "sources": {"polygon": [[20, 20], [60, 20], [60, 980], [20, 980]], "height_m": 1.0,
                     "mass_kg": {"dist": "lognormal", "median": 2000, "sigma": 1.0, "max": 200000},
                     "speed_ms": 1.0},
         "collectors": [{"name": "road", "line": [[800, 0], [800, 1000]]}]}, terrain=terrain)
    zmin, zmax = np.nanmin(terrain.z), np.nanmax(terrain.z)
    idx = np.where(terrain.z > zmin + 0.6 * (zmax - zmin), 0, 1).astype(np.int64)
    from dataclasses import replace
    return replace(sc, material_grid=MaterialGrid(index=idx, names=("bedrock", "talus")))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=20_000)
    ap.add_argument("--million", action="store_true", help="also 10^6 trajectories on 2 threads (wall time)")
    ap.add_argument("--hazard", action="store_true", help="also time a run recording hazard pixels")
    args = ap.parse_args()
    t0 = time.perf_counter()
    dem = mountainside()
    sc = scenario(dem)
    print(f"DEM {dem.shape[1]} x {dem.shape[0]} cells of {dem.dx:g} m ({dem.dx * dem.dy * dem.z.size / 1e6:.2f} km^2),"
          f" built in {time.perf_counter() - t0:.1f} s")
    run_terrain(sc, 10, seed=0)                                    # compile / load the cache, untimed
    c0 = time.process_time()
    r = run_terrain(sc, args.n, seed=1, chunk_size=5_000)
    cpu = time.process_time() - c0
    st = r.stops()
    rate = args.n / cpu
    print(f"3-D: {args.n:,} trajectories in {cpu:.2f} CPU-s on one thread: {rate:,.0f} trajectories/s per core "
          f"(goal >= 20,000: {'PASS' if rate >= 20_000 else 'FAIL'})")
    print(f"     mean impacts per block {st['impacts'].mean():.1f}, events (impacts and contact steps) "
          f"{r.per_block['events'].mean():.0f}, median runout {st['runout_m'].median():.0f} m, "
          f"reach road {r.collector('road', first_only=True).shape[0] / args.n:.3f}, "
          f"stop reasons {st['reason'].value_counts().to_dict()}")
    print(f"     peak memory so far (max RSS): {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:,.0f} MB")
    if args.hazard:
        c0 = time.process_time()
        rh = run_terrain(sc, args.n, seed=1, chunk_size=5_000, hazard=True)
        grids = rh.hazard_grids()
        cpu_h = time.process_time() - c0
        print(f"3-D with hazard pixels and rasters: {args.n / cpu_h:,.0f} trajectories/s per core "
              f"({len(rh.passages['cell']):,} pixel passages, {len(grids)} rasters); peak memory so far "
              f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:,.0f} MB")
    if args.million:
        w0, c0 = time.perf_counter(), time.process_time()
        run_terrain(sc, 1_000_000, seed=2, chunk_size=20_000, workers=2)
        wall, cpu_m = time.perf_counter() - w0, time.process_time() - c0
        print(f"3-D: 1,000,000 trajectories on 2 threads in {wall:.1f} s wall, {cpu_m:.1f} CPU-s (goal < 120 s "
              f"wall: {'PASS' if wall < 120 else 'FAIL'}; the wall time depends on the machine's other load, "
              f"CPU-s / 2 is the wall time on two idle cores)")
    s2 = simulation.load_scenario(Path(simulation.__file__).parent / "scenarios" / "road_cut_barrier.toml")
    simulation.run(s2, 10, seed=0)
    c0 = time.process_time()
    simulation.run(s2, 100_000, seed=1)
    cpu2 = time.process_time() - c0
    print(f"2-D (road_cut_barrier.toml, for comparison): {100_000 / cpu2:,.0f} trajectories/s per core")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak memory (max RSS of this process): {peak:,.0f} MB")


if __name__ == "__main__":
    main()
