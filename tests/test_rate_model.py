"""Rate models: Poisson / negative-binomial regression of event counts on rainfall,
season and trend.  Known-answer checks on simulated counts (seeded), bad input, and the real Hong Kong
record."""
import warnings

import numpy as np
import pandas as pd
import pytest

import riskrf
from riskrf import read_inventory, rate_model
from riskrf.io.rainfall import rainfall_from_series, read_rainfall

from .conftest import INVENTORIES

HK = INVENTORIES / "hong-kong" / "hong_kong_rock_cuts_1984_2020.csv"
HK_RAIN = INVENTORIES / "hong-kong" / "hko_daily_rainfall_1983_2020.csv"


def _inventory(tmp_path, dates, start, end, name="sim.csv"):
    f = tmp_path / name
    lines = ["date,volume_m3"] + [f"{pd.Timestamp(d).date()},1" for d in dates]
    f.write_text("\n".join(lines) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_inventory(f, start=start, end=end, density_kg_m3=2650)


def _rain(start, end, rng):
    days = pd.date_range(start, end, freq="D")
    wet = rng.random(len(days)) < 0.35
    return pd.Series(np.where(wet, rng.gamma(0.7, 40.0, len(days)), 0.0), index=days)


def _events_from_counts(days, counts):
    return np.repeat(days.to_numpy(), counts)


def test_known_rate_ratio_recovered_within_its_interval(tmp_path):
    # log mu = log 0.08 + log(3) * rain_day / 100 mm + 0.5 cos(season): the rate ratio per 100 mm is 3
    rng = np.random.default_rng(20240612)
    start, end = "2001-01-01", "2012-12-31"
    rain = _rain("2000-12-01", end, rng)
    days = pd.date_range(start, end, freq="D")
    r = rain.reindex(days).to_numpy()
    angle = 2 * np.pi * (days.day_of_year.to_numpy() - 0.5) / 365.25
    mu = 0.08 * 3.0 ** (r / 100) * np.exp(0.5 * np.cos(angle))
    counts = rng.poisson(mu)
    inv = _inventory(tmp_path, _events_from_counts(days, counts), start, end)
    model = rate_model(inv, rainfall_from_series(rain), period="day", windows_days=(1, 3), trend=True)
    rr = model.rate_ratios.set_index("term")
    day = rr.loc["rain_d0_mm"]
    assert day["ci_low"] < 3.0 < day["ci_high"]
    assert day["rate_ratio"] == pytest.approx(3.0, rel=0.3)
    before = rr.loc["rain_d1_2_mm"]                       # no effect simulated
    assert before["ci_low"] < 1.0 < before["ci_high"]
    assert rr.loc["season_cos", "ci_low"] < np.exp(0.5) < rr.loc["season_cos", "ci_high"]
    assert model.n_events == counts.sum() and model.n_periods == len(days)
    # Poisson data: the Poisson GLM's fitted total equals the observed total (canonical link with a constant)
    assert model.comparison.loc["Poisson", "expected_total"] == pytest.approx(counts.sum(), rel=1e-9)
    # predictions: the rate at 100 mm over the rate at 0 mm is the rate ratio
    pred = model.predicted_by_rainfall([0.0, 100.0])
    assert pred["events_per_day"].iloc[1] / pred["events_per_day"].iloc[0] == pytest.approx(day["rate_ratio"],
                                                                                            rel=1e-6)


@pytest.mark.parametrize("true_trend,expect", [(1.04, True), (1.0, False)])
def test_trend_test_detects_a_known_trend_and_not_a_null_one(tmp_path, true_trend, expect):
    rng = np.random.default_rng(7)
    start, end = "1981-01-01", "2010-12-31"
    months = pd.date_range(start, end, freq="MS")
    t = months.year + (months.month - 0.5) / 12 - 1996
    mu = 1.5 * true_trend ** t * np.exp(0.6 * np.cos(2 * np.pi * (months.month - 7) / 12))
    counts = rng.poisson(mu)
    dates = _events_from_counts(months + pd.Timedelta(days=14), counts)
    inv = _inventory(tmp_path, dates, start, end)
    with pytest.warns(riskrf.RiskrfWarning, match="no rainfall or other covariates"):
        model = rate_model(inv, period="month")
    assert model.trend["detected"] is expect
    lo, hi = model.trend["ci_low"], model.trend["ci_high"]
    assert lo < true_trend < hi
    if expect:
        assert model.trend["p_value"] < 1e-6
    else:
        assert model.trend["p_value"] > 0.05


def test_overdispersed_counts_prefer_the_negative_binomial(tmp_path):
    rng = np.random.default_rng(11)
    start, end = "1991-01-01", "2010-12-31"
    months = pd.date_range(start, end, freq="MS")
    mu = 2.0 * rng.gamma(1 / 0.8, 0.8, len(months))        # NB2 with alpha = 0.8
    counts = rng.poisson(mu)
    inv = _inventory(tmp_path, _events_from_counts(months + pd.Timedelta(days=3), counts), start, end)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = rate_model(inv, period="month", season=None, trend=False)
    assert model.preferred == "negative binomial"
    assert model.overdispersion["lr_p_value"] < 0.01 and model.overdispersion["ct_p_value"] < 0.01
    assert 0.4 < model.overdispersion["alpha"] < 1.4
    assert model.comparison.loc["negative binomial", "aic"] < model.comparison.loc["Poisson", "aic"]


def test_bad_input_errors_name_file_row_and_value(tmp_path):
    rng = np.random.default_rng(3)
    inv = _inventory(tmp_path, ["2001-03-04", "2001-07-09", "2002-05-05"], "2001-01-01", "2003-12-31")
    # rainfall with a gap inside the record period: reported, never filled
    f = tmp_path / "gauge.csv"
    days = pd.date_range("2000-12-01", "2003-12-31", freq="D")
    rows = [f"{d.date()},{v:.1f}" for d, v in zip(days, rng.gamma(0.5, 10, len(days)))
            if not (pd.Timestamp("2002-02-01") <= d <= pd.Timestamp("2002-02-10"))]
    f.write_text("date,rainfall_mm\n" + "\n".join(rows) + "\n")
    with pytest.warns(riskrf.RiskrfWarning, match="gap"):
        rain = read_rainfall(f)
    with pytest.raises(ValueError, match=r"gauge.csv: no rainfall from 2002-02-01 to 2002-02-10 \(10 days missing, "
                                         r"between rows 428 and 429\), but .*sim.csv: the record period"):
        rate_model(inv, rain, period="day")
    # an event dated before the rainfall record begins
    short = rainfall_from_series(pd.Series(1.0, index=pd.date_range("2001-06-01", "2003-12-31")), "short.csv")
    with pytest.raises(ValueError, match=r"sim.csv: row 2, date 2001-03-04: outside the rainfall record short.csv"):
        rate_model(inv, short, period="day")
    # covariates that do not cover the inventory's period
    full = rainfall_from_series(pd.Series(1.0, index=pd.date_range("2000-01-01", "2003-12-31")) *
                                rng.random(1461))
    temp = pd.DataFrame({"temperature_c": 10.0 + rng.random(900)}, index=pd.date_range("2001-01-01", periods=900))
    with pytest.raises(ValueError, match=r"column 'temperature_c' has no value for 2003-06-20, but the inventory"):
        rate_model(inv, temp, rainfall=full, period="month")
    # fewer than 20 periods
    with pytest.raises(ValueError, match=r"sim.csv: 3 year period\(s\) from 2001-01-01 to 2003-12-31; a count model "
                                         r"needs at least 20"):
        rate_model(inv, full, period="year")
    with pytest.raises(ValueError, match=r"period = 'week' is not one of"):
        rate_model(inv, full, period="week")
    with pytest.raises(TypeError, match="inventory must be a riskrf Inventory"):
        rate_model("sim.csv", full)


def test_hong_kong_monthly_rate_model_on_the_real_record():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = read_inventory(HK)
        model = rate_model(inv, HK_RAIN, period="month")
    assert model.n_events == 445 and model.n_periods == 444       # every rock-cut incident, 37 x 12 months
    rr = model.rate_ratios.set_index("term").loc["rain_month_mm"]
    # measured on the shipped record (README, Hong Kong worked example): 1.35 (1.278-1.426) per 100 mm
    assert rr["rate_ratio"] == pytest.approx(1.350, abs=0.002)
    assert rr["ci_low"] == pytest.approx(1.278, abs=0.002) and rr["ci_high"] == pytest.approx(1.426, abs=0.002)
    assert model.preferred == "negative binomial" and not model.trend["detected"]
    season = model.predicted_by_season()
    assert season["observed_per_month"].sum() == pytest.approx(445 / 37, rel=1e-9)
    assert season["observed_per_month"].idxmax() in (5, 6, 7, 8)
    s = model.summary()
    assert "rate ratio: rainfall in the month (per 100 mm)" in s.index


def test_cli_rates_writes_tables_and_figures(tmp_path, capsys):
    from riskrf.cli import main
    out = tmp_path / "rates"
    assert main(["rates", str(HK), "--rainfall", str(HK_RAIN), "--period", "month", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Preferred: negative binomial" in text and "rainfall in the month" in text
    for name in ("rate_ratios.csv", "model_comparison.csv", "season.csv", "seasonality.png"):
        assert (out / name).exists()
    assert main(["rates", str(HK), "--rainfall", str(tmp_path / "missing.csv")]) == 2


def test_known_freeze_thaw_rate_ratio_recovered_within_its_interval(tmp_path):
    """A daily covariate other than rainfall: freeze-thaw days (0/1, more often in winter) with a rate ratio of 2.5.

    log mu = log 0.05 + log(2.5) * freeze_thaw; rainfall is given but has no effect (its ratio must cover 1)."""
    rng = np.random.default_rng(20251123)
    start, end = "2001-01-01", "2010-12-31"
    days = pd.date_range(start, end, freq="D")
    winter = 0.5 * (1 + np.cos(2 * np.pi * (days.day_of_year.to_numpy() - 15) / 365.25))   # 1 mid-January
    ft = (rng.random(len(days)) < 0.6 * winter).astype(float)
    counts = rng.poisson(0.05 * 2.5 ** ft)
    inv = _inventory(tmp_path, _events_from_counts(days, counts), start, end)
    rain = _rain("2000-12-01", end, rng)
    cov = pd.DataFrame({"freeze_thaw": ft}, index=days)
    model = rate_model(inv, cov, rainfall=rainfall_from_series(rain), period="day", windows_days=(1,),
                       season=None, trend=False)
    rr = model.rate_ratios.set_index("term")
    row = rr.loc["freeze_thaw"]
    assert row["ci_low"] < 2.5 < row["ci_high"]
    assert row["rate_ratio"] == pytest.approx(2.5, rel=0.25)
    assert row["ci_low"] > 1.5                              # detected, not merely covered
    assert rr.loc["rain_d0_mm", "ci_low"] < 1.0 < rr.loc["rain_d0_mm", "ci_high"]
    assert model.n_events == counts.sum() and model.n_periods == len(days)


def test_negative_binomial_is_the_exact_nb2_maximum_likelihood(tmp_path):
    # The profile fit must reach the NB2 log-likelihood maximum found by a direct numerical maximisation of
    # sum log NB(y | mu = exp(b0 + log exposure), alpha) (scipy.stats.nbinom with n = 1/alpha, p = n/(n + mu)).
    from scipy import optimize, stats
    rng = np.random.default_rng(5)
    start, end = "1995-01-01", "2004-12-31"
    months = pd.date_range(start, end, freq="MS")
    counts = rng.poisson(1.5 * rng.gamma(1 / 0.6, 0.6, len(months)))
    inv = _inventory(tmp_path, _events_from_counts(months + pd.Timedelta(days=3), counts), start, end)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = rate_model(inv, period="month", season=None, trend=False)
    y = model.design["count"].to_numpy(float)
    expo = model.design["exposure_days"].to_numpy(float)

    def nll(p):
        mu, n = np.exp(p[0]) * expo, 1 / np.exp(p[1])
        return -stats.nbinom.logpmf(y, n, n / (n + mu)).sum()

    best = optimize.minimize(nll, [np.log(y.sum() / expo.sum()), np.log(0.5)], method="Nelder-Mead",
                             options={"xatol": 1e-8, "fatol": 1e-10, "maxiter": 4000})
    assert model.comparison.loc["negative binomial", "loglik"] == pytest.approx(-best.fun, abs=1e-5)
    assert model.overdispersion["alpha"] == pytest.approx(np.exp(best.x[1]), rel=1e-3)


def test_short_record_without_overdispersion_fits_on_every_statsmodels(tmp_path):
    # Three months of daily counts with no overdispersion: the NB2 dispersion lies on its boundary (alpha -> 0,
    # the Poisson model).  statsmodels 0.15's quasi-Newton search from a fixed guess returned NaN here and the
    # command failed with statsmodels' own message; the profile fit gives the Poisson model, noted, no error.
    rng = np.random.default_rng(2)
    days = pd.date_range("2019-02-01", "2019-04-30")
    rain = pd.Series(rng.gamma(0.5, 8, len(days)).round(1), index=days)
    events = pd.DatetimeIndex(rng.choice(days[20:], 30))
    inv = _inventory(tmp_path, events, "2019-02-21", "2019-04-30")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = rate_model(inv, rainfall=rainfall_from_series(rain, "rain.csv"), season=None, trend=False)
    assert model.preferred == "Poisson"
    assert np.isfinite(model.comparison["loglik"]).all()
    assert model.comparison.loc["negative binomial", "loglik"] >= model.comparison.loc["Poisson", "loglik"] - 1e-6


def test_a_daily_rainfall_above_the_world_record_is_refused_naming_file_row_and_value(tmp_path):
    f = tmp_path / "rain.csv"
    f.write_text("date,rainfall_mm\n2019-02-01,3.2\n2019-02-02,1000000000\n2019-02-03,0\n")
    with pytest.raises(ValueError, match=r"rain\.csv: row 3, 2019-02-02: daily rainfall 1e\+09 mm is above the "
                                         r"largest ever measured \(1825 mm"):
        read_rainfall(f)
