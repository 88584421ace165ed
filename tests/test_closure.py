"""Rain-triggered closure as a mitigation option: effectiveness from the rate model and the
rainfall record, cost from closure hours, and the option in the decision analysis."""
import warnings

import numpy as np
import pandas as pd
import pytest

from riskrf import rate_model, read_inventory
from riskrf.risk.closure import closure_rule, read_rainstorm_warnings, warning_closure
from riskrf.risk.mitigation import MitigationError, Option, parse_mitigation, parse_option
from riskrf.io.rainfall import rainfall_from_series

from .test_mitigation import study


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A daily model fitted to simulated falls whose rate rises with the day's rainfall (seeded)."""
    rng = np.random.default_rng(42)
    start, end = "2001-01-01", "2010-12-31"
    days = pd.date_range("2000-12-01", end, freq="D")
    rain = pd.Series(np.where(rng.random(len(days)) < 0.35, rng.gamma(0.7, 40.0, len(days)), 0.0), index=days)
    record = pd.date_range(start, end, freq="D")
    mu = 0.05 * 4.0 ** (rain.reindex(record).to_numpy() / 100)
    counts = rng.poisson(mu)
    f = tmp_path_factory.mktemp("closure") / "falls.csv"
    f.write_text("date,volume_m3\n" + "".join(f"{d.date()},1\n" for d in np.repeat(record, counts)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = read_inventory(f, start=start, end=end, density_kg_m3=2650)
        return rate_model(inv, rainfall_from_series(rain), windows_days=(1, 3), trend=False)


def test_effectiveness_equals_the_share_of_simulated_falls_inside_the_closure_windows(fitted):
    rule = closure_rule(fitted, 60.0, window_days=1, cost_per_hour=500.0)
    closed = rule.closed_share_of_time.to_numpy() > 0
    mu = fitted.fitted().to_numpy()
    # simulate many records of falls from the fitted daily rates: the share inside the closure windows
    rng = np.random.default_rng(1)
    sims = rng.poisson(mu, size=(400, mu.size))
    share = sims[:, closed].sum() / sims.sum()
    se = np.sqrt(share * (1 - share) / sims.sum())
    assert rule.effectiveness == pytest.approx(share, abs=4 * se)
    assert 0 < rule.effectiveness < 1
    # cost: closure hours times the cost per hour; closed days x 24 h over the record's years
    years = mu.size / 365.25
    assert rule.closure_hours_per_year == pytest.approx(closed.sum() * 24 / years)
    assert rule.annual_cost == pytest.approx(rule.closure_hours_per_year * 500.0)
    # the recorded falls on closed days agree with the model's share within sampling error
    assert rule.observed_share == pytest.approx(rule.effectiveness, abs=0.08)
    # a higher threshold closes less and protects less
    higher = closure_rule(fitted, 120.0)
    assert higher.effectiveness < rule.effectiveness and higher.closure_hours_per_year < rule.closure_hours_per_year


def test_closure_rule_bad_input(fitted):
    with pytest.raises(ValueError, match=r"threshold_mm = -5 must be > 0"):
        closure_rule(fitted, -5)
    with pytest.raises(ValueError, match=r"window_days = 0"):
        closure_rule(fitted, 50, window_days=0)


def test_closure_option_in_the_decision_analysis():
    share, hours, per_hour = 0.3, 40.0, 2000.0
    base = (Option("nothing", "none", 0.0),)
    spec = {"name": "close", "kind": "closure", "capital_cost": 1e4, "share_while_closed": share,
            "closure_hours_per_year": hours, "cost_per_closure_hour": per_hour}
    close = parse_option(spec, 1, "site.toml")
    assert close.annual_maintenance == pytest.approx(hours * per_hour)      # closure cost per year
    assert "30.0% of falls occur while closed" in close.describe()
    s = study(base + (close,))
    a, b = s.evaluate("nothing"), s.evaluate("close")
    # falls still reach the road (clean-up), but road users meet only the falls on open road
    assert b.road_falls_per_year == pytest.approx(a.road_falls_per_year)
    assert b.deaths_per_year == pytest.approx(a.deaths_per_year * (1 - share))
    assert b.individual_risk == pytest.approx(a.individual_risk * (1 - share))
    assert b.vehicle_hits_per_year == pytest.approx(a.vehicle_hits_per_year * (1 - share))
    t = s.ranking().set_index("option")
    assert "close" in t.index
    fn_a, fn_b = s.fn_curve("nothing"), s.fn_curve("close")
    np.testing.assert_allclose(fn_b.iloc[:, 1].to_numpy(), fn_a.iloc[:, 1].to_numpy() * (1 - share), rtol=1e-9)


@pytest.mark.parametrize("spec,match", [
    ({"kind": "closure", "capital_cost": 0, "closure_hours_per_year": 10}, "a closure needs a rule .* share_while_closed is missing"),
    ({"kind": "closure", "capital_cost": 0, "share_while_closed": 1.2, "closure_hours_per_year": 10},
     "share_while_closed = 1.2 is a share"),
    ({"kind": "closure", "capital_cost": 0, "share_while_closed": 0.2, "closure_hours_per_year": 9000},
     "exceeds the hours of a year"),
    ({"kind": "none", "capital_cost": 0, "share_while_closed": 0.2}, "only for kind = 'closure'"),
])
def test_bad_closure_options(spec, match):
    with pytest.raises(MitigationError, match=match):
        parse_option({"name": "c", **spec}, 0, "site.toml")


def test_option_spec_round_trips_into_a_mitigation_file(fitted):
    rule = closure_rule(fitted, 80.0, cost_per_hour=1000.0)
    spec = rule.option_spec("close at 80 mm", capital_cost=5e4)
    options = parse_mitigation({"options": [{"name": "nothing", "kind": "none", "capital_cost": 0}, spec]},
                               "x.toml")[0]
    opt = options[1]
    assert opt.kind == "closure" and opt.name == "close at 80 mm"
    assert opt.share_while_closed == pytest.approx(rule.effectiveness)
    assert opt.annual_maintenance == pytest.approx(rule.annual_cost)


def test_rainstorm_warning_file_and_closure_bad_rows(fitted, tmp_path):
    f = tmp_path / "warnings.csv"
    f.write_text("color,start time,start date,end time,end date,duration\n"
                 "Amber,5:15,12-Apr-01,8:00,12-Apr-01,02 45\n"
                 "Red,21:50,26-Apr-01,24:00:00,26-Apr-01,02 10\n"
                 "Black,22:00,26-Apr-01,4:00,27-Apr-01,06 00\n")
    w = read_rainstorm_warnings(f)
    assert list(w["level"]) == ["Amber", "Red", "Black"]
    assert w.loc[1, "end"] == pd.Timestamp("2001-04-27 00:00")         # "24:00:00" is the end of the day
    rule = warning_closure(fitted, w, levels=("Red", "Black"), cost_per_hour=100.0)
    # merged signals 26 Apr 21:50 - 27 Apr 04:00: 6 h 10 min in 2001 (the warning record's only year)
    assert rule.closure_hours_per_year * (rule.end - rule.start).days / 365.25 == pytest.approx(
        6 + 10 / 60, rel=0.01)
    day = rule.closed_share_of_time
    assert day["2001-04-26"] == pytest.approx((2 + 10 / 60) / 24) and day["2001-04-27"] == pytest.approx(4 / 24)
    f.write_text("color,start time,start date,end time,end date,duration\nRed,25:10,12-Apr-01,8:00,12-Apr-01,1\n")
    with pytest.raises(ValueError, match=r"warnings.csv: row 2, columns 'start date'/'start time': '12-Apr-01 25:10'"):
        read_rainstorm_warnings(f)
    with pytest.raises(ValueError, match=r"level\(s\) \['Purple'\] do not occur"):
        warning_closure(fitted, w, levels=("Purple",))


def test_cli_rates_with_closure_rules_and_a_change_of_climate(tmp_path, capsys):
    from riskrf.cli import main
    rng = np.random.default_rng(9)
    days = pd.date_range("2000-12-01", "2008-12-31", freq="D")
    rain = np.where(rng.random(len(days)) < 0.35, rng.gamma(0.7, 40.0, len(days)), 0.0)
    (tmp_path / "rain.csv").write_text("date,rainfall_mm\n" + "".join(f"{d.date()},{r:.1f}\n"
                                                                      for d, r in zip(days, rain)))
    record = days[days >= "2001-01-01"]
    counts = rng.poisson(0.05 * 4.0 ** (rain[-len(record):] / 100))
    (tmp_path / "falls.csv").write_text("date,volume_m3\n" + "".join(f"{d.date()},2\n"
                                                                     for d in np.repeat(record, counts)))
    out = tmp_path / "out"
    args = ["rates", str(tmp_path / "falls.csv"), "--rainfall", str(tmp_path / "rain.csv"), "--start", "2001-01-01",
            "--end", "2008-12-31", "--windows", "1,3", "--closure-mm", "80", "--cost-per-hour", "500",
            "--heavy-day-mm", "100", "--heavy-day-change", "0.1", "--out", str(out)]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "close while the 1-day rainfall reaches 80 mm" in text and "Stated change of climate (ASSUMPTION)" in text
    assert (out / "closure_rules.csv").exists()
    assert main(args[:-2] + ["--period", "month", "--out", str(tmp_path / "m")]) == 2
    assert "--period month: closure rules (--closure-mm, --warnings) and --heavy-day-change need a daily model" \
        in capsys.readouterr().err


def test_real_observatory_warning_list_and_closure_on_the_hong_kong_record():
    import os
    from pathlib import Path
    from .conftest import INVENTORIES, ROOT
    path = Path(os.environ.get("RISKRF_SHARED_DIR", ROOT / ".." / "shared")) / "inventories-raw" / \
        "hong-kong-cedd" / "hko_rainstorm_warnings_1998_2022.csv"
    if not path.exists():
        pytest.skip(f"{path} not present (shared raw records)")
    w = read_rainstorm_warnings(path)
    assert len(w) == 721 and w["level"].value_counts().to_dict() == {"Amber": 579, "Red": 117, "Black": 25}
    assert (w["end"] > w["start"]).all()                        # "24:00:00" rows read as the end of the day
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = read_inventory(INVENTORIES / "hong-kong" / "hong_kong_rock_cuts_1984_2020.csv")
        model = rate_model(inv, INVENTORIES / "hong-kong" / "hko_daily_rainfall_1983_2020.csv", rain_transform="sqrt")
    red = warning_closure(model, w, levels=("Red", "Black"))
    assert red.start == pd.Timestamp("1998-01-01") and red.end == pd.Timestamp("2020-12-31")
    # measured (README, "Closing the road on rain"): 3.9 % of falls, 13.5 h per year
    assert red.effectiveness == pytest.approx(0.0393, abs=0.001)
    assert red.closure_hours_per_year == pytest.approx(13.5, abs=0.1)
    day = closure_rule(model, 100.0)
    assert day.effectiveness == pytest.approx(0.250, abs=0.002)
    assert day.observed_share == pytest.approx(0.2225, abs=1e-3)
