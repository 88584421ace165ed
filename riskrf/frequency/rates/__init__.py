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

Where it lives
--------------
The package is cut where the model has seams; the public names below import from here or from :mod:`riskrf`:

- :mod:`~riskrf.frequency.rates.result`: :class:`RateModel`, the fitted model with its predictions (by season,
  by rainfall, the expected annual rate under a stated change of climate), summary, text report, files and plot;
- :mod:`~riskrf.frequency.rates.design`: the count design: the arguments checked, the events counted per period,
  the exposure, the rainfall, covariate, season and trend columns and the table of terms
  (:data:`MIN_PERIODS`, :data:`DEFAULT_WINDOWS_DAYS`);
- :mod:`~riskrf.frequency.rates.fit`: :func:`rate_model`, the Poisson and negative-binomial fits, their
  comparison and overdispersion tests, the preferred model, its rate ratios and the trend test.
"""
from __future__ import annotations

from ...core.validation import RiskrfWarning
from .result import RateModel
from .design import DEFAULT_WINDOWS_DAYS, MIN_PERIODS
from .fit import rate_model

__all__ = ["RateModel", "rate_model", "MIN_PERIODS", "DEFAULT_WINDOWS_DAYS", "RiskrfWarning"]
