"""The fitted power law, :class:`GutenbergRichterFit`: annual frequencies, return levels, one fall's size.

``log10 N(>=m) = a - b log10 m`` [N per year, m in kg or m³] above m_min (and up to m_max when truncated,
Wyllie 2014, section 8.4.1; Corominas et al. 2018).  The fit is also a frozen probability distribution of the
size of one fall (``sf``, ``isf``, ``pdf``, ``rvs``); its goodness-of-fit methods call
:mod:`riskrf.frequency.power_law.goodness`.  Made by :func:`riskrf.frequency.power_law.fit_gutenberg_richter`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import stats

from simulation._display import Displayed, short_repr

from ...core.validation import check_positive, check_probability_level
from .goodness import PowerLawBootstrap, bootstrap_test, compare_alternatives
from .law import _loglik_power, _truncated_isf, _truncated_sf


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
        return bootstrap_test(self, n_bootstrap, seed, min_tail=min_tail, workers=workers, progress=progress,
                              grid=grid)

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
        return compare_alternatives(self)

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
        """Magnitude-frequency plot: the recorded falls and the fitted N(>=m) [1/yr] with the band of b, log-log (drawn by :func:`riskrf.frequency.figures.plot_magnitude_frequency`).

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
        from ..figures import plot_magnitude_frequency
        return plot_magnitude_frequency(self, ax=ax, **kwargs)

