"""Corridor scale: sections per minute on 1 and 2 local dask workers, the serial share, and the expected time
on 16 and 64 workers from the measured parts.

    python tests/benchmarks/bench_corridor.py [--sections 5000] [--run 24] [--blocks 1000] [--kill]

A SYNTHETIC corridor of ``--sections`` generated cuts (200 m each; heights 10-50 m, rates 0.05-2 falls reaching
the road per year, typed mass law, RHRS attributes; a meandering generated centreline) is written to a temporary
directory.  Measured:

* serial, on the full corridor: reading and checking it (``load_corridor``); dispatch (scatter + one task per
  section through the scheduler, with the section pickled as in a real run, the work itself replaced by a no-op);
  writing the outputs (``write_corridor`` with a budget: CSV, sections.gpkg, chainage figure, map, HTML report,
  rating sheets, the exact programme and its frontier; the programme's mixed-integer solves are timed apart
  because their cost is not linear in the sections).  The result table of all sections is the ``--run``
  sections' real rows repeated along the chainage (the report's cost depends on the row count, not on values).
* parallel: the section tasks, on the first ``--run`` sections, on 1 and then 2 worker processes (warm), with the
  two tables compared.

Expected time on W workers = serial + sections / (rate on 1 worker x W x efficiency), with the efficiency
measured on 2 workers (an assumption for W > 2: the tasks are independent, so it is the machine's, not the
method's) and with efficiency 1 (the bound).  ``--kill``: also kill one of two workers mid-run and check the
table is unchanged.
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

TOML = (ROOT / "tests" / "data" / "corridor" / "small.toml").read_text()


def make_corridor(directory: Path, sections: int, blocks: int) -> Path:
    from riskrf.io.gis import centreline_from_vertices, write_centreline
    rng = np.random.default_rng(2024)
    rows = ["id,chainage_from,chainage_to,cut_height_m,ditch_width_m,runout_to_road_m,falls_per_year,"
            "rhrs_rockfall_history"]
    hist = ("few", "occasional", "many", "constant")
    for i in range(sections):
        rows.append(f"S{i:05d},{i * 200},{(i + 1) * 200},{rng.uniform(10, 50):.1f},{rng.uniform(2, 6):.1f},"
                    f"{rng.uniform(0, 3):.1f},{np.exp(rng.uniform(np.log(0.05), np.log(2))):.4f},"
                    f"{hist[rng.integers(4)]}")
    (directory / "bench_sections.csv").write_text("\n".join(rows) + "\n")
    # a meandering road: 100 m steps with a slowly turning heading, long enough for every section
    n = sections * 2 + 2
    heading = np.cumsum(rng.normal(0, 0.08, n))
    xy = np.cumsum(np.column_stack([np.cos(heading), np.sin(heading)]) * 100.0, axis=0) + [5.0e5, 6.9e6]
    write_centreline(centreline_from_vertices(xy, crs="EPSG:25833"), directory / "road.gpkg")
    toml = TOML.replace('sections = "small_sections.csv"', 'sections = "bench_sections.csv"\ncentreline = "road.gpkg"') \
        .replace("n_blocks = 400", f"n_blocks = {blocks}")
    (directory / "bench.toml").write_text(toml)
    return directory / "bench.toml"


def _warm():
    import simulation
    from riskrf.app import corridor as cr
    c = cr.load_corridor(ROOT / "tests" / "data" / "corridor" / "small.toml")
    simulation.run(c.sections[0].scenario, n=50, seed=1, record_paths=0)
    return True


def _noop(section, corridor):
    return section.id


def _cluster(n):
    import distributed
    cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0")
    return distributed.Client(cluster), cluster


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sections", type=int, default=5000)
    ap.add_argument("--run", type=int, default=24, help="sections actually assessed on 1 and 2 workers")
    ap.add_argument("--blocks", type=int, default=1000)
    ap.add_argument("--kill", action="store_true")
    args = ap.parse_args()
    from riskrf.app import corridor as cr
    from riskrf.app.corridor.outputs import FRONTIER_POINTS
    with tempfile.TemporaryDirectory() as d:
        path = make_corridor(Path(d), args.sections, args.blocks)
        t0 = time.perf_counter()
        corridor = cr.load_corridor(path)
        t_load = time.perf_counter() - t0
        sub = replace(corridor, sections=corridor.sections[:args.run])
        tables, rate = {}, {}
        for n in (1, 2):
            client, cluster = _cluster(n)
            try:
                client.run(_warm)
                t0 = time.perf_counter()
                res = cr.run_corridor(sub, client=client, keep_going=True)
                dt = time.perf_counter() - t0
                if n == 2:                       # dispatch of every section through the scheduler, no work
                    t0 = time.perf_counter()
                    cf = client.scatter(replace(corridor, sections=()), broadcast=True)
                    futs = [client.submit(_noop, s, cf, key=f"noop-{s.id}") for s in corridor.sections]
                    client.gather(futs)
                    t_dispatch = time.perf_counter() - t0
            finally:
                client.close()
                cluster.close()
            tables[n] = res.table.drop(columns=["seconds"]).sort_values("id").reset_index(drop=True)
            rate[n] = len(res.table) / dt * 60.0
            print(f"{n} worker(s): {len(res.table)} sections ({len(res.failures)} failed: no block reached the barrier) x {args.blocks:,} blocks in {dt:.1f} s = {rate[n]:.1f} "
                  "sections/min")
        same = tables[1].equals(tables[2])
        print(f"tables identical on 1 and 2 workers: {same}")
        if not same:
            pd.testing.assert_frame_equal(tables[1], tables[2])
        # the full result table: the real rows repeated along the chainage
        rows = tables[1]
        big = pd.concat([rows] * (args.sections // len(rows) + 1), ignore_index=True).iloc[:args.sections].copy()
        secs = corridor.sections
        big["id"] = [s.id for s in secs]
        big["chainage_from_m"] = [s.chainage_from_m for s in secs]
        big["chainage_to_m"] = [s.chainage_to_m for s in secs]
        full = cr.CorridorResult(corridor=corridor, table=big, workers=2, n_blocks=args.blocks)
        budget = float(full.options_table()["capital"].sum()) * 0.1
        t0 = time.perf_counter()
        prog = full.programme(budget)
        t_prog = time.perf_counter() - t0
        pts = FRONTIER_POINTS[0] if args.sections <= FRONTIER_POINTS[2] else FRONTIER_POINTS[1]
        t0 = time.perf_counter()
        front = full.frontier(points=pts)
        t_front = time.perf_counter() - t0
        t0 = time.perf_counter()
        cr.write_corridor(full, Path(d) / "out", budget=budget, programme=prog, frontier=front)
        t_report = time.perf_counter() - t0
        t_write = t_report + t_prog + t_front
        print(f"serial parts for {args.sections:,} sections: load and check {t_load:.1f} s, dispatch {t_dispatch:.1f} s, "
              f"outputs without the optimiser {t_report:.1f} s ({t_report / args.sections * 1e3:.2f} ms per section), "
              f"programme {t_prog:.1f} s (gap {prog.gap:.1e}, {len(prog.chosen)} funded), frontier of {pts} points "
              f"{t_front:.1f} s (max gap {front.table['gap'].max():.1e})")
        serial = t_load + t_dispatch + t_write
        par1 = args.sections / rate[1] * 60.0
        per_task = t_dispatch / args.sections
        print(f"dispatch {per_task * 1e3:.1f} ms per section through the scheduler: it overlaps the work, but the "
              f"scheduler alone cannot feed more than {par1 / args.sections / per_task:.0f} workers at "
              f"{par1 / args.sections:.2f} s per section (counted as serial below: an upper bound)")
        eff = rate[2] / (2 * rate[1])
        print(f"one worker: {par1 / 3600:.2f} h of section tasks + {serial:.0f} s serial -> serial share "
              f"{serial / (serial + par1):.2%}; 2-worker efficiency {eff:.2f} ({rate[2] / rate[1]:.2f}x)")
        for w in (16, 64):
            t_meas = serial + par1 / (w * eff)
            t_ideal = serial + par1 / w
            print(f"expected on {w} workers: {t_meas / 60:.1f} min at the measured efficiency "
                  f"(serial {serial / t_meas:.0%} of it), {t_ideal / 60:.1f} min at efficiency 1 "
                  f"(serial {serial / t_ideal:.0%})")
        if args.kill:
            client, cluster = _cluster(2)
            killed = []
            try:
                client.run(_warm)
                pids = client.run(os.getpid)

                def kill_one(done, total, sid):
                    if not killed:
                        victim = sorted(pids)[0]
                        os.kill(pids[victim], signal.SIGKILL)
                        killed.append(victim)

                res = cr.run_corridor(sub, client=client, progress=kill_one, keep_going=True)
            finally:
                client.close()
                cluster.close()
            after = res.table.drop(columns=["seconds"]).sort_values("id").reset_index(drop=True)
            print(f"worker killed after the first section: {len(res.table)} of {args.run} finished, failures "
                  f"{list(res.failures)}; table identical to the undisturbed run: {after.equals(tables[1])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
