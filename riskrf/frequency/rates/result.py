""":class:`RateModel`: a fitted rate model and what follows from it.

Its design and terms, both fits (Poisson, negative binomial) with their comparison and tests, the rate ratios and
the trend (fitted by :func:`~riskrf.frequency.rates.fit.rate_model`); the expected counts of each period, by
calendar month and against rainfall, the expected annual rate under a stated change of climate, the summary, the
text report of ``riskrf rates``, the tables it writes and the plot.  The model matrix of the terms
(:func:`_exog`) and the season columns of a set of dates (:func:`_season_frame`) live here, as the fit and the
predictions both use them.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ...io.rainfall import Rainfall
from simulation._display import Displayed, short_repr


#: Hong Kong's wet season (Observatory usage): April to September.
WET_MONTHS = (4, 5, 6, 7, 8, 9)


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
        """Events per year: recorded, and expected by the preferred model (drawn by :func:`riskrf.frequency.figures.plot_rate_counts`).

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
        from ..figures import plot_rate_counts
        return plot_rate_counts(self, ax=ax, **kwargs)

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
