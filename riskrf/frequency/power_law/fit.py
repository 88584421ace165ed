"""Fitting the power law: :func:`fit_gutenberg_richter`, its estimators and the checks of its arguments.

``method="mle"``: the continuous maximum-likelihood estimator (Aki 1965; Clauset, Shalizi & Newman 2009,
eq. 3.1) with its exact chi-square interval, or the numerical MLE of the truncated law; ``method="lsq"``:
least squares on the log-log cumulative annual frequency, as practitioners do (Wyllie 2014; Hungr, Evans &
Hazzard 1999), for comparison only.  The threshold is given or searched (:mod:`.threshold`).  Sizes in kg
(or m³ with ``units="m3"``), record length in years, rates per year.
"""
from __future__ import annotations

import numpy as np
from scipy import stats

from ...core.validation import as_positive_array, check_choice, check_positive, check_probability_level, warn
from .law import _mle_truncated_b, _truncated_sf
from .result import GutenbergRichterFit
from .threshold import (
    DISCRETE_BELOW,
    KS_STATISTICS,
    _find_m_min_discrete,
    _is_integer_valued,
    _ks_distance,
    find_m_min,
)


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
    from ..inventory.record import Inventory

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
