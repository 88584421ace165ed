"""Tolerability criteria sets against their published lines, the ALARP test, and the statement when nothing is
tolerable.  Sources and pages: riskrf/risk/tolerability.py (module docstring)."""
import numpy as np
import pandas as pd
import pytest
from scipy import stats

from riskrf.hazard.annual_hazard import EnergyHazard
from riskrf.risk.mitigation import Consequences, Criteria, Economics, Exposure, MitigationError, MitigationStudy, Option, \
    Uncertainty
from riskrf.risk.mitigation_inputs import parse_mitigation
from riskrf.risk.tolerability import CRITERIA_SETS, cost_per_statistical_life_saved, user_criteria


def fn(points):
    return pd.DataFrame(points, columns=["N", "F"])


def test_geo_1998_lines():
    # GEO Report 75 (1998): unacceptable above F = 1e-3/N, broadly acceptable below 1e-5/N, N <= 1,000;
    # intense scrutiny 1,000-5,000; any N > 5,000 unacceptable
    geo = CRITERIA_SETS["hong-kong-geo-1998"]
    assert geo.fn_zone(fn([(1, 1.1e-3)])) == "unacceptable"
    assert geo.fn_zone(fn([(10, 0.9e-4)])) == "ALARP"           # line at N = 10: 1e-4
    assert geo.fn_zone(fn([(10, 1.1e-4)])) == "unacceptable"
    assert geo.fn_zone(fn([(100, 0.9e-7)])) == "broadly acceptable"   # lower line at 100: 1e-7
    assert geo.fn_zone(fn([(2000, 1e-8)])) == "intense scrutiny"
    assert geo.fn_zone(fn([(6000, 1e-12)])) == "unacceptable"
    assert geo.individual_limit("existing") == 1e-4 and geo.individual_limit("new") == 1e-5


def test_ags_2007_individual_risk_existing_and_new():
    # AGS (2007c) section 7, Table 1: 1e-4/yr existing slopes, 1e-5/yr new slopes
    ags = CRITERIA_SETS["ags-2007"]
    assert ags.individual_limit("existing") == 1e-4 and ags.individual_limit("new") == 1e-5
    assert ags.tolerable(5e-5, fn([(1, 1e-5)]), "existing") and not ags.tolerable(5e-5, fn([(1, 1e-5)]), "new")


def test_hse_r2p2_point_50_deaths_one_in_5000_years():
    # R2P2 para 136: 50 or more deaths more often than 1 in 5,000 a year is intolerable; para 130: 1e-4/yr public
    hse = CRITERIA_SETS["uk-hse-r2p2"]
    assert hse.fn_unacceptable.frequency(50) == pytest.approx(1 / 5000)
    assert hse.fn_zone(fn([(50, 1.01 / 5000)])) == "unacceptable"
    assert hse.fn_zone(fn([(50, 0.99 / 5000)])) == "ALARP"
    assert hse.individual_limit("existing") == 1e-4 and hse.individual_broadly_acceptable == 1e-6


def test_swiss_individual_limit_and_marginal_cost():
    # Canton of Bern after PLANAT (2013): individual risk <= 1e-5/yr; CHF 5 million per death avoided
    ch = CRITERIA_SETS["swiss-planat"]
    assert ch.individual_limit("existing") == 1e-5
    assert ch.marginal_cost_per_life == 5e6 and ch.marginal_cost_currency == "CHF"
    assert ch.fn_zone(fn([(1, 1.0)])) == "no societal criterion"


def test_user_line_and_bad_values():
    u = user_criteria(3e-5, fn_c=1e-2, fn_k=2.0)
    assert u.fn_unacceptable.frequency(10) == pytest.approx(1e-4)          # 1e-2 / 10^2
    assert u.fn_zone(fn([(10, 2e-4)])) == "unacceptable"
    with pytest.raises(ValueError, match="fn_k"):
        user_criteria(1e-4, fn_c=1e-3, fn_k=5)
    with pytest.raises(ValueError, match="individual_risk_per_year"):
        user_criteria(-1)


def test_criteria_selected_in_the_site_table_and_bad_input_named():
    opts = [{"name": "a", "kind": "none", "capital_cost": 0}, {"name": "b", "kind": "realignment", "capital_cost": 1}]
    crit = parse_mitigation({"options": opts, "criteria": {"set": "uk-hse-r2p2"}}, "site.toml")[-1]
    assert crit.individual_risk_per_year == 1e-4 and crit.fn_diagram == "UK HSE R2P2 (2001)"
    crit = parse_mitigation({"options": opts, "criteria": {"set": "ags-2007", "slope": "new"}}, "site.toml")[-1]
    assert crit.individual_risk_per_year == 1e-5
    crit = parse_mitigation({"options": opts, "criteria": {"set": "user", "individual_risk_per_year": 2e-5,
                                                           "fn_c": 1e-4}}, "site.toml")[-1]
    assert crit.criteria_set.fn_unacceptable.c == 1e-4
    with pytest.raises(MitigationError, match=r"site.toml: criteria.set = 'geo'"):
        parse_mitigation({"options": opts, "criteria": {"set": "geo"}}, "site.toml")
    with pytest.raises(MitigationError, match="site.toml: criteria.set = 'user' needs individual_risk_per_year"):
        parse_mitigation({"options": opts, "criteria": {"set": "user"}}, "site.toml")
    with pytest.raises(MitigationError, match="criteria.slope"):
        parse_mitigation({"options": opts, "criteria": {"slope": "old"}}, "site.toml")


def test_cost_per_statistical_life_saved_by_hand():
    # 1,000,000 spent, 200,000 of other losses saved, 0.01 deaths/yr avoided over 50 years: 800,000 / 0.5
    assert cost_per_statistical_life_saved(1e6, 2e5, 0.01, 50) == pytest.approx(1.6e6)
    assert cost_per_statistical_life_saved(1e6, 0, 0.0, 50) == np.inf


HAZ = EnergyHazard(mass=stats.lognorm(1.0, scale=3000), velocity=np.full(500, 20.0), rate_per_year=400.0,
                   reach_probability=0.5, heights_m=np.full(500, 1.0))


def _study(criteria, options=None):
    options = options or (Option("nothing", "none"), Option("half", "scaling", 2e5, rate_reduction=0.5),
                          Option("ninety", "scaling", 9e5, rate_reduction=0.9))
    return MitigationStudy(hazard=HAZ, options=options, exposure=Exposure(vehicles_per_day=20000, lanes=2),
                           consequences=Consequences(vulnerability_moving_vehicle=0.5), economics=Economics(0.03, 50),
                           uncertainty=Uncertainty(samples=100, vulnerability_factor=(1.0, 1.0)), criteria=criteria)


def test_when_nothing_is_tolerable_the_recommendation_says_so_first_with_what_is_needed():
    s = _study(Criteria(set="swiss-planat"))
    t = s.ranking()
    assert not t["meets_criteria"].any()
    rec = s.recommendation(t)
    assert rec["reason"].startswith("NO OPTION IS TOLERABLE under Switzerland")
    assert rec["basis"].startswith("no option is tolerable")
    safest = t.sort_values("individual_risk").iloc[0]
    factor = safest["individual_risk"] / 1e-5
    assert f"fall by a factor of {factor:.3g}" in rec["reason"]
    assert safest["option"] in rec["reason"]


def test_alarp_column_and_tolerable_recommendation():
    s = _study(Criteria(set="user", individual_risk_per_year=1.0))       # everything tolerable
    t = s.ranking()
    assert t["meets_criteria"].all()
    assert t["alarp"].str.startswith(("ALARP", "not ALARP")).all()
    assert "cost_per_life_saved" in t and np.isinf(t.set_index("option").loc["nothing", "cost_per_life_saved"])
    assert s.recommendation(t)["basis"] == "cheapest tolerable option"


def test_ranking_resolution_says_when_the_top_two_cannot_be_told_apart():
    twins = (Option("nothing", "none"), Option("also nothing", "none"))
    res = _study(Criteria(), options=twins).resolution()
    assert not res["distinguishable"] and "are NOT distinguishable" in res["text"]
    s = _study(Criteria(set="user", individual_risk_per_year=1.0))
    res = s.resolution()
    assert res["distinguishable"] and res["difference"] > 0
    assert res["text"] in s.recommendation()["reason"].replace(res["text"][0].upper(), res["text"][0], 1) or \
        res["text"][1:] in s.recommendation()["reason"]
