"""Goodness of fit of the power law: the bootstrap test and the likelihood-ratio comparisons.

:func:`bootstrap_test` is the semiparametric bootstrap of Clauset, Shalizi & Newman (2009, section 4.1), run
on threads with one seed child per replicate (:class:`PowerLawBootstrap` holds its result);
:func:`compare_alternatives` the Vuong (1989) likelihood-ratio tests against lognormal and exponential tails
(Clauset et al. 2009, section 5).  Both are reached as methods of
:class:`~riskrf.frequency.power_law.GutenbergRichterFit` (``bootstrap_test``, ``compare``).
"""
from __future__ import annotations

import os
import threading
from dataclasses import dataclass
from functools import partial

import numpy as np
import pandas as pd
from scipy import optimize, stats

from simulation._display import Displayed, short_repr

from ...core.validation import warn
from .law import _loglik_power, _mle_truncated_b, _truncated_isf, _truncated_sf
from .threshold import GRID_CANDIDATES, LARGE_SAMPLE, _find_m_min_discrete, _find_m_min_sorted, _ks_distance


@dataclass(frozen=True, repr=False)
class PowerLawBootstrap(Displayed):
    """Result of :meth:`GutenbergRichterFit.bootstrap_test` (Clauset et al. 2009, §4.1).

    ``p_value`` is the share of the ``n_completed`` replicates (of ``n_requested``)
    whose KS distance is at least the observed ``ks_distance``; its Monte Carlo
    standard error is ``sqrt(p (1 - p) / n_completed)``.  ``grid`` is the number
    of candidate thresholds scanned in the data and each replicate (None: every
    distinct value; see :meth:`GutenbergRichterFit.bootstrap_test`).
    """

    p_value: float
    n_requested: int
    n_completed: int
    ks_distance: float
    ks_statistic: str
    grid: int | None = None

    @property
    def p_stderr(self) -> float:
        """Monte Carlo standard error of the bootstrap p-value, sqrt(p (1 - p) / completed replicates)."""
        return float(np.sqrt(self.p_value * (1 - self.p_value) / self.n_completed))

    def summary(self) -> pd.DataFrame:
        """p-value, its Monte Carlo error, the KS statistic used and the replicates completed.

        Returns
        -------
        pandas.DataFrame
            Indexed by quantity; columns ``value``, ``note``.
        """
        label = {"clauset": "Clauset et al. (2009) code: max |F(x_i) - (i-1)/n|",
                 "sup": "supremum distance of the empirical CDF (ties exact)"}[self.ks_statistic]
        rows = [("p_value", self.p_value, f"Monte Carlo SE {self.p_stderr:.3f}; > 0.1: power law plausible"),
                ("n_completed", self.n_completed, f"of {self.n_requested} replicates requested"),
                ("ks_distance", self.ks_distance, f"observed; statistic: {label}"),
                ("grid", np.nan if self.grid is None else self.grid,
                 "threshold scan of data and replicates: every distinct value" if self.grid is None else
                 f"threshold scan of data and replicates: {self.grid} candidates at log-spaced tail sizes "
                 f"(samples above {LARGE_SAMPLE:,} values)")]
        return pd.DataFrame(rows, columns=["quantity", "value", "note"]).set_index("quantity")

    def __repr__(self) -> str:
        return short_repr(self, p_value=self.p_value, n_completed=self.n_completed, ks_distance=self.ks_distance)





def bootstrap_test(fit, n_bootstrap: int = 1000, seed=None, *, min_tail: int = 10, workers: int | None = 1,
                   progress=None, grid="auto") -> PowerLawBootstrap:
    """The semiparametric bootstrap test of Clauset et al. (2009, §4.1) of a fit (see
    :meth:`GutenbergRichterFit.bootstrap_test`, which calls it and documents every argument).

    Parameters
    ----------
    fit : GutenbergRichterFit
        A maximum-likelihood fit carrying its data.
    n_bootstrap, seed, min_tail, workers, progress, grid
        As in :meth:`GutenbergRichterFit.bootstrap_test`.

    Returns
    -------
    PowerLawBootstrap
        p-value, replicates completed, KS distance and statistic.
    """
    n_bootstrap, workers, search, grid = _bootstrap_options(fit, n_bootstrap, workers, grid)
    x = np.asarray(fit.data, dtype=float)
    observed = fit.ks_distance
    if grid is not None:
        observed = _find_m_min_sorted(np.sort(x), min_tail, False, fit.ks_statistic, grid)[1]
    stop = threading.Event()
    replicate = partial(_bootstrap_replicate, fit, root=np.random.SeedSequence(seed), n=x.size,
                        body=np.sort(x[x < fit.m_min]), search=search, min_tail=min_tail, grid=grid, stop=stop)
    D = _run_replicates(replicate, n_bootstrap, workers, progress, stop)
    ok = np.isfinite(D)
    completed = int(ok.sum())
    exceed = int(np.sum(D[ok] >= observed))
    if completed == 0:
        raise ValueError(f"none of the {n_bootstrap} bootstrap replicates could be refitted (min_tail = "
                         f"{min_tail}); the sample is too small for this test")
    if completed < n_bootstrap:
        warn(f"{n_bootstrap - completed} of {n_bootstrap} bootstrap replicates could not be refitted and were "
             f"skipped; p is over the {completed} completed")
    return PowerLawBootstrap(p_value=exceed / completed, n_requested=n_bootstrap, n_completed=completed,
                             ks_distance=float(observed), ks_statistic=fit.ks_statistic, grid=grid)


def compare_alternatives(fit) -> pd.DataFrame:
    """Likelihood-ratio (Vuong 1989) tests of a fit's power law against lognormal and exponential tails (see
    :meth:`GutenbergRichterFit.compare`, which calls it).

    Parameters
    ----------
    fit : GutenbergRichterFit
        A fit carrying its data.

    Returns
    -------
    pandas.DataFrame
        Indexed by alternative: ``loglik_ratio_R``, ``normalised_R``, ``p_value``, ``favoured``.
    """
    x = _tail(fit)
    ll_pl = _loglik_power(x, fit.b, fit.m_min, fit.m_max)
    rows = []
    for name, ll_alt in (("lognormal", _lognormal_tail_loglik(x, fit.m_min)),
                         ("exponential", _exponential_tail_loglik(x, fit.m_min))):
        diff = ll_pl - ll_alt
        R = float(diff.sum())
        sigma = float(diff.std())
        p = float(stats.norm.sf(abs(R) / (sigma * np.sqrt(len(x)))) * 2) if sigma > 0 else np.nan
        favoured = "power law" if R > 0 else name
        rows.append({"alternative": name, "loglik_ratio_R": R, "normalised_R": R / (sigma * np.sqrt(len(x))),
                     "p_value": p, "favoured": favoured if p < 0.1 else f"{favoured} (not significant)"})
    return pd.DataFrame(rows).set_index("alternative")


def _tail(fit):
    """The fit's data in its support (m_min <= m <= m_max), sorted [the fit's units]."""
    if fit.data is None:
        raise ValueError("this fit carries no data; refit with fit_gutenberg_richter to test it")
    top = fit.m_max if fit.m_max is not None else np.inf
    return np.sort(fit.data[(fit.data >= fit.m_min) & (fit.data <= top)])


def _bootstrap_options(fit, n_bootstrap, workers, grid):
    """Check the arguments of :meth:`GutenbergRichterFit.bootstrap_test` before any replicate is drawn.

    Parameters
    ----------
    fit : GutenbergRichterFit
        The fit under test: it must be a maximum-likelihood fit carrying its data.
    n_bootstrap : int
        Number of replicates requested (>= 1).
    workers : int or None
        Threads running replicates; None picks one per core for samples of 20,000 to
        :data:`LARGE_SAMPLE` values, 1 otherwise.
    grid : "auto", int or None
        Threshold scan of each replicate (see :meth:`GutenbergRichterFit.bootstrap_test`).

    Returns
    -------
    n_bootstrap : int
        The number of replicates.
    workers : int
        The number of threads (>= 1).
    search : bool
        True when each replicate searches its own threshold (m_min chosen by KS, no upper bound).
    grid : int or None
        The number of candidate thresholds scanned, or None to scan every distinct value.

    Raises
    ------
    ValueError
        Naming the argument and its value; checked in the order method, data, n_bootstrap, workers, grid.
    """
    if fit.method != "mle":
        raise ValueError(f"this fit has method = {fit.method!r}: the bootstrap test needs a maximum-likelihood "
                         "fit; refit with method='mle'")
    if fit.data is None:
        raise ValueError("this fit carries no data; refit with fit_gutenberg_richter to test it")
    n_bootstrap = int(n_bootstrap)
    if n_bootstrap < 1:
        raise ValueError(f"n_bootstrap must be >= 1; got {n_bootstrap}")
    size = np.asarray(fit.data, dtype=float).size
    if workers is None:
        workers = (os.cpu_count() or 1) if 20_000 <= size <= LARGE_SAMPLE else 1
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ValueError(f"workers must be a whole number >= 1; got {workers!r}")
    search = fit.m_min_method == "ks" and fit.m_max is None
    if isinstance(grid, str):
        if grid != "auto":
            raise ValueError(f"grid = {grid!r} must be 'auto', None or a number of candidate thresholds")
        grid = GRID_CANDIDATES if size > LARGE_SAMPLE else None
    elif grid is not None:
        if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or grid < 2:
            raise ValueError(f"grid = {grid!r} must be 'auto', None or a whole number >= 2 of candidates")
        grid = int(grid)
    if fit.discrete or not search:
        grid = None
    return n_bootstrap, workers, search, grid


def _bootstrap_replicate(fit, i, *, root, n, body, search, min_tail, grid, stop):
    """KS distance of bootstrap replicate ``i`` of ``fit``, or NaN when it cannot be refitted.

    The replicate keeps the sample size: a binomial number of values is drawn from the fitted law above
    m_min, the rest resampled from ``body`` (Clauset et al. 2009, §4.1); it is then refitted as the data were.

    Parameters
    ----------
    fit : GutenbergRichterFit
        The maximum-likelihood fit under test (its data, b, m_min, m_max and KS statistic).
    i : int
        Index of the replicate: it draws from child ``i`` of ``root.spawn(n_bootstrap)``.
    root : numpy.random.SeedSequence
        The test's seed sequence.
    n : int
        Size of the observed sample, kept by every replicate.
    body : numpy.ndarray
        The observed values below m_min (kg, or the fit's units), sorted.
    search : bool
        Whether the replicate searches its own threshold.
    min_tail : int
        Smallest tail a threshold may leave.
    grid : int or None
        Candidate thresholds scanned (None: every distinct value).
    stop : threading.Event
        Set when the test is interrupted: the replicate then returns NaN at once.

    Returns
    -------
    float
        The replicate's KS distance (the fit's ``ks_statistic``), NaN if it could not be refitted.

    References
    ----------
    Clauset, A., Shalizi, C. R. and Newman, M. E. J. (2009). Power-law distributions in empirical data.
    SIAM Review 51(4), 661-703.
    """
    if stop.is_set():
        return np.nan
    p_tail = fit.n_tail / n
    lower = fit.m_min + 0.5 if fit.discrete else fit.m_min    # the data's own threshold
    # child i of root.spawn(n_bootstrap), made when needed (a million children would hold memory)
    rng = np.random.default_rng(np.random.SeedSequence(root.entropy, spawn_key=root.spawn_key + (i,),
                                                       pool_size=root.pool_size))
    k = rng.binomial(n, p_tail) if body.size else n
    tail = _truncated_isf(1.0 - rng.uniform(size=k), fit.b, fit.m_min, fit.m_max)
    if fit.discrete:
        # the continuous approximation rounds to the integers it stands for (eq. 3.7)
        tail = np.maximum(np.round(tail), lower)
    # n - k values resampled from the body, drawn as rng.choice(body, n - k) draws them, but
    # gathered already sorted (body is sorted and lies below every tail value): no O(n log n) sort
    picks = np.bincount(rng.integers(0, body.size, size=n - k), minlength=body.size) if n - k else 0
    sample = np.concatenate([np.repeat(body, picks) if n - k else body[:0], np.sort(tail)])
    if search:
        try:
            if fit.discrete:
                return _find_m_min_discrete(sample, min_tail, fit.ks_statistic)[1]
            return _find_m_min_sorted(sample, min_tail, False, fit.ks_statistic, grid)[1]
        except ValueError:
            return np.nan
    tail = np.sort(sample[sample >= lower])
    if tail.size < 2 or tail[0] == tail[-1]:
        return np.nan
    if fit.m_max is None:
        b = tail.size / np.sum(np.log(tail / fit.m_min))
    else:
        b, _ = _mle_truncated_b(tail, fit.m_min, fit.m_max)
    return _ks_distance(tail, 1 - _truncated_sf(tail, b, fit.m_min, fit.m_max), fit.ks_statistic)


def _run_replicates(replicate, n_bootstrap, workers, progress, stop):
    """Run ``replicate(i)`` for i = 0 .. n_bootstrap - 1, on ``workers`` threads, reporting progress.

    Parameters
    ----------
    replicate : callable
        ``replicate(i)`` returns replicate i's KS distance or NaN; its draws depend on i only.
    n_bootstrap : int
        Number of replicates.
    workers : int
        Threads; 1 runs the replicates in order on this thread.
    progress : callable or None
        Called as ``progress(done, total)`` before the first and after each finished replicate.
    stop : threading.Event
        Set on Ctrl-C or an error, so that replicates not yet started return at once.

    Returns
    -------
    numpy.ndarray
        The KS distance of each replicate (NaN where it could not be refitted), in replicate order.
    """
    from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

    D = np.full(n_bootstrap, np.nan)
    if progress is not None:
        progress(0, n_bootstrap)
    if workers == 1:
        for i in range(n_bootstrap):
            D[i] = replicate(i)
            if progress is not None:
                progress(i + 1, n_bootstrap)
        return D
    pool = ThreadPoolExecutor(max_workers=int(workers), thread_name_prefix="riskrf-bootstrap")
    try:
        pending, queued, done = {}, 0, 0
        while queued < n_bootstrap or pending:
            while queued < n_bootstrap and len(pending) < 4 * workers:     # a few in flight per thread
                pending[pool.submit(replicate, queued)] = queued
                queued += 1
            finished, _ = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            for f in finished:
                D[pending.pop(f)] = f.result()
                done += 1
            if finished and progress is not None:
                progress(done, n_bootstrap)
    except BaseException:
        stop.set()                      # Ctrl-C or an error: replicates not started return at once
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return D



def _lognormal_tail_loglik(x, m_min):
    lx = np.log(x)

    def pointwise(mu, sigma):
        return (stats.norm.logpdf(lx, mu, sigma) - lx - stats.norm.logsf(np.log(m_min), mu, sigma))

    def nll(theta):
        return -np.sum(pointwise(theta[0], np.exp(theta[1])))
    start = np.array([lx.mean(), np.log(max(lx.std(), 1e-3))])
    res = optimize.minimize(nll, start, method="Nelder-Mead", options={"xatol": 1e-8, "fatol": 1e-10,
                                                                       "maxiter": 4000})
    return pointwise(res.x[0], np.exp(res.x[1]))


def _exponential_tail_loglik(x, m_min):
    lam = 1.0 / np.mean(x - m_min) if np.mean(x - m_min) > 0 else 1.0
    return np.log(lam) - lam * (x - m_min)

