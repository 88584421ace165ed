"""Time-varying rock fall rates: count regression on rainfall, season and a trend.

Rock fall rates are not constant: Wyllie (2014, section 1.3) ties them to
precipitation, freeze-thaw and seismicity.  :func:`rate_model` counts the
events of a dated inventory per day, month or year and fits two log-linear
count models of the expected count :math:`\\mu_t` in period :math:`t`,

.. math::  \\log \\mu_t = \\log E_t + \\beta_0 + \\sum_k \\beta_k x_{kt},

with exposure :math:`E_t` (days of the period inside the record) and
covariates :math:`x_{kt}`: rainfall totals over antecedent windows [per
100 mm], the season (an annual harmonic, or a wet-season indicator, or the
calendar month) and the year (a log-linear trend), plus any user covariates
(temperature, freeze-thaw days ...).  The two models are

* **Poisson** regression (a generalised linear model, McCullagh & Nelder
  1989, ch. 6), Var(Y) = mu;
* **negative binomial** (NB2) regression, Var(Y) = mu + alpha mu^2, which
  allows for clustering of events beyond the covariates (Cameron & Trivedi
  2013, *Regression Analysis of Count Data*, 2nd ed., sections 3.3-3.4).

Both are fitted with statsmodels.  They are compared by AIC and deviance;
overdispersion is tested with the likelihood-ratio test of alpha = 0 (on the
boundary, so the p-value is half the chi-square(1) tail; Cameron & Trivedi 2013,
section 3.4) and with Cameron & Trivedi's (1990) auxiliary regression.  The
preferred model is the negative binomial when the overdispersion test rejects
alpha = 0 at 5 %, else the Poisson.  exp(beta_k) is the rate ratio for a
unit change of x_k (per 100 mm of rainfall, per year of trend) with Wald
intervals; the trend is tested by the likelihood ratio of the preferred model
with and without the year term.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from .inventory.record import Inventory
from ..io.rainfall import Rainfall, read_rainfall
from ..core.validation import RiskrfWarning, warn
from simulation._display import Displayed, short_repr

#: Fewest periods a count model is fitted to.
MIN_PERIODS = 20
#: Default antecedent rainfall bands for daily counts [days]: the day itself,
#: the two days before, and days 3-14 before.
DEFAULT_WINDOWS_DAYS = (1, 3, 15)
_PERIODS = {"day": "D", "month": "MS", "year": "YS"}
_SEASONS = ("harmonic", "wet", "month", None)
#: Hong Kong's wet season (Observatory usage): April to September.
WET_MONTHS = (4, 5, 6, 7, 8, 9)


def _band_name(lo: int, hi: int) -> tuple[str, str]:
    if lo == hi == 0:
        return "rain_d0_mm", "rainfall on the day"
    if lo == hi:
        return f"rain_d{lo}_mm", f"rainfall {lo} day{'s' if lo > 1 else ''} before"
    return f"rain_d{lo}_{hi}_mm", f"rainfall {lo}-{hi} days before"


@dataclass(frozen=True, repr=False)
class RateModel(Displayed):
    """Poisson and negative-binomial regressions of event counts (see :func:`rate_model`).

    Attributes
    ----------
    design : pandas.DataFrame
        One row per period: ``period_start``, ``count``, ``exposure_days`` and the
        covariates as entered (rainfall in mm, ``year_c`` in years from
        ``year_ref``, season terms, user covariates).
    terms : pandas.DataFrame
        Each model term: ``term``, ``label``, ``unit`` (the change the rate ratio
        refers to, e.g. ``100 mm``), ``scale`` (divisor applied to the covariate).
    poisson, negbin : statsmodels results
        The fitted Poisson GLM and negative binomial (NB2) model (None when it
        could not be fitted; see ``notes``).
    preferred : str
        ``"negative binomial"`` or ``"Poisson"``; ``reason`` says why.
    comparison : pandas.DataFrame
        Log-likelihood, AIC, deviance, residual degrees of freedom, Pearson
        chi-square / df and alpha of both models.
    overdispersion : dict
        ``lr_statistic``, ``lr_p_value`` (alpha = 0, boundary-corrected),
        ``ct_statistic``, ``ct_p_value`` (Cameron-Trivedi 1990), ``alpha``.
    rate_ratios : pandas.DataFrame
        The preferred model's rate ratio per term with ``level`` intervals and
        Wald p-values.
    trend : dict or None
        ``rate_ratio_per_year`` with interval, ``lr_statistic``, ``p_value``,
        ``detected`` (p < 0.05), the model it was tested in.
    """

    design: pd.DataFrame
    terms: pd.DataFrame
    period: str
    poisson: object
    negbin: object
    preferred: str
    reason: str
    comparison: pd.DataFrame
    overdispersion: dict
    rate_ratios: pd.DataFrame
    trend: dict | None
    level: float
    year_ref: float
    inventory_source: str
    rainfall_source: str
    start: pd.Timestamp
    end: pd.Timestamp
    season: str | None
    windows_days: tuple
    notes: tuple = field(default_factory=tuple)
    _glm_preferred: object = field(default=None, repr=False, compare=False)
    rainfall: Rainfall | None = field(default=None, repr=False, compare=False)

    # --- small accessors -------------------------------------------------
    @property
    def n_periods(self) -> int:
        """Number of periods (rows) in the regression design."""
        return len(self.design)

    @property
    def n_events(self) -> int:
        """Number of falls counted over all periods."""
        return int(self.design["count"].sum())

    @property
    def preferred_result(self):
        """The fitted statsmodels result of the preferred model (negative binomial or Poisson)."""
        return self.negbin if self.preferred == "negative binomial" else self.poisson

    def _exog(self, frame: pd.DataFrame) -> pd.DataFrame:
        return _exog(frame, self.terms)

    def summary(self) -> pd.DataFrame:
        """Key figures (one-column table): periods, events, preferred model, tests, rate ratios.

        Returns
        -------
        pandas.DataFrame
            Index: quantity (rates in events per year); column ``value``.
        """
        od, rows = self.overdispersion, {}
        rows["inventory"] = self.inventory_source
        rows["rainfall"] = self.rainfall_source
        rows["period"] = f"{self.period} ({self.start.date()} to {self.end.date()})"
        rows["periods / events"] = f"{self.n_periods} / {self.n_events}"
        rows["mean rate [events/yr]"] = round(self.n_events / (self.design["exposure_days"].sum() / 365.25), 3)
        rows["preferred model"] = f"{self.preferred} ({self.reason})"
        for name, r in self.comparison.iterrows():
            rows[f"{name}: AIC / deviance"] = f"{r['aic']:.2f} / {r['deviance']:.2f} (df {r['df_resid']:.0f})"
        if od:
            rows["overdispersion alpha"] = f"{od['alpha']:.4g}"
            rows["overdispersion LR test"] = f"LR = {od['lr_statistic']:.3f}, p = {od['lr_p_value']:.3g}"
            rows["Cameron-Trivedi test"] = f"t = {od['ct_statistic']:.3f}, p = {od['ct_p_value']:.3g}"
        for r in self.rate_ratios.itertuples():
            rows[f"rate ratio: {r.label} (per {r.unit})"] = (
                f"{r.rate_ratio:.4g} ({self.level:.0%} CI {r.ci_low:.4g}-{r.ci_high:.4g}, p = {r.p_value:.3g})")
        if self.trend:
            t = self.trend
            word = "detected" if t["detected"] else "not detected"
            rows["trend"] = (f"{word}: rate x {t['rate_ratio_per_year']:.4f} "
                             f"per year ({t['ci_low']:.4f}-{t['ci_high']:.4f}), LR = {t['lr_statistic']:.3f}, "
                             f"p = {t['p_value']:.3g}")
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    # --- predictions -------------------------------------------------------
    def _predict(self, frame: pd.DataFrame, exposure_days) -> pd.DataFrame:
        X = self._exog(frame)
        pred = self._glm_preferred.get_prediction(X, offset=np.log(np.asarray(exposure_days, float)))
        sf = pred.summary_frame(alpha=1 - self.level)
        return pd.DataFrame({"mean": sf["mean"].to_numpy(), "ci_low": sf["mean_ci_lower"].to_numpy(),
                             "ci_high": sf["mean_ci_upper"].to_numpy()}, index=frame.index)

    def fitted(self) -> pd.Series:
        """Expected count of each period from the preferred model.

        Returns
        -------
        pandas.Series
            Expected events per period, indexed by ``period_start``.
        """
        X = self._exog(self.design)
        mu = self._glm_preferred.predict(X, offset=np.log(self.design["exposure_days"].to_numpy(float)))
        return pd.Series(np.asarray(mu), index=self.design["period_start"], name="expected_count")

    def predicted_by_season(self) -> pd.DataFrame:
        """Observed and expected events per calendar month, averaged over the years of the record.

        ``expected_per_month`` is the preferred model's expected count over the
        record's actual rainfall (the rate over the rainfall climate), so the
        table shows how well season and rainfall together reproduce the
        seasonal cycle.  Units: events per month (of that name) per year.

        Returns
        -------
        pandas.DataFrame
            Indexed by month (1-12): ``observed_per_month``, ``expected_per_month``.
        """
        if self.period == "year":
            raise ValueError("predicted_by_season: yearly counts carry no season; count per day or month")
        d = self.design.assign(expected=self.fitted().to_numpy())
        month = d["period_start"].dt.month
        n_years = d.groupby(month)["exposure_days"].sum() / d.groupby(month)["period_start"].apply(
            lambda s: s.dt.days_in_month.mean())
        g = d.groupby(month)
        out = pd.DataFrame({"observed_per_month": g["count"].sum() / n_years,
                            "expected_per_month": g["expected"].sum() / n_years})
        out.index.name = "month"
        return out

    def predicted_by_rainfall(self, rain_mm=None, *, band: str | None = None) -> pd.DataFrame:
        """Expected events per day (and per year at that daily rate) against rainfall in one band.

        The other rainfall bands are held at their record means, the season is
        averaged over the year (the rate is computed for every day of the year
        and averaged) and the trend is at the end of the record.  Only for
        daily models.  ``band`` defaults to the first (the day's own rainfall).

        Parameters
        ----------
        rain_mm : array_like, optional
            Rainfall totals of the band [mm] (default: 41 values from 0 to the record's 99.9th percentile).
        band : str, optional
            The rainfall term (e.g. ``"rain_d0_mm"``).

        Returns
        -------
        pandas.DataFrame
            The band [mm], ``events_per_day``, ``ci_low``, ``ci_high``, ``events_per_year_equivalent``.
        """
        if self.period != "day":
            raise ValueError(f"predicted_by_rainfall: needs a daily model; this one counts per {self.period}")
        rain_terms = [t for t in self.terms.itertuples() if t.term.startswith("rain_")]
        if not rain_terms:
            raise ValueError("predicted_by_rainfall: the model has no rainfall term")
        names = [t.term for t in rain_terms]
        band = band or names[0]
        if band not in names:
            raise ValueError(f"band = {band!r} is not one of {names}")
        if rain_mm is None:
            rain_mm = np.linspace(0, float(self.design[band].quantile(0.999)), 41)
        rain_mm = np.atleast_1d(np.asarray(rain_mm, dtype=float))
        if not np.isfinite(rain_mm).all() or (rain_mm < 0).any():
            raise ValueError(f"rain_mm must be finite and >= 0; got {rain_mm!r:.80}")
        doy = np.arange(1, 366)
        base = {}
        for t in self.terms.itertuples():
            if t.term.startswith("rain_"):
                base[t.term] = float(self.design[t.term].mean())
            elif t.term == "year_c":
                base[t.term] = float(self.design["year_c"].max())
            elif t.term in ("season_sin", "season_cos", "wet_season") or t.term.startswith("month_"):
                base[t.term] = None
            else:
                base[t.term] = float(self.design[t.term].mean())
        dates = pd.Timestamp("2001-01-01") + pd.to_timedelta(doy - 1, unit="D")
        season = _season_frame(dates, self.season)
        rows = []
        for r in rain_mm:
            frame = pd.DataFrame(index=range(len(doy)))
            for term, value in base.items():
                frame[term] = season[term].to_numpy() if value is None else value
            frame[band] = r
            p = self._predict(frame, np.ones(len(doy)))
            rows.append({band: r, "events_per_day": p["mean"].mean(), "ci_low": p["ci_low"].mean(),
                         "ci_high": p["ci_high"].mean()})
        out = pd.DataFrame(rows)
        out["events_per_year_equivalent"] = out["events_per_day"] * 365.25
        return out

    def expected_annual_rate(self, *, rain_factor: float = 1.0, heavy_day_mm: float | None = None,
                             heavy_day_change: float = 0.0) -> float:
        """Expected events per year over the record's rainfall climate, trend at the end of the record [1/yr].

        A stated change of climate can be applied (an assumption, reported as such by the caller):

        * ``rain_factor``: every rainfall total multiplied by this factor (e.g. 1.1 for +10 %);
        * ``heavy_day_change`` with ``heavy_day_mm`` (daily models): days whose own rainfall reaches
          ``heavy_day_mm`` become ``1 + heavy_day_change`` times as frequent (e.g. 0.1 for +10 % heavy-rain
          days), each with its recorded rainfall pattern, and the other days correspondingly rarer so the
          year keeps its length.  The rate is the reweighted mean of the fitted daily rates.

        Parameters
        ----------
        rain_factor : float
            Multiplier of every rainfall total [-].
        heavy_day_mm : float, optional
            Daily rainfall [mm] from which a day counts as heavy.
        heavy_day_change : float
            Relative change of the frequency of heavy days [-].

        Returns
        -------
        float
            Events per year [1/yr].
        """
        if not (np.isfinite(rain_factor) and rain_factor >= 0):
            raise ValueError(f"rain_factor = {rain_factor!r} must be a number >= 0")
        d = self.design.copy()
        if "year_c" in d:
            d["year_c"] = d["year_c"].max()
        for t in self.terms.itertuples():
            if t.term.startswith("rain_"):
                d[t.term] = d[t.term] * rain_factor
        X = self._exog(d)
        mu = np.asarray(self._glm_preferred.predict(X, offset=np.log(d["exposure_days"].to_numpy(float))))
        weights = np.ones(len(d))
        if heavy_day_change:
            if self.period != "day" or "rain_d0_mm" not in d:
                raise ValueError("heavy_day_change needs a daily model whose first rainfall band is the day itself "
                                 "(windows_days starting with 1)")
            if heavy_day_mm is None or not (np.isfinite(heavy_day_mm) and heavy_day_mm > 0):
                raise ValueError(f"heavy_day_mm = {heavy_day_mm!r}: give the daily rainfall [mm] of a heavy-rain day")
            heavy = self.design["rain_d0_mm"].to_numpy() >= heavy_day_mm
            n_h, n = int(heavy.sum()), len(d)
            if n_h == 0:
                raise ValueError(f"heavy_day_mm = {heavy_day_mm!r}: no day of the record reaches it")
            w_h = 1.0 + heavy_day_change
            if w_h < 0 or w_h * n_h > n:
                raise ValueError(f"heavy_day_change = {heavy_day_change!r} gives an impossible share of heavy days")
            weights = np.where(heavy, w_h, (n - w_h * n_h) / (n - n_h))
        return float(np.sum(weights * mu) / (np.sum(weights * d["exposure_days"].to_numpy(float)) / 365.25))

    # --- text and files ---------------------------------------------------
    def __repr__(self) -> str:
        return short_repr(self, f"{self.n_events} events in {self.n_periods} {self.period} periods",
                          preferred=self.preferred)

    def plot(self, ax=None, **kwargs):
        """Events per year: recorded, and expected by the preferred model (drawn by :func:`riskrf.report.rate_figures.plot_rate_counts`).

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
        return draw("rate_counts", self, ax=ax, **kwargs)

    def summary_text(self) -> str:
        """A readable report (what ``riskrf rates`` prints).

        Returns
        -------
        str
        """
        lines = [f"Rate model: events per {self.period}, {self.start.date()} to {self.end.date()} "
                 f"({self.n_periods} periods, {self.n_events} events)",
                 f"  inventory {self.inventory_source}", f"  rainfall  {self.rainfall_source}", "",
                 "Model comparison:",
                 self.comparison.to_string(float_format=lambda v: f"{v:.4g}"), ""]
        od = self.overdispersion
        if od:
            lines.append(f"Overdispersion: alpha = {od['alpha']:.4g}; LR test of alpha = 0: "
                         f"LR = {od['lr_statistic']:.3f}, "
                         f"p = {od['lr_p_value']:.3g}; Cameron-Trivedi: t = {od['ct_statistic']:.3f}, "
                         f"p = {od['ct_p_value']:.3g}")
        lines += [f"Preferred: {self.preferred} ({self.reason})", "",
                  f"Rate ratios ({self.preferred}, {self.level:.0%} Wald intervals):"]
        for r in self.rate_ratios.itertuples():
            lines.append(f"  {r.label:<44} per {r.unit:<16} {r.rate_ratio:9.4g}  ({r.ci_low:.4g} - {r.ci_high:.4g})  "
                         f"p = {r.p_value:.3g}")
        if self.trend:
            t = self.trend
            word = "detected" if t["detected"] else "not detected"
            lines += ["", f"Trend: {word} (likelihood ratio {t['lr_statistic']:.3f}, "
                          f"p = {t['p_value']:.3g}); rate x {t['rate_ratio_per_year']:.4f} per year "
                          f"({t['ci_low']:.4f} - {t['ci_high']:.4f}), "
                          f"x {t['rate_ratio_per_year'] ** 10:.3f} per decade"]
        lines += ["", f"Expected rate over the record's rainfall climate (trend at {self.end.year}): "
                      f"{self.expected_annual_rate():.4g} events per year"]
        if self.period != "year":
            lines += ["", "By calendar month (events per month per year):",
                      self.predicted_by_season().to_string(float_format=lambda v: f"{v:.3f}")]
        if self.notes:
            lines += ["", "Notes:"] + [f"  - {n}" for n in self.notes]
        return "\n".join(lines)

    def write(self, out_dir) -> list[Path]:
        """Write rate_ratios.csv, model_comparison.csv, season.csv, design.csv, rainfall_response.csv
        (daily models with rainfall terms) into ``out_dir``; returns the files written.  The figures
        (seasonality.png, rainfall_response.png) are drawn by :func:`riskrf.report.rate_figures.write_rate_study`,
        which calls this first.

        Parameters
        ----------
        out_dir : str or path
            Folder (created if needed).

        Returns
        -------
        list of pathlib.Path
            The files written.
        """
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        written = []
        tables = [("rate_ratios.csv", self.rate_ratios, False), ("model_comparison.csv", self.comparison, True),
                  ("design.csv", self.design, False), ("summary.csv", self.summary(), True)]
        if self.period != "year":
            tables.append(("season.csv", self.predicted_by_season(), True))
        for name, table, index in tables:
            table.to_csv(out / name, index=index)
            written.append(out / name)
        response = self.rainfall_response()
        if response is not None:
            response.to_csv(out / "rainfall_response.csv", index=False)
            written.append(out / "rainfall_response.csv")
        return written

    def rainfall_response(self):
        """:meth:`predicted_by_rainfall` for a daily model with rainfall terms, else None (the table and figure
        ``rainfall_response`` are written only then).

        Returns
        -------
        pandas.DataFrame or None
        """
        if self.period == "day" and any(self.terms["term"].str.startswith("rain_")):
            return self.predicted_by_rainfall()
        return None


_TRANSFORMS = {"linear": lambda x: x, "sqrt": np.sqrt, "log1p": np.log1p}


_NB_ALPHA_MIN = 1e-8   # smallest dispersion searched: NB2 with alpha below it is the Poisson model in practice
_NB_ALPHA_MAX = 1e3    # largest dispersion searched (a variance 1,000 mu^2 above the mean)


def _fit_negbin(y, X, offset, pois, GLM, families, NegativeBinomial):
    """Maximum-likelihood NB2 regression, found by profiling the dispersion alpha.

    At a fixed alpha the NB2 model is a generalised linear model fitted by IRLS, which is stable;
    the profile log-likelihood is maximised over log(alpha) in [1e-8, 1e3] (bounded Brent search),
    and statsmodels' NB2 model evaluated at that optimum gives the usual standard errors.  Started instead from the Poisson fit with a fixed alpha guess,
    quasi-Newton search diverged to NaN on short records (statsmodels 0.15).

    Returns
    -------
    statsmodels NegativeBinomialResults
        With finite parameters; raises ValueError otherwise.
    """
    from scipy.optimize import minimize_scalar

    start = pois.params.to_numpy()

    def profile(log_alpha):
        g = GLM(y, X, family=families.NegativeBinomial(alpha=float(np.exp(log_alpha))), offset=offset).fit(
            start_params=start)
        return -g.llf if np.isfinite(g.llf) else np.inf

    opt = minimize_scalar(profile, bounds=(np.log(_NB_ALPHA_MIN), np.log(_NB_ALPHA_MAX)), method="bounded",
                          options={"xatol": 1e-4})
    alpha = float(np.exp(opt.x))
    beta = np.asarray(GLM(y, X, family=families.NegativeBinomial(alpha=alpha), offset=offset).fit(
        start_params=start).params)
    model = NegativeBinomial(y, X, offset=offset, loglike_method="nb2")
    # The profile optimum is the maximum-likelihood estimate (coefficients exact at that alpha, alpha to a
    # relative 1e-4): statsmodels evaluates it without further iterations, the Hessian once for the standard
    # errors.  (Newton iterations on top cost minutes on long daily records: each Hessian evaluates polygamma
    # terms per day.)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nb = model.fit(start_params=np.r_[beta, alpha], disp=0, maxiter=0, method="nm")
    nb.mle_retvals["converged"] = bool(np.isfinite(nb.llf) and np.isfinite(-opt.fun))
    if not np.all(np.isfinite(nb.params)):
        raise ValueError("no finite negative binomial estimate")
    return nb


def _exog(frame: pd.DataFrame, terms: pd.DataFrame) -> pd.DataFrame:
    """Model matrix: constant plus each term transformed and divided so that exp(coef) is its rate ratio."""
    X = pd.DataFrame({"const": 1.0}, index=frame.index)
    for t in terms.itertuples():
        f = _TRANSFORMS[t.transform]
        X[t.term] = f(frame[t.term].to_numpy(float)) / f(t.scale)
    return X


def _season_frame(dates: pd.DatetimeIndex, season: str | None) -> pd.DataFrame:
    dates = pd.DatetimeIndex(dates)
    frame = pd.DataFrame(index=range(len(dates)))
    if season == "harmonic":
        angle = 2 * np.pi * (dates.day_of_year.to_numpy() - 0.5) / 365.25
        frame["season_sin"] = np.sin(angle)
        frame["season_cos"] = np.cos(angle)
    elif season == "wet":
        frame["wet_season"] = np.isin(dates.month, WET_MONTHS).astype(float)
    elif season == "month":
        for m in range(2, 13):
            frame[f"month_{m:02d}"] = (dates.month == m).astype(float)
    return frame


def _as_rainfall(obj, what: str) -> Rainfall | None:
    if obj is None or isinstance(obj, Rainfall):
        return obj
    if isinstance(obj, (str, Path)):
        return read_rainfall(obj)
    raise TypeError(f"{what} must be a Rainfall, a rainfall file path or None; got {type(obj).__name__}")


def rate_model(inventory: Inventory, covariates=None, *, rainfall=None, period: str = "day",
               windows_days=DEFAULT_WINDOWS_DAYS, season: str | None = "harmonic", trend: bool = True,
               rain_per_mm: float = 100.0, rain_transform: str = "linear", level: float = 0.95,
               min_periods: int = MIN_PERIODS) -> RateModel:
    """Fit Poisson and negative-binomial regressions of event counts on rainfall, season and trend.

    Parameters
    ----------
    inventory : Inventory
        A dated inventory with a known record period (``start``/``end``).  All
        events count, censored sizes included (:meth:`Inventory.all_events`);
        events without a full date are left out of daily and monthly models
        with a warning that counts them.
    covariates : Rainfall, str, Path or pandas.DataFrame, optional
        Daily rainfall (a :class:`~riskrf.io.rainfall.Rainfall` or a file for
        :func:`~riskrf.io.rainfall.read_rainfall`), or a DataFrame indexed by date
        with further numeric covariates (e.g. ``temperature_c``,
        ``freeze_thaw``): daily values are summed (``*_mm``, ``*_days``,
        ``freeze_thaw``) or averaged (others) over monthly or yearly periods.
        Every covariate must cover every day of the record period.
    rainfall : Rainfall, str or Path, optional
        Daily rainfall, when ``covariates`` is a DataFrame.
    period : {"day", "month", "year"}
        Counting period.  Default ``"day"``.
    windows_days : tuple of int
        Antecedent rainfall bands for daily counts, as increasing window
        lengths [days]: (1, 3, 15) gives the day's own rainfall, the 2 days
        before and days 3-14 before, each its own term.  Monthly and yearly
        models use the period's rainfall total.
    season : {"harmonic", "wet", "month", None}
        Season terms: an annual sine/cosine pair (default), an April-September
        wet-season indicator, or calendar-month indicators (January the
        reference).  Not used for yearly counts.
    trend : bool
        Include a log-linear trend in the year (rate ratio per year).
    rain_per_mm : float
        Rainfall rate ratios refer to this many mm (default 100 mm).
    rain_transform : {"linear", "sqrt", "log1p"}
        How rainfall enters the linear predictor.  ``"linear"`` (default): the
        rate ratio is per ``rain_per_mm`` mm, the same at any rainfall.
        ``"sqrt"`` / ``"log1p"``: the term is sqrt(mm) or log(1 + mm), scaled so
        that the rate ratio compares ``rain_per_mm`` mm with none; the effect of
        each further mm then shrinks, which daily counts often need (a linear
        term lets the rate explode on the wettest days; compare the models'
        AIC and ``expected_total`` against the observed total).
    level : float
        Confidence level of the intervals (default 0.95).
    min_periods : int
        Fewest periods the model is fitted to (default 20; fewer raise).

    Returns
    -------
    RateModel

    Raises
    ------
    ValueError
        Naming the inventory or rainfall file, row and value: a record period
        that is unknown, fewer than ``min_periods`` periods, an event dated
        outside the rainfall record, a rainfall gap inside the period (gaps are
        never filled), a covariate not covering the period.
    """
    _check_rate_arguments(inventory, period, season, level, rain_per_mm, rain_transform)
    extra, rain, windows = _covariate_inputs(covariates, rainfall, windows_days)
    src = inventory.source
    if inventory.start is None or inventory.end is None:
        raise ValueError(f"{src}: the record period (start, end) is unknown; a rate model needs it "
                         "(give start/end to read_inventory or in the sidecar .toml)")
    start, end = pd.Timestamp(inventory.start), pd.Timestamp(inventory.end)
    notes: list[str] = []
    events = _counted_events(inventory, period, notes)
    days, starts, exposure, key = _record_periods(start, end, period, min_periods, src)

    # Rainfall: every event date and every day of the period with its antecedent window must be covered.
    design = pd.DataFrame({"period_start": starts, "exposure_days": exposure})
    rain_cols: list[tuple[str, str]] = []
    if rain is not None:
        rain_cols = _add_rainfall_columns(design, rain, events, period, windows, start, end, days, key, starts, src)
    elif extra is None:
        _note(notes, f"{src}: no rainfall or other covariates given; the model has only season and trend terms")
    extra_cols = []
    if extra is not None:
        extra_cols = _add_covariate_columns(design, extra, period, start, end, days, key, starts, src)
    season_frame, season_used, year_ref = _add_season_trend_columns(design, period, season, trend, start, end, notes)
    _add_counts(design, events, period, start, end, src)
    terms = _term_table(design, rain_cols, season_frame, trend, extra_cols, rain_per_mm, rain_transform)

    y = design["count"].to_numpy(float)
    X = _exog(design, terms)
    offset = np.log(design["exposure_days"].to_numpy(float))
    pois, nb = _fit_count_models(y, X, offset, src, notes)
    comparison, overdispersion, nb_glm = _compare_models(y, X, offset, pois, nb)

    preferred, reason, res, glm_pref = _preferred_model(pois, nb, nb_glm, overdispersion)
    rate_ratios = _rate_ratio_table(res, terms, level)
    trend_info = _trend_test(y, X, offset, res, preferred, rate_ratios, year_ref) if trend else None

    return RateModel(design=design, terms=terms, period=period, poisson=pois, negbin=nb, preferred=preferred,
                     reason=reason, comparison=comparison, overdispersion=overdispersion, rate_ratios=rate_ratios,
                     trend=trend_info, level=level, year_ref=year_ref, inventory_source=src,
                     rainfall_source=rain.source if rain is not None else "", start=start, end=end,
                     season=season_used, windows_days=windows if period == "day" else (),
                     notes=tuple(list(inventory.notes) + notes), _glm_preferred=glm_pref, rainfall=rain)


def _note(notes: list, msg: str) -> None:
    """Keep ``msg`` among the model's notes and warn with it (:func:`riskrf.core.validation.warn`)."""
    notes.append(msg)
    warn(msg)


def _check_rate_arguments(inventory, period: str, season, level: float, rain_per_mm: float,
                          rain_transform: str) -> None:
    """Check the arguments of :func:`rate_model` that need no data, before any work.

    Parameters
    ----------
    inventory, period, season, level, rain_per_mm, rain_transform
        As :func:`rate_model` (``rain_per_mm`` in mm).

    Raises
    ------
    TypeError
        ``inventory`` is not an :class:`~riskrf.frequency.inventory.Inventory`.
    ValueError
        Naming the argument and its value.
    """
    if not isinstance(inventory, Inventory):
        raise TypeError(f"inventory must be a riskrf Inventory (read_inventory); got {type(inventory).__name__}")
    if period not in _PERIODS:
        raise ValueError(f"period = {period!r} is not one of {list(_PERIODS)}")
    if season not in _SEASONS:
        raise ValueError(f"season = {season!r} is not one of {list(_SEASONS)}")
    if not (0 < level < 1):
        raise ValueError(f"level = {level!r} must be between 0 and 1")
    if not (np.isfinite(rain_per_mm) and rain_per_mm > 0):
        raise ValueError(f"rain_per_mm = {rain_per_mm!r} must be > 0")
    if rain_transform not in _TRANSFORMS:
        raise ValueError(f"rain_transform = {rain_transform!r} is not one of {list(_TRANSFORMS)}")


def _counted_events(inventory: Inventory, period: str, notes: list) -> pd.DataFrame:
    """The inventory's events that can be counted per ``period`` (a full date, or a year for yearly counts).

    Parameters
    ----------
    inventory : Inventory
        The dated inventory (all events, censored sizes included).
    period : {"day", "month", "year"}
        Counting period.
    notes : list of str
        The model's notes; extended (and warned) with the events left out and those with a censored size.

    Returns
    -------
    pandas.DataFrame
        :meth:`Inventory.all_events` without the undated events.
    """
    src = inventory.source
    events = inventory.all_events()
    if period == "year":
        undated = events["year"].isna()
    else:
        undated = events["date"].isna()
    if undated.any():
        rows = events.loc[undated, "source_row"].tolist()
        _note(notes, f"{src}: {len(rows)} event(s) without a {'year' if period == 'year' else 'full date'} are not "
                     f"counted (rows {', '.join(map(str, rows[:12]))}{' ...' if len(rows) > 12 else ''})")
        events = events.loc[~undated]
    n_cens = int((events["censoring"] != "").sum())
    if n_cens:
        notes.append(f"{src}: {n_cens} event(s) with a censored or missing size are counted (the rate model "
                     "counts events of any size)")
    return events


def _record_periods(start: pd.Timestamp, end: pd.Timestamp, period: str, min_periods: int, src: str):
    """The days and counting periods of the record, with each period's exposure [days].

    Parameters
    ----------
    start, end : pandas.Timestamp
        First and last day of the record period.
    period : {"day", "month", "year"}
        Counting period.
    min_periods : int
        Fewest periods allowed.
    src : str
        The inventory's source for messages.

    Returns
    -------
    days : pandas.DatetimeIndex
        Every day of the record.
    starts : pandas.DatetimeIndex
        First day of each period.
    exposure : numpy.ndarray
        Days of each period inside the record.
    key : pandas.DatetimeIndex
        Each day's period start.
    """
    days = pd.date_range(start, end, freq="D")
    if period == "day":
        starts = days
        exposure = np.ones(len(days))
        key = days
    else:
        key = days.to_period("M" if period == "month" else "Y").to_timestamp()
        starts = pd.DatetimeIndex(pd.unique(key))
        exposure = pd.Series(1.0, index=days).groupby(key).sum().reindex(starts).to_numpy()
    if len(starts) < min_periods:
        raise ValueError(f"{src}: {len(starts)} {period} period(s) from {start.date()} to {end.date()}; a count model "
                         f"needs at least {min_periods} (count per month or per day instead)")
    return days, starts, exposure, key


def _add_rainfall_columns(design: pd.DataFrame, rain: Rainfall, events: pd.DataFrame, period: str, windows: tuple,
                          start: pd.Timestamp, end: pd.Timestamp, days, key, starts, src: str) -> list:
    """Check that the rainfall covers every event and day (with its antecedent window) and add its columns.

    Parameters
    ----------
    design : pandas.DataFrame
        The model frame, one row per period; rainfall columns [mm] are added in place.
    rain : Rainfall
        Daily rainfall.
    events : pandas.DataFrame
        The counted events (:func:`_counted_events`).
    period : {"day", "month", "year"}
        Counting period.
    windows : tuple of int
        Antecedent rainfall bands of daily counts [days].
    start, end : pandas.Timestamp
        The record period.
    days, key, starts
        As :func:`_record_periods`.
    src : str
        The inventory's source for messages.

    Returns
    -------
    list of (str, str)
        Name and label of each rainfall column added.
    """
    rain_cols: list[tuple[str, str]] = []
    lead = max(windows) - 1 if period == "day" else 0
    first_needed = start - pd.Timedelta(days=lead)
    for r in events.itertuples():
        d = r.date if period != "year" or pd.notna(r.date) else pd.Timestamp(int(r.year), 1, 1)
        if pd.isna(d):
            continue
        if d - pd.Timedelta(days=lead) < rain.first_day or d > rain.last_day:
            raise ValueError(f"{src}: row {r.source_row}, date {d.date()}: outside the rainfall record "
                             f"{rain.source} ({rain.first_day.date()} to {rain.last_day.date()}"
                             + (f", and the {max(windows)}-day antecedent window needs rainfall from "
                                f"{(d - pd.Timedelta(days=lead)).date()}" if lead else "") + ")")
    rain.check_covers(first_needed, end, f"{src}: the record period {start.date()} to {end.date()}"
                      + (f" with its {max(windows)}-day antecedent window" if lead else ""))
    if period == "day":
        lo = 0
        for w in windows:
            name, label = _band_name(lo, w - 1)
            total = rain.window_total(w - lo, lag=lo).reindex(days)
            design[name] = total.to_numpy()
            rain_cols.append((name, label))
            lo = w
    else:
        total = rain.daily.reindex(days).groupby(key).sum(min_count=1).reindex(starts)
        design[f"rain_{period}_mm"] = total.to_numpy()
        rain_cols.append((f"rain_{period}_mm", f"rainfall in the {period}"))
    return rain_cols


def _add_covariate_columns(design: pd.DataFrame, extra: pd.DataFrame, period: str, start: pd.Timestamp,
                           end: pd.Timestamp, days, key, starts, src: str) -> list:
    """Check the user's daily covariates and add them per period (summed or averaged) to the model frame.

    Parameters
    ----------
    design : pandas.DataFrame
        The model frame, one row per period; a column per covariate is added in place.
    extra : pandas.DataFrame
        Daily covariates indexed by date.  ``*_mm``, ``*_days`` and ``freeze_thaw`` are summed over a month or
        year, the others averaged.
    period : {"day", "month", "year"}
        Counting period.
    start, end : pandas.Timestamp
        The record period.
    days, key, starts
        As :func:`_record_periods`.
    src : str
        The inventory's source for messages.

    Returns
    -------
    list of str
        The covariate columns added.
    """
    extra_cols = []
    if not isinstance(extra.index, pd.DatetimeIndex):
        raise TypeError("covariates: a DataFrame of covariates must be indexed by date (DatetimeIndex)")
    for col in extra.columns:
        values = pd.to_numeric(extra[col], errors="coerce")
        bad = values.isna() & extra[col].notna()
        if bad.any():
            d = extra.index[bad.to_numpy()][0]
            raise ValueError(f"covariates: column {col!r}, date {d.date()}: {extra[col][d]!r} is not a number")
        series = values.groupby(extra.index.normalize()).mean()
        daily = series.reindex(days)
        if daily.isna().any():
            d = days[daily.isna().to_numpy()][0]
            raise ValueError(f"covariates: column {col!r} has no value for {d.date()}, but the inventory "
                             f"{src} covers {start.date()} to {end.date()}: covariates must cover every day "
                             f"of the period (given {series.index.min().date()} to {series.index.max().date()})")
        if period == "day":
            design[col] = daily.to_numpy()
        else:
            how = "sum" if (col.endswith(("_mm", "_days")) or col == "freeze_thaw") else "mean"
            design[col] = daily.groupby(key).agg(how).reindex(starts).to_numpy()
        extra_cols.append(col)
    return extra_cols


def _add_season_trend_columns(design: pd.DataFrame, period: str, season, trend: bool, start: pd.Timestamp,
                              end: pd.Timestamp, notes: list):
    """Add the season terms and the centred year [yr] of the trend to the model frame.

    Parameters
    ----------
    design : pandas.DataFrame
        The model frame (``period_start``, ``exposure_days``); columns are added in place.
    period : {"day", "month", "year"}
        Counting period (the middle of a month or year dates it).
    season : {"harmonic", "wet", "month", None}
        Season terms (none for yearly counts; a note says so).
    trend : bool
        Add ``year_c``, the decimal year minus ``year_ref``.
    start, end : pandas.Timestamp
        The record period.
    notes : list of str
        The model's notes.

    Returns
    -------
    season_frame : pandas.DataFrame
        The season columns added.
    season_used : str or None
        The season terms used.
    year_ref : float
        Reference year of the trend [yr]: the middle of the record, to 0.1 yr.
    """
    mid = design["period_start"] + pd.to_timedelta(design["exposure_days"] / 2, unit="D") \
        if period != "day" else design["period_start"]
    season_used = season if period != "year" else None
    if season is not None and period == "year":
        notes.append("season terms are not used for yearly counts")
    season_frame = _season_frame(pd.DatetimeIndex(mid), season_used)
    for c in season_frame.columns:
        design[c] = season_frame[c].to_numpy()
    decimal_year = mid.dt.year + (mid.dt.day_of_year - 0.5) / 365.25 if period != "day" else \
        design["period_start"].dt.year + (design["period_start"].dt.day_of_year - 0.5) / 365.25
    year_ref = float(np.round((start.year + end.year + 1) / 2, 1))
    if trend:
        design["year_c"] = decimal_year.to_numpy() - year_ref
    return season_frame, season_used, year_ref


def _add_counts(design: pd.DataFrame, events: pd.DataFrame, period: str, start: pd.Timestamp, end: pd.Timestamp,
                src: str) -> None:
    """Insert the count of events per period as the model frame's column ``count`` (raises when all are 0)."""
    ev_key = events["date"].dt.normalize() if period == "day" else (
        events["date"].dt.to_period("M").dt.to_timestamp() if period == "month"
        else pd.to_datetime(events["year"].astype(int).astype(str) + "-01-01"))
    counts = ev_key.value_counts()
    design.insert(1, "count", counts.reindex(design["period_start"]).fillna(0).astype(int).to_numpy())
    n_counted = int(design["count"].sum())
    if n_counted == 0:
        raise ValueError(f"{src}: no event falls inside the record period {start.date()} to {end.date()}")


def _term_table(design: pd.DataFrame, rain_cols: list, season_frame: pd.DataFrame, trend: bool, extra_cols: list,
                rain_per_mm: float, rain_transform: str) -> pd.DataFrame:
    """The model's terms: column, label, unit of the rate ratio, scale and transform; each must vary.

    Parameters
    ----------
    design : pandas.DataFrame
        The model frame.
    rain_cols : list of (str, str)
        Rainfall columns and labels.
    season_frame : pandas.DataFrame
        The season columns.
    trend : bool
        Whether ``year_c`` is a term.
    extra_cols : list of str
        The user's covariates.
    rain_per_mm : float
        Rainfall [mm] that a rainfall rate ratio refers to.
    rain_transform : {"linear", "sqrt", "log1p"}
        How rainfall enters the linear predictor.

    Returns
    -------
    pandas.DataFrame
        Columns ``term``, ``label``, ``unit``, ``scale``, ``transform``.
    """
    terms = []
    rain_unit = f"{rain_per_mm:g} mm" if rain_transform == "linear" else f"{rain_per_mm:g} mm vs none"
    for name, label in rain_cols:
        if rain_transform != "linear":
            label = f"{label} ({'square root' if rain_transform == 'sqrt' else 'log(1 + mm)'})"
        terms.append((name, label, rain_unit, rain_per_mm, rain_transform))
    for c in season_frame.columns:
        terms.append((c, {"season_sin": "season (sine of the day of year)",
                          "season_cos": "season (cosine of the day of year)",
                          "wet_season": "wet season (April-September)"}.get(c, f"calendar month {c[-2:]}"),
                      "unit", 1.0, "linear"))
    if trend:
        terms.append(("year_c", "trend", "year", 1.0, "linear"))
    for c in extra_cols:
        terms.append((c, c, "unit", 1.0, "linear"))
    terms = pd.DataFrame(terms, columns=["term", "label", "unit", "scale", "transform"])
    const_like = [t for t in terms["term"] if np.ptp(design[t].to_numpy(float)) == 0]
    if const_like:
        raise ValueError(f"covariate(s) {const_like} do not vary over the record period; they cannot be estimated")
    return terms


def _fit_count_models(y, X, offset, src: str, notes: list):
    """Fit the Poisson and the negative binomial (NB2) regressions of the counts.

    Parameters
    ----------
    y : numpy.ndarray
        Counts per period.
    X : pandas.DataFrame
        Model matrix (:func:`_exog`).
    offset : numpy.ndarray
        log of the exposure [days].
    src : str
        The inventory's source for messages.
    notes : list of str
        The model's notes; a negative binomial fit that fails or does not converge is noted (and warned).

    Returns
    -------
    pois : statsmodels GLMResults
        The Poisson fit.
    nb : statsmodels NegativeBinomialResults or None
        The NB2 fit; None when it failed.
    """
    # the model classes used, not statsmodels.api (which imports all of statsmodels: 0.7 s more)
    from statsmodels.discrete.discrete_model import NegativeBinomial
    from statsmodels.genmod import families
    from statsmodels.genmod.generalized_linear_model import GLM
    from statsmodels.tools.sm_exceptions import ConvergenceWarning

    try:
        pois = GLM(y, X, family=families.Poisson(), offset=offset).fit()
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise ValueError(f"{src}: the Poisson rate model cannot be fitted to these counts and covariates "
                         f"({exc}); check the rainfall record for impossible values") from None
    if not np.all(np.isfinite(pois.params)):
        raise ValueError(f"{src}: the Poisson rate model has no finite estimate for these counts and "
                         f"covariates; check the rainfall record for impossible values")
    trouble = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ConvergenceWarning)
        try:
            nb = _fit_negbin(y, X, offset, pois, GLM, families, NegativeBinomial)
        except (np.linalg.LinAlgError, ValueError) as exc:
            nb = None
            trouble.append(str(exc))
    trouble += [str(w.message) for w in caught if issubclass(w.category, (ConvergenceWarning, RuntimeWarning))]
    if nb is None or not np.all(np.isfinite(nb.params)) or (trouble and not nb.mle_retvals.get("converged", False)):
        _note(notes, f"negative binomial model did not converge ({'; '.join(trouble)[:200] or 'no finite estimate'}); "
                     f"the Poisson model is used")
        nb = None
    return pois, nb


def _compare_models(y, X, offset, pois, nb):
    """Goodness of fit of both models and the overdispersion tests.

    The likelihood-ratio test of alpha = 0 lies on the boundary, so its p-value is half the chi-square(1)
    tail (Cameron & Trivedi 2013, section 3.4); Cameron & Trivedi's (1990) auxiliary regression is the second test.

    Parameters
    ----------
    y, X, offset
        Counts, model matrix and log exposure [days].
    pois, nb
        The fits of :func:`_fit_count_models`.

    Returns
    -------
    comparison : pandas.DataFrame
        Per model: log-likelihood, AIC, deviance, residual df, Pearson chi2 per df, alpha, expected and
        observed totals.
    overdispersion : dict
        alpha and both tests (empty without a negative binomial fit).
    nb_glm : statsmodels GLMResults or None
        The NB2 model at its fitted alpha as a GLM.
    """
    from statsmodels.genmod import families
    from statsmodels.genmod.generalized_linear_model import GLM
    from statsmodels.regression.linear_model import OLS

    comparison = {"Poisson": {"loglik": pois.llf, "aic": pois.aic, "deviance": pois.deviance,
                              "df_resid": pois.df_resid, "pearson_chi2_per_df": pois.pearson_chi2 / pois.df_resid,
                              "alpha": 0.0, "expected_total": float(np.sum(pois.mu)), "observed_total": y.sum()}}
    overdispersion = {}
    nb_glm = None
    if nb is not None:
        alpha = float(nb.params["alpha"])
        # the NB2 model at its fitted alpha as a GLM (deviance, Pearson chi2, predictions with intervals),
        # started from the maximum-likelihood coefficients so IRLS begins at the solution
        nb_glm = GLM(y, X, family=families.NegativeBinomial(alpha=max(alpha, _NB_ALPHA_MIN)), offset=offset).fit(
            start_params=nb.params.drop("alpha").to_numpy())
        comparison["negative binomial"] = {"loglik": nb.llf, "aic": nb.aic, "deviance": nb_glm.deviance,
                                           "df_resid": nb.df_resid - 1,
                                           "pearson_chi2_per_df": nb_glm.pearson_chi2 / (nb_glm.df_resid - 1),
                                           "alpha": alpha, "expected_total": float(np.sum(nb_glm.mu)),
                                           "observed_total": y.sum()}
        lr = max(2 * (nb.llf - pois.llf), 0.0)
        mu = np.asarray(pois.mu)
        aux = ((y - mu) ** 2 - y) / mu
        ct = OLS(aux, mu).fit()
        ct_t = float(ct.tvalues[0])
        overdispersion = {"alpha": alpha, "lr_statistic": lr, "lr_p_value": 0.5 * stats.chi2.sf(lr, 1),
                          "ct_statistic": ct_t, "ct_p_value": float(stats.t.sf(ct_t, ct.df_resid))}
    comparison = pd.DataFrame(comparison).T
    comparison.index.name = "model"
    return comparison, overdispersion, nb_glm


def _covariate_inputs(covariates, rainfall, windows_days):
    """Sort :func:`rate_model`'s ``covariates`` and ``rainfall`` into a covariate frame and daily rainfall.

    Parameters
    ----------
    covariates, rainfall, windows_days
        As :func:`rate_model`.

    Returns
    -------
    extra : pandas.DataFrame or None
        The user's daily covariates.
    rain : Rainfall or None
        Daily rainfall (a file is read).
    windows : tuple of int
        The antecedent rainfall bands [days], checked increasing and >= 1.
    """
    extra = None
    if isinstance(covariates, pd.DataFrame):
        extra = covariates
    elif covariates is not None:
        if rainfall is not None:
            raise ValueError("give rainfall either as covariates= or as rainfall=, not both")
        rainfall = covariates
    rain = _as_rainfall(rainfall, "rainfall")
    windows = tuple(int(w) for w in windows_days)
    if not windows or any(w < 1 for w in windows) or list(windows) != sorted(set(windows)):
        raise ValueError(f"windows_days = {windows_days!r} must be increasing whole numbers of days >= 1")
    return extra, rain, windows


def _preferred_model(pois, nb, nb_glm, overdispersion: dict):
    """The preferred model: the negative binomial when the LR test rejects alpha = 0 at 5 %, else the Poisson.

    Parameters
    ----------
    pois, nb, nb_glm
        The fits (:func:`_fit_count_models`, :func:`_compare_models`); ``nb`` may be None.
    overdispersion : dict
        The overdispersion tests (:func:`_compare_models`).

    Returns
    -------
    preferred : str
        "negative binomial" or "Poisson".
    reason : str
        Why, with the test's p-value and the AICs.
    res
        The preferred fit.
    glm_pref
        The preferred model as a GLM (for predictions with intervals).
    """
    if nb is not None and overdispersion["lr_p_value"] < 0.05:
        preferred = "negative binomial"
        reason = (f"overdispersion: LR test of alpha = 0 gives p = {overdispersion['lr_p_value']:.3g}; "
                  f"AIC {nb.aic:.1f} vs {pois.aic:.1f}")
        res, glm_pref = nb, nb_glm
    else:
        preferred = "Poisson"
        reason = ("no significant overdispersion" + (f" (p = {overdispersion['lr_p_value']:.3g})" if overdispersion
                  else "") + f"; AIC {pois.aic:.1f}" + (f" vs {nb.aic:.1f}" if nb is not None else ""))
        res, glm_pref = pois, pois
    return preferred, reason, res, glm_pref


def _rate_ratio_table(res, terms: pd.DataFrame, level: float) -> pd.DataFrame:
    """Coefficients, rate ratios exp(beta) with Wald intervals at ``level``, and p-values of every term."""
    z = stats.norm.isf((1 - level) / 2)
    rr = []
    for t in terms.itertuples():
        b, se, p = float(res.params[t.term]), float(res.bse[t.term]), float(res.pvalues[t.term])
        rr.append({"term": t.term, "label": t.label, "unit": t.unit, "coefficient": b, "stderr": se,
                   "rate_ratio": np.exp(b), "ci_low": np.exp(b - z * se), "ci_high": np.exp(b + z * se),
                   "p_value": p})
    return pd.DataFrame(rr)


def _trend_test(y, X, offset, res, preferred: str, rate_ratios: pd.DataFrame, year_ref: float) -> dict:
    """Likelihood-ratio test of the trend: the preferred model with and without ``year_c``.

    Parameters
    ----------
    y, X, offset
        Counts, model matrix and log exposure [days].
    res
        The preferred model's fit.
    preferred : {"Poisson", "negative binomial"}
        The preferred model.
    rate_ratios : pandas.DataFrame
        :func:`_rate_ratio_table` of the preferred model.
    year_ref : float
        Reference year of the trend [yr].

    Returns
    -------
    dict
        Rate ratio per year with its interval, LR statistic, p-value, ``detected`` (p < 0.05), model and
        ``year_ref``.
    """
    from statsmodels.discrete.discrete_model import NegativeBinomial
    from statsmodels.genmod import families
    from statsmodels.genmod.generalized_linear_model import GLM

    X0 = X.drop(columns="year_c")
    if preferred == "Poisson":
        llf0 = GLM(y, X0, family=families.Poisson(), offset=offset).fit().llf
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sp = np.r_[res.params.drop(["year_c"]).to_numpy()]
            llf0 = NegativeBinomial(y, X0, offset=offset, loglike_method="nb2").fit(
                start_params=sp, disp=0, maxiter=300, method="bfgs").llf
    lr_t = max(2 * (res.llf - llf0), 0.0)
    row = rate_ratios.set_index("term").loc["year_c"]
    p_t = float(stats.chi2.sf(lr_t, 1))
    return {"rate_ratio_per_year": float(row["rate_ratio"]), "ci_low": float(row["ci_low"]),
            "ci_high": float(row["ci_high"]), "lr_statistic": lr_t, "p_value": p_t,
            "detected": bool(p_t < 0.05), "model": preferred, "year_ref": year_ref}


__all__ = ["RateModel", "rate_model", "MIN_PERIODS", "DEFAULT_WINDOWS_DAYS", "RiskrfWarning"]
