"""Benchmark: peak memory of a 3-D hazard map against the number of blocks.

Run: python tests/benchmarks/bench_hazard_map.py [--blocks 10000 100000] [--legacy] [--workers 2] [--write]

Each figure comes from a fresh child process (so one run's peak does not hide another's): the DEM is the
synthetic 1 km^2, 1 m mountainside of ``bench_kernel3d.py`` (1,001 x 1,001 cells, sources along the top band),
the run is :func:`riskrf.app.hazard_map.hazard_map` (its default chunks of 2,000 blocks, streamed aggregation, exact
percentiles) and, with ``--legacy``, also the unchunked path it replaces (``run_terrain(..., hazard=True)`` keeping
every pixel passage, in chunks of 5,000 as before, then ``TerrainResult.hazard_grids()``).  Printed per run: the resident memory before the run
(imports, DEM, compiled kernel), the peak resident memory of the child (``ru_maxrss``), the difference, wall
time, pixel passages per block and the scratch bytes the streamed aggregation wrote; at the end the ratio of the
peaks at the largest and the smallest number of blocks (goal <= 1.25 for the streamed map).  With ``--write``
the child also writes the map (GeoTIFFs, GeoPackage, figure) and prints the peak after writing.
"""
from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _rss_mb() -> float:
    """Current resident memory of this process [MB] (from /proc, Linux)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2 ** 20


def child(n: int, mode: str, workers: int, write: bool) -> dict:
    """One run in this process; returns its figures."""
    import tempfile

    sys.path.insert(0, str(HERE))
    from bench_kernel3d import mountainside, scenario

    import simulation
    from riskrf.app.hazard_map import HazardMap, hazard_map
    sc = scenario(mountainside())
    hazard_map(sc, n=20, seed=0, record_paths=1)                     # compile / load the caches, untimed
    simulation.run_terrain(sc, 20, seed=0, hazard=True).hazard_grids()
    before = _rss_mb()
    t0 = time.perf_counter()
    scratch = largest = None
    if mode == "streamed":
        from simulation import hazard_grids
        seen = []
        orig = hazard_grids.PassageAggregator.rasters

        def spy(self, *a, **k):                                      # the scratch bytes, read before cleanup
            seen.append((self.scratch_bytes, self.largest_tile_bytes))
            return orig(self, *a, **k)
        hazard_grids.PassageAggregator.rasters = spy
        hm = hazard_map(sc, n=n, seed=1, workers=workers, chunk_size=2_000, record_paths=50)
        scratch, largest = seen[0]
        passages = None
    else:
        res = simulation.run_terrain(sc, n, seed=1, workers=workers, chunk_size=5_000, hazard=True, record_paths=50)
        passages = len(res.passages["cell"])
        hm = HazardMap(result=res, grids=res.hazard_grids())
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    out = {"n": n, "mode": mode, "before_mb": before, "peak_mb": peak, "wall_s": wall,
           "passages_per_block": None if passages is None else passages / n,
           "scratch_mb": None if scratch is None else scratch / 2 ** 20,
           "largest_tile_mb": None if largest is None else largest / 2 ** 20}
    if write:
        with tempfile.TemporaryDirectory() as d:
            t1 = time.perf_counter()
            hm.write(Path(d) / "maps")
            out["write_s"] = time.perf_counter() - t1
        out["peak_after_write_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--blocks", type=int, nargs="+", default=[10_000, 100_000])
    ap.add_argument("--legacy", action="store_true", help="also the unchunked path (every passage kept)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--write", action="store_true", help="also write the map and report the peak after it")
    ap.add_argument("--child", nargs=2, metavar=("N", "MODE"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        print(json.dumps(child(int(args.child[0]), args.child[1], args.workers, args.write)))
        return
    print(f"hazard map on the 1 km^2, 1 m mountainside (1,001 x 1,001 cells), "
          f"{args.workers} threads; one child process per figure")
    modes = ["streamed"] + (["legacy"] if args.legacy else [])
    peaks = {}
    for mode in modes:
        for n in args.blocks:
            cmd = [sys.executable, __file__, "--child", str(n), mode, "--workers", str(args.workers)]
            cmd += ["--write"] if args.write else []
            r = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.splitlines()[-1])
            peaks[mode, n] = r["peak_mb"]
            extra = (f", {r['passages_per_block']:.0f} pixel passages per block" if r["passages_per_block"] else
                     f", scratch files {r['scratch_mb']:,.0f} MB (largest tile {r['largest_tile_mb']:.1f} MB)")
            if args.write:
                extra += f"; written in {r['write_s']:.1f} s, peak after writing {r['peak_after_write_mb']:,.0f} MB"
            print(f"{mode:8s} {n:>9,} blocks: peak RSS {r['peak_mb']:7,.0f} MB (before the run {r['before_mb']:,.0f} MB,"
                  f" run +{r['peak_mb'] - r['before_mb']:,.0f} MB), {r['wall_s']:.1f} s{extra}", flush=True)
    lo, hi = min(args.blocks), max(args.blocks)
    for mode in modes:
        ratio = peaks[mode, hi] / peaks[mode, lo]
        goal = f" (goal <= 1.25: {'PASS' if ratio <= 1.25 else 'FAIL'})" if mode == "streamed" else ""
        print(f"{mode}: peak at {hi:,} / peak at {lo:,} blocks = {ratio:.2f}{goal}")


if __name__ == "__main__":
    main()
