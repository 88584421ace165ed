"""Accuracy of the energy quadrature with a truncated power-law mass model.

Exact case: mass M ~ power law with cumulative exponent b on [m0, m1] (Corominas et al. 2018
truncation, riskrf.frequency.power_law), speed V ~ lognormal(mu, s), E = 1/2 M V^2 / 1000 kJ.  With
m(v) = 2000 e / v^2,

    P(E > e) = P(V > v0) + [ (2000 e)^-b E(V^2b; v1 < V < v0) - m1^-b P(v1 < V < v0) ] / (m0^-b - m1^-b)

where v0 = sqrt(2000 e / m0), v1 = sqrt(2000 e / m1) and, for a lognormal,
E(V^k; a < V < c) = exp(k mu + k^2 s^2 / 2) [Phi((ln c - mu - k s^2)/s) - Phi((ln a - mu - k s^2)/s)].
"""
import numpy as np
import pytest
from scipy import stats

from riskrf import exceedance_probability
from riskrf.frequency.power_law import GutenbergRichterFit


def _exact(e, b, m0, m1, mu, s):
    e = np.asarray(e, float)
    v1, v0 = np.sqrt(2000 * e / m1), np.sqrt(2000 * e / m0)
    Phi, k = stats.norm.cdf, 2 * b
    partial = np.exp(k * mu + 0.5 * k * k * s * s) * (Phi((np.log(v0) - mu - k * s * s) / s)
                                                      - Phi((np.log(v1) - mu - k * s * s) / s))
    inside = Phi((np.log(v0) - mu) / s) - Phi((np.log(v1) - mu) / s)
    return stats.norm.sf((np.log(v0) - mu) / s) + ((2000 * e) ** -b * partial - m1 ** -b * inside) / (m0 ** -b
                                                                                                      - m1 ** -b)


def _law(b, m0, m1):
    return GutenbergRichterFit(a=0.0, b=b, b_stderr=0.0, b_ci=(b, b), level=0.95, b_ci_method="", m_min=m0,
                               m_max=m1, rate_min=1.0, n_tail=1, n_total=1, duration_years=1.0, method="mle",
                               m_min_method="given", ks_distance=0.0)


@pytest.mark.parametrize("b,m0,m1,s", [(0.7, 100.0, 2e6, 0.4), (1.2, 10.0, 1e5, 0.1), (0.5, 1000.0, 5e6, 0.25),
                                       (0.9, 50.0, 5e4, 0.6)])
def test_truncated_power_law_quadrature_meets_documented_accuracy(b, m0, m1, s):
    # Documented in riskrf.hazard.impact_energy: about 1e-6 relative down to probabilities of 1e-8.  Before the
    # panels were split at the support kinks the error here reached 2e-5.
    e = np.geomspace(0.01, 1e8, 300)
    ref = _exact(e, b, m0, m1, np.log(20.0), s)
    keep = ref > 1e-8
    got = exceedance_probability(e[keep], _law(b, m0, m1), stats.lognorm(s, scale=20.0))
    np.testing.assert_allclose(got, ref[keep], rtol=1e-6, atol=0)


def test_exact_formula_agrees_with_monte_carlo():
    # Guards the closed form itself: 10^6 draws, inside 4 binomial standard errors.
    rng = np.random.default_rng(1)
    law = _law(0.7, 100.0, 2e6)
    m = law.rvs(1_000_000, rng)
    v = stats.lognorm(0.4, scale=20.0).rvs(size=1_000_000, random_state=rng)
    energy = 0.5 * m * v * v / 1000
    for e in (1.0, 100.0, 1e4):
        p = _exact(e, 0.7, 100.0, 2e6, np.log(20.0), 0.4)
        assert abs(np.mean(energy > e) - p) < 4 * np.sqrt(p * (1 - p) / 1e6) + 1e-12
