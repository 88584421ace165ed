"""Power-law ("Gutenberg-Richter") magnitude-frequency relations of rock fall masses.

The cumulative annual frequency of falls of mass at least m is

    log10 N(>=m) = a - b log10 m,   m >= m_min          (Wyllie 2014, section 8.4.1)

with N per year and m in kg (or any size unit: the code is unit-agnostic and a
fit to volumes differs from a fit to masses only in ``a``, by ``b log10 rho``).
Optionally the law is truncated above at a maximum credible mass ``m_max``
(Corominas et al. 2018):  N(>=m) = N0 (m^-b - m_max^-b) / (m_min^-b - m_max^-b).

Estimation
----------
``method="mle"`` (default): the continuous maximum-likelihood estimator of Aki
(1965) and Clauset, Shalizi & Newman (2009, eq. 3.1): ``b = n / sum ln(m_i/m_min)``,
standard error ``b/sqrt(n)`` and an exact confidence interval from
``2 b sum ln(m_i/m_min) ~ chi2(2n)``.  ``unbiased=True`` uses ``(n-1)/sum``.
``m_min=None`` picks the completeness threshold that minimises the
Kolmogorov-Smirnov distance (Clauset et al. 2009, section 3.3).

``method="lsq"``: ordinary least squares of log10 N on log10 m over the
cumulative annual frequency points, as practitioners do (Wyllie 2014; Hungr,
Evans & Hazzard 1999).  It is biased and its standard errors ignore that the
cumulative points are dependent; it is offered for comparison with published
practice, never as the default.
"""
from __future__ import annotations

import os
import threading
from dataclasses import dataclass, field
from functools import partial

import numpy as np
import pandas as pd
from scipy import optimize, stats

from simulation._display import Displayed, short_repr

from ..core.validation import (
    as_positive_array,
    check_choice,
    check_positive,
    check_probability_level,
    warn,
)

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
    from ._power_law_kernels import ks_lower_bounds, ks_scan, ks_scan_best

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


def _truncated_sf(m, b, m_min, m_max):
    """P(M > m) for the (optionally upper-truncated) power law on [m_min, m_max]."""
    m = np.asarray(m, dtype=float)
    z = np.clip(m, m_min, m_max if m_max is not None else np.inf)
    if m_max is None:
        return (z / m_min) ** (-b)
    top = m_max ** (-b)
    return np.clip((z ** (-b) - top) / (m_min ** (-b) - top), 0.0, 1.0)


def _truncated_isf(p, b, m_min, m_max):
    p = np.asarray(p, dtype=float)
    if m_max is None:
        return m_min * p ** (-1.0 / b)
    top = m_max ** (-b)
    return (top + p * (m_min ** (-b) - top)) ** (-1.0 / b)


def _loglik_power(x, b, m_min, m_max):
    """Pointwise log density of the (truncated) power law with cumulative exponent b."""
    norm = m_min ** (-b) - (m_max ** (-b) if m_max is not None else 0.0)
    return np.log(b) - (b + 1.0) * np.log(x) - np.log(norm)


def _mle_truncated_b(x, m_min, m_max):
    """MLE of b for the upper-truncated law, and its standard error from the observed information."""
    def nll(b):
        return -np.sum(_loglik_power(x, b, m_min, m_max))
    b0 = len(x) / np.sum(np.log(x / m_min))
    res = optimize.minimize_scalar(nll, bounds=(1e-6, max(20.0, 5 * b0)), method="bounded",
                                   options={"xatol": 1e-10})
    b = float(res.x)
    h = 1e-4 * b
    info = (nll(b + h) - 2 * nll(b) + nll(b - h)) / h ** 2
    return b, float(1.0 / np.sqrt(info)) if info > 0 else np.nan


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


@dataclass(frozen=True, repr=False)
class GutenbergRichterFit(Displayed):
    """A fitted (optionally truncated) power law of annual cumulative frequency.

    ``log10 N(>=m) = a - b log10 m`` [N per year] for ``m_min <= m`` (``<= m_max``).
    Also a probability distribution of the size of one fall of at least
    ``m_min`` (``sf``, ``isf``, ``cdf``, ``pdf``, ``rvs``), so it can stand for
    the mass model of :func:`riskrf.exceedance_probability`.

    Attributes
    ----------
    a, b : float
        Intercept and cumulative exponent (Clauset's alpha = b + 1).
    b_stderr : float
        Standard error of b.
    b_ci : (float, float)
        Confidence interval of b at ``level`` (see ``b_ci_method``).
    m_min, m_max : float
        Completeness threshold and upper truncation (None if untruncated).
    rate_min : float
        Falls of at least m_min per year, ``n_tail / duration_years``.
    n_tail, n_total : int
        Values used (>= m_min) and values given.
    duration_years : float
        Record length [yr].
    method : str
        ``"mle"`` or ``"lsq"``.
    m_min_method : str
        ``"ks"`` (Clauset search) or ``"given"``.
    ks_distance : float
        KS distance between the tail and the fitted law.
    units : str
        Unit of the sizes (``"kg"`` or ``"m3"``).
    ks_statistic : str
        KS statistic of ``ks_distance``, the threshold search and the bootstrap
        (see :data:`KS_STATISTICS`).
    discrete : bool
        True when integer data were fitted with the half-unit continuous
        approximation of the discrete power law (Clauset et al. 2009, eq. 3.7).
    """

    a: float
    b: float
    b_stderr: float
    b_ci: tuple
    level: float
    b_ci_method: str
    m_min: float
    m_max: float | None
    rate_min: float
    n_tail: int
    n_total: int
    duration_years: float
    method: str
    m_min_method: str
    ks_distance: float
    unbiased: bool = False
    units: str = "kg"
    data: np.ndarray = field(default=None, repr=False, compare=False)
    ks_statistic: str = "clauset"
    discrete: bool = False

    # -- distribution of one fall ------------------------------------------------
    def sf(self, m):
        """P(one fall of at least m_min is larger than m) [-]; 1 below m_min.

        Parameters
        ----------
        m : float or array_like
            Size [units: kg, or m³ for a fit to volumes].

        Returns
        -------
        numpy.ndarray
            (m / m_min)^-b, renormalised between m_min and m_max when truncated.
        """
        return _truncated_sf(m, self.b, self.m_min, self.m_max)

    def cdf(self, m):
        """P(M <= m) of the fitted law above m_min (truncated at m_max where given).

        Parameters
        ----------
        m : float or array_like
            Size [units].

        Returns
        -------
        numpy.ndarray
            1 - :meth:`sf`.
        """
        return 1.0 - self.sf(m)

    def isf(self, p):
        """Mass exceeded with probability p by one fall of at least m_min [units].

        Parameters
        ----------
        p : float or array_like
            Probabilities, in (0, 1].

        Returns
        -------
        numpy.ndarray
            Sizes [units].
        """
        p = np.asarray(p, dtype=float)
        if np.any((p <= 0) | (p > 1)):
            raise ValueError(f"p = {p[(p <= 0) | (p > 1)].ravel()[0]!r}: probabilities must lie in (0, 1]")
        return _truncated_isf(p, self.b, self.m_min, self.m_max)

    def pdf(self, m):
        """Probability density [1/kg] of the fitted law, zero outside its support.

        Parameters
        ----------
        m : float or array_like
            Size [units].

        Returns
        -------
        numpy.ndarray
            Density [1/units].
        """
        m = np.asarray(m, dtype=float)
        inside = (m >= self.m_min) & (m <= (self.m_max if self.m_max is not None else np.inf))
        with np.errstate(divide="ignore", invalid="ignore"):
            dens = np.exp(_loglik_power(np.where(inside, m, self.m_min), self.b, self.m_min, self.m_max))
        return np.where(inside, dens, 0.0)

    def rvs(self, size=None, random_state=None):
        """Random masses of falls of at least m_min (inverse-CDF sampling).

        Parameters
        ----------
        size : int or tuple, optional
            Output shape.
        random_state : int or numpy.random.Generator, optional
            Seed or generator.

        Returns
        -------
        numpy.ndarray
            Sizes [units].
        """
        rng = np.random.default_rng(random_state)
        return _truncated_isf(1.0 - rng.uniform(size=size), self.b, self.m_min, self.m_max)

    @property
    def support(self) -> tuple:
        """(m_min, m_max) in kg; m_max is infinite for the untruncated law."""
        return (self.m_min, self.m_max if self.m_max is not None else np.inf)

    # -- frequencies ---------------------------------------------------------------
    def _check_above_m_min(self, m, name="m"):
        m = np.asarray(m, dtype=float)
        if np.any(~np.isfinite(m) | (m < self.m_min * (1 - 1e-12))):
            bad = m[~np.isfinite(m) | (m < self.m_min * (1 - 1e-12))].ravel()[0]
            raise ValueError(f"{name} = {bad!r} {self.units} lies below m_min = {self.m_min:.6g} {self.units}: "
                             "the fitted law only describes falls at least as large as the completeness threshold")
        return m

    def annual_frequency(self, m):
        """N(>=m): falls of at least m per year [1/yr], for m >= m_min.

        Parameters
        ----------
        m : float or array_like
            Size [units], >= m_min.

        Returns
        -------
        numpy.ndarray
            rate_min x sf(m) [1/yr] (10^(a - b log10 m) when untruncated).

        References
        ----------
        Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, section 8.4.1.
        """
        return self.rate_min * self.sf(self._check_above_m_min(m))

    def return_period(self, m):
        """Mean time between falls of at least m [yr], 1 / N(>=m).

        Parameters
        ----------
        m : float or array_like
            Size [units], >= m_min.

        Returns
        -------
        numpy.ndarray
            Return period [yr].
        """
        with np.errstate(divide="ignore"):
            return 1.0 / self.annual_frequency(m)

    def mass_at_return_period(self, T):
        """Mass m with N(>=m) = 1/T, i.e. exceeded on average once in T years [units].

        This is Wyllie's return period of a magnitude.  The T-year level of the
        *annual maximum* is :meth:`annual_max_return_level` (slightly larger).

        Parameters
        ----------
        T : float or array_like
            Return period [yr], at least 1 / rate_min.

        Returns
        -------
        numpy.ndarray
            Size [units].

        References
        ----------
        Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, section 8.4.1.
        """
        T = np.asarray(T, dtype=float)
        p = 1.0 / (T * self.rate_min)
        if np.any(~np.isfinite(T) | (p > 1) | (T <= 0)):
            raise ValueError(f"T = {T[~np.isfinite(T) | (p > 1) | (T <= 0)].ravel()[0]!r} yr is shorter than the return "
                             f"period of m_min ({1 / self.rate_min:.4g} yr): below m_min the law does not apply")
        return _truncated_isf(p, self.b, self.m_min, self.m_max)

    def probability_in(self, years, m):
        """P(at least one fall of mass >= m in ``years``), Poisson: 1 - exp(-N(>=m) years).

        Parameters
        ----------
        years : float or array_like
            Period [yr].
        m : float or array_like
            Size [units], >= m_min.

        Returns
        -------
        numpy.ndarray
            Probability [-].
        """
        years = check_positive(years, "years") if np.ndim(years) == 0 else np.asarray(years, dtype=float)
        return -np.expm1(-np.asarray(years) * self.annual_frequency(m))

    def annual_max_cdf(self, m):
        """P(largest fall of a year <= m) = exp(-N(>=m)) (a Frechet law when untruncated).

        Parameters
        ----------
        m : float or array_like
            Size [units], >= m_min.

        Returns
        -------
        numpy.ndarray
            Probability [-].
        """
        return np.exp(-self.annual_frequency(m))

    def annual_max_return_level(self, T):
        """T-year level of the annual maximum implied by the Poisson power law [units].

        Solves exp(-N(>=m)) = 1 - 1/T, i.e. ``m = (10^a / -ln(1 - 1/T))^(1/b)``
        when untruncated (a Frechet, or GEV with xi = 1/b, law).

        Parameters
        ----------
        T : float or array_like
            Return period [yr], > 1.

        Returns
        -------
        numpy.ndarray
            Size [units].
        """
        T = np.asarray(T, dtype=float)
        p = -np.log1p(-1.0 / T) / self.rate_min
        if np.any((T <= 1) | (p > 1)):
            raise ValueError(f"T = {T.ravel()[0]!r}: the annual-maximum level lies below m_min; use a longer T")
        return _truncated_isf(p, self.b, self.m_min, self.m_max)

    def return_level(self, T):
        """Mass exceeded on average once in T years [units]: the same as :meth:`mass_at_return_period`, under
        the name the annual-maximum fits use (:meth:`riskrf.GumbelFit.return_level`).

        Parameters
        ----------
        T : float or array_like
            Return period [yr], at least the return period of m_min (``1 / rate_min``).

        Returns
        -------
        numpy.ndarray
            Mass m with N(>=m) = 1/T [kg, or m³ for a fit to volumes].
        """
        return self.mass_at_return_period(T)

    def mass_at_return_period_ci(self, T, level: float = 0.95):
        """Deprecated name of :meth:`return_level_ci` (the name the annual-maximum fits use).

        Parameters
        ----------
        T : float or array_like
            Return period [yr].
        level : float
            Confidence level, in (0, 1).

        Returns
        -------
        tuple of numpy.ndarray
            (lower, upper) [units].
        """
        import warnings
        warnings.warn("GutenbergRichterFit.mass_at_return_period_ci is deprecated; use return_level_ci (the name "
                      "GumbelFit and GEVFit use)", DeprecationWarning, stacklevel=2)
        return self.return_level_ci(T, level)

    def return_level_ci(self, T, level: float = 0.95):
        """Delta-method interval of :meth:`mass_at_return_period` (:meth:`return_level`) on the log scale.

        Carries the uncertainty of b (``b_stderr``) and of the Poisson rate of
        falls above m_min (var ln rate = 1/n_tail), taken as independent.

        Parameters
        ----------
        T : float or array_like
            Return period [yr], at least the return period of m_min.
        level : float
            Confidence level, in (0, 1); default 0.95.

        Returns
        -------
        tuple of numpy.ndarray
            (lower, upper) bounds of the mass [units] exceeded once in T years.

        References
        ----------
        Coles, S. (2001). An Introduction to Statistical Modeling of Extreme Values. Springer, London, §3.3.3
        (return-level intervals by the delta method).
        """
        level = check_probability_level(level)
        T = np.asarray(T, dtype=float)
        log_rate = np.log(self.rate_min)

        def log_mass(b, lr):
            p = 1.0 / (T * np.exp(lr))
            return np.log(_truncated_isf(p, b, self.m_min, self.m_max))
        self.mass_at_return_period(T)  # validates T
        hb, hr = 1e-6 * self.b, 1e-6
        db = (log_mass(self.b + hb, log_rate) - log_mass(self.b - hb, log_rate)) / (2 * hb)
        dr = (log_mass(self.b, log_rate + hr) - log_mass(self.b, log_rate - hr)) / (2 * hr)
        se = np.sqrt((db * self.b_stderr) ** 2 + dr ** 2 / self.n_tail)
        z = stats.norm.isf((1 - level) / 2)
        centre = log_mass(self.b, log_rate)
        return np.exp(centre - z * se), np.exp(centre + z * se)

    def to_mass(self, density_kg_m3: float) -> "GutenbergRichterFit":
        """Convert a fit to volumes [m³] into one to masses [kg]: b is unchanged, a shifts by b log10 rho.

        Parameters
        ----------
        density_kg_m3 : float
            Rock density [kg/m³].

        Returns
        -------
        GutenbergRichterFit
            In kg.
        """
        if self.units != "m3":
            raise ValueError(f"to_mass converts a fit to volumes (units 'm3'); this fit is in {self.units!r}")
        rho = check_positive(density_kg_m3, "density_kg_m3")
        from dataclasses import replace
        return replace(self, a=self.a + self.b * np.log10(rho), m_min=self.m_min * rho,
                       m_max=None if self.m_max is None else self.m_max * rho, units="kg",
                       data=None if self.data is None else self.data * rho)

    # -- goodness of fit -------------------------------------------------------------
    def _tail(self):
        if self.data is None:
            raise ValueError("this fit carries no data; refit with fit_gutenberg_richter to test it")
        top = self.m_max if self.m_max is not None else np.inf
        return np.sort(self.data[(self.data >= self.m_min) & (self.data <= top)])

    def bootstrap_test(self, n_bootstrap: int = 1000, seed=None, *, min_tail: int = 10, workers: int | None = 1,
                       progress=None, grid="auto") -> "PowerLawBootstrap":
        """Clauset et al. (2009, §4.1) semiparametric bootstrap goodness-of-fit test of the power law.

        Each replicate keeps the sample size: with probability n_tail/n a value
        is drawn from the fitted law above m_min, otherwise resampled from the
        observed values below m_min; the replicate is then refitted the same way
        (threshold search included when m_min was chosen by KS) and its KS
        distance (the fit's ``ks_statistic``) compared with the observed one.
        p > 0.1 means the power law is a plausible description (Clauset et al.
        2009).  A replicate that cannot be refitted (too few values above a
        threshold) is skipped; p is the share of the *completed* replicates whose
        distance is at least the observed one, and the result says how many
        completed.  Replicate i draws from the i-th child of
        ``SeedSequence(seed).spawn(n_bootstrap)``, so the result does not depend
        on ``workers`` or on the order in which replicates finish.  A Ctrl-C (``KeyboardInterrupt``) stops the
        remaining replicates and propagates.

        Parameters
        ----------
        n_bootstrap : int
            Replicates.
        seed : int, optional
            Seed of the replicates.
        min_tail : int
            Fewest values above a threshold in a replicate's search.
        workers : int, optional
            Threads running replicates (the compiled threshold scan releases the
            interpreter lock).  None: one per core for samples of 20,000 to
            :data:`LARGE_SAMPLE` values, where the compiled scan is nearly all of a
            replicate's time; 1 otherwise (smaller replicates are too short to gain,
            and above LARGE_SAMPLE the gridded replicate is mostly memory-bound numpy
            work that ran slower on two threads than on one: 62 s against 46 s for
            1,000 replicates of 10^6 falls on the 2-core test machine).
        progress : callable, optional
            Called as ``progress(done, total)`` after each replicate (the CLI draws a bar).
        grid : "auto", int or None
            Threshold scan of each replicate (continuous data, m_min searched):
            None scans every distinct value (exact, as Clauset et al.); an int
            scans that many candidates at tail sizes evenly spaced in log
            (:func:`find_m_min` ``grid``).  The observed statistic is then
            recomputed with the same grid, so data and replicates are measured
            alike.  ``"auto"`` (default): every value up to
            :data:`LARGE_SAMPLE` (100,000) values, a grid of
            :data:`GRID_CANDIDATES` (2,000) above: a replicate of 10^6 values
            then takes about 0.05 s instead of 3-7 s; neighbouring candidates
            are under 0.6 % apart in tail size.

        Returns
        -------
        PowerLawBootstrap
            p-value, replicates completed, KS distance and statistic.

        References
        ----------
        Clauset, A., Shalizi, C. R. & Newman, M. E. J. (2009). Power-law distributions in empirical data. SIAM Review
        51(4), 661-703., §4.1.
        """
        n_bootstrap, workers, search, grid = _bootstrap_options(self, n_bootstrap, workers, grid)
        x = np.asarray(self.data, dtype=float)
        observed = self.ks_distance
        if grid is not None:
            observed = _find_m_min_sorted(np.sort(x), min_tail, False, self.ks_statistic, grid)[1]
        stop = threading.Event()
        replicate = partial(_bootstrap_replicate, self, root=np.random.SeedSequence(seed), n=x.size,
                            body=np.sort(x[x < self.m_min]), search=search, min_tail=min_tail, grid=grid, stop=stop)
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
                                 ks_distance=float(observed), ks_statistic=self.ks_statistic, grid=grid)

    def bootstrap_pvalue(self, n_bootstrap: int = 1000, seed=None, *, min_tail: int = 10, **kwargs) -> float:
        """p-value of :meth:`bootstrap_test` (over the completed replicates; warns if any were skipped).

        Parameters
        ----------
        n_bootstrap : int
            Replicates.
        seed : int, optional
            Seed.
        min_tail : int
            Fewest values above a threshold in a replicate's search.
        **kwargs
            Passed to :meth:`bootstrap_test`.

        Returns
        -------
        float
            p [-].
        """
        return self.bootstrap_test(n_bootstrap, seed, min_tail=min_tail, **kwargs).p_value

    def compare(self) -> pd.DataFrame:
        """Likelihood-ratio (Vuong) tests of the power law against lognormal and exponential tails.

        Both alternatives are fitted by maximum likelihood to the same tail
        (m >= m_min), conditioned on exceeding m_min (Clauset et al. 2009, §5).
        ``R`` > 0 favours the power law; ``p`` is the two-sided significance of
        the sign of R (small p: the sign can be trusted).

        Returns
        -------
        pandas.DataFrame
            Indexed by alternative: ``loglik_ratio_R``, ``normalised_R``, ``p_value``, ``favoured``.

        References
        ----------
        Vuong, Q. H. (1989). Likelihood ratio tests for model selection and non-nested hypotheses. Econometrica
        57(2), 307-333.
        Clauset, A., Shalizi, C. R. & Newman, M. E. J. (2009). Power-law distributions in empirical data. SIAM Review
        51(4), 661-703., §5.
        """
        x = self._tail()
        ll_pl = _loglik_power(x, self.b, self.m_min, self.m_max)
        rows = []
        for name, ll_alt in (("lognormal", _lognormal_tail_loglik(x, self.m_min)),
                             ("exponential", _exponential_tail_loglik(x, self.m_min))):
            diff = ll_pl - ll_alt
            R = float(diff.sum())
            sigma = float(diff.std())
            p = float(stats.norm.sf(abs(R) / (sigma * np.sqrt(len(x)))) * 2) if sigma > 0 else np.nan
            favoured = "power law" if R > 0 else name
            rows.append({"alternative": name, "loglik_ratio_R": R, "normalised_R": R / (sigma * np.sqrt(len(x))),
                         "p_value": p, "favoured": favoured if p < 0.1 else f"{favoured} (not significant)"})
        return pd.DataFrame(rows).set_index("alternative")

    # -- reporting ---------------------------------------------------------------
    def summary(self) -> pd.DataFrame:
        """Parameters with standard errors and intervals, and how they were obtained.

        Returns
        -------
        pandas.DataFrame
            Indexed by parameter; columns ``value`` (sizes in ``units``, rate per year), ``stderr``, ``ci_low``,
            ``ci_high``, ``note``.
        """
        method = ("maximum likelihood (Aki 1965; Clauset et al. 2009)" + (", unbiased (n-1)/n" if self.unbiased else "")
                  if self.method == "mle" else
                  "least squares on log10 cumulative frequency (practitioners' method: biased, SE too small)")
        rows = [
            ("b", self.b, self.b_stderr, self.b_ci[0], self.b_ci[1], f"{self.b_ci_method}, {self.level:.0%}"),
            ("a", self.a, np.nan, np.nan, np.nan, f"log10 N(>=1 {self.units}) per year"),
            ("m_min", self.m_min, np.nan, np.nan, np.nan,
             f"{self.units}; {'Kolmogorov-Smirnov search' if self.m_min_method == 'ks' else 'given'}"),
            ("m_max", self.m_max if self.m_max is not None else np.nan, np.nan, np.nan, np.nan,
             f"{self.units}; upper truncation" if self.m_max is not None else "untruncated"),
            ("rate_min", self.rate_min, self.rate_min / np.sqrt(self.n_tail), np.nan, np.nan,
             "falls >= m_min per year (Poisson SE)"),
            ("n_tail", self.n_tail, np.nan, np.nan, np.nan, f"of {self.n_total} values"),
            ("duration_years", self.duration_years, np.nan, np.nan, np.nan, "record length"),
            ("ks_distance", self.ks_distance, np.nan, np.nan, np.nan,
             "tail vs fitted law; " + ("integer data: CDFs compared at each value" if self.discrete else
                                       {"clauset": "Clauset et al. (2009) statistic max|F(x_i) - (i-1)/n|",
                                        "sup": "supremum distance (ties exact)"}[self.ks_statistic])),
            ("discrete", float(self.discrete), np.nan, np.nan, np.nan,
             "integer data, half-unit approximation (Clauset et al. 2009, eq. 3.7): m_min = x_min - 1/2"
             if self.discrete else "continuous"),
            ("method", np.nan, np.nan, np.nan, np.nan, method),
        ]
        return pd.DataFrame(rows, columns=["parameter", "value", "stderr", "ci_low", "ci_high", "note"]
                            ).set_index("parameter")

    def __repr__(self) -> str:
        return short_repr(self, a=self.a, b=self.b, b_stderr=self.b_stderr, m_min=self.m_min, m_max=self.m_max,
                          n_tail=self.n_tail, duration_years=self.duration_years, method=self.method,
                          units=self.units)

    def plot(self, ax=None, **kwargs):
        """Magnitude-frequency plot: the recorded falls and the fitted N(>=m) [1/yr] with the band of b, log-log (drawn by :func:`riskrf.report.fit_figures.plot_magnitude_frequency`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).
        **kwargs
            Passed to the drawing function.

        Returns
        -------
        matplotlib.axes.Axes
        """
        from ..core.figures import draw
        return draw("magnitude_frequency", self, ax=ax, **kwargs)

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


def _ks_distance(x_sorted, F, statistic="sup"):
    """KS distance between the empirical CDF of sorted ``x`` and model CDF values F (see KS_STATISTICS)."""
    n = x_sorted.size
    if statistic == "clauset":
        return float(np.max(np.abs(F - np.arange(n) / n)))
    first = np.searchsorted(x_sorted, x_sorted, side="left")
    last = np.searchsorted(x_sorted, x_sorted, side="right") - 1
    return float(max(np.max(np.abs(F - (last + 1) / n)), np.max(np.abs(F - first / n))))


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


def fit_gutenberg_richter(masses, duration_years=None, m_min=None, method: str = "mle", *, m_max=None,
                          unbiased: bool = False, level: float = 0.95, min_tail: int = 10,
                          units: str = "kg", ks_statistic: str = "clauset",
                          discrete: bool | None = None) -> GutenbergRichterFit:
    """Fit ``log10 N(>=m) = a - b log10 m`` to an inventory of masses (Wyllie 2014, 8.4.1).

    Parameters
    ----------
    masses : array_like or Inventory
        Fall sizes [kg] (or volumes [m³] with ``units="m3"``).  An
        :class:`~riskrf.Inventory` supplies its masses and record length.
    duration_years : float
        Length of the record [yr]; turns counts into annual frequencies.
    m_min : float, optional
        Completeness threshold.  None (default) chooses it by the
        Kolmogorov-Smirnov method of Clauset et al. (2009).
    method : {"mle", "lsq"}
        Maximum likelihood (default, better) or least squares on the log-log
        cumulative frequency (the practitioners' method, for comparison).
    m_max : float, optional
        Upper truncation, the maximum credible fall.
    unbiased : bool
        Use the small-sample unbiased MLE ``(n-1)/sum ln(m/m_min)``.
    level : float
        Confidence level of the interval on b.
    min_tail : int
        Fewest values above a candidate threshold in the KS search.
    units : str
        Label of the size unit, ``"kg"`` or ``"m3"``.
    ks_statistic : {"clauset", "sup"}
        KS statistic of the threshold search, ``ks_distance`` and the bootstrap
        test (see :data:`KS_STATISTICS`); the default reproduces Clauset et al. (2009).
    discrete : bool, optional
        Integer data (counts, or sizes recorded in whole units) are fitted with the
        half-unit continuous approximation of the discrete power law (Clauset et al.
        2009, eq. 3.7): the integers >= x_min stand for the continuous law above
        x_min - 1/2, so ``m_min`` of the result is x_min - 1/2 and ``discrete`` is
        True.  None (default) applies the stated rule: when ``m_min`` is searched,
        the data are discrete if every value is an integer and the continuous
        search puts the threshold below :data:`DISCRETE_BELOW` (100); the search
        is then redone for integers and a warning says so.  With ``m_min`` given,
        integer data below 100 stay continuous with a warning recommending
        ``discrete=True``.  Above 100 the half-unit correction changes b by well
        under 1 % (their Appendix B).

    Returns
    -------
    GutenbergRichterFit
        a, b with its standard error and interval, m_min, m_max, the rate above m_min [1/yr] and the KS distance.
    """
    x, duration_years, level, m_max, integer = _check_fit_arguments(masses, duration_years, method, level, m_max,
                                                                     ks_statistic, discrete, units)
    if m_min is None:
        m_min_method = "ks"
        m_min, switch = _search_m_min(x, discrete, integer, min_tail, ks_statistic, units)
        if switch:
            warn(switch)
            discrete = True
            m_min, _, _ = _find_m_min_discrete(x, min_tail, ks_statistic)
    else:
        m_min_method = "given"
        m_min, advice = _check_given_m_min(x, m_min, discrete, integer, units)
        if advice:
            warn(advice)
    discrete = bool(discrete)
    tail, n = _fit_tail(x, m_min, units)
    if n < 30:
        warn(f"only {n} values above m_min = {m_min:g} {units}: b is uncertain (SE about b/sqrt(n) = {100 / np.sqrt(n):.0f} %)")
    rate_min = n / duration_years
    if method == "mle":
        b, b_stderr, b_ci, ci_method = _fit_b_mle(tail, m_min, m_max, unbiased, level)
        a = np.log10(rate_min) + b * np.log10(m_min)
    else:
        a, b, b_stderr, b_ci, ci_method = _fit_b_lsq(tail, duration_years, level)
        if m_max is not None:
            warn("m_max is ignored by method='lsq' (a straight line on log-log axes cannot be truncated)")
            m_max = None
        rate_min = 10 ** (a - b * np.log10(m_min))
    if not np.isfinite(b) or b <= 0:
        raise ValueError(f"the fitted exponent b = {b:.4g} is not positive: the sizes above m_min = {m_min:g} "
                         "do not decrease in frequency; check the data and m_min")
    D = _fit_ks_distance(tail, b, m_min, m_max, discrete, ks_statistic)
    return GutenbergRichterFit(a=float(a), b=float(b), b_stderr=float(b_stderr), b_ci=tuple(map(float, b_ci)),
                               level=level, b_ci_method=ci_method, m_min=float(m_min), m_max=m_max,
                               rate_min=float(rate_min), n_tail=int(n), n_total=int(x.size),
                               duration_years=duration_years, method=method, m_min_method=m_min_method,
                               ks_distance=D, unbiased=unbiased, units=units, data=x, ks_statistic=ks_statistic,
                               discrete=discrete)


def _check_fit_arguments(masses, duration_years, method, level, m_max, ks_statistic, discrete, units):
    """Check the arguments of :func:`fit_gutenberg_richter` that do not depend on the threshold, before any work.

    Parameters
    ----------
    masses, duration_years, method, level, m_max, ks_statistic, discrete, units
        As in :func:`fit_gutenberg_richter` (an :class:`~riskrf.Inventory` supplies the sizes and, when
        ``duration_years`` is None, the record length [yr]).

    Returns
    -------
    tuple
        (x, duration_years, level, m_max, integer): the sizes as a positive float array [``units``], the record
        length [yr], the checked confidence level, the checked truncation [``units``] or None, and whether every
        size is an integer.

    Raises
    ------
    ValueError
        Naming the first bad argument and its value.
    """
    from .inventory import Inventory

    if isinstance(masses, Inventory):
        if duration_years is None:
            duration_years = masses.duration_years
        masses = masses.volumes if units == "m3" else masses.masses
    x = as_positive_array(masses, "masses")
    if duration_years is None:
        raise ValueError("duration_years is needed to turn counts into annual frequencies")
    duration_years = check_positive(duration_years, "duration_years")
    check_choice(method, "method", ("mle", "lsq"))
    level = check_probability_level(level)
    if m_max is not None:
        m_max = check_positive(m_max, "m_max")
        if m_max < x.max():
            raise ValueError(f"m_max = {m_max:g} {units} is smaller than the largest value {x.max():g} {units}")
    check_choice(ks_statistic, "ks_statistic", KS_STATISTICS)
    integer = _is_integer_valued(x)
    if discrete and not integer:
        i = int(np.argmax(x != np.round(x)))
        raise ValueError(f"discrete=True needs integer data; masses[{i}] = {float(x[i])!r} is not an integer")
    return x, duration_years, level, m_max, integer


def _search_m_min(x, discrete, integer, min_tail, ks_statistic, units):
    """Completeness threshold by the KS search of Clauset et al. (2009), discrete or continuous.

    Parameters
    ----------
    x : numpy.ndarray
        The sizes [``units``].
    discrete : bool or None
        The caller's ``discrete``.
    integer : bool
        Whether every size is an integer.
    min_tail : int
        Fewest values above a candidate threshold.
    ks_statistic : str
        KS statistic of the search.
    units : str
        Label of the size unit (for the message).

    Returns
    -------
    tuple
        (m_min, switch): the threshold [``units``] and, when integer data put the continuous threshold below
        :data:`DISCRETE_BELOW` with ``discrete`` None, the warning to give before redoing the search for integers
        (else None).
    """
    if discrete:
        m_min, _, _ = _find_m_min_discrete(x, min_tail, ks_statistic)
        return m_min, None
    m_min, _, _ = find_m_min(x, min_tail=min_tail, statistic=ks_statistic)
    if discrete is None and integer and m_min < DISCRETE_BELOW:
        return m_min, (f"masses are integers and the continuous threshold search gives {m_min:g} {units} < "
                       f"{DISCRETE_BELOW}: fitting the discrete power law (half-unit approximation, Clauset et al. "
                       "2009 eq. 3.7); pass discrete=False to treat them as continuous")
    return m_min, None


def _check_given_m_min(x, m_min, discrete, integer, units):
    """Check a stated completeness threshold; a discrete fit moves it half a unit down (Clauset et al. 2009, eq. 3.7).

    Parameters
    ----------
    x : numpy.ndarray
        The sizes [``units``].
    m_min : float
        The caller's threshold [``units``].
    discrete : bool or None
        The caller's ``discrete``.
    integer : bool
        Whether every size is an integer.
    units : str
        Label of the size unit (for the messages).

    Returns
    -------
    tuple
        (m_min, advice): the threshold of the fit [``units``] and, for integer data below :data:`DISCRETE_BELOW`
        fitted as continuous with ``discrete`` None, the warning recommending ``discrete=True`` (else None).

    Raises
    ------
    ValueError
        When ``m_min`` is not positive, lies above every value, or is not an integer >= 1 for a discrete fit.
    """
    m_min = check_positive(m_min, "m_min")
    if m_min > x.max():
        raise ValueError(f"m_min = {m_min:g} {units} lies above every value (largest {x.max():g} {units})")
    advice = None
    if discrete is None and integer and m_min == round(m_min) and m_min < DISCRETE_BELOW:
        advice = (f"masses are integers and m_min = {m_min:g} < {DISCRETE_BELOW}: fitted as continuous; if they are "
                  "counts or sizes recorded in whole units pass discrete=True (half-unit approximation of the "
                  "discrete power law, Clauset et al. 2009 eq. 3.7)")
    if discrete:
        if m_min != round(m_min) or m_min < 1:
            raise ValueError(f"m_min = {m_min!r}: a discrete fit needs an integer threshold >= 1")
        m_min = m_min - 0.5
    return m_min, advice


def _fit_tail(x, m_min, units):
    """The sorted sizes at or above ``m_min`` [``units``] and their number, refused when b cannot be fitted.

    Parameters
    ----------
    x : numpy.ndarray
        The sizes [``units``].
    m_min : float
        The threshold of the fit [``units``].
    units : str
        Label of the size unit (for the message).

    Returns
    -------
    tuple
        (tail, n): sorted sizes >= ``m_min`` and their count.
    """
    tail = np.sort(x[x >= m_min])
    n = tail.size
    if n < 2 or np.all(tail == tail[0]):
        raise ValueError(f"m_min = {m_min:g} {units} leaves {n} value(s) (all equal) above it: at least two "
                         "distinct values are needed to fit b")
    return tail, n


def _fit_b_mle(tail, m_min, m_max, unbiased, level):
    """Maximum-likelihood b [-] of the (truncated) power law above ``m_min`` and its interval.

    Untruncated: the Hill estimator n / sum ln(m/m_min) (or (n-1)/... unbiased) with the exact chi-square interval;
    truncated at ``m_max``: the numerical MLE with the Wald interval from the observed information.

    Parameters
    ----------
    tail : numpy.ndarray
        Sorted sizes >= ``m_min``.
    m_min, m_max : float
        Threshold and truncation (None: untruncated), same unit as ``tail``.
    unbiased : bool
        Small-sample correction (n-1)/n.
    level : float
        Confidence level of the interval.

    Returns
    -------
    tuple
        (b, b_stderr, b_ci, ci_method).
    """
    n = tail.size
    S = float(np.sum(np.log(tail / m_min)))
    if m_max is None:
        b = (n - 1) / S if unbiased else n / S
        b_stderr = b / np.sqrt(n)
        q = (1 - level) / 2
        b_ci = (stats.chi2.ppf(q, 2 * n) / (2 * S), stats.chi2.isf(q, 2 * n) / (2 * S))
        ci_method = "exact chi-square interval (2 b sum ln(m/m_min) ~ chi2(2n))"
    else:
        b, b_stderr = _mle_truncated_b(tail, m_min, m_max)
        if unbiased:
            b *= (n - 1) / n
        z = stats.norm.isf((1 - level) / 2)
        b_ci = (b - z * b_stderr, b + z * b_stderr)
        ci_method = "Wald interval from the observed information"
    return b, b_stderr, b_ci, ci_method


def _fit_b_lsq(tail, duration_years, level):
    """Least-squares a and b [-] of the log-log cumulative annual frequency of the distinct sizes in ``tail``.

    Parameters
    ----------
    tail : numpy.ndarray
        Sorted sizes >= m_min.
    duration_years : float
        Record length [yr].
    level : float
        Confidence level of the t-interval on b.

    Returns
    -------
    tuple
        (a, b, b_stderr, b_ci, ci_method).
    """
    n = tail.size
    # Cumulative annual frequency of each distinct size: N(>=m_i) = #(x >= m_i) / T.
    values = np.unique(tail)
    counts = n - np.searchsorted(tail, values, side="left")
    X, Y = np.log10(values), np.log10(counts / duration_years)
    if values.size < 3:
        raise ValueError(f"least squares needs at least 3 distinct sizes above m_min; got {values.size}")
    reg = stats.linregress(X, Y)
    b, a, b_stderr = -reg.slope, reg.intercept, reg.stderr
    t = stats.t.isf((1 - level) / 2, values.size - 2)
    b_ci = (b - t * b_stderr, b + t * b_stderr)
    ci_method = "OLS t-interval (ignores dependence of cumulative points)"
    return a, b, b_stderr, b_ci, ci_method


def _fit_ks_distance(tail, b, m_min, m_max, discrete, ks_statistic):
    """KS distance between the tail and the fitted law (discrete data: at the half-unit cell edges).

    Parameters
    ----------
    tail : numpy.ndarray
        Sorted sizes >= ``m_min``.
    b : float
        Fitted exponent [-].
    m_min, m_max : float
        Threshold and truncation (None: untruncated), same unit as ``tail``.
    discrete : bool
        Whether the fit is the half-unit discrete approximation.
    ks_statistic : str
        KS statistic of the continuous case.

    Returns
    -------
    float
    """
    n = tail.size
    if discrete:
        values, counts = np.unique(tail, return_counts=True)
        return float(np.max(np.abs(np.cumsum(counts) / n - (1 - _truncated_sf(values + 0.5, b, m_min, m_max)))))
    return _ks_distance(tail, 1 - _truncated_sf(tail, b, m_min, m_max), ks_statistic)
