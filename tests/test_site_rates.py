"""The site file's [rates] table: the hazard's rate from the rate model and closure options
given as rules, computed from it.  Small simulated records (seeded) keep these fast."""
import json
import warnings

import numpy as np
import pandas as pd
import pytest

from riskrf import read_inventory, rate_model
from riskrf.app.assess.run import run_assessment
from riskrf.risk.closure import closure_rule, warning_closure
from riskrf.risk.mitigation import MitigationError, MitigationStudy
from riskrf.io.rainfall import read_rainfall
from riskrf.app.site import SiteError, load_site
from riskrf.risk.site_rates import evaluate_rates, resolve_closures

WARNINGS = ("color,start time,start date,end time,end date,duration\n"
            "Amber,5:15,12-Apr-01,8:00,12-Apr-01,02 45\n"
            "Red,21:50,26-Apr-01,24:00:00,26-Apr-01,02 10\n"
            "Black,22:00,26-Apr-02,4:00,27-Apr-02,06 00\n")

SITE = """
[site]
name = "rain site"

[inventory]
path = "falls.csv"
start = "2001-01-01"
end = "2006-12-31"
density_kg_m3 = 2650
m_min_kg = 100                 # below every fall: the whole inventory is the power law's tail
rate_scale = 0.5
{inventory_extra}

[hazard]
velocities = "v.csv"
bootstrap = 20

{rates}

[traffic]
vehicles_per_day = 3000

[uncertainty]
samples = 50

[[options]]
name = "do nothing"
kind = "none"
capital_cost = 0

[[options]]
name = "close on rain"
kind = "closure"
capital_cost = 10000
{closure}
"""
RATES = """[rates]
rainfall = "rain.csv"
windows_days = [1, 3]
trend = false
warnings = "warnings.csv"
"""
RULE = "threshold_mm = 60\nwindow_days = 1\ncost_per_closure_hour = 500"


def write_site(d, inventory_extra="", rates=RATES, closure=RULE):
    d.mkdir(exist_ok=True)
    if not (d / "falls.csv").exists():
        rng = np.random.default_rng(7)
        days = pd.date_range("2000-12-01", "2006-12-31", freq="D")
        rain = np.where(rng.random(len(days)) < 0.35, rng.gamma(0.7, 40.0, len(days)), 0.0)
        (d / "rain.csv").write_text("date,rainfall_mm\n" + "".join(f"{x.date()},{r:.1f}\n" for x, r in zip(days, rain)))
        record = days[days >= "2001-01-01"]
        counts = rng.poisson(0.06 * 4.0 ** (rain[-len(record):] / 100))
        dates = np.repeat(record, counts)
        vols = 0.1 * (1 - rng.random(len(dates))) ** (-1 / 0.7)          # Pareto sizes >= 0.1 m3 (265 kg)
        (d / "falls.csv").write_text("date,volume_m3\n" + "".join(f"{x.date()},{v:.4f}\n"
                                                                  for x, v in zip(dates, vols)))
        (d / "v.csv").write_text("velocity_ms\n" + "\n".join(f"{v:.3f}" for v in rng.gamma(8, 2.0, 400)) + "\n")
        (d / "warnings.csv").write_text(WARNINGS)
    path = d / "site.toml"
    path.write_text(SITE.format(inventory_extra=inventory_extra, rates=rates, closure=closure))
    return path


def direct_model(d):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = read_inventory(d / "falls.csv", start="2001-01-01", end="2006-12-31", density_kg_m3=2650)
        return inv, rate_model(inv, read_rainfall(d / "rain.csv"), windows_days=(1, 3), trend=False)


def test_closure_rule_option_share_and_hours_equal_closure_rule_on_the_same_model(tmp_path):
    # test_closure checks that closure_rule's effectiveness is the share of simulated falls in the closure windows;
    # here the site's option must carry exactly closure_rule's numbers on the same model.
    site = load_site(write_site(tmp_path / "s"))
    opt = site.mitigation.options[1]
    assert opt.has_closure_rule and opt.share_while_closed is None and not opt.typed
    with pytest.raises(MitigationError, match="closure rule .* has not been evaluated"):
        MitigationStudy(hazard=None, options=site.mitigation.options, source="x")
    sr = evaluate_rates(site.rates, site.path.parent, site.inventory, site.mitigation.options)
    resolved = resolve_closures(site.mitigation.options, sr)[1]
    _, model = direct_model(tmp_path / "s")
    rule = closure_rule(model, 60.0, window_days=1, cost_per_hour=500.0)
    assert resolved.share_while_closed == pytest.approx(rule.effectiveness, rel=1e-12)
    assert resolved.closure_hours_per_year == pytest.approx(rule.closure_hours_per_year, rel=1e-12)
    assert resolved.annual_maintenance == pytest.approx(rule.annual_cost)
    assert 0 < resolved.share_while_closed < 1 and not resolved.typed
    text = resolved.describe()
    assert "close while the 1-day rainfall reaches 60 mm" in text and "computed from the rate model" in text
    assert "ASSUMED" not in text
    # a warning rule on the same model
    site = load_site(write_site(tmp_path / "s", closure='warning_levels = ["Red", "black"]\ncost_per_closure_hour = 50'))
    sr = evaluate_rates(site.rates, site.path.parent, site.inventory, site.mitigation.options)
    resolved = resolve_closures(site.mitigation.options, sr)[1]
    rule = warning_closure(model, tmp_path / "s" / "warnings.csv", levels=("Red", "Black"), cost_per_hour=50.0)
    assert resolved.share_while_closed == pytest.approx(rule.effectiveness, rel=1e-12)
    assert resolved.closure_hours_per_year == pytest.approx(rule.closure_hours_per_year, rel=1e-12)


def test_typed_closure_shares_are_labelled_assumptions(tmp_path):
    site = load_site(write_site(tmp_path / "s", rates="", closure="share_while_closed = 0.2\n"
                                                                   "closure_hours_per_year = 30"))
    opt = site.mitigation.options[1]
    assert opt.typed and "ASSUMED (typed)" in opt.describe()
    study = MitigationStudy(hazard=None, options=site.mitigation.options, source="x")
    assert study._basis(opt).startswith("ASSUMPTION: typed effectiveness")


def test_hazard_rate_from_the_rate_model_in_a_site(tmp_path):
    d = tmp_path / "s"
    site = load_site(write_site(d, inventory_extra='rate_from = "rate_model"'))
    a = run_assessment(site, log=lambda *_: None)
    inv, model = direct_model(d)
    assert a.frequency.power_law.n_tail == len(inv.masses)        # m_min below every fall
    # rate of falls >= m_min = expected annual rate x (share of sized falls >= m_min, here 1) x rate_scale
    assert a.energy.hazard.rate_per_year == pytest.approx(model.expected_annual_rate() * 0.5, rel=1e-9)
    assert "rate model" in a.rate_source and "times rate_scale 0.5" in a.rate_source
    s = a.summary()
    assert s["hazard"]["rate_source"] == a.rate_source
    assert s["rate_model"]["closures"]["close on rain"]["share_while_closed"] == pytest.approx(
        closure_rule(model, 60.0).effectiveness)
    json.dumps(s, default=str)
    from riskrf.report.html import _assumptions
    table = _assumptions(a, a.energy.hazard, 0.5)
    assert table["input"].str.contains("hazard rate source").any()
    # a stated change of climate: every rainfall 10 % heavier
    site = load_site(write_site(d, inventory_extra='rate_from = "rate_model"\nrain_factor = 1.1'))
    a2 = run_assessment(site, log=lambda *_: None)
    assert a2.energy.hazard.rate_per_year == pytest.approx(model.expected_annual_rate(rain_factor=1.1) * 0.5,
                                                           rel=1e-9)
    assert "ASSUMPTION" in a2.rate_source and "every rainfall x 1.1" in a2.rate_source


@pytest.mark.parametrize("kw,match", [
    ({"rates": RATES.replace('"rain.csv"', '"no_rain.csv"')}, r"rates.rainfall = 'no_rain.csv': file not found"),
    ({"rates": RATES.replace('rainfall = "rain.csv"\n', "")}, r"rates.rainfall is required"),
    ({"closure": RULE.replace("threshold_mm = 60", "threshold_mm = 0")}, r"option 'close on rain': threshold_mm = 0 "
                                                                          r"must be a rainfall > 0 mm"),
    ({"closure": RULE.replace("threshold_mm = 60", "threshold_mm = -5")}, r"threshold_mm = -5 must be a number"),
    ({"closure": RULE.replace("window_days = 1", "window_days = 0")}, r"window_days = 0 must be a whole number of "
                                                                       r"days >= 1"),
    ({"closure": RULE.replace("window_days = 1", "window_days = 1.5")}, r"window_days = 1.5 must be a whole"),
    ({"closure": 'warning_levels = ["Red"]', "rates": RATES.replace('warnings = "warnings.csv"\n', "")},
     r"warning_levels = \['Red'\] needs the rainstorm warning list: give rates.warnings"),
    ({"closure": 'warning_levels = ["Purple"]'}, r"warning_levels \['Purple'\] do not occur in rates.warnings"),
    ({"closure": RULE + "\nshare_while_closed = 0.2"}, r"give a closure rule .* or typed share_while_closed"),
    ({"closure": RULE, "rates": ""}, r"option 'close on rain': a closure rule \(close while the 1-day rainfall "
                                     r"reaches 60 mm.*add a \[rates\] table"),
    ({"inventory_extra": 'rate_from = "rate_model"', "rates": "", "closure": "share_while_closed = 0.2\n"
                                                                            "closure_hours_per_year = 30"},
     r'inventory.rate_from = "rate_model" needs a \[rates\] table'),
    ({"inventory_extra": 'rate_from = "model"'}, r"inventory.rate_from = 'model' must be one of"),
    ({"inventory_extra": "rain_factor = 1.1"}, r"inventory.rain_factor = 1.1 states a change of climate .* needs "
                                               r"inventory.rate_from"),
    ({"inventory_extra": 'rate_from = "rate_model"\nheavy_day_mm = 50'}, r"give both"),
    ({"inventory_extra": 'rate_from = "rate_model"\nrain_factor = -1'}, r"inventory.rain_factor = -1 must be"),
    ({"rates": RATES + "windows = [1, 3]\n"}, r"unknown field rates.'windows'; did you mean 'windows_days'"),
    ({"rates": RATES.replace("[1, 3]", "[3, 1]")}, r"rates.windows_days = \[3, 1\] must be increasing"),
    ({"rates": RATES + 'period = "month"\n'}, r"a closure rule needs a daily rate model; rates.period = 'month'"),
    ({"rates": RATES + 'rain_transform = "cube"\n'}, r"rates.rain_transform = 'cube' must be one of"),
])
def test_rates_and_closure_fields_are_checked_before_any_work(tmp_path, kw, match):
    with pytest.raises((SiteError, MitigationError), match=match) as info:
        load_site(write_site(tmp_path / "s", **kw))
    assert "site.toml" in str(info.value)


def test_rainfall_file_errors_name_the_site_field_and_row(tmp_path):
    path = write_site(tmp_path / "s")
    (tmp_path / "s" / "rain.csv").write_text("date,rainfall_mm\n2001-01-01,1.0\n2001-01-02,wet\n")
    with pytest.raises(SiteError, match=r"site.toml: rates.rainfall = 'rain.csv': .*row 3, column 'rainfall_mm': "
                                        r"'wet'"):
        load_site(path)


def test_options_file_with_rates_resolves_closure_rules_for_riskrf_decide(tmp_path):
    from riskrf.risk.mitigation import load_mitigation
    path = write_site(tmp_path / "s")
    study = load_mitigation(path, None)             # riskrf decide --options: a site file works too
    opt = study.option("close on rain")
    _, model = direct_model(tmp_path / "s")
    assert opt.share_while_closed == pytest.approx(closure_rule(model, 60.0).effectiveness, rel=1e-12)
    assert study._basis(opt).startswith("computed: closure rule")
    path.write_text(path.read_text().replace(RATES, ""))
    with pytest.raises(MitigationError, match=r"site.toml: option 'close on rain': a closure rule .* add a \[rates\]"):
        load_mitigation(path, None)


@pytest.mark.parametrize("edit,match", [
    (lambda d: (d / "rain.csv").write_text("\n".join((d / "rain.csv").read_text().splitlines()[:300]) + "\n"),
     r"rates.rainfall = 'rain.csv': rates.record 'falls.csv' \(2001-01-01 to 2006-12-31, with its 3-day antecedent "
     r"window\): needs rainfall to 2006-12-31, after the rainfall record .* ends \(2001-09-25, row 300\)"),
    (lambda d: (d / "rain.csv").write_text("\n".join(line for i, line in enumerate(
        (d / "rain.csv").read_text().splitlines()) if not 400 <= i < 403) + "\n"),
     r"rates.rainfall = 'rain.csv': .*no rainfall from 2002-01-04 to 2002-01-06 \(3 days missing, between rows 400 "
     r"and 401\)"),
])
def test_rainfall_that_does_not_cover_the_record_fails_at_the_site_check(tmp_path, edit, match):
    path = write_site(tmp_path / "s")
    edit(tmp_path / "s")
    with pytest.raises(SiteError, match=match):
        load_site(path)
