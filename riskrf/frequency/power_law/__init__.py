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

Where it lives
--------------
The package is cut where the statistics have seams; import the names below from here
(``riskrf.frequency.power_law``) or from :mod:`riskrf`, not from the modules, which may move:

- :mod:`~riskrf.frequency.power_law.law`: the (truncated) law's formulas: survival function, its inverse,
  log density, the maximum-likelihood b of the truncated law;
- :mod:`~riskrf.frequency.power_law.threshold`: tail selection: the Kolmogorov-Smirnov statistics and the
  completeness-threshold search (:func:`find_m_min`, continuous and discrete);
- :mod:`~riskrf.frequency.power_law.goodness`: goodness of fit: the bootstrap test
  (:class:`PowerLawBootstrap`) and the likelihood-ratio comparison with lognormal and exponential tails;
- :mod:`~riskrf.frequency.power_law.result`: :class:`GutenbergRichterFit`, the fitted law as frequencies,
  return levels and a distribution of one fall's size, with its summary and plot;
- :mod:`~riskrf.frequency.power_law.fit`: :func:`fit_gutenberg_richter`, the estimators (MLE, least squares)
  and the checks of their arguments.
"""
from __future__ import annotations

from .goodness import PowerLawBootstrap
from .result import GutenbergRichterFit
from .threshold import DISCRETE_BELOW, GRID_CANDIDATES, KS_STATISTICS, LARGE_SAMPLE, find_m_min
from .fit import fit_gutenberg_richter

__all__ = ["DISCRETE_BELOW", "GRID_CANDIDATES", "KS_STATISTICS", "LARGE_SAMPLE", "GutenbergRichterFit",
           "PowerLawBootstrap", "find_m_min", "fit_gutenberg_richter"]
