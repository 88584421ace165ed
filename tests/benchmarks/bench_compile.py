"""Benchmark: first compilation of the numba kernels (the demo's first run).

Run: python tests/benchmarks/bench_compile.py [--repeat N]
Each group of kernels is compiled in a fresh interpreter with an empty ``NUMBA_CACHE_DIR``, after numba's own
one-time start-up (a trivial function compiled first); the CPU seconds of the compilation are printed, best of
N runs (default 2).  The groups are those a first ``riskrf demo`` compiles: the trajectory simulator (on the
second core, beside the fits), the power-law threshold search and the GEV/Gumbel likelihood kernels.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

_START = """
import time, numba, numpy as np
@numba.njit
def _trivial(x):
    return x + 1
_trivial(1)
"""

GROUPS = {
    "trajectory simulator (simulation.kernel)": """
import simulation, simulation.engine
t = time.process_time()
simulation.run(simulation.load_scenario(SCENARIO), n=4, seed=0, record_paths=4)
""",
    "power-law threshold search (riskrf.frequency._power_law_kernels)": """
from riskrf import find_m_min
t = time.process_time()
find_m_min(np.random.default_rng(1).pareto(1.0, 500) + 1.0)
""",
    "GEV / Gumbel likelihood (riskrf.frequency._extremes_kernels)": """
from riskrf import fit_gev
t = time.process_time()
fit = fit_gev(np.random.default_rng(1).gumbel(10.0, 2.0, 37))
fit.return_level_ci(100, method="profile")
""",
}


def compile_cpu(snippet: str) -> float:
    """CPU seconds to run ``snippet`` (from its ``t = time.process_time()``) with an empty numba cache, after
    numba's start-up and the snippet's imports."""
    scenario = ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml"
    code = _START + snippet.replace("SCENARIO", repr(str(scenario))) + "\nprint(time.process_time() - t)\n"
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    return float(out.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    total = 0.0
    for name, snippet in GROUPS.items():
        best = min(compile_cpu(snippet) for _ in range(args.repeat))
        total += best
        print(f"{name}: {best:.1f} CPU-s (best of {args.repeat})")
    print(f"all kernels: {total:.1f} CPU-s; load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
