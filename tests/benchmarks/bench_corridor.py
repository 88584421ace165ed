"""Corridor throughput on 1 and 2 local dask workers (processes), same generated corridor, results compared.

    python tests/benchmarks/bench_corridor.py [--sections 20] [--blocks 2000]

The issue's full size is --sections 200 --blocks 20000 (minutes: 86-362 s per worker count measured on
the shared 2-core machine before the hazard was mass-coupled, which doubles the simulated blocks; see the README).  A SYNTHETIC
corridor of generated cuts (heights 10-50 m, rates 0.05-2 falls reaching the road per year, typed mass law)
is written to a temporary directory.  Prints sections per second and per minute, trajectories per second
(2 x blocks per section: the mass-coupled hazard and the seeder's reference run),
parallel efficiency, peak resident memory of the client and of each worker, and whether the two runs'
tables are identical; then kills one of two workers mid-run and checks the table is still the same.
Workers are warmed up (numba kernel loaded) before timing.
"""
from __future__ import annotations

import argparse
import os
import resource
import signal
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

TOML = (ROOT / "tests" / "data" / "corridor" / "small.toml").read_text()


def make_corridor(directory: Path, sections: int, blocks: int) -> Path:
    rng = np.random.default_rng(2024)
    rows = ["id,chainage_from,chainage_to,cut_height_m,ditch_width_m,runout_to_road_m,falls_per_year"]
    for i in range(sections):
        rows.append(f"S{i:04d},{i * 200},{(i + 1) * 200},{rng.uniform(10, 50):.1f},{rng.uniform(2, 6):.1f},"
                    f"{rng.uniform(0, 3):.1f},{np.exp(rng.uniform(np.log(0.05), np.log(2))):.4f}")
    (directory / "bench_sections.csv").write_text("\n".join(rows) + "\n")
    toml = TOML.replace('sections = "small_sections.csv"', 'sections = "bench_sections.csv"') \
        .replace("n_blocks = 400", f"n_blocks = {blocks}")
    (directory / "bench.toml").write_text(toml)
    return directory / "bench.toml"


def _warm():
    import simulation
    from riskrf.app import corridor as cr
    c = cr.load_corridor(ROOT / "tests" / "data" / "corridor" / "small.toml")
    simulation.run(c.sections[0].scenario, n=50, seed=1, record_paths=0)
    return True


def _peak_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sections", type=int, default=20)
    ap.add_argument("--blocks", type=int, default=2000)
    args = ap.parse_args()
    import distributed

    from riskrf.app import corridor as cr
    with tempfile.TemporaryDirectory() as d:
        path = make_corridor(Path(d), args.sections, args.blocks)
        corridor = cr.load_corridor(path)
        tables, rates = {}, {}
        for n in (1, 2):
            cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                               dashboard_address=":0")
            client = distributed.Client(cluster)
            try:
                client.run(_warm)
                t0 = time.perf_counter()
                res = cr.run_corridor(corridor, client=client)
                dt = time.perf_counter() - t0
                worker_mb = client.run(_peak_mb)
            finally:
                client.close()
                cluster.close()
            tables[n] = res.table.drop(columns=["seconds"]).sort_values("id").reset_index(drop=True)
            rates[n] = args.sections / dt
            print(f"{n} worker(s): {args.sections} sections x {args.blocks:,} blocks in {dt:.1f} s = "
                  f"{rates[n]:.2f} sections/s ({rates[n] * 60:.1f} per minute), "
                  f"{rates[n] * 2 * args.blocks:,.0f} trajectories/s (2 x blocks per section: the mass-coupled hazard "
                  "and the seeder's reference run; option re-simulations not counted); peak RSS per worker "
                  + ", ".join(f"{v:.0f} MB" for v in worker_mb.values()))
        print(f"parallel efficiency (2 workers): {rates[2] / (2 * rates[1]):.2f}")
        print(f"client peak RSS: {_peak_mb():.0f} MB")
        same = tables[1].equals(tables[2])
        if not same:
            pd.testing.assert_frame_equal(tables[1], tables[2])
        print(f"tables identical between 1 and 2 workers: {same}")
        per_section_s = 1.0 / rates[1]
        print(f"measured cost: {per_section_s:.2f} s per section at {args.blocks:,} blocks on one worker")
        # a worker killed mid-run: its sections are rescheduled on the restarted/other worker; same table
        cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0")
        client = distributed.Client(cluster)
        killed = []
        try:
            client.run(_warm)
            pids = client.run(os.getpid)

            def kill_one(done, total, sid):
                if not killed:
                    victim = sorted(pids)[0]
                    os.kill(pids[victim], signal.SIGKILL)        # the worker process crashes
                    killed.append(victim)

            res = cr.run_corridor(corridor, client=client, progress=kill_one)
        finally:
            client.close()
            cluster.close()
        after = res.table.drop(columns=["seconds"]).sort_values("id").reset_index(drop=True)
        print(f"worker {killed[0]} killed after the first section: {len(res.table)} of {args.sections} sections "
              f"finished, failures {list(res.failures)}; table identical to the undisturbed run: {after.equals(tables[1])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
