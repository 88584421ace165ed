"""Gumbel and GEV fits of annual maxima against published values."""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from riskrf import (encounter_probability, fit_gev, fit_gumbel, gumbel_frequency_factor, gumbel_reduced_variate,
                    plotting_positions)

from .conftest import DATA

PORT_PIRIE = pd.read_csv(DATA / "coles2001" / "portpirie.csv")["sea_level_m"].to_numpy()


def test_coles_port_pirie_gev_mle_covariance_and_return_levels():
    gev = fit_gev(PORT_PIRIE)
    # ismev::gev.fit / Coles (2001) example 3.4.1: (3.87474692, 0.19804120, -0.05008773), loglik 4.339058
    np.testing.assert_allclose(gev.params, [3.87474692, 0.19804120, -0.05008773], atol=5e-5)
    assert gev.loglik == pytest.approx(4.339058, abs=1e-5)
    # Coles (2001) p. 59: covariance matrix of (mu, sigma, xi)
    V = np.array([[0.000780, 0.000197, -0.00107], [0.000197, 0.000410, -0.000778], [-0.00107, -0.000778, 0.00965]])
    np.testing.assert_allclose(gev.cov, V, rtol=5e-3, atol=5e-6)
    # p. 60: 10- and 100-year return levels 4.30 and 4.69 m; Var(x_10) = 0.00303
    np.testing.assert_allclose(gev.return_level([10, 100]), [4.30, 4.69], atol=0.005)
    assert gev._return_level_variance(10) == pytest.approx(0.00303, abs=5e-6)
    lo, hi = gev.return_level_ci(10, method="delta")
    assert (float(lo), float(hi)) == pytest.approx((4.19, 4.40), abs=0.01)   # 4.30 +- 1.96 sqrt(0.00303)
    plo, phi = gev.return_level_ci(100)                                      # profile (default)
    assert plo > lo and phi > 4.69 + (4.69 - plo)                            # skewed to the right


def test_port_pirie_deviance_says_gumbel_is_adequate():
    gev = fit_gev(PORT_PIRIE)
    d = gev.deviance_vs_gumbel()
    assert d["gumbel_adequate"] and d["p_value"] > 0.5
    assert d["deviance"] == pytest.approx(2 * (4.339058 - d["loglik_gumbel"]), abs=1e-4)


def test_gumbel_methods_agree_with_scipy_and_closed_forms():
    mle = fit_gumbel(PORT_PIRIE)
    loc, scale = stats.gumbel_r.fit(PORT_PIRIE)
    assert mle.loc == pytest.approx(loc, rel=1e-5) and mle.scale == pytest.approx(scale, rel=1e-4)
    mom = fit_gumbel(PORT_PIRIE, method="moments")
    s = np.std(PORT_PIRIE, ddof=1)
    assert mom.scale == pytest.approx(s * np.sqrt(6) / np.pi)
    assert mom.loc == pytest.approx(PORT_PIRIE.mean() - 0.5772157 * mom.scale)
    lmom = fit_gumbel(PORT_PIRIE, method="lmoments")
    pytest.importorskip("lmoments3")
    from lmoments3 import distr
    ref = distr.gum.lmom_fit(PORT_PIRIE)
    assert lmom.loc == pytest.approx(ref["loc"], rel=1e-6) and lmom.scale == pytest.approx(ref["scale"], rel=1e-6)


def test_wyllie_moment_equations_worked_example():
    # domain-methods.md E15: M = 2.0 t, S = 1.0 t -> beta = 0.77970, alpha = 1.54995,
    # x_10 = 3.3046, x_50 = 4.5923, x_100 = 5.1367, x_500 = 6.3947 t; SE(x_100 | n = 20) = 0.877 t (Kite 1977).
    z = np.random.default_rng(1).normal(size=20)
    x = 2.0 + (z - z.mean()) / z.std(ddof=1)
    g = fit_gumbel(x, method="moments")
    assert g.scale == pytest.approx(0.77970, abs=5e-6) and g.loc == pytest.approx(1.54995, abs=5e-6)
    np.testing.assert_allclose(g.return_level([10, 50, 100, 500]), [3.3046, 4.5923, 5.1367, 6.3947], atol=5e-5)
    assert g.return_period(5.0) == pytest.approx(1 / 0.011904, rel=5e-4)
    lo, hi = g.return_level_ci(100)          # delta method (default for moments)
    assert (hi - lo) / (2 * 1.959964) == pytest.approx(0.877, abs=5e-4)


def test_gumbel_reduced_variates_and_frequency_factors():
    # Standard table for an infinite sample (Chow 1951; domain-methods.md 2.1).
    T = [2, 5, 10, 25, 50, 100, 200, 500, 1000]
    y = [0.3665, 1.4999, 2.2504, 3.1985, 3.9019, 4.6001, 5.2958, 6.2136, 6.9073]
    K = [-0.1643, 0.7194, 1.3046, 2.0438, 2.5923, 3.1367, 3.6791, 4.3947, 4.9355]
    np.testing.assert_allclose(gumbel_reduced_variate(T), y, atol=5e-5)
    np.testing.assert_allclose(gumbel_frequency_factor(T), K, atol=5e-5)


@pytest.mark.parametrize("T,n,p,tol", [(100, 30, 0.260, 5e-4), (50, 10, 0.183, 5e-4), (500, 30, 0.058, 5e-4),
                                       (10, 4, 0.3439, 5e-5), (475, 50, 0.10, 5e-4), (2475, 50, 0.02, 5e-5)])
def test_encounter_probabilities(T, n, p, tol):
    # E1-E5 of domain-methods.md: 1 - (1 - 1/T)^n
    assert encounter_probability(T, n) == pytest.approx(p, abs=tol)


def test_plotting_positions():
    np.testing.assert_allclose(plotting_positions(4, "weibull"), [0.2, 0.4, 0.6, 0.8])
    np.testing.assert_allclose(plotting_positions(4, "hazen"), [0.125, 0.375, 0.625, 0.875])
    np.testing.assert_allclose(plotting_positions(3, "gringorten"), (np.arange(1, 4) - 0.44) / 3.12)
    np.testing.assert_allclose(plotting_positions(3, "cunnane"), (np.arange(1, 4) - 0.4) / 3.2)
    np.testing.assert_allclose(plotting_positions(3, "blom"), (np.arange(1, 4) - 0.375) / 3.25)
    with pytest.raises(ValueError, match="formula = 'x' is not one of"):
        plotting_positions(3, "x")


def test_mixed_model_for_years_without_falls():
    rng = np.random.default_rng(8)
    values = stats.gumbel_r.rvs(loc=100, scale=30, size=30, random_state=rng)
    maxima = np.concatenate([values, [np.nan] * 10])             # 10 of 40 years empty
    g = fit_gumbel(maxima)
    assert g.p_zero == 0.25 and g.n_years == 40 and g.data.size == 30
    x100 = g.return_level(100)
    assert g.sf(x100) == pytest.approx(0.01)
    assert 0.75 * g.dist.sf(x100) == pytest.approx(0.01)
    dropped = fit_gumbel(maxima, zero_years="drop")
    assert dropped.return_level(100) > x100
    with pytest.raises(ValueError, match="return period must exceed"):
        g.return_level(1.2)


def test_bootstrap_interval_is_seeded():
    g = fit_gumbel(PORT_PIRIE, method="lmoments")
    a = g.return_level_ci(100, n_bootstrap=200, seed=5)
    b = g.return_level_ci(100, n_bootstrap=200, seed=5)
    assert a == b and a[0] < g.return_level(100) < a[1]


def test_too_few_maxima_and_bad_values():
    with pytest.raises(ValueError, match="3 annual maxima .* a gumbel fit needs at least 5"):
        fit_gumbel([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="a gev fit needs at least 10"):
        fit_gev([1.0, 2.0, 3.0, 4, 5, 6])
    with pytest.raises(ValueError, match="maxima\\[1\\] is infinite"):
        fit_gumbel([1.0, np.inf, 3.0, 4, 5])
    with pytest.raises(ValueError, match="return periods must be finite and > 1 year"):
        fit_gumbel(PORT_PIRIE).return_level(0.5)


def test_gumbel_ci_coverage_seeded():
    rng = np.random.default_rng(99)
    true = stats.gumbel_r(loc=50, scale=10).isf(0.01)
    hits = 0
    for _ in range(150):
        g = fit_gumbel(stats.gumbel_r.rvs(loc=50, scale=10, size=40, random_state=rng))
        lo, hi = g.return_level_ci(100, method="delta")
        hits += lo <= true <= hi
    assert 0.88 <= hits / 150 <= 0.99


@settings(max_examples=30, deadline=None)
@given(loc=st.floats(1, 1e4), scale=st.floats(0.1, 1e3), T=st.floats(1.01, 1e5))
def test_gumbel_return_level_and_period_invert(loc, scale, T):
    x = np.random.default_rng(0).gumbel(loc, scale, size=30)
    g = fit_gumbel(x, method="moments")
    assert g.return_period(g.return_level(T)) == pytest.approx(T, rel=1e-6)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 1000))
def test_return_levels_monotone_in_T(seed):
    x = np.random.default_rng(seed).gumbel(10, 3, size=25)
    T = np.array([2, 5, 10, 100, 1000])
    for fit in (fit_gumbel(x), fit_gev(x)):
        assert np.all(np.diff(fit.return_level(T)) > 0)


# ---------------------------------------------------------------- profile interval, degenerate samples
SYNTHETIC = Path(__file__).resolve().parents[1] / "riskrf" / "data" / "synthetic_corridor_1985_2024.csv"


def _brute_gev_profile_loglik(x, z, q):
    """Profile log-likelihood of the GEV at return level z, computed independently of riskrf.

    Coles (2001) eq. 3.7 written out; mu is eliminated by eq. 3.4.  For each shape on a grid
    (xi in [-0.9, 4], 99 points) the scale is scanned on a grid of 451 log-offsets above the
    smallest scale that keeps every observation in the support, then refined by bounded
    Brent searches (scipy ``minimize_scalar``) in sigma and then in xi.
    """
    from scipy import optimize
    y = -np.log1p(-q)

    def gev_ll(mu, s, xi):
        t = 1 + xi * (x[:, None] - mu) / s
        with np.errstate(all="ignore"):
            v = -np.log(s) - (1 + 1 / xi) * np.log(t) - t ** (-1 / xi)
        return np.where((t > 0).all(0), np.where(np.isfinite(v), v, -np.inf).sum(0), -np.inf)

    def best_over_sigma(xi):
        xi = xi if abs(xi) > 1e-6 else 1e-6
        floor = max(0.0, np.max(xi * (z - x)) * y ** xi)
        lead = np.log(floor) if floor > 0 else np.log(np.ptp(x))

        def ll(d):
            s = floor + np.exp(lead + np.atleast_1d(d))
            return gev_ll(z - s * (y ** (-xi) - 1) / xi, s, xi)
        grid = np.linspace(-30, 15, 451)
        vals = ll(grid)
        k = int(np.argmax(vals))
        r = optimize.minimize_scalar(lambda d: -ll(d)[0], bounds=(grid[max(k - 1, 0)], grid[min(k + 1, 450)]),
                                     method="bounded", options={"xatol": 1e-10})
        return max(-r.fun, vals[k])
    xis = np.linspace(-0.9, 4.0, 99)
    vals = np.array([best_over_sigma(xi) for xi in xis])
    k = int(np.argmax(vals))
    r = optimize.minimize_scalar(lambda xi: -best_over_sigma(xi), bounds=(xis[max(k - 1, 0)], xis[min(k + 1, 98)]),
                                 method="bounded", options={"xatol": 1e-8})
    return max(-r.fun, vals[k])


def test_gev_profile_interval_heavy_tail_matches_independent_profile():
    # The shipped SYNTHETIC corridor record (riskrf/data, xi-hat = 1.94): before the fix the 100-year
    # interval was [2.63e6, 6.58e7] kg while the profile crosses the 95 % cut near 1.77e9 kg.
    from riskrf import read_inventory
    with pytest.warns(Warning):
        maxima = read_inventory(SYNTHETIC).annual_maxima()
    gev = fit_gev(maxima)
    assert gev.shape > 1.5
    lo, hi = (float(v) for v in gev.return_level_ci(100))
    q = 0.01 / (1 - gev.p_zero)
    cut = gev.loglik - stats.chi2.ppf(0.95, 1) / 2
    for limit, inward in ((lo, 1.01), (hi, 0.99)):
        assert _brute_gev_profile_loglik(gev.data, limit, q) == pytest.approx(cut, abs=2e-3)
        assert _brute_gev_profile_loglik(gev.data, limit * inward, q) > cut          # inside the interval
        assert _brute_gev_profile_loglik(gev.data, limit / inward, q) < cut          # outside
    assert hi > 1e9


def test_gev_profile_interval_coverage_seeded():
    # xi = 0.5, n = 40, 100-year level: the cut-off interval covered 0.59 of 0.95.
    true = stats.genextreme(-0.5, loc=100.0, scale=20.0)
    z100 = true.isf(0.01)
    rng = np.random.default_rng(2026)
    hits = 0
    for _ in range(200):
        lo, hi = fit_gev(true.rvs(size=40, random_state=rng)).return_level_ci(100)
        hits += lo <= z100 <= hi
    assert hits / 200 >= 0.9


def test_gumbel_profile_interval_matches_chi_square_cut():
    g = fit_gumbel(PORT_PIRIE)
    lo, hi = (float(v) for v in g.return_level_ci(100))
    # Independent: maximise the Gumbel log-likelihood over sigma with mu = z + sigma ln(-ln(1 - 1/T)).
    from scipy import optimize
    ly = np.log(-np.log1p(-0.01))

    def prof(z):
        r = optimize.minimize_scalar(lambda ls: -stats.gumbel_r.logpdf(PORT_PIRIE, z + np.exp(ls) * ly,
                                                                       np.exp(ls)).sum(),
                                     bounds=(np.log(1e-3), np.log(10.0)), method="bounded",
                                     options={"xatol": 1e-12})
        return -r.fun
    cut = g.loglik - stats.chi2.ppf(0.95, 1) / 2
    assert prof(lo) == pytest.approx(cut, abs=1e-4) and prof(hi) == pytest.approx(cut, abs=1e-4)
    assert lo < g.return_level(100) < hi


@pytest.mark.parametrize("fit", [fit_gumbel, fit_gev])
def test_constant_maxima_raise_naming_the_value(fit):
    with pytest.raises(ValueError, match=r"maxima: all 12 annual maxima equal 5\.0"):
        fit([5.0] * 12)


def test_direct_construction_with_zero_scale_raises():
    from riskrf.frequency.extremes import GEVFit
    with pytest.raises(ValueError, match=r"scale = 0\.0: the scale of a GEVFit must be finite and > 0"):
        GEVFit(p_zero=0.0, n_years=10, method="mle", level=0.95, cov=None, data=np.arange(10.0),
               loc=1.0, scale=0.0, shape=0.1)


def test_return_level_figure_bands_use_the_table_method_and_never_go_below_zero():
    """return_levels.png: the bands are the intervals of design_masses.csv (profile likelihood for MLE fits),
    labelled so, and a band whose interval reaches below zero stops above zero on the log axis."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from riskrf.report import plot_return_levels
    gum = fit_gumbel(PORT_PIRIE)
    ax = plot_return_levels({"Gumbel": gum}, units="m", T_max=200)
    assert ax.get_legend().get_title().get_text() == "bands: 95% profile likelihood intervals"
    T = np.geomspace(1.05, 200, 16)                          # the band's return periods
    lo, hi = gum.return_level_ci(T)                         # the default (profile) method, as the table
    y = ax.collections[0].get_paths()[0].vertices[:, 1]
    assert all(np.isclose(y, v, rtol=1e-9, atol=0).any() for v in np.r_[lo, hi])
    d_lo, _ = gum.return_level_ci(T, method="delta")        # not the delta band drawn before
    assert not all(np.isclose(y, v, rtol=1e-9, atol=0).any() for v in d_lo)
    plt.close(ax.figure)
    # a moment fit (delta intervals) of very dispersed small maxima: its lower limits fall below zero
    rng = np.random.default_rng(3)
    small = rng.gumbel(1.0, 3.0, 12).clip(0.05)
    mom = fit_gumbel(small, method="moments")
    lo_d, _ = mom.return_level_ci(np.geomspace(1.05, 1000, 30), method="delta")
    assert (lo_d <= 0).any()
    ax = plot_return_levels({"Gumbel": mom}, units="m")
    assert "delta method" in ax.get_legend().get_title().get_text()
    y = ax.collections[0].get_paths()[0].vertices[:, 1]
    assert np.nanmin(y) > 0
    plt.close(ax.figure)
