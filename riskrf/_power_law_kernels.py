"""Compiled inner loops of the power-law fit (Kolmogorov-Smirnov threshold scan).

Kept apart from :mod:`riskrf.power_law` so that the statistics read as
statistics; these functions only evaluate sums over sorted samples.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def ks_scan(logx, suffix_log, first, last, candidates):
    """KS distance and MLE exponent for each candidate threshold index.

    Parameters
    ----------
    logx : ascending natural logs of the sample.
    suffix_log : ``suffix_log[k] = sum(logx[k:])`` (length N + 1).
    first, last : for each position, the first and last index holding the same value.
    candidates : indices k; the threshold is ``exp(logx[k])`` and k is a first occurrence.

    Returns
    -------
    (D, b) arrays: the KS distance between the tail's empirical CDF (ties
    handled exactly) and the fitted continuous power law
    ``F(x) = 1 - (x / x_min)^-b`` with ``b = n / sum(ln(x_i / x_min))``.
    """
    N = logx.shape[0]
    D = np.full(candidates.shape[0], np.inf)
    B = np.full(candidates.shape[0], np.nan)
    for c in range(candidates.shape[0]):
        k = candidates[c]
        n = N - k
        s = suffix_log[k] - n * logx[k]
        if s <= 0.0:
            continue
        b = n / s
        d = 0.0
        for j in range(k, N):
            F = 1.0 - np.exp(-b * (logx[j] - logx[k]))
            hi = abs(F - (last[j] - k + 1) / n)
            lo = abs(F - (first[j] - k) / n)
            if hi > d:
                d = hi
            if lo > d:
                d = lo
        D[c] = d
        B[c] = b
    return D, B
