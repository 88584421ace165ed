"""Power-law (Gutenberg-Richter) fits against published values (issue 2, item 3)."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import riskrf
from riskrf import fit_gutenberg_richter, read_inventory

from .conftest import DATA, INVENTORIES


def test_aki_estimator_worked_case():
    # Aki (1965) b = log10(e) / (mean log10 V - log10 Vmin); V = 1,2,4,8,16, Vmin = 1
    # -> b = 0.72135, SE = b/sqrt(5) = 0.32260 (domain-methods.md E9, as rockfall_ml.m computes it).
    fit = fit_gutenberg_richter([1, 2, 4, 8, 16], duration_years=5, m_min=1)
    assert fit.b == pytest.approx(0.72135, abs=5e-6)
    assert fit.b_stderr == pytest.approx(0.32260, abs=5e-6)
    assert fit.rate_min == 1.0 and fit.a == pytest.approx(0.0)
    unbiased = fit_gutenberg_richter([1, 2, 4, 8, 16], duration_years=5, m_min=1, unbiased=True)
    assert unbiased.b == pytest.approx(0.72135 * 4 / 5, abs=5e-6)


def test_strunden_2015_lauterbrunnen_exponent():
    # Strunden et al. (2015, JGR Earth Surface 120:1251) via the authors' plotting script:
    # 1.5-year TLS inventory, V >= 0.35 m3, density exponent 1.67 +- 0.07, i.e. cumulative b = 0.67 +- 0.07.
    inv = read_inventory(INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2015.csv")
    fit = fit_gutenberg_richter(inv.volumes, inv.duration_years, m_min=0.35, units="m3")
    assert fit.b == pytest.approx(0.67, abs=0.01)          # 0.665: one unit of the last published digit
    assert fit.b_stderr == pytest.approx(0.07, abs=0.005)


@pytest.mark.parametrize("name,xmin,alpha,tol,n_tail", [
    ("words", 7, 1.95, 0.01, 2958),        # Clauset et al. (2009) Table 6.1
    ("terrorism", 12, 2.4, 0.05, 547),
    ("flares", 323, 1.79, 0.01, 1711),
])
def test_clauset_2009_table_6_1_exponents(name, xmin, alpha, tol, n_tail):
    x = np.loadtxt(DATA / "clauset2009" / f"{name}.txt")
    # Integer data: Clauset's continuous approximation of the discrete MLE uses x_min - 1/2 (their eq. 3.7).
    fit = fit_gutenberg_richter(x, 1.0, m_min=xmin - 0.5)
    assert fit.n_tail == n_tail
    assert 1 + fit.b == pytest.approx(alpha, abs=tol)


def test_clauset_solar_flares_threshold_found_by_ks():
    # Table 6.1: x_min = 323 +- 89, n_tail = 1711 +- 384, alpha = 1.79 +- 0.02.
    x = np.loadtxt(DATA / "clauset2009" / "flares.txt")
    fit = fit_gutenberg_richter(x, 1.0)
    assert fit.m_min_method == "ks"
    assert abs(fit.m_min - 323) <= 89 and abs(fit.n_tail - 1711) <= 384
    assert 1 + fit.b == pytest.approx(1.79, abs=0.02)


def test_volume_fit_and_mass_fit_differ_only_in_a():
    rng = np.random.default_rng(3)
    vols = 0.5 * (1 - rng.uniform(size=400)) ** (-1 / 0.6)
    fv = fit_gutenberg_richter(vols, 10.0, m_min=0.5, units="m3")
    fm = fit_gutenberg_richter(vols * 2650, 10.0, m_min=0.5 * 2650)
    conv = fv.to_mass(2650)
    assert conv.b == pytest.approx(fm.b) and conv.a == pytest.approx(fm.a)
    assert fm.a - fv.a == pytest.approx(fv.b * np.log10(2650))   # domain-methods.md 1.1


def test_frequency_methods_are_consistent():
    rng = np.random.default_rng(4)
    m = 100 * (1 - rng.uniform(size=500)) ** (-1 / 0.7)
    fit = fit_gutenberg_richter(m, 25.0, m_min=100)
    assert fit.rate_min == pytest.approx(20.0)
    T = np.array([5, 50, 500])
    mT = fit.mass_at_return_period(T)
    np.testing.assert_allclose(fit.return_period(mT), T)
    np.testing.assert_allclose(fit.mass_at_return_period(T), (10 ** fit.a * T) ** (1 / fit.b))
    # Frechet annual maximum: m_T = (10^a / -ln(1 - 1/T))^(1/b)   (domain-methods.md 1.1)
    np.testing.assert_allclose(fit.annual_max_return_level(T), (10 ** fit.a / -np.log(1 - 1 / T)) ** (1 / fit.b))
    # exp(-N(>=m)) is the annual-maximum CDF; at its T-year level it equals 1 - 1/T.
    np.testing.assert_allclose(fit.annual_max_cdf(fit.annual_max_return_level(T)), 1 - 1 / T)
    p = fit.probability_in(30, mT[1])
    assert p == pytest.approx(1 - np.exp(-30 / 50))
    lo, hi = fit.mass_at_return_period_ci(T)
    assert np.all(lo < mT) and np.all(mT < hi)
    with pytest.raises(ValueError, match="below m_min"):
        fit.annual_frequency(50)
    with pytest.raises(ValueError, match="shorter than the return period of m_min"):
        fit.mass_at_return_period(0.01)


def test_grenoble_law_return_periods():
    # Dussauge-Peisser et al. (2002) Grenoble law N(>=V) = 4.2 V^-0.41 per year (domain-methods.md E14):
    # N(>=1e4 m3) = 0.09622 (T = 10.39 yr); N(>=1e6) = 0.01456 (T = 68.67 yr); exact 100-yr annual max 2.47e6 m3.
    from riskrf.power_law import GutenbergRichterFit
    law = GutenbergRichterFit(a=np.log10(4.2), b=0.41, b_stderr=0.0, b_ci=(0.41, 0.41), level=0.95, b_ci_method="",
                              m_min=1.0, m_max=None, rate_min=4.2, n_tail=1, n_total=1, duration_years=1.0,
                              method="mle", m_min_method="given", ks_distance=0.0, units="m3")
    assert law.annual_frequency(1e4) == pytest.approx(0.09622, abs=5e-6)
    assert law.return_period(1e6) == pytest.approx(68.67, abs=0.005)
    assert law.annual_max_return_level(100) == pytest.approx(2.47e6, rel=2e-3)


def test_truncated_power_law_recovers_b_and_respects_m_max():
    rng = np.random.default_rng(5)
    lo, hi, b = 1.0, 1000.0, 0.6
    u = rng.uniform(size=3000)
    x = (lo ** -b - u * (lo ** -b - hi ** -b)) ** (-1 / b)
    fit = fit_gutenberg_richter(x, 10.0, m_min=1.0, m_max=1000.0)
    assert fit.b == pytest.approx(0.6, abs=3 * fit.b_stderr)
    assert fit.sf(1000.0) == 0.0 and fit.annual_frequency(1000.0) == 0.0
    with pytest.raises(ValueError, match="m_max = 10 kg is smaller than the largest value"):
        fit_gutenberg_richter(x, 10.0, m_min=1.0, m_max=10.0)


def test_least_squares_is_labelled_and_close_on_clean_data():
    rng = np.random.default_rng(6)
    x = (1 - rng.uniform(size=2000)) ** (-1 / 0.5)
    mle = fit_gutenberg_richter(x, 10.0, m_min=1.0)
    lsq = fit_gutenberg_richter(x, 10.0, m_min=1.0, method="lsq")
    assert lsq.method == "lsq" and "least squares" in lsq.summary().loc["method", "note"]
    assert abs(lsq.b - mle.b) < 0.05


def test_goodness_of_fit_bootstrap_and_likelihood_ratios():
    rng = np.random.default_rng(7)
    pl = 10 * (1 - rng.uniform(size=300)) ** (-1 / 0.7)
    fit = fit_gutenberg_richter(pl, 5.0, m_min=10)
    p1 = fit.bootstrap_pvalue(200, seed=11)
    assert p1 == fit.bootstrap_pvalue(200, seed=11)      # seeded
    assert p1 > 0.1                                      # true power law: plausible
    table = fit.compare()
    assert table.loc["exponential", "loglik_ratio_R"] > 0 and table.loc["exponential", "p_value"] < 0.01
    expo = 10 + rng.exponential(5.0, size=300)
    bad = fit_gutenberg_richter(expo, 5.0, m_min=10)
    assert bad.bootstrap_pvalue(200, seed=11) < 0.1      # exponential data: power law rejected
    assert bad.compare().loc["exponential", "loglik_ratio_R"] < 0


def test_bad_input_messages():
    with pytest.raises(ValueError, match=r"masses\[1\] = -2.0"):
        fit_gutenberg_richter([1, -2, 3], 1.0)
    with pytest.raises(ValueError, match="masses is empty"):
        fit_gutenberg_richter([], 1.0)
    with pytest.raises(ValueError, match="m_min = 100 kg lies above every value"):
        fit_gutenberg_richter([1, 2, 3], 1.0, m_min=100)
    with pytest.raises(ValueError, match="duration_years must be finite and > 0; got 0"):
        fit_gutenberg_richter([1, 2, 3], 0)
    with pytest.raises(ValueError, match="method = 'ols' is not one of"):
        fit_gutenberg_richter([1, 2, 3], 1.0, m_min=1, method="ols")


def test_fit_accepts_an_inventory():
    inv = read_inventory(INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2018.csv")
    fit = fit_gutenberg_richter(inv)
    assert fit.duration_years == 5.2 and fit.n_total == 317
    assert fit.b == pytest.approx(0.74, abs=0.01)       # documented result in inventories/README.md


def test_ci_coverage_of_b_from_simulated_data():
    # Parameter recovery with seeded coverage: 400 samples of n = 50 from b = 0.7.
    rng = np.random.default_rng(2024)
    hits = 0
    for _ in range(400):
        x = (1 - rng.uniform(size=50)) ** (-1 / 0.7)
        lo, hi = fit_gutenberg_richter(x, 1.0, m_min=1.0).b_ci
        hits += lo <= 0.7 <= hi
    assert 0.92 <= hits / 400 <= 0.98


@settings(max_examples=40, deadline=None)
@given(b=st.floats(0.2, 2.0), p=st.floats(1e-9, 1.0), m_max=st.one_of(st.none(), st.floats(1e3, 1e8)))
def test_sf_isf_round_trip(b, p, m_max):
    from riskrf.power_law import _truncated_isf, _truncated_sf
    m = _truncated_isf(p, b, 1.0, m_max)
    assert _truncated_sf(m, b, 1.0, m_max) == pytest.approx(p, rel=1e-7, abs=1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), b=st.floats(0.3, 1.5))
def test_return_levels_increase_with_T(seed, b):
    rng = np.random.default_rng(seed)
    x = (1 - rng.uniform(size=60)) ** (-1 / b)
    fit = fit_gutenberg_richter(x, 10.0, m_min=1.0)
    T = np.array([1, 2, 10, 100, 1000, 1e4])
    assert np.all(np.diff(fit.mass_at_return_period(T)) > 0)
    assert np.all(np.diff(fit.annual_frequency(np.geomspace(1, 1e6, 20))) <= 0)


def test_powerlaw_package_cross_check():
    powerlaw = pytest.importorskip("powerlaw")
    x = np.loadtxt(DATA / "clauset2009" / "flares.txt")
    ours = fit_gutenberg_richter(x, 1.0)
    theirs = powerlaw.Fit(x, discrete=False, verbose=False)
    assert ours.m_min == pytest.approx(theirs.power_law.xmin)
    assert 1 + ours.b == pytest.approx(theirs.power_law.alpha, rel=1e-6)


def test_threshold_search_handles_ties_exactly():
    x = np.array([1, 1, 1, 2, 2, 3, 5, 8, 13, 21, 34, 55, 89, 144, 233] * 3, dtype=float)
    m_min, D, b = riskrf.find_m_min(x, min_tail=5)
    assert m_min in x and 0 < D < 1 and b > 0
