"""Compiled inner loops of the power-law fit (Kolmogorov-Smirnov threshold scan).

Kept apart from :mod:`riskrf.frequency.power_law` so that the statistics read as
statistics; these functions only evaluate sums over sorted samples.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def tail_ks(logx, first, last, k, b):
    """KS distance of the tail from index k to the power law F(x) = 1 - (x / x_k)^-b, over every point.

    The empirical CDF is compared on both sides of each jump: ``last``/``first`` index arrays give the
    step heights (see :func:`riskrf.frequency.power_law.threshold._tail_arrays`).
    """
    return _ks_over(logx, first, last, k, b, k, logx.shape[0], 0.0)


@njit(cache=True)
def _ks_over(logx, first, last, k, b, j0, j1, d):
    """max(d, KS deviations at positions j0 .. j1 - 1) of the tail from index k (both sides of each jump)."""
    n = logx.shape[0] - k
    for j in range(j0, j1):
        F = 1.0 - np.exp(-b * (logx[j] - logx[k]))
        hi = abs(F - (last[j] - k + 1) / n)
        lo = abs(F - (first[j] - k) / n)
        if hi > d:
            d = hi
        if lo > d:
            d = lo
    return d


@njit(cache=True, nogil=True)
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
        D[c] = tail_ks(logx, first, last, k, b)
        B[c] = b
    return D, B


@njit(cache=True)
def _ks_bounds(logx, first, last, k, b, m):
    """Lower and upper bounds of the KS distance of the tail from index k, from m rank-spaced points.

    The lower bound is the distance at the m points (a maximum over fewer points).  Between two
    sampled positions a < b the model CDF F and the empirical CDF are both non-decreasing, so every
    deviation there is at most max(F_b - E_lo(a), E_hi(b) - F_a): that gives the upper bound.  With
    m at least the tail size every point is visited and both bounds equal the distance of
    :func:`ks_scan` (same arithmetic, so the same floating-point value).
    """
    N = logx.shape[0]
    n = N - k
    d = 0.0
    if m >= n:
        d = tail_ks(logx, first, last, k, b)
        return d, d
    ub = 0.0
    prev_F = 0.0
    prev_lo = 0.0
    for i in range(m):
        j = k + (i * (n - 1)) // (m - 1)
        F = 1.0 - np.exp(-b * (logx[j] - logx[k]))
        e_hi = (last[j] - k + 1) / n
        e_lo = (first[j] - k) / n
        hi = abs(F - e_hi)
        lo = abs(F - e_lo)
        if hi > d:
            d = hi
        if lo > d:
            d = lo
        if i > 0:
            g = max(F - prev_lo, e_hi - prev_F)
            if g > ub:
                ub = g
        prev_F = F
        prev_lo = e_lo
    return d, max(d, ub)


@njit(cache=True)
def _ks_exact(logx, first, last, k, b, stop, F_buf, hi_buf, lo_buf):
    """KS distance of the tail from index k, or any value above ``stop`` once it is sure to exceed it.

    First every 64th position (and the last) is evaluated; then only the blocks between them whose
    bound max(F_right - E_lo(left), E_hi(right) - F_left) (both CDFs are non-decreasing) could
    exceed the running maximum are scanned point by point.  Points that are skipped cannot raise the
    maximum, so the value returned (when <= stop) is the distance of :func:`ks_scan` exactly.
    """
    N = logx.shape[0]
    n = N - k
    d = 0.0
    nb = 0
    j = k
    while True:
        F = 1.0 - np.exp(-b * (logx[j] - logx[k]))
        e_hi = (last[j] - k + 1) / n
        e_lo = (first[j] - k) / n
        F_buf[nb] = F
        hi_buf[nb] = e_hi
        lo_buf[nb] = e_lo
        nb += 1
        d = max(d, abs(F - e_hi), abs(F - e_lo))
        if j == N - 1:
            break
        j = min(j + 64, N - 1)
    if d > stop:
        return d
    for i in range(nb - 1):
        if max(F_buf[i + 1] - lo_buf[i], hi_buf[i + 1] - F_buf[i]) + 1e-12 <= d:
            continue
        a = k + 64 * i
        e = min(a + 64, N - 1)
        d = _ks_over(logx, first, last, k, b, a + 1, e, d)
        if d > stop:
            return d
    return d


@njit(cache=True, nogil=True)
def ks_lower_bounds(logx, suffix_log, first, last, candidates):
    """MLE exponent and a lower bound of the KS distance of each candidate, from 32 rank-spaced points of its
    tail (:func:`_ks_bounds`); (NaN, inf) for a candidate whose tail has no spread.  Returns (B, lb)."""
    N = logx.shape[0]
    C = candidates.shape[0]
    B = np.empty(C)
    lb = np.empty(C)
    for c in range(C):
        k = candidates[c]
        n = N - k
        s = suffix_log[k] - n * logx[k]
        B[c] = np.nan
        lb[c] = np.inf
        if s > 0.0:
            B[c] = n / s
            lb[c] = _ks_bounds(logx, first, last, k, B[c], 32)[0]
    return B, lb


@njit(cache=True, nogil=True)
def ks_scan_best(logx, first, last, candidates, B, lb, order):
    """The candidate of :func:`ks_scan` with the smallest KS distance, found exactly by bounding.

    ``B`` and ``lb`` are the exponents and lower bounds of :func:`ks_lower_bounds`; ``order`` sorts ``lb``
    (done by numpy outside: a sort compiled here would double this kernel's compilation time).  Candidates are
    visited in increasing order of their bound; each one's distance is computed exactly (:func:`_ks_exact`,
    abandoned as soon as it exceeds the best so far), and the visit stops at the first bound above the best
    distance.  The result equals the first minimum of the exhaustive :func:`ks_scan` (ties go to the lower
    threshold, as ``argmin`` does, whatever the order of equal bounds), at a cost near O(N log N) on
    power-law-like samples instead of O(N^2).

    Returns (position in ``candidates``, D); position -1 if no candidate has a tail with spread.
    """
    N = logx.shape[0]
    C = candidates.shape[0]
    size = N // 64 + 2
    F_buf = np.empty(size)
    hi_buf = np.empty(size)
    lo_buf = np.empty(size)
    best = -1
    best_d = np.inf
    for r in range(C):
        c = order[r]
        if not lb[c] < np.inf or lb[c] > best_d:
            break
        d = _ks_exact(logx, first, last, candidates[c], B[c], best_d, F_buf, hi_buf, lo_buf)
        if d < best_d or (d == best_d and c < best):
            best, best_d = c, d
    return best, best_d
