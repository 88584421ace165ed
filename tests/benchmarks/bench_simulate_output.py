"""Where the time of ``riskrf simulate`` goes, and what writing its tables costs.

Run from the repository root::

    python tests/benchmarks/bench_simulate_output.py [-n 1000000] [--repeat 3] [--cli] [--before DIR]

In one process it times the stages of ``riskrf simulate`` on the shipped barrier scenario: the kernel
(``simulation.run``), building the crossings table, the printed summary, drawing the figures, then writing
the three tables (crossings, ``runout``, ``envelopes``) with :func:`riskrf.io.outputs.write_csv` and as
Parquet when pyarrow is installed; it runs that sequence ``--repeat`` times (default 3) and prints the median of
each stage and of the share of writing in the run (kernel + table + summary + figures + writing, one after the
other), with each run's share.  The previous writer (pandas ``to_csv``, then every cell read back and checked one
by one, timed apart) is timed once, for comparison.  Stage times are wall seconds of one
process; the machine's other jobs move them.

With ``--cli`` it also runs the whole command in a child process (``--format csv`` and ``--format parquet``)
and prints its wall time and peak memory (the child's maximum resident set).  ``--before DIR`` runs the same
command from another source tree beside it (e.g. ``git archive COMMIT | tar -x -C DIR``), whose numba cache is
warmed by a small run first.
"""
from __future__ import annotations

import argparse
import csv
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml"


def previous_neutralise(path) -> None:
    """The cell-by-cell check of every CSV in the previous writer (read whole, rewrite when a cell changed)."""
    from riskrf.io.outputs import _neutralise_cell
    with open(path, newline="", encoding="utf-8", errors="surrogateescape") as fh:
        rows = list(csv.reader(fh))
    changed = False
    for row in rows:
        for j, cell in enumerate(row):
            new = _neutralise_cell(cell)
            if new is not cell:
                row[j] = new
                changed = True
    if changed:
        with open(path, "w", newline="", encoding="utf-8", errors="surrogateescape") as fh:
            csv.writer(fh, lineterminator="\n").writerows(rows)


def _timed(fn, *args, **kwargs) -> float:
    t0 = time.perf_counter()
    fn(*args, **kwargs)
    return time.perf_counter() - t0


def stages(n: int, seed: int, folder: Path, repeat: int = 3) -> float:
    """Time the stages of ``riskrf simulate`` in this process, ``repeat`` times over, and print their medians.

    Each repetition runs the whole sequence (kernel, table build, summary, figures, then ``write_csv`` and Parquet
    into new files), so that the machine's noise moves every stage alike; the share of writing is taken per
    repetition and its median printed beside the range.  The previous writer (slow) is timed once.
    """
    import statistics

    import matplotlib
    matplotlib.use("Agg")
    import pandas as pd

    import simulation
    from riskrf.io.outputs import write_csv, write_parquet
    from riskrf.report import files as report_files

    sc = simulation.load_scenario(SCENARIO)
    simulation.run(sc, n=1000, seed=seed)                       # compilation (cached on disk) out of the timing
    names = ("crossings", "runout", "envelopes")
    runs = []
    for k in range(repeat):
        t = {}
        t0 = time.perf_counter()
        result = simulation.run(sc, n=n, seed=seed)
        t["kernel"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        crossings = pd.concat([result.collector(c.name).assign(collector=c.name) for c in sc.collectors],
                              ignore_index=True)
        crossings["outcome"] = crossings["outcome"].astype(str)
        tables = {"crossings": crossings, "runout": result.runout, "envelopes": result.envelopes}
        t["build"] = time.perf_counter() - t0
        t["summary"] = _timed(result.summary)
        figs = folder / f"figures-{k}"
        figs.mkdir()
        t["figures"] = _timed(report_files.write_simulation_figures, result, figs, [c.name for c in sc.collectors])
        for name in names:
            t[f"csv {name}"] = _timed(write_csv, tables[name], folder / f"{name}-{k}.csv")
            try:
                t[f"parquet {name}"] = _timed(write_parquet, tables[name], folder / f"{name}-{k}.parquet")
            except ImportError:
                t[f"parquet {name}"] = float("nan")
        runs.append(t)
        if k < repeat - 1:
            del result, crossings, tables

    rows = []
    for name in names:
        table = tables[name]
        old = folder / f"{name}-previous.csv"
        to_csv = _timed(table.to_csv, old, index=False)
        neutral = _timed(previous_neutralise, old)
        same = all((folder / f"{name}-{k}.csv").read_bytes() == old.read_bytes() for k in range(repeat))
        pq = folder / f"{name}-0.parquet"
        mb_parquet = pq.stat().st_size / 1e6 if pq.exists() else float("nan")
        med = {key: statistics.median(r[f"{key} {name}"] for r in runs) for key in ("csv", "parquet")}
        rows.append((name, len(table), to_csv, neutral, med["csv"], med["parquet"], old.stat().st_size / 1e6,
                     mb_parquet, same))

    def median(key):
        return statistics.median(r[key] for r in runs)

    def base(r):
        return r["kernel"] + r["build"] + r["summary"] + r["figures"]

    def share(r, kind):
        w = sum(r[f"{kind} {name}"] for name in names)
        return w, w / (base(r) + w)

    prev = sum(r[2] + r[3] for r in rows)
    print(f"riskrf simulate stages, {n:,} blocks of {SCENARIO.name}, seed {seed} "
          f"(wall s, one process, median of {repeat} runs of the whole sequence)")
    print(f"  kernel (simulation.run)      {median('kernel'):8.2f}")
    print(f"  table build (crossings)      {median('build'):8.2f}")
    print(f"  printed summary              {median('summary'):8.2f}")
    print(f"  figures (4 PNG)              {median('figures'):8.2f}")
    print(f"  {'table':<12}{'rows':>10}{'to_csv':>9}{'neutral.':>10}{'previous':>10}{'write_csv':>11}"
          f"{'parquet':>9}{'CSV MB':>8}{'PQ MB':>7}  identical")
    for name, nrows, to_csv, neutral, new, parquet, mb, mbp, same in rows:
        print(f"  {name:<12}{nrows:>10,}{to_csv:>9.2f}{neutral:>10.2f}{to_csv + neutral:>10.2f}{new:>11.2f}"
              f"{parquet:>9.2f}{mb:>8.1f}{mbp:>7.1f}  {'yes' if same else 'NO'}")
    neutral = sum(r[3] for r in rows)
    base_med = statistics.median(base(r) for r in runs)
    print(f"  writing, previous (once): {prev:.2f} s = {prev / (base_med + prev):.0%} of the run "
          f"(neutralising {neutral:.2f} s = {neutral / (base_med + prev):.0%})")
    csv_runs = [share(r, "csv") for r in runs]
    csv_share = statistics.median(s for _, s in csv_runs)
    print(f"  writing, CSV now:  {statistics.median(w for w, _ in csv_runs):.2f} s = {csv_share:.0%} of the run, "
          f"median of {', '.join(f'{s:.0%}' for _, s in csv_runs)} "
          f"({'PASS' if csv_share <= 0.20 else 'FAIL'}: target <= 20 %)")
    pq_runs = [share(r, "parquet") for r in runs]
    if all(w == w for w, _ in pq_runs):
        print(f"  writing, Parquet:  {statistics.median(w for w, _ in pq_runs):.2f} s = "
              f"{statistics.median(s for _, s in pq_runs):.0%} of the run")
    return statistics.median(w for w, _ in csv_runs)


def _child(cmd, cwd, env) -> tuple[float, float, int]:
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        sys.exit(f"{' '.join(map(str, cmd))} failed: {proc.stderr.read().decode()}")
    return wall, usage.ru_maxrss / 1024, proc.returncode          # ru_maxrss is in KiB on Linux


def whole_command(n: int, seed: int, folder: Path, trees: dict, write_s: float) -> None:
    """Run ``riskrf simulate`` in child processes from each source tree; print wall time and peak memory, and
    ``write_s`` (this tree's CSV writing, timed in :func:`stages`) as a share of this tree's CSV run."""
    print(f"\nwhole command: python -m riskrf.cli simulate {SCENARIO.relative_to(ROOT)} -n {n} --seed {seed} "
          "--no-progress --out run.<csv|parquet> (child process)")
    for label, tree in trees.items():
        env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(tree))
        base = [sys.executable, "-m", "riskrf.cli", "simulate", str(SCENARIO), "--seed", str(seed),
                "--no-progress"]
        warm = folder / f"warm-{label}"
        _child(base + ["-n", "1000", "--out", str(warm / "w.csv")], folder, env)      # numba cache of this tree
        for fmt in ("csv", "parquet"):
            out = folder / f"{label}-{fmt}"
            wall, peak, _ = _child(base + ["-n", str(n), "--out", str(out / f"run.{fmt}")], folder, env)
            size = sum(p.stat().st_size for p in out.rglob("*") if p.is_file()) / 1e6
            print(f"  {label:<8} {fmt:<8} {wall:7.2f} s  peak {peak:7.0f} MiB  outputs {size:6.1f} MB")
            shutil.rmtree(out, ignore_errors=True)
            if label == "now" and fmt == "csv":
                print(f"           CSV writing ({write_s:.2f} s, timed above) = {write_s / wall:.0%} of this run "
                      f"(the figures are drawn on the other core meanwhile)")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=1_000_000, help="blocks (default 10^6)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3, help="runs of the whole stage sequence (default 3; medians)")
    ap.add_argument("--cli", action="store_true", help="also run the whole command in child processes")
    ap.add_argument("--before", default=None, metavar="DIR",
                    help="with --cli: a source tree of an earlier commit, run beside this one")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench-simulate-output-") as tmp:
        folder = Path(tmp)
        write_s = stages(args.n, args.seed, folder, args.repeat)
        if args.cli:
            trees = {"now": ROOT}
            if args.before:
                trees = {"before": Path(args.before).resolve(), **trees}
            whole_command(args.n, args.seed, folder, trees, write_s)
    print(f"\nload average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
