"""Mitigation options from the energy hazard, ranking and break-even (issue 5, item 3)."""
import numpy as np
import pytest
from scipy import stats

from riskrf.cli import main
from riskrf.annual_hazard import EnergyHazard
from riskrf.mitigation import (Consequences, Economics, Exposure, MitigationError, MitigationStudy, Option,
                               parse_mitigation)
from riskrf.road_risk import pv_factor, spatial_temporal_probability

from .conftest import INVENTORIES, ROOT
from .test_simulation_run import BARRIER

rng = np.random.default_rng(0)
V = stats.lognorm(0.2, scale=20).rvs(4000, random_state=rng)
H = rng.exponential(2.0, 4000)
HAZ = EnergyHazard(mass=stats.lognorm(1.0, scale=3000), velocity=V, rate_per_year=2.0, reach_probability=0.5,
                   heights_m=H)
OPTIONS = (Option("nothing", "none", 0.0), Option("scale", "scaling", 2e5, 5e3, rate_reduction=0.5),
           Option("fence", "fence", 5e5, 1e4, 25, 2e4, capacity_kj=2000, height_m=4),
           Option("shed", "shed", 5e6, capacity_kj=1e5), Option("move", "realignment", 2e7))


def study(**kw):
    return MitigationStudy(hazard=HAZ, options=OPTIONS, exposure=Exposure(vehicles_per_day=5000),
                           consequences=Consequences(), economics=Economics(0.03, 50), **kw)


def test_expected_annual_loss_by_hand():
    s = study()
    r = s.evaluate(OPTIONS[0])
    ex, co = s.exposure, s.consequences
    road = 2.0 * 0.5
    p_st = spatial_temporal_probability(5000, ex.vehicle_length_m, ex.speed_kmh)
    strikes = road * ex.share_stopping_on_road * (1 - np.exp(-5000 * ex.hours_rock_on_road * ex.p_cannot_stop / 24))
    deaths = ex.occupants_per_vehicle * (road * p_st * co.vulnerability_moving_vehicle
                                         + strikes * co.vulnerability_striking_rock)
    eal = (deaths * co.value_of_statistical_life + (road * p_st + strikes) * co.vehicle_damage
           + road * (co.closure_days_per_fall * co.closure_cost_per_day + co.cleanup_cost_per_fall))
    assert r.road_falls_per_year == pytest.approx(1.0) and r.expected_annual_loss == pytest.approx(eal)
    assert s.evaluate(OPTIONS[1]).expected_annual_loss == pytest.approx(eal / 2)
    assert s.evaluate(OPTIONS[4]).expected_annual_loss == 0


def test_fence_residual_from_paired_heights_and_energies():
    s = study()
    r = s.evaluate(OPTIONS[2])
    mass = stats.lognorm(1.0, scale=3000)
    expected = np.mean(np.where(H > 4, 1.0, mass.sf(2000 * 2000 / V ** 2)))
    assert r.road_falls_per_year == pytest.approx(1.0 * expected)
    assert r.held_impacts_above_sel_per_year > 0


def test_ranking_table_columns_totals_and_tree_agree():
    s = study()
    t = s.ranking()
    for col in ("capital", "pv_maintenance", "pv_expected_loss", "expected_total_cost", "road_falls_per_year",
                "individual_risk", "benefit_cost_ratio", "rank"):
        assert col in t.columns
    np.testing.assert_allclose(t["expected_total_cost"], t["capital"] + t["pv_maintenance"] + t["pv_expected_loss"])
    assert t["expected_total_cost"].is_monotonic_increasing
    nothing = t.set_index("option").loc["nothing"]
    assert nothing["pv_expected_loss"] == pytest.approx(pv_factor(0.03, 50) * s.evaluate(OPTIONS[0]).expected_annual_loss)
    tree = s.to_tree()
    ov = tree.rollback().option_values
    for name, total in zip(t["option"], t["expected_total_cost"]):
        assert ov[name] == pytest.approx(total, rel=1e-9)


def test_break_even_makes_the_second_option_tie():
    s = study()
    t = s.ranking()
    a, b = t["option"].iloc[0], t["option"].iloc[1]
    be = s.break_even(f"capital_cost:{a}")
    assert be is not None
    tied = s._scaled(f"capital_cost:{a}", be[0]).ranking().set_index("option")["expected_total_cost"]
    assert tied[a] == pytest.approx(tied[b], rel=1e-8)
    tornado = s.tornado()
    assert tornado["swing"].is_monotonic_decreasing


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
])
def test_bad_mitigation_files(data, match):
    with pytest.raises(MitigationError, match=match):
        parse_mitigation(data, "site.toml")


def test_decide_command_on_bundled_site(tmp_path, capsys):
    out = tmp_path / "d"
    rc = main(["decide", "--options", str(ROOT / "riskrf" / "data" / "demo_site.toml"), "--inventory",
               str(INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2018.csv"), "--scenario", str(BARRIER),
               "-n", "5000", "--m-max", "2e6", "--rate-scale", "0.05", "--out", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "Mitigation ranking by expected total cost (CHF" in text and "break-even" in text
    for name in ("ranking.csv", "tornado.csv", "break_even.csv", "decision.json", "tree.png", "tornado.png",
                 "fn_curve.png"):
        assert (out / name).exists()


def test_decide_command_on_a_tree_file(tmp_path, capsys):
    from .conftest import DATA
    rc = main(["decide", str(DATA / "clemen2001" / "texaco_pennzoil.json"), "--out", str(tmp_path / "t")])
    assert rc == 0
    text = capsys.readouterr().out
    assert "counteroffer 5 billion" in text and "EVPI of 'court'" in text
    assert (tmp_path / "t" / "tree.png").stat().st_size > 0


def test_value_of_information_about_the_rate():
    s = study()
    voi = s.value_of_information()
    tables = [s._scaled("fall_rate", f).ranking().set_index("option")["expected_total_cost"] for f in (0.5, 1, 2)]
    expected = 0.25 * tables[0] + 0.5 * tables[1] + 0.25 * tables[2]
    informed = 0.25 * tables[0].min() + 0.5 * tables[1].min() + 0.25 * tables[2].min()
    assert voi["evpi"] == pytest.approx(expected.min() - informed) and voi["evpi"] >= 0
    with pytest.raises(MitigationError, match="summing to 1"):
        s.value_of_information(weights=(0.5, 0.5, 0.5))
