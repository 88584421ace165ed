"""Mitigation options as transformations of the site, one loss engine, uncertainty and recommendation."""
import numpy as np
import pytest
from scipy import stats

import simulation
from riskrf.hazard.annual_hazard import EnergyHazard
from riskrf.hazard.barriers import barrier_history, out_of_service_share
from riskrf.cli import main
from riskrf.risk.economics import pv_factor
from riskrf.risk.measures import SimulationContext
from riskrf.risk.mitigation import (Consequences, Economics, Exposure, MitigationError, MitigationStudy, Option,
                               Uncertainty, parse_mitigation, parse_option)
from riskrf.frequency.power_law import fit_gutenberg_richter
from riskrf.risk.road_risk import (commuter_passage_probability, commuter_strike_probability, fn_zone,
                              occupancy_distribution, spatial_temporal_probability)

from .conftest import INVENTORIES, ROOT
from .test_simulation_run import BARRIER

rng = np.random.default_rng(0)
V = stats.lognorm(0.2, scale=20).rvs(4000, random_state=rng)
H = rng.exponential(2.0, 4000)
HAZ = EnergyHazard(mass=stats.lognorm(1.0, scale=3000), velocity=V, rate_per_year=2.0, reach_probability=0.5,
                   heights_m=H)
OPTIONS = (Option("nothing", "none", 0.0), Option("scale", "scaling", 2e5, 5e3, rate_reduction=0.5),
           Option("fence", "fence", 5e5, 1e4, 25, 2e4, capacity_kj=2000, height_m=4, repair_days=30),
           Option("shed", "shed", 5e6, capacity_kj=1e5, repair_days=180), Option("move", "realignment", 2e7))
CONSTANT_V = Consequences(vulnerability_moving_vehicle=0.5, vulnerability_striking_rock=0.1)


def study(options=OPTIONS, **kw):
    kw.setdefault("consequences", CONSTANT_V)
    kw.setdefault("uncertainty", Uncertainty(samples=200))
    return MitigationStudy(hazard=HAZ, options=options, exposure=Exposure(vehicles_per_day=5000),
                           economics=Economics(0.03, 50), **kw)


def test_expected_annual_loss_by_hand_with_strikes_in_individual_risk():
    s = study()
    r = s.evaluate("nothing")
    ex, co = s.exposure, s.consequences
    road = 2.0 * 0.5
    # per lane (Bunce et al. 1997 for the lane a fall lands in): 2 lanes of 2,500 vehicles/day, 5 m, 80 km/h
    p_st = 2500 * 5.0 / (24 * 1000 * 80)
    assert p_st == pytest.approx(spatial_temporal_probability(5000, ex.vehicle_length_m, ex.speed_kmh) / 2)
    # the first vehicle of the lane arriving within 0.5 h fails to stop with probability 0.002
    strikes = road * ex.share_stopping_on_road * 0.002 * -np.expm1(-2500 * 0.5 / 24)
    k, p = occupancy_distribution(ex.occupants_per_vehicle)
    occ = float(np.dot(k, p))
    deaths = occ * (road * p_st * 0.5 + strikes * 0.1)
    eal = (deaths * co.value_of_statistical_life + (road * p_st + strikes) * co.vehicle_damage
           + road * (co.closure_days_per_fall * co.closure_cost_per_day + co.cleanup_cost_per_fall))
    assert r.road_falls_per_year == pytest.approx(1.0, rel=1e-6)
    assert r.expected_annual_loss == pytest.approx(eal, rel=1e-6)
    # individual risk: direct hit and striking a rock on the road
    ir = road * (commuter_passage_probability(2, 5, 80) * 0.5 + ex.share_stopping_on_road
                 * commuter_strike_probability(2, ex.hours_rock_on_road, ex.p_cannot_stop) * 0.1)
    assert r.individual_risk == pytest.approx(ir, rel=1e-6)
    assert s.evaluate("scale").expected_annual_loss == pytest.approx(eal / 2, rel=1e-6)
    assert s.evaluate("move").expected_annual_loss == 0


def test_fn_curve_counts_hits_and_strikes_and_sums_to_deaths():
    """sum_N F(N) = E[deaths per year]: occupants as a distribution, nothing rounded."""
    s = study()
    fn = s.fn_curve("nothing")
    assert len(fn) == 9 and fn["F"].is_monotonic_decreasing
    assert fn["F"].sum() == pytest.approx(s.evaluate("nothing").deaths_per_year, rel=1e-9)


def test_geo_diagram_zones_with_the_large_n_cut_off():
    import pandas as pd
    assert fn_zone(pd.DataFrame({"N": [1.0, 2000.0], "F": [1e-6, 1e-8]})) == "intense scrutiny"
    assert fn_zone(pd.DataFrame({"N": [1.0, 6000.0], "F": [1e-6, 1e-12]})) == "unacceptable"
    assert fn_zone(pd.DataFrame({"N": [1.0, 100.0], "F": [5e-4, 2e-6]})) == "ALARP"


def test_fence_residual_from_paired_heights_and_energies_with_damage_states():
    s = study()
    r = s.evaluate("fence")
    edges, mid, _ = s._grid
    pmf = s._mass_pmf()[0]
    e = 0.5 * mid[None, :] * V[:, None] ** 2 / 1000
    # over-topping as in the simulator's barrier (simulation.kernel.barrier_outcome): the block's underside, centre
    # height minus the radius of a sphere of that mass (2,650 kg/m3 without a scenario), clears the 4 m fence
    radius = (3 * mid / (4 * np.pi * 2650.0)) ** (1 / 3)
    over = H[:, None] - radius[None, :] > 4
    assert (over != (H > 4)[:, None]).any()         # the block size matters on this grid
    passing = np.mean(over | (e > 2000), axis=0)
    destroy = np.mean(~over & (e > 2000), axis=0)
    lam_d = 1.0 * float(pmf @ destroy)
    down = out_of_service_share(lam_d, 30)
    expected = 1.0 * float(pmf @ (down + (1 - down) * passing))
    assert r.road_falls_per_year == pytest.approx(expected, rel=1e-9)
    assert r.replacements_per_year == pytest.approx(lam_d * (1 - down), rel=1e-9)
    assert r.repairs_per_year > 0
    # the engine's PV of maintenance: pv factor x (maintenance + repairs x repair cost + replacements x replacement
    # cost; the replacement cost defaults to the capital cost)
    row = s.ranking().set_index("option").loc["fence"]
    opt = s.option("fence")
    assert opt.replacement_cost is None
    assert row["pv_maintenance"] == pytest.approx(pv_factor(0.03, 50) * (
        opt.annual_maintenance + r.repairs_per_year * opt.repair_cost_per_impact
        + r.replacements_per_year * opt.capital_cost), rel=1e-9)


def test_fence_hit_above_capacity_costs_replacement_and_lets_later_falls_through_until_repaired():
    days = 1 / 365.25
    h = barrier_history([0.0, 5 * days, 20 * days, 31 * days, 40 * days], [3000.0, 100.0, 1500.0, 900.0, 100.0],
                        [1.0, 1.0, 1.0, 1.0, 1.0], mel_kj=2000, height_m=5, repair_days=30, repair_cost=40_000,
                        replacement_cost=250_000)
    assert h["outcome"].tolist() == ["destroyed", "passed, out of service", "passed, out of service", "held, repair",
                                     "held"]
    assert h["cost"].tolist() == [250_000, 0, 0, 40_000, 0]
    assert h["passes"].tolist() == [True, True, True, False, False]


def test_engine_damage_model_matches_simulated_histories():
    """The engine's expected rates (alternating renewal) against a Monte Carlo of barrier_history."""
    r = np.random.default_rng(5)
    lam, years, mel, repair_days = 4.0, 4000.0, 2000.0, 60.0
    n = r.poisson(lam * years)
    t = np.sort(r.uniform(0, years, n))
    e = r.choice([100.0, 1000.0, 5000.0], n, p=[0.5, 0.3, 0.2])
    hist = barrier_history(t, e, np.zeros(n), mel_kj=mel, height_m=5, repair_days=repair_days, repair_cost=1.0,
                           replacement_cost=10.0)
    lam_d = lam * 0.2
    down = out_of_service_share(lam_d, repair_days)
    assert (hist["outcome"] == "destroyed").sum() / years == pytest.approx(lam_d * (1 - down), rel=0.05)
    assert hist["passes"].mean() == pytest.approx(down + (1 - down) * 0.2, rel=0.05)
    assert (hist["outcome"] == "held, repair").sum() / years == pytest.approx(lam * 0.3 * (1 - down), rel=0.05)


def test_ranking_uncertainty_columns_probabilities_and_tree_agree():
    s = study()
    t = s.ranking()
    for col in ("capital", "pv_renewals", "pv_maintenance", "pv_expected_loss", "expected_total_cost", "cost_p05",
                "cost_p95", "probability_best", "expected_regret", "road_falls_per_year", "individual_risk",
                "deaths_per_year", "fn_zone", "meets_criteria", "rank"):
        assert col in t.columns
    np.testing.assert_allclose(t["cost_at_central_values"],
                               t["capital"] + t["pv_renewals"] + t["pv_maintenance"] + t["pv_expected_loss"])
    assert t["expected_total_cost"].is_monotonic_increasing
    assert t["probability_best"].sum() == pytest.approx(1.0, abs=1e-12)
    assert np.all(t["cost_p05"] <= t["expected_total_cost"] * (1 + 1e-12))
    assert np.all(t["expected_total_cost"] <= t["cost_p95"] * (1 + 1e-12))
    nothing = t.set_index("option").loc["nothing"]
    eal = s.evaluate("nothing").expected_annual_loss
    assert nothing["pv_expected_loss"] == pytest.approx(pv_factor(0.03, 50) * eal)
    # the capital column holds the first build only; renewals are a separate column
    fence = t.set_index("option").loc["fence"]
    assert fence["capital"] == 5e5 and fence["pv_renewals"] == pytest.approx(5e5 * 1.03 ** -25)
    ov = s.to_tree().rollback().option_values
    for name, total in zip(t["option"], t["cost_at_central_values"]):
        assert ov[name] == pytest.approx(total, rel=1e-9)
    # same seed, same numbers
    assert study().ranking()["expected_total_cost"].tolist() == t["expected_total_cost"].tolist()


def test_typed_effectiveness_is_labelled_an_assumption():
    t = study().ranking().set_index("option")
    assert "ASSUMPTION" in t.loc["scale", "effect_basis"]
    assert "ASSUMPTION" not in t.loc["fence", "effect_basis"]


def test_break_even_makes_the_two_cheapest_tie_and_tornado_flags_order_changes():
    s = study()
    r = s._central_result
    order = np.argsort(r["total"][0])
    a, b = r["names"][order[0]], r["names"][order[1]]
    be = s.break_even(f"capital_cost:{a}")
    assert be is not None
    tied = s._central({f"capital_cost:{a}": [be[1]]})["total"][0]
    assert tied[r["names"].index(a)] == pytest.approx(tied[r["names"].index(b)], rel=1e-8)
    tornado = s.tornado()
    assert {"changes_best", "best_at_low", "best_at_high"} <= set(tornado.columns)
    assert set(tornado["parameter"]) >= {"rate_factor", "value_of_statistical_life", "rate_reduction:scale"}


def test_recommendation_cheapest_tolerable_or_most_risk_reduction_per_cost():
    s = study()
    rec = s.recommendation()
    t = s.ranking()
    ok = t[t["meets_criteria"]]
    assert rec["option"] == (ok["option"].iloc[0] if len(ok) else rec["option"]) and rec["reason"]


# ---- derived effects: simulation --------------------------------------------------------------------
TOE = {"name": "toe", "profile": {"x": [0.0, 5.0, 30.0, 80.0], "z": [40.0, 40.0, 0.0, 0.0],
                                  "materials": ["rock", "rock", "soil"]},
       "materials": {"rock": {"normal_restitution": {"law": "constant", "mean": 0.3, "std": 0.05},
                              "tangential": {"law": "friction", "friction_angle_deg": 30}, "roughness_m": 0.1,
                              "ground_friction_angle_deg": 20},
                     "soil": {"normal_restitution": {"law": "constant", "mean": 0.2, "std": 0.05},
                              "tangential": {"law": "friction", "friction_angle_deg": 30}, "roughness_m": 0.05,
                              "ground_motion": "roll", "ground_friction_angle_deg": 8},
                     "gravel": {"normal_restitution": {"law": "constant", "mean": 0.15, "std": 0.03},
                                "tangential": {"law": "friction", "friction_angle_deg": 40}, "roughness_m": 0.1,
                                "ground_motion": "slide", "ground_friction_angle_deg": 35}},
       "seeder": {"type": "line", "x": [6.0, 9.0], "height_m": 0.5, "mass_kg": 500,
                  "vx_ms": {"dist": "uniform", "low": 0.5, "high": 1.5}},
       "collectors": [{"name": "barrier", "x": 31.0}, {"name": "road", "x": 60.0}]}


def _toe_study(options):
    sc = simulation.scenario_from_dict(TOE)
    return MitigationStudy(hazard=HAZ, options=options, consequences=CONSTANT_V, uncertainty=Uncertainty(samples=50),
                           context=SimulationContext(sc, n_blocks=2000, seed=3))


def test_wider_ditch_on_the_same_profile_retains_more_derived_by_simulation():
    opts = parse_mitigation({"options": [
        {"name": "nothing", "kind": "none", "capital_cost": 0},
        {"name": "narrow", "kind": "ditch", "capital_cost": 1e5, "x_m": 31.0, "width_m": 8.0, "depth_m": 1.0,
         "material": "gravel"},
        {"name": "wide", "kind": "ditch", "capital_cost": 2e5, "x_m": 31.0, "width_m": 24.0, "depth_m": 1.0,
         "material": "gravel"}]}, "toe.toml")[0]       # no typed retention: accepted
    s = _toe_study(opts)
    narrow, wide = s.evaluate("narrow").retention, s.evaluate("wide").retention
    assert 0 < narrow < wide <= 1 and wide - narrow > 0.05
    assert s.ranking().set_index("option").loc["wide", "effect_basis"].startswith("derived")


def test_scaling_removes_the_release_share_of_its_zone_and_size_range():
    # a perfect, lasting scaling (typed: effectiveness 1, no decay) removes the release of its zone
    opts = (Option("nothing", "none"), Option("scale", "scaling", 1e5, zone_x_m=(6.0, 7.5), max_mass_kg=1e12,
                                              effectiveness=1.0, effectiveness_half_life_years=1e15))
    s = _toe_study(opts)
    assert s.evaluate("scale").effectiveness == pytest.approx(0.5, rel=1e-9)     # half of the 6-9 m release line


def test_scaling_effectiveness_is_below_100_percent_decays_and_is_labelled_assumed():
    opts = (Option("nothing", "none"), Option("scale", "scaling", 1e5, zone_x_m=(6.0, 7.5), max_mass_kg=1e12)
            , Option("scale15", "scaling", 1e5, zone_x_m=(6.0, 7.5), max_mass_kg=1e12, life_years=15,
                     effectiveness_half_life_years=5))
    s = _toe_study(opts)
    # default: 80 % when new, halving every 10 years (no life_years: a 10-year cycle): mean e0 h (1 - 2^-(L/h)) /
    # (L ln 2) = 0.8 x 10 x 0.5 / (10 ln 2) = 0.57708; times the zone's half of the release line
    assert s.evaluate("scale").effectiveness == pytest.approx(0.5 * 0.8 * 0.5 / np.log(2), rel=1e-9)
    # 15-year cycle, half-life 5 years: 0.8 x 5 x (1 - 1/8) / (15 ln 2) = 0.33665
    assert s.evaluate("scale15").effectiveness == pytest.approx(0.5 * 0.8 * 5 * 0.875 / (15 * np.log(2)), rel=1e-9)
    ranges = s.parameter_ranges()
    lo, hi, how = ranges["scaling_effectiveness:scale"]
    assert (lo, hi) == pytest.approx((0.6 * 0.5 / np.log(2), 0.95 * 0.5 / np.log(2))) and "ASSUMED" in how
    basis = s.ranking().set_index("option").loc["scale", "effect_basis"]
    assert "ASSUMED effectiveness" in basis and "80% when new" in basis


def test_combined_option_does_not_double_count():
    opts = (Option("nothing", "none"), Option("scale", "scaling", 1e5, rate_reduction=0.5),
            Option("fence", "fence", 5e5, capacity_kj=2000, height_m=4, repair_days=30),
            Option("both", "combined", options=("scale", "fence")))
    s = study(opts)
    e = {o: s.evaluate(o).effectiveness for o in ("scale", "fence", "both")}
    assert 1 - e["both"] < 1 - e["fence"]
    assert e["both"] < e["scale"] + e["fence"]
    t = s.ranking().set_index("option")
    assert t.loc["both", "capital"] == pytest.approx(t.loc["scale", "capital"] + t.loc["fence", "capital"])


# ---- bad input ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("data,match", [
    ({"options": [{"name": "a", "kind": "none", "capital_cost": 0}]}, "needs at least two options"),
    ({"options": [{"name": "a", "kind": "none"}, {"name": "b", "kind": "none", "capital_cost": 0}]},
     "option 'a': missing field 'capital_cost'"),
    ({"options": [{"name": "a", "kind": "wall", "capital_cost": 0}, {"name": "b", "kind": "none", "capital_cost": 0}]},
     "option 'a': kind = 'wall' is not one of"),
    ({"options": [{"name": "f", "kind": "fence", "capital_cost": 1, "capacity_kj": 100},
                  {"name": "b", "kind": "none", "capital_cost": 0}]}, "option 'f': a fence needs height_m"),
    ({"options": [{"name": "s", "kind": "scaling", "capital_cost": 1, "rate_reduction": 1.5},
                  {"name": "b", "kind": "none", "capital_cost": 0}]}, "rate_reduction = 1.5 is a share"),
    ({"traffic": {"vehicles_per_dya": 10}, "options": []}, "unknown field traffic.vehicles_per_dya; did you mean "
                                                            "'vehicles_per_day'"),
    ({"economic": {}}, r"unknown table \[economic\]; did you mean \[economics\]"),
    ({"options": [{"name": "a", "kind": "none", "capital_cost": -5}, {"name": "b", "kind": "none", "capital_cost": 0}]},
     "capital_cost = -5 must be a number >= 0"),
    ({"options": [{"name": "d", "kind": "ditch", "capital_cost": 1, "capital_cost_range": [9, 2], "x_m": 1,
                   "width_m": 1, "depth_m": 1}, {"name": "b", "kind": "none", "capital_cost": 0}]},
     r"option 'd': capital_cost_range = \[9, 2\]: low 9 is greater than high 2"),
    ({"options": [{"name": "b", "kind": "none", "capital_cost": 0},
                  {"name": "c", "kind": "combined", "options": ["b2", "x"]}]},
     "option 'c': options names unknown option 'b2'"),
    ({"options": [{"name": "d1", "kind": "ditch", "capital_cost": 1, "x_m": 10, "width_m": 5, "depth_m": 1},
                  {"name": "d2", "kind": "ditch", "capital_cost": 1, "x_m": 12, "width_m": 5, "depth_m": 1},
                  {"name": "c", "kind": "combined", "options": ["d1", "d2"]}]},
     r"option 'c': ditches 'd1' \(10-15 m\) and 'd2' \(12-17 m\) overlap"),
    ({"options": [{"name": "d", "kind": "ditch", "capital_cost": 1, "x_m": 10},
                  {"name": "b", "kind": "none", "capital_cost": 0}]}, "option 'd': a ditch needs width_m"),
    ({"uncertainty": {"rate_factor": [2, 1]}, "options": []}, r"uncertainty.rate_factor = \[2, 1\]: low 2 is greater"),
])
def test_bad_mitigation_files(data, match):
    with pytest.raises(MitigationError, match=match):
        parse_mitigation(data, "site.toml")


def test_option_geometry_outside_the_profile_names_option_and_field():
    opts = (Option("nothing", "none"), Option("ditch", "ditch", 1.0, x_m=75.0, width_m=10.0, depth_m=1.0))
    with pytest.raises(MitigationError, match="option 'ditch'.*x_m = 75 m with width_m = 10 m spans 75-85 m, "
                                              "outside the profile"):
        _toe_study(opts).ranking()
    opts = (Option("nothing", "none"), Option("move", "realignment", 1.0, road_x_m=500.0))
    with pytest.raises(MitigationError, match="option 'move': road_x_m = 500 m is outside the profile"):
        _toe_study(opts).ranking()
    with pytest.raises(MitigationError, match="zone_x_m"):
        _toe_study((Option("nothing", "none"), Option("s", "scaling", 1.0, zone_x_m=(50.0, 60.0)))).ranking()


def test_site_file_geometry_errors_before_computing(tmp_path):
    from riskrf.app.site import SiteError, load_site
    text = (ROOT / "riskrf" / "data" / "demo_site.toml").read_text()
    bad = text.replace("x_m = 85.0", "x_m = 128.0")
    site = tmp_path / "site.toml"
    site.write_text(bad.replace('"lauterbrunnen', f'"{ROOT}/riskrf/data/lauterbrunnen').replace(
        '"synthetic_corridor', f'"{ROOT}/riskrf/data/synthetic_corridor').replace(
        '"hong_kong_rock_cuts', f'"{ROOT}/riskrf/data/hong_kong_rock_cuts').replace(
        '"hko_daily_rainfall', f'"{ROOT}/riskrf/data/hko_daily_rainfall').replace(
        '"../../simulation', f'"{ROOT}/simulation'))
    with pytest.raises(SiteError, match="option 'catch ditch': x_m = 128 m with width_m = 8 m spans 128-136 m, "
                                        "outside the profile"):
        load_site(site)


# ---- command line ------------------------------------------------------------------------------------
def test_decide_command_on_bundled_site(tmp_path, capsys):
    out = tmp_path / "d"
    rc = main(["decide", "--options", str(ROOT / "riskrf" / "data" / "demo_site.toml"), "--inventory",
               str(INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2018.csv"), "--scenario", str(BARRIER),
               "-n", "5000", "--option-blocks", "3000", "--m-max", "2e6", "--rate-scale", "0.05", "--out", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "Mitigation ranking by expected total cost (CHF" in text and "RECOMMENDATION:" in text
    assert "Break-even" in text
    for name in ("ranking.csv", "tornado.csv", "break_even.csv", "decision.json", "tree.png", "tornado.png",
                 "fn_curve.png"):
        assert (out / name).exists()
    import json
    d = json.loads((out / "decision.json").read_text())
    assert sum(o["probability_best"] for o in d["options"]) == pytest.approx(1.0)
    ditch = next(o for o in d["options"] if o["kind"] == "ditch")
    assert 0 <= ditch["retention"] <= 1 and d["recommendation"]["option"] in {o["name"] for o in d["options"]}


def test_decide_command_on_a_tree_file(tmp_path, capsys):
    from .conftest import DATA
    rc = main(["decide", str(DATA / "clemen2001" / "texaco_pennzoil.json"), "--out", str(tmp_path / "t")])
    assert rc == 0


def test_small_falls_below_m_min_reach_the_road():
    inv = fit_gutenberg_richter(np.geomspace(1e3, 1e5, 200), 10.0, m_min=1e3)
    hz = EnergyHazard(mass=inv, velocity=V, rate_per_year=inv.rate_min, heights_m=H)
    opts = (Option("nothing", "none"), Option("move", "realignment", 1.0))
    without = MitigationStudy(hazard=hz, options=opts, uncertainty=Uncertainty(samples=10)).evaluate("nothing")
    small = MitigationStudy(hazard=hz, options=opts, uncertainty=Uncertainty(samples=10),
                            small_fall_masses_kg=np.full(50, 200.0), small_falls_per_year=5.0).evaluate("nothing")
    assert small.road_falls_per_year == pytest.approx(without.road_falls_per_year + 5.0, rel=1e-9)
    assert small.deaths_per_year > without.deaths_per_year


def test_parse_option_ranges_and_overrides():
    o = parse_option({"name": "d", "kind": "ditch", "capital_cost": 5, "retention": 0.4, "retention_range": [0.2, 0.6]},
                     0, "f.toml")
    assert o.typed and o.retention_range == (0.2, 0.6)
    with pytest.raises(MitigationError, match="option 'd': retention = 0.9 lies outside retention_range"):
        parse_option({"name": "d", "kind": "ditch", "capital_cost": 5, "retention": 0.9,
                      "retention_range": [0.2, 0.6]}, 0, "f.toml")


def test_material_parameters_are_resimulated_jointly_and_at_the_ends_of_their_ranges():
    # (the ditch's cost makes "nothing" and the fence the two cheapest, tied inside the friction range: below)
    opts = (Option("nothing", "none"), Option("ditch", "ditch", 1.5e6, x_m=31.0, width_m=8.0, depth_m=1.0,
                                               material="gravel"),
            Option("fence", "fence", 5e5, capacity_kj=2000, height_m=3, repair_days=30))
    sc = simulation.scenario_from_dict(TOE)
    # one lane and 15.3 % of first arrivals unable to stop: the losses this tie was built on
    s = MitigationStudy(hazard=HAZ, options=opts, consequences=CONSTANT_V,
                        exposure=Exposure(lanes=1, p_cannot_stop=0.153),
                        uncertainty=Uncertainty(samples=100, material_draws=3,
                                                materials={"gravel.ground_friction_angle_deg": (20.0, 45.0)}),
                        context=SimulationContext(sc, n_blocks=1000, seed=3))
    models = s.material_models()
    assert len(models) == 1 + 3 + 2
    assert models["label"].tolist()[-2:] == ["gravel.ground_friction_angle_deg low",
                                             "gravel.ground_friction_angle_deg high"]
    s.central_parameters()
    per_model = s._derived["ditch"][2]
    assert per_model.shape == (6,) and np.ptp(per_model) > 0        # the derived retention changes with the floor
    P = s.sample_parameters()
    assert set(np.unique(P["material_draw"])) <= {1.0, 2.0, 3.0}
    tornado = s.tornado()
    assert "material:gravel.ground_friction_angle_deg" in set(tornado["parameter"])
    assert s.ranking()["probability_best"].sum() == pytest.approx(1.0)
    # the break-even table has a row per material parameter, from the low / base / high models
    be = s.break_even_table().set_index("parameter")
    row = be.loc["material:gravel.ground_friction_angle_deg"]
    assert (row["range_low"], row["range_high"]) == (20.0, 45.0)
    r = s._central_result
    order = np.argsort(r["total"][0], kind="stable")
    ia, ib = order[0], order[1]
    labels = s.material_models()["label"].tolist()
    t = s._central({"material_draw": [labels.index("gravel.ground_friction_angle_deg low"), 0,
                                      labels.index("gravel.ground_friction_angle_deg high")]})["total"]
    x = np.array([20.0, row["current"], 45.0])
    d = t[:, ia] - t[:, ib]
    assert d[1] * d[2] < 0                                  # the order flips between the base and the high end
    assert row["within_stated_range"] and row["current"] < row["break_even"] < 45.0
    assert np.interp(row["break_even"], x, d) == pytest.approx(0.0, abs=1e-9 * np.abs(d).max())
    assert "ties with" in row["note"] and row["factor"] == pytest.approx(row["break_even"] / row["current"])
    # no tie when the two cheapest keep their order over the whole range: the row says so
    from dataclasses import replace
    s2 = MitigationStudy(hazard=HAZ, options=(opts[0], replace(opts[1], capital_cost=1e5)), consequences=CONSTANT_V,
                         uncertainty=s.uncertainty,
                         context=s.context)
    s2.__dict__["_slopes"] = s._slopes                     # the same slope models, not simulated again
    row2 = s2.break_even_table().set_index("parameter").loc["material:gravel.ground_friction_angle_deg"]
    assert np.isnan(row2["break_even"]) and not row2["within_stated_range"]
    assert "no tie within [20, 45]" in row2["note"]


def test_bad_material_uncertainty_names_the_field():
    with pytest.raises(MitigationError, match=r"uncertainty.materials: 'talus.friction' must be"):
        parse_mitigation({"uncertainty": {"materials": {"talus.friction": [1, 2]}}, "options": []}, "s.toml")
    with pytest.raises(MitigationError, match=r"uncertainty.materials.talus.roughness_m = \[0.3, 0.1\]: low 0.3 is "
                                              "greater than high 0.1"):
        parse_mitigation({"uncertainty": {"materials": {"talus.roughness_m": [0.3, 0.1]}}, "options": []}, "s.toml")


def test_the_pfeiffer_bowen_scale_is_a_material_parameter_of_the_uncertainty():
    # the site file's [uncertainty.materials] may range a rock's vt0 (docs/user-guide/contact-model.md): it is read,
    # set and acts on the trajectories; a Stronge-law material and vt0 <= 0 are refused by name
    from riskrf.risk.measures import MeasureError, material_value, scenario_with_materials
    uncertainty = parse_mitigation({"uncertainty": {"materials": {"rock.tangential.normal_scale_ms": [30.0, 76.2]}}},
                                   "s.toml", require_options=False)[5]
    assert list(uncertainty.materials) == ["rock.tangential.normal_scale_ms"]
    odot = simulation.load_scenario(ROOT / "simulation" / "scenarios" / "odot_catchment_cut.toml")
    assert material_value(odot, "rock.tangential.normal_scale_ms") == pytest.approx(76.2)
    hard = scenario_with_materials(odot, {"rock.tangential.normal_scale_ms": 5.0,
                                          "catchment.tangential.normal_scale_ms": 5.0})
    assert material_value(hard, "catchment.tangential.normal_scale_ms") == 5.0
    x0 = simulation.run(odot, n=300, seed=4).per_block["x"]
    x1 = simulation.run(hard, n=300, seed=4).per_block["x"]
    assert np.median(x1) < np.median(x0)                 # landings keep less tangential speed: shorter rollout
    with pytest.raises(MeasureError, match=r"'bedrock.tangential.normal_scale_ms': material 'bedrock' uses "
                                           r"Stronge's 'friction' law"):
        scenario_with_materials(simulation.load_scenario(BARRIER), {"bedrock.tangential.normal_scale_ms": 30.0})
    with pytest.raises(MeasureError, match=r"'rock.tangential.normal_scale_ms' = 0.0: the Pfeiffer & Bowen scale "
                                           r"must be > 0 m/s"):
        scenario_with_materials(odot, {"rock.tangential.normal_scale_ms": 0.0})


def test_fence_at_another_position_and_realignment_are_derived_from_simulation():
    opts = (Option("nothing", "none"), Option("fence", "fence", 5e5, capacity_kj=2000, height_m=3.0, x_m=45.0,
                                               repair_days=30),
            Option("move", "realignment", 1e6, road_x_m=75.0))
    s = _toe_study(opts)
    res = s.context.run(s.context.scenario)
    from riskrf.risk.measures import runout_beyond
    expected = runout_beyond(res, 75.0).sum() / runout_beyond(res, 60.0).sum()
    assert s.evaluate("move").effectiveness == pytest.approx(1 - expected, abs=1e-12)
    assert 0 < s.evaluate("fence").retention <= 1


def test_material_draws_from_a_calibration_bootstrap(tmp_path):
    import pandas as pd
    boot = pd.DataFrame({"materials.gravel.ground_friction_angle_deg": [22.0, 25.0, 30.0, 41.0, 44.0],
                         "materials.gravel.roughness_m": [0.05, 0.08, 0.1, 0.12, 0.2]})
    (tmp_path / "bootstrap.csv").write_text(boot.to_csv(index=False))
    site = tmp_path / "options.toml"
    site.write_text("")
    data = {"uncertainty": {"calibration_bootstrap": "bootstrap.csv", "material_draws": 4, "samples": 50},
            "options": [{"name": "nothing", "kind": "none", "capital_cost": 0},
                        {"name": "ditch", "kind": "ditch", "capital_cost": 1e5, "x_m": 31.0, "width_m": 8.0,
                         "depth_m": 1.0, "material": "gravel"}]}
    opts, ex, co, ec, used, unc, crit = parse_mitigation(data, str(site))
    sc = simulation.scenario_from_dict(TOE)
    s = MitigationStudy(hazard=HAZ, options=opts, consequences=CONSTANT_V, uncertainty=unc,
                        context=SimulationContext(sc, n_blocks=500, seed=3))
    m = s.material_models()
    draws = m[m["label"] == "draw"][["gravel.ground_friction_angle_deg", "gravel.roughness_m"]]
    rows = set(map(tuple, boot.to_numpy()))
    assert len(draws) == 4 and all(tuple(r) in rows for r in draws.to_numpy())   # joint rows, correlation kept
    ranges = s.parameter_ranges()
    assert ranges["material:gravel.roughness_m"][0] == pytest.approx(np.quantile(boot.iloc[:, 1], 0.05))
    # the posterior of a pooled calibration (its first line a comment with the prior's bounds) is read the same
    (tmp_path / "bootstrap.csv").write_text('# simulation pooled posterior; bounds = {"x": [0, 1]}\n'
                                            + boot.to_csv(index=False))
    assert parse_mitigation(data, str(site))[5].calibration.equals(boot)
    bad = boot.rename(columns={"materials.gravel.roughness_m": "seeder.height_m"})
    (tmp_path / "bootstrap.csv").write_text(bad.to_csv(index=False))
    with pytest.raises(MitigationError, match="column 'seeder.height_m' is not a material parameter"):
        parse_mitigation(data, str(site))


def test_road_user_delay_from_closures_enters_the_expected_loss():
    base = study().evaluate("nothing").expected_annual_loss
    co = Consequences(vulnerability_moving_vehicle=0.5, vulnerability_striking_rock=0.1, detour_hours=0.25,
                      value_of_time_per_hour=20.0)
    delayed = study(consequences=co).evaluate("nothing").expected_annual_loss
    # 1 fall a year on the road x 0.5 closed days x 5,000 vehicles/day x 0.25 h x 20 per hour
    assert delayed - base == pytest.approx(1.0 * 0.5 * 5000 * 0.25 * 20.0, rel=1e-6)


def test_probability_meeting_the_criteria_uses_the_same_fn_as_the_curve():
    s = study()
    r = s._central(per_bin=True)
    ok = s._fn_tolerable(r)[0]
    for k, name in enumerate(r["names"]):
        assert bool(ok[k]) == (fn_zone(s.fn_curve(name)) != "unacceptable")
    t = s.ranking()
    assert t["probability_meets_criteria"].between(0, 1).all()


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@settings(max_examples=15)
@given(cap=st.floats(100.0, 50_000.0), height=st.floats(0.5, 10.0), rr=st.floats(0.0, 1.0),
       repair=st.floats(1.0, 365.0))
def test_property_structures_only_remove_falls_and_combinations_compose(cap, height, rr, repair):
    opts = (Option("nothing", "none"), Option("scale", "scaling", 1.0, rate_reduction=rr),
            Option("fence", "fence", 1.0, capacity_kj=cap, height_m=height, repair_days=repair),
            Option("both", "combined", options=("scale", "fence")))
    s = study(opts)
    none, scale, fence, both = (s.evaluate(n).road_falls_per_year for n in ("nothing", "scale", "fence", "both"))
    assert fence <= none * (1 + 1e-12) and both <= min(scale, fence) * (1 + 1e-12) + 1e-15
    # scaling acts on the release only, so the fence in series sees (1 - rr) of the falls
    assert scale == pytest.approx(none * (1 - rr), rel=1e-9, abs=1e-15)
    assert s.uncertain["probability_best"].sum() == pytest.approx(1.0)


def test_damage_state_shares_with_no_arrivals_are_zero_not_nan():
    """A slope model (material draw) in which no simulated block reaches the road gave a nan expected cost for the
    rock shed (np.mean over no falls); the shares of no falls multiply a zero arrival rate and are 0."""
    from riskrf.hazard.barriers import damage_state_shares
    passing, held, destroyed = damage_state_shares(np.zeros((0, 4)), np.zeros(0, dtype=bool), 1000.0)
    assert passing.shape == (4,) and not np.isnan(passing).any() and not held.any() and not destroyed.any()
    p, h, d = damage_state_shares(np.array([[500.0], [2000.0]]), np.array([False, False]), 1000.0)
    assert (p[0], h[0], d[0]) == (0.5, 0.5, 0.5)          # SEL = 333 kJ: 500 held for repair, 2000 through


def test_mass_coupled_hazard_gives_each_mass_its_own_reach_and_speed_at_the_fence():
    """Two mass classes: light blocks (1-10 t) reach the line half the time at 10 m/s, heavy ones (10-100 t)
    always at 30 m/s.  A 4,000 kJ fence holds every light block (E <= 500 kJ, below SEL) and no heavy one
    (E >= 4,500 kJ): the barrier is destroyed by exactly the heavy arrivals, rate x P(heavy) x 1.  Pooled
    speeds (one law for all masses) would let light blocks break it and heavy ones be held."""
    from riskrf.hazard.mass_coupling import MassCoupledSamples
    from riskrf.hazard.mass_models import mass_model
    n = 2000
    m = np.geomspace(1e3, 1e5, n + 2)[1:-1]
    heavy = m > 1e4
    speed = np.where(heavy, 30.0, np.where(np.arange(n) % 2 == 0, 10.0, np.nan))
    height = np.where(np.isfinite(speed), 1.0, np.nan)
    samples = MassCoupledSamples(m, speed, height, np.array([1e3, 1e4, 1e5]), "barrier")
    mass = stats.loguniform(1e3, 1e5)
    mm = mass_model(mass)
    rep = samples.with_representative(mm)
    hz = EnergyHazard(mass=mass, velocity=rep, rate_per_year=2.0, reach_probability=samples.reach_probability(mm),
                      heights_m=rep.heights_m)
    assert hz.mass_coupled and hz.reach_probability == pytest.approx(0.75, abs=1e-3)
    fence = Option("fence", "fence", 5e5, capacity_kj=4000, height_m=5, repair_days=0)
    s = MitigationStudy(hazard=hz, options=(Option("nothing", "none"), fence), consequences=CONSTANT_V,
                        uncertainty=Uncertainty(samples=20))
    assert s.evaluate("nothing").road_falls_per_year == pytest.approx(2.0 * 0.75, rel=0.01)
    r = s.evaluate("fence")
    assert r.replacements_per_year == pytest.approx(2.0 * 0.5, rel=0.02)
    assert r.repairs_per_year == 0.0


def test_material_variant_with_the_central_materials_reproduces_a_mass_coupled_reference():
    """A material variant is scaled relative to the unmodified slope simulated like it (same blocks, seed and
    seeder masses), not to the mass-coupled hazard's own samples (another mass mixture): the tornado's 'low'
    variant below has exactly the central materials, so its reach, fence impacts and overtopping must equal the
    reference's.  (Before: its reach was the seeder run's, its speeds scaled by the seeder-run median over the
    hazard's median, and its heights by a ratio of medians that is 0 when most arriving blocks roll, h = 0:
    no block ever passed over a fence in that variant.)"""
    import riskrf
    from riskrf.risk.measures import material_value
    sc = simulation.load_scenario(ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml")
    hz = riskrf.energy_hazard(stats.loguniform(50.0, 5e4), sc, "barrier", rate_per_year=1.0, n=2000, seed=1)
    name = "talus.ground_friction_angle_deg"
    central = material_value(sc, name)
    fence = Option("fence", "fence", 5e5, capacity_kj=500, height_m=1.0, repair_days=0)
    s = MitigationStudy(hazard=hz, options=(Option("nothing", "none"), fence), consequences=CONSTANT_V,
                        uncertainty=Uncertainty(samples=20, material_draws=1,
                                                materials={name: (central, central + 5.0)}),
                        context=SimulationContext(sc, barrier_collector="barrier", road_collector="road",
                                                  n_blocks=1000, seed=3))
    labels = [m.label for m in s._models]
    low = labels.index(f"{name} low")
    assert s._models[low].values[name] == central
    reach = s._model_arrays[0]
    assert reach[low] == pytest.approx(reach[0], rel=1e-12)
    st = s._barrier_stage(fence)
    assert st.passing[0].max() > 0                          # some blocks pass over or break through the fence
    for arr in (st.passing, st.held_sel, st.destroy):
        np.testing.assert_allclose(arr[low], arr[0], atol=1e-12)


def test_quantile_mapping_of_bounce_heights_keeps_the_rolling_share():
    """The variant's height law is applied by quantile mapping: twice the heights map each height to twice
    itself, rolling blocks (h = 0) stay on the ground, and a variant whose median is 0 still bounces above it."""
    from riskrf.risk.mitigation import _quantile_map
    ref = np.r_[np.zeros(600), np.linspace(0.1, 4.0, 400)]
    x = np.array([0.0, 0.5, 2.0, 3.9, 6.0])
    np.testing.assert_allclose(_quantile_map(x, ref, 2 * ref), 2 * x, rtol=1e-12)
    np.testing.assert_allclose(_quantile_map(x, ref, ref), x, rtol=1e-12)
    var = np.r_[np.zeros(700), np.linspace(1.0, 9.0, 300)]          # median 0, yet 30 % bounce up to 9 m
    mapped = _quantile_map(ref, ref, var)
    assert np.mean(mapped > 5.0) == pytest.approx(np.mean(var > 5.0), abs=0.01)
    # 60 % of the reference rolls; in a variant where only 30 % roll, half of the reference's rolling blocks bounce
    var = np.r_[np.zeros(300), np.linspace(1.0, 9.0, 700)]
    assert np.mean(_quantile_map(np.zeros(100), ref, var) > 0) == pytest.approx(0.5, abs=0.02)


def test_simulations_on_threads_equal_one_by_one_runs():
    from riskrf.risk.measures import scenario_with_materials
    sc = simulation.load_scenario(ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml")
    scs = [scenario_with_materials(sc, {"talus.ground_friction_angle_deg": v}) for v in (15.0, 20.0, 25.0)]
    ctx = SimulationContext(sc, n_blocks=800, seed=3, threads=2)
    for a, b in zip(ctx.run_many(scs), [ctx.run(x) for x in scs]):
        for name in a.crossings:
            np.testing.assert_array_equal(a.crossings[name], b.crossings[name])
        for name in a.per_block:
            np.testing.assert_array_equal(a.per_block[name], b.per_block[name])


def test_fragmentation_breaks_event_volumes_into_the_blocks_that_travel():
    """uncertainty.fractal_dimension: each event volume breaks into the expected fragments of fractal fragmentation
    (Perfect 1997); the fragments travel, the road users meet events.  Here every block reaches the road with the
    same probability tau = 0.5 and the vulnerability is 0.5 whatever the mass, so with N expected fragments an
    event reaches the road with probability 1 - exp(-N tau) and is fatal to a vehicle it meets with probability
    (1 - exp(-N tau v)) / (1 - exp(-N tau)).  The fragments keep the event's mass (the grid reaches down to the
    finest generation); the tree and the F-N curve use the same events and vulnerabilities as the ranking."""
    from riskrf.hazard.design_block import fractal_fragments
    frag = study(uncertainty=Uncertainty(samples=200, fractal_dimension=(2.5, 2.5), fragmentation_iterations=3))
    n_frag = fractal_fragments(1.0, 2.5, 3)["count"].sum()
    reach = -np.expm1(-0.5 * n_frag)
    r = frag.evaluate("nothing")
    assert r.road_falls_per_year == pytest.approx(2.0 * reach, rel=1e-9)
    v_eff = -np.expm1(-0.5 * n_frag * 0.5) / reach
    ex = frag.exposure
    k, p = occupancy_distribution(ex.occupants_per_vehicle)
    p_st = 2500 * 5.0 / (24 * 1000 * 80)                     # per lane: 2 lanes of 2,500 vehicles/day
    strikes = ex.share_stopping_on_road * 0.002 * -np.expm1(-2500 * 0.5 / 24)
    v_s_eff = -np.expm1(-0.5 * n_frag * 0.1) / reach
    assert r.deaths_per_year == pytest.approx(float(np.dot(k, p)) * 2.0 * reach * (p_st * v_eff + strikes * v_s_eff),
                                              rel=1e-9)
    # a source measure removes events (and so all their fragments): scaling by half halves the events at the road
    assert frag.evaluate("scale").road_falls_per_year == pytest.approx(r.road_falls_per_year / 2, rel=1e-9)
    eff = frag.ranking().set_index("option")["effectiveness"]
    assert eff["nothing"] == pytest.approx(0.0, abs=1e-12) and eff["scale"] == pytest.approx(0.5, rel=1e-9)
    # the fragments' masses add up to the event's (bin middles: within a bin's width)
    edges, mid, _ = frag._grid
    F = frag._fragment_matrix([2.2, 2.8])
    j = int(np.searchsorted(mid, 1e4))
    assert F[0, j] @ mid == pytest.approx(mid[j], rel=0.1)
    assert np.all(F.sum(axis=2)[1] > F.sum(axis=2)[0])
    assert np.all(np.nonzero(F[0])[1] <= np.nonzero(F[0])[0])          # a fragment is never heavier than its event
    # one loss engine: the tree rolls back to the central cost, the F-N curve sums to the deaths
    c = frag._central_result
    tree = frag.to_tree()
    assert tree.rollback().value == pytest.approx(float(c["total"][0].min()), rel=1e-9)
    fn = frag.fn_curve("nothing")
    assert fn["F"].sum() == pytest.approx(r.deaths_per_year, rel=1e-9)
    # sampled D: an uncertain input with its tornado and break-even rows; a fixed D has a tornado row too
    ranged = study(uncertainty=Uncertainty(samples=200, fractal_dimension=(2.2, 2.8)))
    assert "fractal_dimension" in ranged.parameter_ranges()
    assert ranged.ranking()["probability_best"].sum() == pytest.approx(1.0)
    assert "fractal_dimension" in set(frag.tornado()["parameter"])
    assert "fractal_dimension" in set(ranged.break_even_table()["parameter"])


@pytest.mark.parametrize("value,match", [([3.2, 3.5], "strictly between 0 and 3"), ([0, 2.5], "strictly between")])
def test_bad_fractal_dimension_range_names_the_field(value, match):
    with pytest.raises(MitigationError, match=rf"uncertainty\.fractal_dimension.*{match}"):
        parse_mitigation({"options": [{"name": "nothing", "kind": "none", "capital_cost": 0}],
                          "uncertainty": {"fractal_dimension": value}}, source="site.toml")
