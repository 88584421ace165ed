"""Power-law (Gutenberg-Richter) fits against published values."""
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
    lo, hi = fit.return_level_ci(T)
    assert np.all(lo < mT) and np.all(mT < hi)
    with pytest.raises(ValueError, match="below m_min"):
        fit.annual_frequency(50)
    with pytest.raises(ValueError, match="shorter than the return period of m_min"):
        fit.mass_at_return_period(0.01)


def test_grenoble_law_return_periods():
    # Dussauge-Peisser et al. (2002) Grenoble law N(>=V) = 4.2 V^-0.41 per year (domain-methods.md E14):
    # N(>=1e4 m3) = 0.09622 (T = 10.39 yr); N(>=1e6) = 0.01456 (T = 68.67 yr); exact 100-yr annual max 2.47e6 m3.
    from riskrf.frequency.power_law import GutenbergRichterFit
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
    from riskrf.frequency.power_law.law import _truncated_isf, _truncated_sf
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


def _ks_sup_by_definition(tail_sorted, b, x_min):
    """sup_x |S(x) - F(x)| by evaluating both one-sided limits of the step CDF at every distinct value."""
    n = tail_sorted.size
    best = 0.0
    for v in np.unique(tail_sorted):
        F = 1 - (v / x_min) ** (-b)
        below = np.count_nonzero(tail_sorted < v) / n          # S just before the jump at v
        at = np.count_nonzero(tail_sorted <= v) / n            # S at v
        best = max(best, abs(F - below), abs(F - at))
    return best


def test_threshold_search_handles_ties_exactly():
    # Heavily tied sample: the search must return the minimum over every candidate of the KS distance
    # computed from its definition, with ties in the empirical CDF treated exactly.
    x = np.array([1, 1, 1, 2, 2, 3, 5, 8, 13, 21, 34, 55, 89, 144, 233] * 3, dtype=float)
    m_min, D, b = riskrf.find_m_min(x, min_tail=5, statistic="sup")
    brute = {}
    for c in np.unique(x):
        tail = np.sort(x[x >= c])
        if tail.size >= 5 and c < x.max():
            bc = tail.size / np.sum(np.log(tail / c))
            brute[c] = (_ks_sup_by_definition(tail, bc, c), bc)
    best = min(brute, key=lambda c: brute[c][0])
    assert m_min == best
    assert D == pytest.approx(brute[best][0], rel=1e-12) and b == pytest.approx(brute[best][1], rel=1e-12)
    # The default statistic is Clauset's (F(x_i) against (i - 1)/n), which differs on tied data.
    _, D_clauset, _ = riskrf.find_m_min(x, min_tail=5)
    assert D_clauset != D


def _inventory(n, seed):
    """Synthetic inventory: power-law tail over a uniform body (like the benchmark), 6,000-30,000 values."""
    rng = np.random.default_rng(seed)
    b = rng.uniform(0.4, 1.2)
    k = int(n * rng.uniform(0.4, 0.9))
    tail = 10.0 * (1 - rng.uniform(size=k)) ** (-1 / b)
    return np.concatenate([tail, rng.uniform(1.0, 10.0, size=n - k)])


@pytest.mark.slow
@pytest.mark.parametrize("statistic,sizes", [("sup", (6_000, 30_000)), ("clauset", (12_000, 20_000))])
def test_threshold_search_equals_exhaustive_scan_on_large_inventories(statistic, sizes):
    # Issue 10: the old coarse-to-fine scan missed the best threshold on 12 of 30 such inventories.
    for seed, n in enumerate(sizes):
        x = _inventory(n, seed)
        fast = riskrf.find_m_min(x, statistic=statistic)
        full = riskrf.find_m_min(x, statistic=statistic, exhaustive=True)
        assert fast == full


def test_clauset_cities_threshold_both_statistics():
    # Clauset et al. (2009) Table 6.1, populations of US cities (2000 census; data in thousands there):
    # x_min = 52.46 +- 11.88 (thousand), alpha = 2.37 +- 0.08, n_tail = 580 +- 177.  Clauset's statistic
    # (their published code) reproduces it; the supremum statistic's exhaustive minimum is at 52.65
    # thousand, D = 0.019423 (an independent re-computation).
    x = np.loadtxt(DATA / "clauset2009" / "cities.txt")
    fit = fit_gutenberg_richter(x, 1.0)
    assert fit.ks_statistic == "clauset" and not fit.discrete
    assert fit.m_min == 52457 and fit.n_tail == 580
    assert 1 + fit.b == pytest.approx(2.37, abs=0.005)
    m_min, D, _ = riskrf.find_m_min(x, statistic="sup")
    assert m_min == 52648 and D == pytest.approx(0.019423, abs=5e-7)


def test_clauset_blackouts_bootstrap_pvalue():
    # Clauset et al. (2009) Table 6.1, US blackouts 1984-2002 (customers affected, thousands): x_min = 230,
    # alpha = 2.3 +- 0.3, n_tail = 59, p = 0.62.  Clauset's statistic gives 0.61 here (2,500 replicates,
    # Monte Carlo SE 0.01); the supremum statistic gives 0.81.
    x = np.loadtxt(DATA / "clauset2009" / "blackouts.txt") / 1000.0
    fit = fit_gutenberg_richter(x, 1.0)
    assert fit.m_min == 230 and fit.n_tail == 59 and 1 + fit.b == pytest.approx(2.3, abs=0.05)
    res = fit.bootstrap_test(2500, seed=1)
    assert res.n_completed == res.n_requested == 2500
    assert abs(res.p_value - 0.62) <= 3 * res.p_stderr
    sup = fit_gutenberg_richter(x, 1.0, ks_statistic="sup").bootstrap_test(2500, seed=1)
    assert sup.p_value > 0.75
    assert "Clauset" in res.summary().loc["ks_distance", "note"]


def test_bootstrap_pvalue_divides_by_completed_replicates():
    # 3 of 40 values above the given m_min: a replicate draws Binomial(40, 3/40) tail values and about one
    # in five has fewer than two, so it cannot be refitted.  p must be the share of the completed
    # replicates (it used to divide by all requested, biasing p down).
    rng = np.random.default_rng(12)
    x = np.concatenate([[12.0, 30.0, 95.0], rng.uniform(1, 10, size=37)])
    with pytest.warns(riskrf.core.validation.RiskrfWarning, match="only 3 values above m_min"):
        fit = fit_gutenberg_richter(x, 1.0, m_min=10.0)
    with pytest.warns(riskrf.core.validation.RiskrfWarning, match="could not be refitted"):
        res = fit.bootstrap_test(300, seed=3)
    assert 200 < res.n_completed < 290
    exceed = res.p_value * res.n_completed
    assert exceed == pytest.approx(round(exceed), abs=1e-9) and res.p_value > 0
    with pytest.warns(riskrf.core.validation.RiskrfWarning):
        assert fit.bootstrap_pvalue(300, seed=3) == res.p_value


def test_integer_data_fitted_as_discrete_words():
    # Clauset et al. (2009) Table 6.1, word frequencies in Moby Dick: x_min = 7 +- 2, alpha = 1.95 +- 0.02,
    # n_tail = 2958 +- 987, fitted with the discrete law.  Treated as continuous the search gives 26.
    x = np.loadtxt(DATA / "clauset2009" / "words.txt")
    assert riskrf.find_m_min(x)[0] == 26
    with pytest.warns(riskrf.core.validation.RiskrfWarning, match="discrete power law"):
        fit = fit_gutenberg_richter(x, 1.0)
    assert fit.discrete and fit.m_min == 6.5 and fit.n_tail == 2958      # integers >= 7
    assert 1 + fit.b == pytest.approx(1.95, abs=0.005)
    cont = fit_gutenberg_richter(x, 1.0, discrete=False)
    assert not cont.discrete and cont.m_min == 26
    given = fit_gutenberg_richter(x, 1.0, m_min=7, discrete=True)
    assert given.m_min == 6.5 and given.b == pytest.approx(fit.b)
    with pytest.raises(ValueError, match=r"discrete=True needs integer data; masses\[1\] = 2.5"):
        fit_gutenberg_richter([1.0, 2.5, 3.0], 1.0, discrete=True)


def test_discrete_terrorism_threshold():
    # Clauset et al. (2009) Table 6.1, deaths in terrorist attacks: x_min = 12 +- 4, alpha = 2.4 +- 0.2,
    # n_tail = 547 +- 1663 (discrete fit).
    x = np.loadtxt(DATA / "clauset2009" / "terrorism.txt")
    with pytest.warns(riskrf.core.validation.RiskrfWarning):
        fit = fit_gutenberg_richter(x, 1.0)
    assert fit.discrete and fit.m_min + 0.5 == 12 and fit.n_tail == 547
    assert 1 + fit.b == pytest.approx(2.4, abs=0.05)
