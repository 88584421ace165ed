"""Tail selection of the power law: Kolmogorov-Smirnov statistics and the completeness-threshold search.

The threshold m_min above which the sizes follow the power law is the candidate whose tail is closest, in
Kolmogorov-Smirnov distance, to the law fitted above it (Clauset, Shalizi & Newman 2009, section 3.3);
integer data are searched with the half-unit approximation of the discrete law (their eq. 3.7).  The
compiled scans are in :mod:`riskrf.frequency._power_law_kernels`.  Sizes in kg (or any one size unit).
"""
from __future__ import annotations

import numpy as np

from ...core.validation import as_positive_array, check_choice

#: Kolmogorov-Smirnov statistics offered for the threshold search and the goodness-of-fit test.
#: ``"clauset"``: max_i |F(x_i) - (i - 1)/n| over the sorted tail, as computed by the code published
#: with Clauset, Shalizi & Newman (2009) (plfit.m / plpva.m); it reproduces their Table 6.1
#: thresholds and p-values (blackouts p = 0.62 with 2,500 replicates here 0.6x, see the tests).
#: ``"sup"``: the exact supremum distance between the step-function empirical CDF (ties exact) and
#: the model CDF, max over both sides of every jump (the textbook D of their eq. 3.9).
KS_STATISTICS = ("clauset", "sup")


def _tail_arrays(x_sorted, statistic="sup"):
    """Logs, suffix sums of logs and the empirical-CDF index arrays of the KS kernels.

    For ``"sup"`` ``first``/``last`` are the first and last index of each value's run of ties; for
    ``"clauset"`` they are set so that the kernels compare F(x_j) with (j - k)/n only.
    """
    logx = np.log(x_sorted)
    suffix = np.concatenate([np.cumsum(logx[::-1])[::-1], [0.0]])
    if statistic == "clauset":
        idx = np.arange(x_sorted.size)
        return logx, suffix, idx, idx - 1
    first = np.searchsorted(x_sorted, x_sorted, side="left")
    last = np.searchsorted(x_sorted, x_sorted, side="right") - 1
    return logx, suffix, first, last


#: Above this many values the bootstrap test scans a grid of thresholds instead of every distinct value
#: (see :meth:`GutenbergRichterFit.bootstrap_test`): below it every replicate's scan is exact as in
#: Clauset et al. (2009); above it a replicate of 10^6 values would take seconds.
LARGE_SAMPLE = 100_000
#: Candidate thresholds of that grid: tail sizes evenly spaced in log between ``min_tail`` and n.
GRID_CANDIDATES = 2_000


def _candidates(x_sorted, min_tail, grid=None):
    """Candidate threshold indices: first occurrences of values with >= min_tail values at or above them.

    ``grid`` (int): at most that many, at tail sizes evenly spaced in log between ``min_tail`` and n
    (each moved down to the first occurrence of its value); None: every distinct value.
    """
    N = x_sorted.size
    if grid is None or N <= grid:
        starts = np.flatnonzero(np.concatenate([[True], x_sorted[1:] != x_sorted[:-1]]))
    else:
        tails = np.unique(np.round(np.geomspace(min(min_tail, N), N, int(grid))).astype(np.int64))
        starts = np.unique(np.searchsorted(x_sorted, x_sorted[N - tails], side="left"))
    return starts[(N - starts >= min_tail) & (x_sorted[starts] < x_sorted[-1])]


def find_m_min(masses, *, min_tail: int = 10, exhaustive: bool = False, statistic: str = "clauset",
               grid: int | None = None):
    """Completeness threshold by the Kolmogorov-Smirnov method of Clauset et al. (2009, §3.3).

    Every distinct value with at least ``min_tail`` values at or above it is a
    candidate; the exponent is fitted by maximum likelihood above each, and the
    candidate whose tail is closest (smallest KS distance D) to its fitted
    power law is kept (the lowest such threshold if several tie).

    The search is exact: it returns the minimum of the exhaustive scan.  By
    default it bounds each candidate's D from a few points of its tail and
    computes D in full only for candidates that can still win
    (:func:`riskrf.frequency._power_law_kernels.ks_scan_best`); 100,000 masses take a
    fraction of a second.  ``exhaustive=True`` computes D for every candidate
    (O(N^2), the reference for tests).

    Parameters
    ----------
    masses : array_like
        Sizes [kg or m³], finite and > 0.
    min_tail : int
        Fewest values at or above a candidate threshold.
    exhaustive : bool
        Compute D for every candidate.
    statistic : {"clauset", "sup"}
        The KS statistic (see :data:`KS_STATISTICS`); ``"clauset"`` (default)
        reproduces the published thresholds and p-values of Clauset et al. (2009).
    grid : int, optional
        Scan at most this many candidates, at tail sizes evenly spaced in log
        between ``min_tail`` and the sample size (like the 'sample' option of
        Clauset's plpva.m, which spaces candidates evenly over the distinct
        values); the minimum is then over those candidates only.
        Used by the bootstrap test of large samples (:data:`LARGE_SAMPLE`).

    Returns
    -------
    tuple of float
        (m_min, D, b): the threshold [unit of ``masses``], its KS distance [-] and the cumulative exponent b
        above it.

    References
    ----------
    Clauset, A., Shalizi, C. R. & Newman, M. E. J. (2009). Power-law distributions in empirical data. SIAM Review
    51(4), 661-703.
    """
    check_choice(statistic, "statistic", KS_STATISTICS)
    x = np.sort(as_positive_array(masses, "masses"))
    return _find_m_min_sorted(x, min_tail, exhaustive, statistic, grid)


def _find_m_min_sorted(x, min_tail, exhaustive, statistic, grid=None):
    from .._power_law_kernels import ks_lower_bounds, ks_scan, ks_scan_best

    logx, suffix, first, last = _tail_arrays(x, statistic)
    candidates = _candidates(x, min_tail, grid)
    if candidates.size == 0:
        raise ValueError(f"masses: {len(x)} values with {len(np.unique(x))} distinct; a threshold search needs at "
                         f"least min_tail = {min_tail} values above a threshold and two distinct values")
    if exhaustive:
        D, B = ks_scan(logx, suffix, first, last, candidates)
        i = int(np.argmin(D))
        return float(x[candidates[i]]), float(D[i]), float(B[i])
    B, lb = ks_lower_bounds(logx, suffix, first, last, candidates)
    i, d = ks_scan_best(logx, first, last, candidates, B, lb, np.argsort(lb, kind="stable"))
    return float(x[candidates[i]]), float(d), float(B[i]) if i >= 0 else np.nan


#: Integer data whose threshold lies below this value are fitted as discrete by default (see
#: :func:`fit_gutenberg_richter`): above it the half-unit correction changes b by well under 1 %.
DISCRETE_BELOW = 100


def _is_integer_valued(x) -> bool:
    return bool(np.all(x == np.round(x)))


def _discrete_ks(values, counts, n_at_or_above, j, b):
    """KS distance between the integer tail from distinct value ``values[j]`` and the half-unit law.

    Empirical and model CDFs are compared at every distinct value v of the tail:
    S(v) = #(x <= v)/n and P(v) = 1 - ((v + 1/2) / (x_min - 1/2))^-b, the continuous law on
    [x_min - 1/2, inf) that stands for the integers >= x_min (Clauset et al. 2009, eq. 3.7).
    """
    v = values[j:]
    n = n_at_or_above
    S = np.cumsum(counts[j:]) / n
    P = 1.0 - ((v + 0.5) / (values[j] - 0.5)) ** (-b)
    return float(np.max(np.abs(S - P)))


def _find_m_min_discrete(x, min_tail=10, statistic="clauset"):
    """Threshold search of Clauset et al. (2009, §3.3) for integer data with the half-unit approximation.

    Every distinct integer x_min with at least ``min_tail`` values at or above it (and a larger
    value) is a candidate; b = n / sum ln(x_i / (x_min - 1/2)) (their eq. 3.7) and D compares the
    CDFs at the distinct values (:func:`_discrete_ks`).  Returns (x_min - 1/2, D, b): the threshold
    of the continuous law that stands for the integers >= x_min.
    """
    x = np.sort(np.asarray(x, dtype=float))
    values, counts = np.unique(x, return_counts=True)
    above = x.size - np.concatenate([[0], np.cumsum(counts)[:-1]])      # values >= values[j]
    logsum = np.concatenate([np.cumsum((counts * np.log(values))[::-1])[::-1]])
    best = (np.inf, None, None)
    for j in range(values.size - 1):
        n = above[j]
        if n < min_tail:
            break
        if values[j] < 1:
            continue
        s = logsum[j] - n * np.log(values[j] - 0.5)
        b = n / s
        d = _discrete_ks(values, counts, n, j, b)
        if d < best[0]:
            best = (d, values[j], b)
    if best[1] is None:
        raise ValueError(f"masses: {x.size} integer values with {values.size} distinct; a threshold search needs "
                         f"at least min_tail = {min_tail} values at or above a threshold >= 1 and two distinct values")
    return float(best[1] - 0.5), float(best[0]), float(best[2])


def _ks_distance(x_sorted, F, statistic="sup"):
    """KS distance between the empirical CDF of sorted ``x`` and model CDF values F (see KS_STATISTICS)."""
    n = x_sorted.size
    if statistic == "clauset":
        return float(np.max(np.abs(F - np.arange(n) / n)))
    first = np.searchsorted(x_sorted, x_sorted, side="left")
    last = np.searchsorted(x_sorted, x_sorted, side="right") - 1
    return float(max(np.max(np.abs(F - (last + 1) / n)), np.max(np.abs(F - first / n))))

