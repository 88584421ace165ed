"""Real multi-decade records: the Hong Kong rock-cut register, the Observatory's
rainfall and the NVDB E6 record; censored sizes in read_inventory.

Reference numbers are the facts measured in ../shared/inventories-raw/*/PROVENANCE.md.
"""
import os
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from riskrf import RiskrfWarning, read_inventory
from riskrf.io.rainfall import read_rainfall
from riskrf.io.records import read_cedd_incidents

from .conftest import INVENTORIES, ROOT

SHARED = Path(os.environ.get("RISKRF_SHARED_DIR", ROOT / ".." / "shared"))
RAW_HK = SHARED / "inventories-raw" / "hong-kong-cedd"
HK = INVENTORIES / "hong-kong" / "hong_kong_rock_cuts_1984_2020.csv"
HK_RAIN = INVENTORIES / "hong-kong" / "hko_daily_rainfall_1983_2020.csv"
E6 = INVENTORIES / "nvdb-norway" / "nvdb_e6_rockfalls_2000_2014.csv"


def _raw(name):
    path = RAW_HK / name
    if not path.exists():
        pytest.skip(f"{path} not present (shared raw records)")
    return path


@pytest.fixture(scope="module")
def cedd():
    return read_cedd_incidents(_raw("cedd_incidents_1984_2020.csv"))


def test_cedd_register_bad_bytes_censored_sizes_and_missing_failure_dates(cedd):
    t = cedd.table
    # PROVENANCE.md: 445 rock-cut incidents of 9,840; three rows with bytes that are not UTF-8
    assert cedd.n_rows == 9840 and len(t) == 445
    assert len(cedd.bad_byte_rows) == 3 and "2005/08/0510" in cedd.bad_byte_rows[0]
    # FAILDATE given for 353; the other 92 are dated by the call, flagged
    assert (t["date_source"] == "FAILDATE").sum() == 353
    assert (t["date_source"] == "CALLDATE").sum() == 92
    assert t.loc[t["date_source"] == "CALLDATE", "notes"].str.contains("date of the call").all()
    # SCALE numeric for 411; "<1", "~15" kept as written (censored), "Minor"/"-" have no size
    numeric = t["volume_m3"].str.fullmatch(r"\d+(\.\d+)?")
    assert numeric.sum() == 411
    assert {"<1", "~15", "<0.1", "~1000"} <= set(t["volume_m3"])
    assert (t.loc[t["scale_as_recorded"] == "Minor", "volume_m3"] == "").all()
    vols = t.loc[numeric, "volume_m3"].astype(float)
    assert vols.min() == 0.0001 and vols.max() == 4000 and vols.median() == 1   # PROVENANCE.md
    assert t["date"].str[:4].astype(int).between(1984, 2020).all()


def test_shipped_hong_kong_csv_is_the_conversion_of_the_raw_register(cedd):
    shipped = HK.read_text(encoding="utf-8")
    assert shipped == cedd.table.to_csv(index=False, lineterminator="\n")


def test_read_inventory_hong_kong_keeps_censored_sizes_as_censored():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        inv = read_inventory(HK)
    text = " ".join(str(w.message) for w in caught)
    assert "25 censored size(s) kept as censored" in text and "20 below, 5 approximate" in text
    assert "9 row(s) have no size" in text
    assert inv.n_events == 411 and inv.n_censored == 34 and len(inv.all_events()) == 445
    cens = inv.censored.set_index("size_text")
    assert cens.loc["~15", "censoring"] == "approximate" and cens.loc["~15", "volume_m3"] == 15
    assert cens.loc["<5", "censoring"] == "below" and cens.loc["<5", "volume_m3"] == 5
    assert (inv.censored["censoring"] == "unknown").sum() == 9
    assert not np.isin(inv.volumes, [1000.0]).any()          # "~1000" is not used as an exact size
    m = inv.annual_maxima(unit="m3")       # no censored size exceeds its year's exact maximum
    assert len(m) == 37 and m.notna().all()                   # a maximum in every year (PROVENANCE.md)
    assert m[1985] == 4000 and m[1997] == 3000 and m[2017] == 1300
    table = inv.completeness()
    assert (table["n_events"] > 0).all() and table["n_events"].sum() == 411


def test_censored_maximum_warning_when_a_bound_exceeds_the_years_exact_maximum(tmp_path):
    f = tmp_path / "inv.csv"
    f.write_text("date,volume_m3\n2001-05-01,2\n2001-06-01,~50\n2002-03-03,1\n2002-04-04,<0.5\n2003-01-01,<3\n")
    inv = read_inventory(f, start="2001-01-01", end="2003-12-31", density_kg_m3=2600)
    assert inv.n_events == 2 and list(inv.censored["censoring"]) == ["approximate", "below", "below"]
    with pytest.warns(RiskrfWarning, match=r"1 censored or missing size\(s\) could set or change") as rec:
        m = inv.annual_maxima(unit="m3")
    msg = " ".join(str(w.message) for w in rec)
    assert "2001 (~50, row 3)" in msg and "2002" not in msg.split("change")[1]
    # 2003 has a fall, of unknown exact size (<3): its maximum is unknown, so it is left out, not an empty year
    assert "1 of 3 years have falls but no exact size (2003)" in msg and "no recorded fall" not in msg
    assert m[2001] == 2 and 2003 not in m.index and m.attrs["years_without_exact_size"] == [2003]


def test_bad_size_text_names_file_row_and_value(tmp_path):
    f = tmp_path / "inv.csv"
    f.write_text("date,volume_m3\n2001-05-01,2\n2001-06-01,about 5\n")
    with pytest.raises(ValueError, match=r"inv.csv: row 3, column 'volume_m3': 'about 5' is not a number"):
        read_inventory(f, duration_years=1)


def test_hko_rainfall_file_gap_trace_and_impossible_day():
    path = _raw("hko_daily_rainfall_1884_2022.csv")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rain = read_rainfall(path)
    text = " ".join(str(w.message) for w in caught)
    assert rain.file_format == "HKO"
    assert rain.first_day.date().isoformat() == "1884-03-01" and rain.last_day.date().isoformat() == "2022-06-30"
    # PROVENANCE.md: no record for 1940-1946; the gap is reported, never filled
    assert len(rain.gaps) == 1
    g = rain.gaps.iloc[0]
    assert g["start"].date().isoformat() == "1940-01-01" and g["end"].date().isoformat() == "1946-12-31"
    assert rain.daily.loc["1940":"1946"].isna().all() and "2557 missing days" in text
    assert "1900-02-29" in text                                # a day the calendar does not have
    assert (rain.flags == "trace").sum() == 6687               # 'Trace' rows in the file, read as 0 mm
    with pytest.raises(ValueError, match=r"no rainfall from 1940-01-01 to 1946-12-31 .*between rows 20397 and 20398"):
        rain.check_covers("1945-06-01", "1950-01-01", "the test period")
    # the shipped 1983-2020 extract is the same numbers in the generic format
    shipped = read_rainfall(HK_RAIN)
    assert shipped.file_format == "generic" and shipped.gaps.empty
    np.testing.assert_array_equal(shipped.daily.to_numpy(), rain.daily.loc["1983":"2020"].to_numpy())


def test_generic_rainfall_gaps_are_reported_not_filled_and_bad_values_named(tmp_path):
    f = tmp_path / "gauge.csv"
    f.write_text("date,rainfall_mm\n2001-01-01,0\n2001-01-02,5.5\n2001-01-03,\n2001-01-04,2\n2001-01-06,trace\n"
                 "2001-01-07,1\n")
    with pytest.warns(RiskrfWarning, match=r"2 gap\(s\), 2 missing days"):
        rain = read_rainfall(f)
    assert rain.daily.isna().sum() == 2 and rain.daily["2001-01-06"] == 0.0
    assert list(rain.gaps["n_days"]) == [1, 1]
    with pytest.raises(ValueError, match=r"gauge.csv: no rainfall from 2001-01-03 to 2001-01-03"):
        rain.check_covers("2001-01-02", "2001-01-07", "inventory x")
    rain.check_covers("2001-01-06", "2001-01-07", "inventory x")      # no gap there: no error
    bad = tmp_path / "bad.csv"
    bad.write_text("date,rainfall_mm\n2001-01-01,0\n2001-01-02,-3\n")
    with pytest.raises(ValueError, match=r"bad.csv: row 3, column 'rainfall_mm': rainfall '-3' must be"):
        read_rainfall(bad)
    bad.write_text("date,rainfall_mm\n2001-01-01,0\n2001-13-02,3\n")
    with pytest.raises(ValueError, match=r"bad.csv: row 3, column 'date': '2001-13-02' is not a date"):
        read_rainfall(bad)
    bad.write_text("date,rain\n2001-01-01,0\n")
    with pytest.raises(ValueError, match=r"needs columns 'date'.*'rainfall_mm'"):
        read_rainfall(bad)


def test_nvdb_e6_record_road_reference_and_chainage():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = read_inventory(E6)
    assert inv.start.isoformat() == "2000-01-01" and inv.end.isoformat() == "2014-12-31"
    every = inv.all_events()
    assert len(every) == 77                                   # PROVENANCE.md: 77 rock falls on E6
    assert inv.n_events == 34                                 # 34 with a volume
    assert every["volume_m3"].max() == 30                     # 1-30 m3
    per_year = every["year"].value_counts().reindex(range(2000, 2015), fill_value=0)
    # PROVENANCE.md: falls per year 2,0,1,0,4,0,3,6,7,6,11,10,2,12,12 (76 dated, one without a date)
    assert per_year.tolist() == [2, 0, 1, 0, 4, 0, 3, 6, 7, 6, 11, 10, 2, 12, 12]
    raw = pd.read_csv(E6, dtype=str, keep_default_na=False)
    assert raw["road_reference"].str.match(r"EV6 hp\d+$").all()
    assert raw["chainage_from_m"].astype(int).between(0, 100_000).all()


def test_nvdb_e6_empty_years_come_from_every_fall_not_only_the_sized_ones():
    """2002, 2006 and 2009 have falls (1, 3, 6) but none with a size: unknown maxima, not empty years.

    PROVENANCE.md falls per year 2000-2014: 2,0,1,0,4,0,3,6,7,6,11,10,2,12,12, so exactly 3 of 15
    years (2001, 2003, 2005) have no fall and the mixed model's p0 is 3/15.
    """
    from riskrf.frequency.study import analyse_inventory
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = read_inventory(E6)
    with pytest.warns(UserWarning) as rec:
        maxima = inv.annual_maxima()
    text = " | ".join(str(w.message) for w in rec)
    assert "3 of 15 years have falls but no exact size (2002, 2006, 2009)" in text
    assert "3 of 15 years have no recorded fall (2001, 2003, 2005)" in text
    assert maxima.attrs["years_without_exact_size"] == [2002, 2006, 2009]
    assert not {2002, 2006, 2009} & set(maxima.index)             # left out: unknown, not zero, not empty
    assert maxima.index[maxima.isna()].tolist() == [2001, 2003, 2005]
    assert maxima.notna().sum() == 9
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        analysis = analyse_inventory(inv, n_bootstrap=0)
    assert analysis.gumbel.p_zero == pytest.approx(3 / 15) and analysis.gumbel.n_years == 15


def test_fit_on_the_hong_kong_record_prefers_the_power_law_over_an_infinite_mean_gev():
    from riskrf.frequency.study import analyse_inventory
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = read_inventory(HK)
        analysis = analyse_inventory(inv, n_bootstrap=0)
    assert analysis.maxima.notna().sum() == 37 and analysis.gumbel.p_zero == 0   # no empty year
    assert analysis.maxima.attrs["years_without_exact_size"] == []          # every year has an exact size
    # measured (README, Hong Kong worked example): xi = 1.71, b = 0.691 above m_min 2.5 m3
    assert analysis.gev.shape == pytest.approx(1.712, abs=0.01)
    assert analysis.power_law.b == pytest.approx(0.691, abs=0.005)
    assert not analysis.deviance["gumbel_adequate"]
    pref = analysis.preferred_model()
    assert pref["model"] == "power law" and pref["gev_shape_plausible"] is False
    assert "implausible" in pref["reason"] and "infinite" in pref["reason"] and "1/b = 1.45" in pref["reason"]


@pytest.mark.parametrize("kind,expected", [("exp-gumbel", "GEV"), ("gumbel", "Gumbel")])
def test_preferred_model_wording_for_a_plausible_gev_and_an_adequate_gumbel(tmp_path, kind, expected):
    from riskrf.frequency.study import analyse_inventory
    rng = np.random.default_rng(5)
    years = np.arange(1961, 2021)
    z = rng.gumbel(0, 1, years.size)
    masses = 1000 * np.exp(0.3 * z) if kind == "exp-gumbel" else 5000 + 800 * z   # GEV xi > 0, or Gumbel
    f = tmp_path / "maxima.csv"
    f.write_text("date,mass_kg\n" + "".join(f"{y}-07-01,{m:.1f}\n" for y, m in zip(years, masses)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = read_inventory(f, start="1961-01-01", end="2020-12-31", density_kg_m3=2650)
        analysis = analyse_inventory(inv, n_bootstrap=0, m_min=float(masses.min()))
    pref = analysis.preferred_model()
    assert pref["model"] == expected and pref["gev_shape_plausible"] is True
    assert ("does not reject the Gumbel" in pref["reason"]) is (expected == "Gumbel")
