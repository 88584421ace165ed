"""Extreme-value models of annual-maximum masses: Gumbel and GEV (Wyllie 2014, section 8.4.2).

Gumbel (EV type I), in the ``scipy.stats.gumbel_r`` convention::

    F(x) = exp(-exp(-(x - loc) / scale)),   loc = alpha, scale = beta   (Wyllie's symbols)

GEV with the shape ``xi`` in the sign convention of Coles (2001, eq. 3.2)::

    F(x) = exp(-[1 + xi (x - mu) / sigma]^(-1/xi))

``xi > 0`` is the heavy-tailed Frechet type (the one a Poisson power law of
masses implies), ``xi < 0`` the bounded Weibull type.  scipy's ``genextreme``
uses ``c = -xi``; riskrf converts internally and only ever shows ``xi``.

Years without a recorded fall
-----------------------------
Annual maxima may contain NaN for years with no fall (see
:meth:`riskrf.Inventory.annual_maxima`).  With ``zero_years="mixed"`` (the
default) the fit uses the mixed model

    P(annual maximum <= x) = p0 + (1 - p0) F(x),   p0 = (years with no fall) / (years)

with F fitted to the years that had a fall, so return levels solve
``(1 - p0) (1 - F(x)) = 1/T``.  p0 is estimated by its sample fraction and held
fixed in the intervals.  ``zero_years="drop"`` ignores those years (with a
warning); it overstates the annual frequency of large falls.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize, stats

from simulation._display import Displayed, short_repr

from ..core.validation import (
    check_choice,
    check_probability_level,
    check_return_periods,
    warn,
)
from .empirical import _n_unknown_years, gumbel_reduced_variate

EULER_GAMMA = 0.5772156649015329

MIN_MAXIMA = {"gumbel": 5, "gev": 10}


def gumbel_frequency_factor(T):
    """K_T = (sqrt(6)/pi)(y_T - 0.5772), so that x_T = M + K_T S (Wyllie 2014, 8.4.2; Chow 1951).

    Parameters
    ----------
    T : float or array_like
        Return period [yr], > 1.

    Returns
    -------
    numpy.ndarray
        Frequency factor K_T [-] (M the mean, S the standard deviation of the annual maxima).

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, section 8.4.2.
    Chow, V. T. (1951). A general formula for hydrologic frequency analysis. Transactions, American
    Geophysical Union 32(2), 231-237.
    """
    return np.sqrt(6.0) / np.pi * (gumbel_reduced_variate(T) - EULER_GAMMA)


def encounter_probability(T, years):
    """P(the T-year event is exceeded at least once in ``years``) = 1 - (1 - 1/T)^years.

    Parameters
    ----------
    T : float or array_like
        Return period [yr], > 1.
    years : float or array_like
        Exposure time, e.g. a design life [yr].

    Returns
    -------
    numpy.ndarray
        Probability [-] of at least one exceedance (independent years).
    """
    T = check_return_periods(T)
    return -np.expm1(np.asarray(years, dtype=float) * np.log1p(-1.0 / T))


def _hessian(f, theta, rel=1e-4):
    """Central-difference Hessian of a scalar function."""
    theta = np.asarray(theta, dtype=float)
    k = theta.size
    h = rel * np.maximum(np.abs(theta), 1e-2)
    H = np.empty((k, k))
    for i in range(k):
        for j in range(i, k):
            ei, ej = np.zeros(k), np.zeros(k)
            ei[i], ej[j] = h[i], h[j]
            H[i, j] = H[j, i] = (f(theta + ei + ej) - f(theta + ei - ej) - f(theta - ei + ej)
                                 + f(theta - ei - ej)) / (4 * h[i] * h[j])
    return H


def _split_maxima(maxima, zero_years: str, model: str):
    check_choice(zero_years, "zero_years", ("mixed", "drop"))
    try:
        x = np.asarray(maxima, dtype=float).ravel()
    except (TypeError, ValueError) as exc:
        raise TypeError(f"maxima must be numeric; got {maxima!r:.80}") from exc
    if np.any(np.isinf(x)):
        raise ValueError(f"maxima[{int(np.argmax(np.isinf(x)))}] is infinite")
    empty = np.isnan(x)
    values = x[~empty]
    need = MIN_MAXIMA[model]
    if values.size < need:
        raise ValueError(f"maxima: {values.size} annual maxima (of {x.size} years) but a {model} fit needs at "
                         f"least {need}; a longer record is needed")
    if np.ptp(values) == 0:
        raise ValueError(f"maxima: all {values.size} annual maxima equal {float(values[0])!r}: a {model} fit needs "
                         "maxima that differ (its scale would be 0)")
    if values.size < 20:
        warn(f"only {values.size} annual maxima: return levels beyond about {2 * values.size} years are "
             "extrapolations with wide intervals")
    n_empty = int(empty.sum())
    if n_empty and zero_years == "drop":
        warn(f"{n_empty} year(s) without a fall dropped (zero_years='drop'): annual frequencies are overstated")
        return values, 0.0, values.size
    # years with falls of unknown size (Inventory.annual_maxima leaves them out): not empty, so they count in p0
    n_years = x.size + _n_unknown_years(maxima)
    return values, n_empty / n_years, n_years


@dataclass(frozen=True, repr=False)
class _AnnualMaximumFit(Displayed):
    """Shared behaviour of the Gumbel and GEV fits (mixed model with empty years)."""

    p_zero: float
    n_years: int
    method: str
    level: float
    cov: np.ndarray = field(repr=False)
    data: np.ndarray = field(repr=False)

    # Subclasses define: params (tuple), _frozen(params), _nll(params), _fit_params(x), param_names.

    def __post_init__(self):
        scale = self.params[1]
        if not (np.isfinite(scale) and scale > 0):
            raise ValueError(f"scale = {float(scale)!r}: the scale of a {type(self).__name__} must be finite and > 0")

    @property
    def dist(self):
        """The fitted scipy frozen distribution of the maximum of a year *with* a fall."""
        return self._frozen(self.params)

    def cdf(self, x):
        """P(annual maximum <= x), counting years without a fall (mixed model)."""
        return self.p_zero + (1 - self.p_zero) * self.dist.cdf(x)

    def sf(self, x):
        """Annual exceedance probability P(annual maximum > x)."""
        return (1 - self.p_zero) * self.dist.sf(x)

    def isf(self, p):
        """Annual maximum exceeded with annual probability p."""
        p = np.asarray(p, dtype=float)
        q = p / (1 - self.p_zero)
        if np.any((p <= 0) | (q >= 1)):
            raise ValueError(f"annual probability {p.ravel()[0]!r} is not reached: with {self.p_zero:.1%} of years "
                             "without a fall the return period must exceed "
                             f"{1 / (1 - self.p_zero):.3g} years")
        return self.dist.isf(q)

    def _quantile(self, params, T):
        q = (1.0 / np.asarray(T, dtype=float)) / (1 - self.p_zero)
        return self._isf_params(params, q)

    def return_level(self, T):
        """Annual maximum exceeded on average once in T years.

        Parameters
        ----------
        T : float or array_like
            Return period [yr], > 1/(1 - p_zero).

        Returns
        -------
        numpy.ndarray
            The annual maximum with annual exceedance probability 1/T [unit of the maxima, e.g. kg].
        """
        return self.isf(1.0 / check_return_periods(T))

    def __repr__(self) -> str:
        return short_repr(self, **dict(zip(self.param_names, self.params)), n_maxima=int(np.size(self.data)),
                          n_years=self.n_years, p_zero=self.p_zero, method=self.method)

    def plot(self, ax=None, **kwargs):
        """Return-level plot: the fitted annual maximum against the return period [yr], with its interval band (drawn by :func:`riskrf.frequency.figures.plot_return_levels`).

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
        from .figures import plot_return_levels
        return plot_return_levels(self, ax=ax, **kwargs)

    def return_period(self, x):
        """Return period [yr] of an annual maximum x, 1 / P(annual max > x)."""
        with np.errstate(divide="ignore"):
            return 1.0 / self.sf(x)

    @property
    def loglik(self) -> float:
        """Maximised log-likelihood of the annual maxima."""
        return float(-self._nll(self.params))

    @property
    def aic(self) -> float:
        """Akaike information criterion 2k - 2 ln L (lower is better)."""
        return 2 * len(self.params) - 2 * self.loglik

    @property
    def stderr(self) -> np.ndarray:
        """Standard errors of the parameters from the observed information (NaN where unavailable)."""
        return np.sqrt(np.diag(self.cov)) if self.cov is not None else np.full(len(self.params), np.nan)

    def return_level_ci(self, T, level: float = 0.95, method: str | None = None, *, n_bootstrap: int = 1000,
                        seed=None):
        """Confidence interval of the T-year return level.

        method : {"profile", "delta", "bootstrap"}, optional
            ``"profile"``: profile likelihood (Coles 2001, §3.3.3) - the default for
            maximum-likelihood fits, because return levels are skewed and the
            profile interval follows that asymmetry, where the symmetric delta
            interval undercovers at long return periods (Coles 2001, §4.3.3).
            ``"delta"``: the normal approximation with the covariance from the
            observed information (MLE) or Kite's (1977) variance for the moment
            estimator - the default for ``method="moments"``.
            ``"bootstrap"``: seeded parametric bootstrap, refitting with the same
            estimator each time (percentile interval) - the default for
            ``method="lmoments"``.

        Returns (lower, upper) arrays.  p0 (empty years) is held fixed.
        """
        T = check_return_periods(T)
        level = check_probability_level(level)
        if method is None:
            method = self.default_ci_method
        check_choice(method, "method", ("profile", "delta", "bootstrap"))
        if method == "delta":
            return self._delta_ci(T, level)
        if method == "bootstrap":
            return self._bootstrap_ci(T, level, n_bootstrap, seed)
        if self.method != "mle":
            raise ValueError(f"this fit has method = {self.method!r}: profile-likelihood intervals need a "
                             "maximum-likelihood fit (method='mle')")
        flat = np.atleast_1d(T).ravel()
        bounds = np.array([self._profile_ci(t, level) for t in flat])
        return bounds[:, 0].reshape(np.shape(T)), bounds[:, 1].reshape(np.shape(T))

    @property
    def default_ci_method(self) -> str:
        """Interval method used when none is asked: profile likelihood for MLE, delta for moments, bootstrap for L-moments."""
        return {"mle": "profile", "moments": "delta", "lmoments": "bootstrap"}[self.method]

    def _delta_ci(self, T, level):
        z = stats.norm.isf((1 - level) / 2)
        centre = self.return_level(T)
        var = self._return_level_variance(T)
        se = np.sqrt(var)
        return centre - z * se, centre + z * se

    def _return_level_variance(self, T):
        """Var(x_T) by the delta method: grad' V grad."""
        if self.cov is None:
            raise ValueError(f"no covariance for method={self.method!r}; use method='bootstrap'")
        theta = np.asarray(self.params, dtype=float)
        grads = []
        for i in range(theta.size):
            h = 1e-6 * max(abs(theta[i]), 1e-2)
            up, dn = theta.copy(), theta.copy()
            up[i] += h
            dn[i] -= h
            grads.append((self._quantile(up, T) - self._quantile(dn, T)) / (2 * h))
        g = np.stack(grads, axis=-1)
        return np.einsum("...i,ij,...j->...", g, self.cov, g)

    def _bootstrap_ci(self, T, level, n_bootstrap, seed):
        n = self.data.size
        levels = []
        for child in np.random.SeedSequence(seed).spawn(int(n_bootstrap)):
            sample = self.dist.rvs(size=n, random_state=np.random.default_rng(child))
            try:
                params = self._fit_params(sample, self.method)
            except (RuntimeError, ValueError, FloatingPointError):
                continue
            levels.append(self._quantile(params, T))
        levels = np.array(levels)
        q = (1 - level) / 2
        return np.quantile(levels, q, axis=0), np.quantile(levels, 1 - q, axis=0)

    def _profile_ci(self, T, level):
        """Profile-likelihood interval of the T-year return level (Coles 2001, §3.3.3, fig. 3.3).

        The model is reparametrised in terms of the return level z itself:
        for each trial z the location follows from z and the free parameters
        (``_profile_map``), and the free parameters are mapped so that every
        point of the search space is feasible (for the GEV the scale is kept
        above the value at which some observation would leave the support, see
        :meth:`GEVFit._profile_map`).  The inner optimisation therefore never
        starts from a point of zero likelihood, however far z lies from the
        estimate.  The crossing of the chi-square cut is bracketed by doubling
        steps away from the estimate and located by Brent's method.  An end of
        the interval that is not reached within 2^60 standard errors is reported
        as -inf or +inf (the data do not bound it at this level).
        """
        crit = stats.chi2.ppf(level, 1) / 2
        best = -self._nll(self.params)
        q = (1.0 / float(T)) / (1 - self.p_zero)
        xhat = float(self._isf_params(self.params, q))
        cold = self._profile_start(xhat, q)
        warm = {"u": cold}

        from ._extremes_kernels import profile_nll_min

        x = np.ascontiguousarray(self.data, dtype=float)
        ly = float(np.log(-np.log1p(-q)))

        def profile(z):
            """Profile log-likelihood at return level z minus the cut: > 0 inside the interval."""
            fun, arg = np.inf, None
            for start in (warm["u"], self._profile_start(z, q)):
                f, u = profile_nll_min(self._profile_model, np.asarray(start, dtype=float), float(z), ly, x,
                                       0.3, 1e-6, 1e-8, 4000)
                if f < fun:
                    fun, arg = f, u
                if np.isfinite(fun) and start is warm["u"] and crit - best - fun > 0.5:
                    break           # clearly inside the interval: the second start cannot change the sign
            if arg is not None:
                warm["u"] = arg
            return crit - best - fun     # -fun is the profile log-likelihood

        try:
            se = float(np.sqrt(self._return_level_variance(T)))
        except (ValueError, FloatingPointError):
            se = np.nan
        if not np.isfinite(se) or se <= 0:
            se = max(abs(xhat), 1.0) * 0.1
        out = []
        for sign in (-1.0, 1.0):
            warm["u"] = cold
            inner, step = xhat, se / 4.0
            for _ in range(64):
                edge = xhat + sign * step
                if -profile(edge) > 0:
                    break
                inner, step = edge, step * 2.0
            else:
                out.append(sign * np.inf)
                continue
            lo, hi = sorted((inner, edge))
            warm["u"] = cold
            try:
                out.append(optimize.brentq(lambda z: -profile(z), lo, hi,
                                           xtol=1e-7 * max(abs(lo), abs(hi), 1e-3), rtol=1e-6))
            except ValueError:
                out.append(np.nan)
        return out


def _gumbel_lmoments(x):
    x = np.sort(x)
    n = x.size
    b0 = x.mean()
    b1 = np.sum(np.arange(n) / (n - 1) * x) / n
    l2 = 2 * b1 - b0
    scale = l2 / np.log(2.0)
    return b0 - EULER_GAMMA * scale, scale


@dataclass(frozen=True, repr=False)
class GumbelFit(_AnnualMaximumFit):
    """Gumbel fit of annual maxima.  ``loc`` = alpha, ``scale`` = beta (scipy ``gumbel_r``)."""

    loc: float = np.nan
    scale: float = np.nan
    param_names = ("loc", "scale")

    @property
    def params(self):
        """(loc, scale) in the unit of the maxima."""
        return (self.loc, self.scale)

    @staticmethod
    def _frozen(params):
        return stats.gumbel_r(loc=params[0], scale=params[1])

    @staticmethod
    def _isf_params(params, q):
        """x exceeded with probability q: loc - scale ln(-ln(1 - q))."""
        return params[0] - params[1] * np.log(-np.log1p(-q))

    _profile_model = 0      # Gumbel in riskrf.frequency._extremes_kernels.profile_nll

    def _profile_map(self, z, q, u):
        """(loc, scale) with return level z at exceedance probability q; u = (ln scale,)."""
        if not abs(u[0]) < 700:
            return (z, -1.0)
        sigma = np.exp(u[0])
        return (z + sigma * np.log(-np.log1p(-q)), sigma)

    def _profile_start(self, z, q):
        return np.array([np.log(self.scale)])

    def _nll(self, params):
        if params[1] <= 0:
            return np.inf
        return -float(np.sum(stats.gumbel_r.logpdf(self.data, loc=params[0], scale=params[1])))

    @staticmethod
    def _fit_params(x, method):
        if method == "moments":
            scale = np.std(x, ddof=1) * np.sqrt(6.0) / np.pi
            return (float(np.mean(x) - EULER_GAMMA * scale), float(scale))
        if method == "lmoments":
            return tuple(float(v) for v in _gumbel_lmoments(x))
        loc0, scale0 = _gumbel_lmoments(x)
        loc, scale = stats.gumbel_r.fit(x, loc=loc0, scale=scale0)
        return (float(loc), float(scale))

    def _return_level_variance(self, T):
        if self.method == "moments":
            # Kite (1977): Var(x_T) = (S^2/n)(1 + 1.1396 K + 1.1000 K^2), K the frequency factor.
            K = np.sqrt(6.0) / np.pi * (-np.log(-np.log1p(-(1 / np.asarray(T)) / (1 - self.p_zero))) - EULER_GAMMA)
            S = np.std(self.data, ddof=1)
            return S ** 2 / self.data.size * (1 + 1.1396 * K + 1.1000 * K ** 2)
        return super()._return_level_variance(T)

    def summary(self) -> pd.DataFrame:
        """Parameters with standard errors and the fitting method, one row each.

        Returns
        -------
        pandas.DataFrame
            Indexed by parameter; columns ``value`` (loc and scale in the unit of the maxima), ``stderr``,
            ``note``.
        """
        se = self.stderr
        label = {"mle": "maximum likelihood", "moments": "method of moments (Wyllie: S with ddof=1)",
                 "lmoments": "L-moments (Hosking 1990)"}[self.method]
        rows = [("loc (alpha)", self.loc, se[0], label), ("scale (beta)", self.scale, se[1], label),
                ("p_zero", self.p_zero, np.nan, "share of years without a fall (mixed model)"),
                ("n_maxima", self.data.size, np.nan, f"of {self.n_years} years"),
                ("loglik", self.loglik, np.nan, ""),
                ("ci method", np.nan, np.nan, f"{self.default_ci_method} (default for {self.method})")]
        return pd.DataFrame(rows, columns=["parameter", "value", "stderr", "note"]).set_index("parameter")


@dataclass(frozen=True, repr=False)
class GEVFit(_AnnualMaximumFit):
    """GEV fit of annual maxima; ``shape`` is xi in Coles' sign (scipy's c = -xi)."""

    loc: float = np.nan
    scale: float = np.nan
    shape: float = np.nan
    param_names = ("loc", "scale", "shape")

    @property
    def params(self):
        """(loc, scale, shape xi) with scipy's sign convention reversed: xi > 0 is a heavy (Frechet) tail."""
        return (self.loc, self.scale, self.shape)

    @staticmethod
    def _frozen(params):
        return stats.genextreme(-params[2], loc=params[0], scale=params[1])

    @staticmethod
    def _isf_params(params, q):
        """x exceeded with probability q (Coles 2001, eq. 3.4)."""
        mu, sigma, xi = params
        y = -np.log1p(-np.asarray(q, dtype=float))
        if abs(xi) < 1e-9:
            return mu - sigma * np.log(y)
        return mu + sigma / xi * (y ** (-xi) - 1.0)

    def _scale_floor(self, z, q, xi):
        """Smallest scale for which every observation lies inside the support when the
        return level is z: sigma y^-xi + xi (x_i - z) > 0 for all i, y = -ln(1 - q)."""
        y = -np.log1p(-q)
        reach = max(0.0, xi * (z - self.data.min()), xi * (z - self.data.max()))
        return reach * y ** xi

    _profile_model = 1      # GEV in riskrf.frequency._extremes_kernels.profile_nll

    def _profile_map(self, z, q, u):
        """(mu, sigma, xi) with return level z at exceedance probability q.

        u = (xi, t) with sigma = floor(z, xi) + e^t: every u is a feasible point,
        so the profile search can start anywhere (Coles 2001, §3.3.3 reparametrises
        the GEV by z_p in the same way, eq. 3.4 solved for mu).
        """
        xi, t = float(u[0]), float(u[1])
        if not (abs(xi) < 20 and abs(t) < 700):
            return (z, -1.0, xi)
        sigma = self._scale_floor(z, q, xi) + np.exp(t)
        ly = np.log(-np.log1p(-q))
        mu = z + sigma * ly if abs(xi) < 1e-9 else z - sigma * np.expm1(-xi * ly) / xi
        return (mu, sigma, xi)

    def _profile_start(self, z, q):
        xi = float(np.clip(self.shape, -0.9, 3.0))
        floor = self._scale_floor(z, q, xi)
        gap = max(self.scale - floor, 0.5 * floor, 1e-6 * abs(self.scale))
        return np.array([xi, np.log(gap)])

    def _nll(self, params):
        return _gev_nll(params, self.data)

    @staticmethod
    def _fit_params(x, method):
        return _fit_gev_mle(x)

    def deviance_vs_gumbel(self) -> dict:
        """Deviance test of Gumbel (xi = 0) against this GEV (Coles 2001, §2.6.6).

        D = 2 (l_GEV - l_Gumbel) ~ chi2(1) under the Gumbel; a small p-value
        says the Gumbel is not adequate.

        Returns
        -------
        dict
            ``deviance`` D [-], ``p_value``, ``gumbel_adequate`` (p >= 0.05), ``loglik_gev``, ``loglik_gumbel``.

        References
        ----------
        Coles, S. (2001). An Introduction to Statistical Modeling of Extreme Values. Springer, §2.6.6.
        """
        gum = GumbelFit(p_zero=self.p_zero, n_years=self.n_years, method="mle", level=self.level, cov=None,
                        data=self.data, **dict(zip(("loc", "scale"), GumbelFit._fit_params(self.data, "mle"))))
        D = max(2 * (self.loglik - gum.loglik), 0.0)
        p = float(stats.chi2.sf(D, 1))
        return {"deviance": D, "p_value": p, "gumbel_adequate": p >= 0.05,
                "loglik_gev": self.loglik, "loglik_gumbel": gum.loglik}

    def summary(self) -> pd.DataFrame:
        """Parameters with standard errors, the shape's meaning and the fitting method, one row each.

        Returns
        -------
        pandas.DataFrame
            Indexed by parameter; columns ``value`` (loc and scale in the unit of the maxima, shape [-]),
            ``stderr``, ``note``.
        """
        se = self.stderr
        rows = [("loc (mu)", self.loc, se[0], "maximum likelihood"),
                ("scale (sigma)", self.scale, se[1], "maximum likelihood"),
                ("shape (xi, Coles sign)", self.shape, se[2], "xi>0 heavy (Frechet), xi<0 bounded"),
                ("p_zero", self.p_zero, np.nan, "share of years without a fall (mixed model)"),
                ("n_maxima", self.data.size, np.nan, f"of {self.n_years} years"),
                ("loglik", self.loglik, np.nan, ""),
                ("ci method", np.nan, np.nan, "profile likelihood (default)")]
        return pd.DataFrame(rows, columns=["parameter", "value", "stderr", "note"]).set_index("parameter")


def _gev_nll(params, x):
    mu, sigma, xi = params
    if sigma <= 0:
        return np.inf
    z = (x - mu) / sigma
    if abs(xi) < 1e-8:
        return float(np.sum(np.log(sigma) + z + np.exp(-z)))
    t = 1 + xi * z
    if np.any(t <= 0):
        return np.inf
    return float(np.sum(np.log(sigma) + (1 + 1 / xi) * np.log(t) + t ** (-1 / xi)))


def _fit_gev_mle(x):
    """GEV maximum likelihood: a compiled Nelder-Mead search from the L-moment Gumbel fit with
    shapes 0.1, -0.1 and 0.3, in coordinates standardised by that fit; the best is kept."""
    from ._extremes_kernels import profile_nll_min

    loc0, scale0 = _gumbel_lmoments(x)
    if not scale0 > 0:
        raise ValueError(f"maxima: the annual maxima have no spread (all equal to {x[0]:.6g}); "
                         "a GEV needs a positive scale")
    xs = np.ascontiguousarray(x, dtype=float)
    best, arg = np.inf, None
    for xi0 in (0.1, -0.1, 0.3):
        u = np.array([0.0, 0.0, xi0])
        for _ in range(3):          # restart from the optimum: Nelder-Mead can stall on a ridge
            f, u = profile_nll_min(2, u, float(loc0), float(scale0), xs, 0.3, 1e-10, 1e-12, 20000)
        if f < best:
            best, arg = f, u
    if arg is None or not np.isfinite(best):
        raise RuntimeError("GEV maximum likelihood did not converge")
    return (float(loc0 + scale0 * arg[0]), float(scale0 * np.exp(arg[1])), float(arg[2]))


def fit_gumbel(maxima, method: str = "mle", *, zero_years: str = "mixed", level: float = 0.95) -> GumbelFit:
    """Fit a Gumbel distribution to annual maxima (Wyllie 2014, 8.4.2).

    Parameters
    ----------
    maxima : array_like or pandas.Series
        Annual maxima [kg]; NaN marks a year without a fall (see module notes).
    method : {"mle", "moments", "lmoments"}
        ``"mle"`` (default): maximum likelihood, covariance from the observed
        information.  ``"moments"``: Wyllie's equations beta = S sqrt(6)/pi,
        alpha = M - 0.5772 beta with M the mean and S the sample standard
        deviation (ddof = 1).  ``"lmoments"``: beta = l2 / ln 2, alpha = l1 - 0.5772 beta.
    zero_years : {"mixed", "drop"}
        How years without a fall enter (default: the mixed model).
    level : float
        Default confidence level recorded with the fit.

    Returns
    -------
    GumbelFit
        ``loc`` (alpha) and ``scale`` (beta) in the unit of the maxima [kg], the share of years without a fall,
        and the covariance (maximum likelihood).

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, section 8.4.2 (method of moments).
    Hosking, J. R. M. (1990). L-moments. Journal of the Royal Statistical Society B 52(1), 105-124.
    """
    check_choice(method, "method", ("mle", "moments", "lmoments"))
    x, p0, n_years = _split_maxima(maxima, zero_years, "gumbel")
    loc, scale = GumbelFit._fit_params(x, method)
    fit = GumbelFit(p_zero=p0, n_years=n_years, method=method, level=check_probability_level(level), cov=None,
                    data=x, loc=loc, scale=scale)
    if method == "mle":
        cov = np.linalg.inv(_hessian(fit._nll, fit.params))
        object.__setattr__(fit, "cov", cov)
    return fit


def fit_gev(maxima, *, zero_years: str = "mixed", level: float = 0.95) -> GEVFit:
    """Fit a GEV distribution to annual maxima by maximum likelihood (Coles 2001, ch. 3).

    The optimiser starts from the L-moment Gumbel fit with several shapes and
    keeps the best; the covariance is the inverse observed information (a
    numerical Hessian).  ``shape`` is xi in Coles' sign convention.

    Parameters
    ----------
    maxima : array_like or pandas.Series
        Annual maxima [kg]; NaN marks a year without a fall.
    zero_years : {"mixed", "drop"}
        How years without a fall enter (default: the mixed model).
    level : float
        Default confidence level recorded with the fit.

    Returns
    -------
    GEVFit
        ``loc`` (mu), ``scale`` (sigma) [unit of the maxima] and ``shape`` (xi, Coles' sign), with the covariance.

    References
    ----------
    Coles, S. (2001). An Introduction to Statistical Modeling of Extreme Values. Springer, chapter 3 (eq. 3.2).
    """
    x, p0, n_years = _split_maxima(maxima, zero_years, "gev")
    params = _fit_gev_mle(x)
    fit = GEVFit(p_zero=p0, n_years=n_years, method="mle", level=check_probability_level(level), cov=None,
                 data=x, loc=params[0], scale=params[1], shape=params[2])
    H = _hessian(fit._nll, fit.params)
    try:
        cov = np.linalg.inv(H)
    except np.linalg.LinAlgError:
        cov = None
    object.__setattr__(fit, "cov", cov)
    if params[2] < -0.5:
        warn(f"GEV shape xi = {params[2]:.3f} < -0.5: the maximum-likelihood estimator is irregular "
             "(Smith 1985) and its intervals unreliable")
    return fit
