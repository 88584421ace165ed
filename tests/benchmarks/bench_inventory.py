"""Benchmark: reading (and optionally fitting) a European-style export of 10^6 rock falls.

Run: python tests/benchmarks/bench_inventory.py [--n 1000000] [--fit] [--bootstrap 20] [--cli]

Writes a semicolon-separated file with day-first dotted dates (``05.03.2019``) and decimal
commas (``0,0139``), cp1252-encoded with ``Volumen [m³]`` in the header, into a temporary
directory (in a child process), then times :func:`riskrf.read_inventory` on it and prints
the wall time and the process's peak resident memory (``ru_maxrss``: the interpreter,
numpy, pandas and pyarrow included).  With ``--fit`` it also times
:func:`riskrf.fit_gutenberg_richter` on the masses (no bootstrap); with ``--bootstrap N`` it
times N replicates of the goodness-of-fit bootstrap with 1 and with 2 worker threads (the
default grid of 2,000 thresholds above 100,000 falls) and prints the time per replicate;
with ``--cli`` it runs ``riskrf fit --bootstrap 0`` on the file in a child process and
prints its wall time and peak memory (``ru_maxrss`` of the child).  The volumes are
synthetic (lognormal), the dates uniform over 30 years: this measures the reader, not a site.
"""
from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd


def make_file(path: Path, n: int, seed: int = 1) -> None:
    rng = np.random.default_rng(seed)
    dates = pd.Timestamp("1990-01-01") + pd.to_timedelta(rng.integers(0, 30 * 365, n), unit="D")
    vols = np.exp(rng.normal(-3.0, 1.5, n))
    text = pd.Series(np.char.mod("%.6g", vols)).str.replace(".", ",", regex=False)
    lines = "\n".join(dates.strftime("%d.%m.%Y") + ";" + text.to_numpy())
    path.write_bytes(("Datum;Volumen [m³]\n" + lines + "\n").encode("cp1252"))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--fit", action="store_true", help="also fit the power law (no bootstrap)")
    ap.add_argument("--bootstrap", type=int, default=0, metavar="N",
                    help="with --fit: time N bootstrap replicates with 1 and 2 workers")
    ap.add_argument("--cli", action="store_true", help="also time 'riskrf fit --bootstrap 0' in a child process")
    ap.add_argument("--make", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.make:
        make_file(Path(args.make), args.n)
        return

    def peak_mb():
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    import riskrf
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "kataster.csv"
        subprocess.run([sys.executable, __file__, "--make", str(f), "--n", str(args.n)], check=True)
        print(f"peak memory after imports {peak_mb():.0f} MB")
        print(f"{args.n:,} rows, {f.stat().st_size / 1e6:.1f} MB (cp1252, ';', decimal commas, DD.MM.YYYY)")
        t = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            inv = riskrf.read_inventory(f, density_kg_m3=2650, duplicates="keep")
        read_s = time.perf_counter() - t
        print(f"read_inventory: {read_s:.1f} s, peak memory {peak_mb():.0f} MB; "
              f"{inv.n_events:,} events, record {inv.start} to {inv.end}")
        if args.fit:
            t = time.perf_counter()
            gr = riskrf.fit_gutenberg_richter(inv.masses, inv.duration_years)
            fit_s = time.perf_counter() - t
            print(f"fit_gutenberg_richter (KS threshold search, no bootstrap): {fit_s:.1f} s, peak memory "
                  f"{peak_mb():.0f} MB; b = {gr.b:.4f}, m_min = {gr.m_min:.4g} kg")
            print(f"read + fit: {read_s + fit_s:.1f} s")
            for workers in (1, 2) if args.bootstrap else ():
                t = time.perf_counter()
                res = gr.bootstrap_test(args.bootstrap, seed=1, workers=workers)
                per = (time.perf_counter() - t) / args.bootstrap
                print(f"bootstrap, {workers} worker(s): {per:.3f} s per replicate ({args.bootstrap} replicates, "
                      f"threshold grid {res.grid}); 1,000 replicates ~ {per * 1000:.0f} s; peak memory "
                      f"{peak_mb():.0f} MB")
        if args.cli:
            out = Path(d) / "fit-out"
            t = time.perf_counter()
            code = ("import resource, sys; from riskrf.cli import main; "
                    f"rc = main(['fit', {str(f)!r}, '--density', '2650', '--duplicates', 'keep', '--bootstrap', '0', "
                    f"'--out', {str(out)!r}]); "
                    "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr); sys.exit(rc)")
            run = subprocess.run([sys.executable, "-c", code], check=True, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.PIPE, text=True)
            cli_s = time.perf_counter() - t
            child = int(run.stderr.strip().splitlines()[-1]) / 1024
            print(f"riskrf fit --bootstrap 0 (whole command: imports, read, fits, figures): {cli_s:.1f} s, "
                  f"peak memory {child:.0f} MB")


if __name__ == "__main__":
    main()
