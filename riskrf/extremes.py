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

from .validation import (
    check_choice,
    check_probability_level,
    check_return_periods,
    warn,
)

EULER_GAMMA = 0.5772156649015329

#: Plotting-position constants ``a`` of ``(i - a) / (n + 1 - 2a)`` for ascending rank i.
PLOTTING_POSITIONS = {"weibull": 0.0, "gringorten": 0.44, "cunnane": 0.4, "hazen": 0.5, "blom": 0.375}

MIN_MAXIMA = {"gumbel": 5, "gev": 10}


def plotting_positions(n: int, formula: str = "gringorten") -> np.ndarray:
    """Non-exceedance probabilities of the ascending order statistics 1..n.

    ``(i - a) / (n + 1 - 2a)`` with a = 0 (Weibull, i/(n+1)), 0.44 (Gringorten,
    recommended for Gumbel), 0.4 (Cunnane), 0.5 (Hazen, (i-0.5)/n) or 0.375 (Blom).
    """
    check_choice(formula, "formula", tuple(PLOTTING_POSITIONS))
    if int(n) < 1:
        raise ValueError(f"n must be >= 1; got {n}")
    a = PLOTTING_POSITIONS[formula]
    i = np.arange(1, int(n) + 1)
    return (i - a) / (n + 1 - 2 * a)


def gumbel_reduced_variate(T):
    """y_T = -ln(-ln(1 - 1/T)): the Gumbel reduced variate of return period T [yr]."""
    T = check_return_periods(T)
    return -np.log(-np.log1p(-1.0 / T))


def gumbel_frequency_factor(T):
    """K_T = (sqrt(6)/pi)(y_T - 0.5772), so that x_T = M + K_T S (Wyllie 2014, 8.4.2; Chow 1951)."""
    return np.sqrt(6.0) / np.pi * (gumbel_reduced_variate(T) - EULER_GAMMA)


def encounter_probability(T, years):
    """P(the T-year event is exceeded at least once in ``years``) = 1 - (1 - 1/T)^years."""
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
    if values.size < 20:
        warn(f"only {values.size} annual maxima: return levels beyond about {2 * values.size} years are "
             "extrapolations with wide intervals")
    n_empty = int(empty.sum())
    if n_empty and zero_years == "drop":
        warn(f"{n_empty} year(s) without a fall dropped (zero_years='drop'): annual frequencies are overstated")
        return values, 0.0, values.size
    return values, n_empty / x.size, x.size


@dataclass(frozen=True)
class _AnnualMaximumFit:
    """Shared behaviour of the Gumbel and GEV fits (mixed model with empty years)."""

    p_zero: float
    n_years: int
    method: str
    level: float
    cov: np.ndarray = field(repr=False)
    data: np.ndarray = field(repr=False)

    # Subclasses define: params (tuple), _frozen(params), _nll(params), _fit_params(x), param_names.

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
        """Annual maximum exceeded on average once in T years."""
        return self.isf(1.0 / check_return_periods(T))

    def return_period(self, x):
        """Return period [yr] of an annual maximum x, 1 / P(annual max > x)."""
        with np.errstate(divide="ignore"):
            return 1.0 / self.sf(x)

    @property
    def loglik(self) -> float:
        return float(-self._nll(self.params))

    @property
    def aic(self) -> float:
        return 2 * len(self.params) - 2 * self.loglik

    @property
    def stderr(self) -> np.ndarray:
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
        crit = stats.chi2.ppf(level, 1) / 2
        best = -self._nll(self.params)
        xhat = float(self._quantile(self.params, T))
        free0 = np.asarray(self.params[1:], dtype=float)

        warm = {"free": free0}

        unit = np.maximum(np.abs(free0), 0.1)  # optimise in units of the estimates: scale-free tolerances

        def profile(z):
            def nll_free(u):
                free = u * unit
                mu = z - (float(self._quantile(np.concatenate([[0.0], free]), T)))
                return self._nll(np.concatenate([[mu], free]))
            fun, x = np.inf, warm["free"]
            for start in (warm["free"], free0):
                res = optimize.minimize(nll_free, start / unit, method="Nelder-Mead",
                                        options={"xatol": 1e-6, "fatol": 1e-7, "maxiter": 600})
                if res.fun < fun:
                    fun, x = res.fun, res.x * unit
            if np.isfinite(fun):
                warm["free"] = x
            return best + max(fun, -best) - crit

        se = float(np.sqrt(self._return_level_variance(T))) if self.cov is not None else abs(xhat) * 0.1
        out = []
        for sign in (-1.0, 1.0):
            warm["free"] = free0
            step, edge = se, xhat
            for _ in range(60):
                edge = xhat + sign * step
                if profile(edge) > 0:
                    break
                step *= 2.0
            else:
                out.append(np.nan)
                continue
            inner = xhat + sign * (step / 2.0 if step > se else 0.0)
            lo, hi = sorted((inner, edge))
            try:
                out.append(optimize.brentq(profile, lo, hi, xtol=1e-6 * max(1e-3, abs(xhat)), rtol=1e-7))
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


@dataclass(frozen=True)
class GumbelFit(_AnnualMaximumFit):
    """Gumbel fit of annual maxima.  ``loc`` = alpha, ``scale`` = beta (scipy ``gumbel_r``)."""

    loc: float = np.nan
    scale: float = np.nan
    param_names = ("loc", "scale")

    @property
    def params(self):
        return (self.loc, self.scale)

    @staticmethod
    def _frozen(params):
        return stats.gumbel_r(loc=params[0], scale=params[1])

    @staticmethod
    def _isf_params(params, q):
        """x exceeded with probability q: loc - scale ln(-ln(1 - q))."""
        return params[0] - params[1] * np.log(-np.log1p(-q))

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
        se = self.stderr
        label = {"mle": "maximum likelihood", "moments": "method of moments (Wyllie: S with ddof=1)",
                 "lmoments": "L-moments (Hosking 1990)"}[self.method]
        rows = [("loc (alpha)", self.loc, se[0], label), ("scale (beta)", self.scale, se[1], label),
                ("p_zero", self.p_zero, np.nan, "share of years without a fall (mixed model)"),
                ("n_maxima", self.data.size, np.nan, f"of {self.n_years} years"),
                ("loglik", self.loglik, np.nan, ""),
                ("ci method", np.nan, np.nan, f"{self.default_ci_method} (default for {self.method})")]
        return pd.DataFrame(rows, columns=["parameter", "value", "stderr", "note"]).set_index("parameter")


@dataclass(frozen=True)
class GEVFit(_AnnualMaximumFit):
    """GEV fit of annual maxima; ``shape`` is xi in Coles' sign (scipy's c = -xi)."""

    loc: float = np.nan
    scale: float = np.nan
    shape: float = np.nan
    param_names = ("loc", "scale", "shape")

    @property
    def params(self):
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

    def _nll(self, params):
        return _gev_nll(params, self.data)

    @staticmethod
    def _fit_params(x, method):
        return _fit_gev_mle(x)

    def deviance_vs_gumbel(self) -> dict:
        """Deviance test of Gumbel (xi = 0) against this GEV (Coles 2001, §2.6.6).

        D = 2 (l_GEV - l_Gumbel) ~ chi2(1) under the Gumbel; a small p-value
        says the Gumbel is not adequate.
        """
        gum = GumbelFit(p_zero=self.p_zero, n_years=self.n_years, method="mle", level=self.level, cov=None,
                        data=self.data, **dict(zip(("loc", "scale"), GumbelFit._fit_params(self.data, "mle"))))
        D = max(2 * (self.loglik - gum.loglik), 0.0)
        p = float(stats.chi2.sf(D, 1))
        return {"deviance": D, "p_value": p, "gumbel_adequate": p >= 0.05,
                "loglik_gev": self.loglik, "loglik_gumbel": gum.loglik}

    def summary(self) -> pd.DataFrame:
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
    loc0, scale0 = _gumbel_lmoments(x)
    best = None
    for xi0 in (0.1, -0.1, 0.3):
        res = optimize.minimize(lambda p: _gev_nll(p, x), [loc0, scale0, xi0], method="Nelder-Mead",
                                options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 20000, "maxfev": 40000})
        if np.isfinite(res.fun) and (best is None or res.fun < best.fun):
            best = res
    if best is None:
        raise RuntimeError("GEV maximum likelihood did not converge")
    return tuple(float(v) for v in best.x)


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
