"""Benchmark: KS threshold search and bootstrap p-value.

Run: python tests/benchmarks/bench_powerlaw_fit.py
Prints the time of the (exact) KS threshold search on 100,000 masses, checked against the
exhaustive O(N^2) scan on 20,000 masses, the time of one GEV profile-likelihood interval,
and of 1,000 bootstrap
replicates on 1,000 masses, side by side with fitting each replicate with the
``powerlaw`` package (Alstott et al. 2014) when it is installed (optional).
"""
from __future__ import annotations

import time
import warnings

import numpy as np

from riskrf import find_m_min, fit_gutenberg_richter


def sample(n, seed, b=0.7, body=0.3):
    rng = np.random.default_rng(seed)
    k = int(n * (1 - body))
    tail = 10.0 * (1 - rng.uniform(size=k)) ** (-1 / b)
    low = rng.uniform(1.0, 10.0, size=n - k)
    return np.concatenate([tail, low])


def main():
    find_m_min(sample(2000, 0))  # compile the kernels once
    find_m_min(sample(2000, 0), exhaustive=True)
    x = sample(100_000, 1)
    for statistic in ("clauset", "sup"):
        times = []
        for _ in range(3):
            t = time.perf_counter()
            m_min, D, b = find_m_min(x, statistic=statistic)
            times.append(time.perf_counter() - t)
        print(f"KS threshold search ({statistic}), 100,000 masses: {min(times):.3f} s best of 3 "
              f"(m_min = {m_min:.3f}, D = {D:.6f}, b = {b:.4f})")
    z = sample(20_000, 4)
    t = time.perf_counter()
    full = find_m_min(z, exhaustive=True)
    t_full = time.perf_counter() - t
    t = time.perf_counter()
    fast = find_m_min(z)
    t_fast = time.perf_counter() - t
    print(f"20,000 masses: exact search {t_fast:.3f} s, exhaustive scan {t_full:.2f} s, same result: {fast == full}")

    from scipy import stats

    from riskrf import fit_gev
    maxima = stats.genextreme(-0.5, loc=100, scale=20).rvs(size=40, random_state=np.random.default_rng(5))
    gev = fit_gev(maxima)
    gev.return_level_ci(100)  # compile
    t = time.perf_counter()
    for _ in range(10):
        lo, hi = gev.return_level_ci(100)
    print(f"GEV profile-likelihood interval (n = 40, xi-hat = {gev.shape:.2f}, T = 100 yr): "
          f"{(time.perf_counter() - t) / 10 * 1000:.1f} ms per call -> [{float(lo):.4g}, {float(hi):.4g}]")

    y = sample(1000, 2)
    fit = fit_gutenberg_richter(y, 10.0)
    n_boot = 1000
    t = time.perf_counter()
    p = fit.bootstrap_pvalue(n_boot, seed=3)
    ours = time.perf_counter() - t
    print(f"riskrf bootstrap p-value, {n_boot} replicates x 1,000 masses: {ours:.2f} s (p = {p:.3f})")
    try:
        import powerlaw
    except ImportError:
        print("powerlaw not installed: `pip install powerlaw` to compare")
        return
    # Same replicates, each fitted with powerlaw.Fit (xmin search + alpha), timed on a subset.
    n_peer = 50
    rng = np.random.default_rng(3)
    body = y[y < fit.m_min]
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(n_peer):
            k = rng.binomial(y.size, fit.n_tail / y.size)
            rep = np.concatenate([fit.rvs(k, rng), rng.choice(body, y.size - k)])
            powerlaw.Fit(rep, verbose=False).power_law.D
    peer = (time.perf_counter() - t) / n_peer * n_boot
    print(f"powerlaw {powerlaw.__version__}: {n_peer} replicates timed, {n_boot} extrapolated: {peer:.1f} s")
    print(f"speed-up: {peer / ours:.0f}x")


if __name__ == "__main__":
    main()
