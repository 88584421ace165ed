"""Benchmark: is the start-up machinery worth its code?  ``riskrf demo`` timed with each piece on and off.

Run: python tests/benchmarks/bench_startup.py [--rounds N] [-n BLOCKS] [--configs all,no_precompile,...]

Each configuration runs ``riskrf demo`` twice in a row: a *first* run with an empty numba cache (a fresh
``NUMBA_CACHE_DIR``: every kernel compiles, as on a fresh installation) and a *later* run on the cache the first
one wrote.  The configurations are interleaved (A/B/A/B ...) over ``--rounds`` rounds so that a busy machine's
load falls on all of them alike; the wall-clock seconds of every run, the median per configuration and the
load average before and after are printed.  Targets: first run < 30 s, later < 10 s on 2 quiet cores.

Pieces switched off, one at a time, by environment variables the code honours:

* ``no_precompile``  ``RISKRF_NO_PRECOMPILE=1``: no child compiling the simulator on the other core
  (simulation/precompile.py); the kernel compiles on first use in the run's own process.
* ``no_fork``        ``RISKRF_NO_FORK=1``: figures and the rate model are drawn/fitted in the run's own process,
  not in forked children (riskrf/cli/runner.py).
* ``no_gc_freeze``   ``RISKRF_NO_GC_FREEZE=1``: no ``gc.freeze()`` at the command's exit or around a fork.

It also times the lazy public names (simulation/_lazy.py): ``import riskrf.cli`` against importing every public
name at once (what an eager ``__init__`` would cost a light command such as ``riskrf --help``), and, with ``--gc``,
the two uses of ``gc.freeze()`` on the demo's heap: the CPU seconds of the interpreter's exit after ``riskrf demo``
with and without it (riskrf/cli/__init__.py), and of a full collection in a forked child with and without it
(riskrf/cli/runner.py, which freezes before each fork).
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

CONFIGS = {
    "all_on": {},
    "no_precompile": {"RISKRF_NO_PRECOMPILE": "1"},
    "no_fork": {"RISKRF_NO_FORK": "1"},
    "no_gc_freeze": {"RISKRF_NO_GC_FREEZE": "1"},
    "all_off": {"RISKRF_NO_PRECOMPILE": "1", "RISKRF_NO_FORK": "1", "RISKRF_NO_GC_FREEZE": "1"},
}


def _env(extra: dict, cache: str) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("RISKRF_NO_")}
    env.update(extra, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT) + os.pathsep + env.get("PYTHONPATH", ""))
    return env


#: ``riskrf demo`` through the console script's entry point (``riskrf.cli.command``), printing at its very end the CPU
#: seconds of the command's own process and of the children it waited for (forked figure writers, the compiling
#: child), so that the work on the critical path can be told from the work beside it.
_DEMO = """import resource, sys
from riskrf.cli import command
sys.argv[0] = "riskrf"
try:
    status = command()
finally:
    s, c = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    print(f"CPU-SPLIT {s.ru_utime + s.ru_stime:.3f} {c.ru_utime + c.ru_stime:.3f}", file=sys.stderr)
sys.exit(status)
"""


def demo_seconds(env: dict, out: Path, n: int | None) -> tuple[float, float, float]:
    """Wall-clock seconds, total CPU seconds (user + system, the command and every child it waited for) and the
    command's own CPU seconds (its main process: a lower bound of the wall clock on quiet cores) of one
    ``riskrf demo``."""
    cmd = [sys.executable, "-c", _DEMO, "demo", "--out", str(out), "--overwrite"]
    if n is not None:
        cmd += ["-n", str(n)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    done = subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    own = float(next(line for line in done.stderr.splitlines() if line.startswith("CPU-SPLIT")).split()[1])
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), own


_EXIT = """import gc, resource as r, sys
from riskrf.cli import main
main(["demo", "--out", sys.argv[1], "--overwrite"])
if sys.argv[2] == "freeze":
    gc.freeze()
print(sum(x.ru_utime + x.ru_stime for x in (r.getrusage(r.RUSAGE_SELF), r.getrusage(r.RUSAGE_CHILDREN))))
"""

_FORK = """import gc, os, sys
from riskrf.cli import main
main(["demo", "--out", sys.argv[1], "--overwrite"])
for _ in range(int(sys.argv[2])):
    for freeze in (True, False):
        if freeze:
            gc.freeze()
        pid = os.fork()
        if pid == 0:
            gc.collect()
            os._exit(0)
        ru = os.wait4(pid, 0)[2]
        if freeze:
            gc.unfreeze()
        print(f"  forked child's full collection, gc.freeze() {'before' if freeze else 'not before'} the fork: "
              f"CPU {ru.ru_utime + ru.ru_stime:.3f} s, {ru.ru_minflt} page faults (copied pages)", flush=True)
"""


def gc_freeze_figures(rounds: int) -> None:
    """Print the exit cost and a forked child's collection cost with and without ``gc.freeze()`` (warm cache)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("RISKRF_NO_")}
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryDirectory() as work:
        env["NUMBA_CACHE_DIR"] = work
        subprocess.run([sys.executable, "-c", _EXIT, f"{work}/warm", "no"], env=env, check=True,
                       capture_output=True)                                    # fills the numba cache
        for _ in range(rounds):
            for mode in ("freeze", "no"):
                before = resource.getrusage(resource.RUSAGE_CHILDREN)
                out = subprocess.run([sys.executable, "-c", _EXIT, f"{work}/{mode}", mode], env=env, check=True,
                                     capture_output=True, text=True)
                after = resource.getrusage(resource.RUSAGE_CHILDREN)
                total = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
                at_end = float(out.stdout.strip().splitlines()[-1])
                print(f"  exit after riskrf demo, gc.freeze() {'at the end' if mode == 'freeze' else 'not called'}: "
                      f"CPU {total - at_end:.3f} s  (load {os.getloadavg()[0]:.2f})", flush=True)
        out = subprocess.run([sys.executable, "-c", _FORK, f"{work}/fork", str(rounds)], env=env, check=True,
                             capture_output=True, text=True)
        print("\n".join(line for line in out.stdout.splitlines() if line.startswith("  forked")))


def import_seconds(code: str, repeat: int = 5) -> float:
    """Best wall-clock seconds of a fresh interpreter running ``code`` (interpreter start-up included)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], env=env, check=True)
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("-n", type=int, default=None, help="simulated blocks (default: the demo's own)")
    parser.add_argument("--configs", default=",".join(CONFIGS), help="comma-separated subset of " + ", ".join(CONFIGS))
    parser.add_argument("--gc", action="store_true", help="only the gc.freeze() figures (see the module notes)")
    args = parser.parse_args()
    if args.gc:
        print(f"load average before: {os.getloadavg()}  cores: {os.cpu_count()}", flush=True)
        gc_freeze_figures(args.rounds)
        return
    names = args.configs.split(",")
    print(f"load average before: {os.getloadavg()}  cores: {os.cpu_count()}", flush=True)
    first = {k: [] for k in names}
    later = {k: [] for k in names}
    cpu_first = {k: [] for k in names}
    cpu_later = {k: [] for k in names}
    own_first = {k: [] for k in names}
    own_later = {k: [] for k in names}
    work = Path(tempfile.mkdtemp(prefix="bench_startup_"))
    try:
        for r in range(args.rounds):
            for name in names:
                cache = tempfile.mkdtemp(dir=work, prefix="numba_")
                env = _env(CONFIGS[name], cache)
                out = work / f"demo_{name}"
                for wall, cpu, own in (first, cpu_first, own_first), (later, cpu_later, own_later):
                    w, c, o = demo_seconds(env, out, args.n)
                    wall[name].append(w)
                    cpu[name].append(c)
                    own[name].append(o)
                print(f"round {r + 1} {name:14s} first {first[name][-1]:6.1f} s (CPU {cpu_first[name][-1]:5.1f} s, "
                      f"main process {own_first[name][-1]:5.1f} s)  later {later[name][-1]:6.1f} s (CPU "
                      f"{cpu_later[name][-1]:5.1f} s, main process {own_later[name][-1]:5.1f} s)  "
                      f"load {os.getloadavg()[0]:.2f}", flush=True)
                shutil.rmtree(cache, ignore_errors=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"load average after: {os.getloadavg()}")
    print(f"\n{'configuration':14s} {'first run wall [s] median (all)':>40s} {'later run wall [s] median (all)':>40s}"
          f" {'CPU first / later [s] median':>30s} {'main-process CPU first / later [s]':>36s}")
    for name in names:
        f, lt = first[name], later[name]
        print(f"{name:14s} {statistics.median(f):8.1f} ({', '.join(f'{x:.1f}' for x in f):>28s}) "
              f"{statistics.median(lt):8.1f} ({', '.join(f'{x:.1f}' for x in lt):>28s}) "
              f"{statistics.median(cpu_first[name]):14.1f} / {statistics.median(cpu_later[name]):.1f} "
              f"{statistics.median(own_first[name]):20.1f} / {statistics.median(own_later[name]):.1f}")
    print("\nOn quiet cores the wall clock of a run is at least its main-process CPU (the critical path) and, for a "
          "run without children, about its total CPU.")
    lazy = import_seconds("import riskrf, riskrf.cli, simulation")
    eager = import_seconds("import riskrf, riskrf.cli, simulation\n"
                           "for p in (riskrf, simulation):\n    [getattr(p, n) for n in p.__all__]")
    print(f"\nimport riskrf.cli (lazy public names): {lazy:.2f} s; with every public name imported (eager): "
          f"{eager:.2f} s (best of 5, interpreter start-up included)")


if __name__ == "__main__":
    main()
