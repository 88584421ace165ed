"""Decision trees, road-user risk and discounting."""
import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import riskrf
from riskrf.risk.decision_tree import DecisionTree, TreeError
from riskrf.risk.economics import pv_factor, pv_of_renewals
from riskrf.risk.road_risk import (fn_curve, fn_zone, individual_risk, probability_at_least_one_hit,
                         spatial_temporal_probability, stationary_rock_strike_probability, vehicle_occupant_fn)

from .conftest import DATA

TEXACO = DATA / "clemen2001" / "texaco_pennzoil.json"


def test_texaco_pennzoil_rollback_clemen_reilly_2001_ch4():
    tree = DecisionTree.from_file(TEXACO)
    rb = tree.rollback()
    # Clemen & Reilly (2001) ch. 4: counteroffer EMV $4.63 billion (4.6348 unrounded), accept $2 billion.
    assert rb.option_values["counteroffer 5 billion"] == pytest.approx(4.63, abs=0.005)
    assert rb.option_values["counteroffer 5 billion"] == pytest.approx(0.17 * 5 + 0.83 * 4.56)
    assert rb.option_values["accept 2 billion"] == 2.0
    pennzoil = [p for p in rb.policy if p.endswith("Texaco counteroffers 3")][0]
    assert rb.policy[pennzoil] == "refuse 3"          # court EMV 4.56 > 3
    ranking = tree.ranking()
    assert list(ranking["option"]) == ["counteroffer 5 billion", "accept 2 billion"]


def test_texaco_pennzoil_risk_profile_and_evpi():
    tree = DecisionTree.from_file(TEXACO)
    prof = tree.risk_profile("counteroffer 5 billion").set_index("value")["probability"]
    # Refuse 3 => court with probability 0.83: 10.3 (0.166), 5 (0.17 + 0.415), 0 (0.249).
    assert prof[10.3] == pytest.approx(0.166) and prof[5.0] == pytest.approx(0.585) and prof[0.0] == pytest.approx(0.249)
    # Perfect information on the court outcome [derived]: 0.2 x 9.399 + 0.5 x 5 + 0.3 x 2 - 4.6348 = 0.345.
    assert tree.evpi("court") == pytest.approx(0.2 * (0.17 * 5 + 0.83 * 10.3) + 0.5 * 5 + 0.3 * 2 - 4.6348)
    # Break-even: P(high) at which accepting 2 billion ties (medium held at 0.5).
    be = tree.break_even("p_high", 0.0, 0.5, option_a="counteroffer 5 billion", option_b="accept 2 billion")
    assert be is None      # counteroffer is better for every P(high) in [0, 0.5] with P(medium) = 0.5
    sens = tree.sensitivity("p_medium", [0.0, 0.2, 0.5])
    assert sens["best"].iloc[-1] == "counteroffer 5 billion"


def test_present_value_factors():
    # domain-methods.md section 5: 18.256 (5 %, 50 yr), 25.730 (3 %, 50 yr), 15.622 (4 %, 25 yr).
    assert pv_factor(0.05, 50) == pytest.approx(18.256, abs=5e-4)
    assert pv_factor(0.03, 50) == pytest.approx(25.730, abs=5e-4)
    assert pv_factor(0.04, 25) == pytest.approx(15.622, abs=5e-4)
    assert pv_factor(0.0, 10) == 10
    assert pv_of_renewals(100.0, 20, 50, 0.05) == pytest.approx(100 * (1.05 ** -20 + 1.05 ** -40))


def test_bunce_probabilities_by_hand():
    # domain-methods.md E10: N_v 4000/day, L_v 6 m, V_v 80 km/h -> P(S:T) = 4000 * 6 / (24 * 1000 * 80) = 0.0125;
    # P(S:H) = 1 - (1 - 0.0125)^N_r = 0.1182 (10 falls), 0.2224 (20 falls).
    p = spatial_temporal_probability(4000, 6, 80)
    assert p == pytest.approx(4000 * 6 / (24 * 1000 * 80)) == 0.0125
    assert probability_at_least_one_hit(p, 10) == pytest.approx(0.1182, abs=5e-5)
    assert probability_at_least_one_hit(p, 20) == pytest.approx(0.2224, abs=5e-5)
    assert stationary_rock_strike_probability(2400, 1.0, 0.1) == pytest.approx(1 - np.exp(-10))
    # Commuter making 2 trips a day, 5 falls/yr, 5 m vehicle, 80 km/h, vulnerability 0.5.
    assert individual_risk(5, 2, 5, 80, 0.5) == pytest.approx(5 * 2 * 5 / (24 * 1000 * 80) * 0.5)
    with pytest.raises(ValueError, match="speed_kmh must be finite and > 0; got 0"):
        spatial_temporal_probability(100, 5, 0)


def test_fn_curves():
    fn = fn_curve([(1e-3, 1), (1e-4, 3), (2e-5, 10)])
    assert list(fn["N"]) == [1, 3, 10] and fn["F"].tolist() == pytest.approx([1.12e-3, 1.2e-4, 2e-5])
    occ = vehicle_occupant_fn(0.01, 2, 0.5)
    assert occ["F"].tolist() == pytest.approx([0.01 * 0.75, 0.01 * 0.25])
    # Hong Kong GEO lines through F = 1e-3 and 1e-5 at N = 1, slope -1:
    assert fn_zone(fn_curve([(2e-3, 1)])) == "unacceptable"
    assert fn_zone(fn_curve([(5e-4, 1), (2e-4, 3)])) == "ALARP"
    assert fn_zone(fn_curve([(5e-6, 1), (1e-6, 3)])) == "broadly acceptable"


def _random_tree(draw_rng, depth=0):
    kind = draw_rng.choice(["decision", "chance", "terminal"] if depth < 3 else ["terminal"])
    if kind == "terminal":
        return {"type": "terminal", "value": float(draw_rng.integers(-50, 50))}
    n = int(draw_rng.integers(2, 4))
    branches = []
    probs = draw_rng.dirichlet(np.ones(n))
    probs[-1] = 1 - probs[:-1].sum()
    for i in range(n):
        b = {"name": f"b{depth}{i}", "cost": float(draw_rng.integers(0, 20)), "child": _random_tree(draw_rng, depth + 1)}
        if kind == "chance":
            b["probability"] = float(probs[i])
        branches.append(b)
    return {"type": kind, "name": f"n{depth}", "branches": branches}


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 100_000), objective=st.sampled_from(["min", "max"]))
def test_rollback_equals_brute_force_enumeration(seed, objective):
    rng = np.random.default_rng(seed)
    spec = {"type": "decision", "name": "root", "objective": objective,
            "branches": [{"name": f"o{i}", "cost": float(rng.integers(0, 30)), "child": _random_tree(rng, 1)}
                         for i in range(3)]}
    tree = DecisionTree.from_dict(spec)
    values = [v for _, v in tree.enumerate_policies()]
    best = min(values) if objective == "min" else max(values)
    assert tree.rollback().value == pytest.approx(best)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 100_000), scale=st.floats(0.1, 100))
def test_dominated_option_and_cost_scaling(seed, scale):
    rng = np.random.default_rng(seed)
    branches = [{"name": f"o{i}", "cost": float(rng.integers(0, 30)), "child": _random_tree(rng, 1)} for i in range(3)]
    tree = DecisionTree.from_dict({"type": "decision", "name": "root", "branches": branches})
    best = tree.ranking()["option"].iloc[0]
    worst_value = tree.ranking()["expected_value"].max()
    dominated = {"name": "dominated", "cost": worst_value + 1000.0}
    bigger = DecisionTree.from_dict({"type": "decision", "name": "root", "branches": branches + [dominated]})
    assert bigger.ranking()["option"].iloc[0] == best

    def scaled(node):
        node = json.loads(json.dumps(node))
        if node.get("type") == "terminal":
            node["value"] = node.get("value", 0.0) * scale
        for b in node.get("branches", []):
            b["cost"] = b.get("cost", 0.0) * scale
            b["child"] = scaled(b.get("child", {"type": "terminal"}))
        return node
    big = DecisionTree.from_dict(scaled({"type": "decision", "name": "root", "branches": branches}))
    np.testing.assert_allclose(list(big.rollback().option_values.values()),
                               np.array(list(tree.rollback().option_values.values())) * scale, rtol=1e-9, atol=1e-9)


def test_exponential_utility_is_risk_averse():
    spec = {"type": "decision", "objective": "max", "branches": [
        {"name": "sure", "payoff": 40},
        {"name": "gamble", "child": {"type": "chance", "branches": [
            {"name": "win", "probability": 0.5, "payoff": 100}, {"name": "lose", "probability": 0.5, "payoff": 0}]}}]}
    tree = DecisionTree.from_dict(spec)
    assert tree.ranking()["option"].iloc[0] == "gamble"                       # EMV 50 > 40
    ce = tree.rollback(risk_tolerance=50).option_values["gamble"]
    assert ce == pytest.approx(-50 * np.log(0.5 + 0.5 * np.exp(-100 / 50)))  # = 28.3
    assert tree.ranking(risk_tolerance=50)["option"].iloc[0] == "sure"


def test_evsi_of_a_survey_option():
    spec = {"type": "decision", "objective": "min", "branches": [
        {"name": "decide now", "child": {"type": "decision", "branches": [
            {"name": "fence", "cost": 60},
            {"name": "nothing", "child": {"type": "chance", "branches": [
                {"name": "active", "probability": 0.5, "cost": 200}, {"name": "dormant", "probability": 0.5, "cost": 0}]}}]}},
        {"name": "survey first", "cost": 5, "child": {"type": "chance", "branches": [
            {"name": "says active", "probability": 0.5, "child": {"type": "decision", "branches": [
                {"name": "fence", "cost": 60}, {"name": "nothing", "cost": 180}]}},
            {"name": "says dormant", "probability": 0.5, "child": {"type": "decision", "branches": [
                {"name": "fence", "cost": 60}, {"name": "nothing", "cost": 20}]}}]}}]}
    tree = DecisionTree.from_dict(spec)
    assert tree.rollback().option_values["survey first"] == pytest.approx(5 + 0.5 * 60 + 0.5 * 20)
    assert tree.evsi("survey first", "decide now") == pytest.approx(60 - 40)


@pytest.mark.parametrize("spec,match", [
    ({"type": "decision", "branches": [{"name": "a", "child": {"type": "chance", "branches": [
        {"name": "x", "probability": 0.5}, {"name": "y", "probability": 0.4}]}}, {"name": "b"}]},
     "probabilities sum to 0.9, not 1"),
    ({"type": "decision", "branches": [{"name": "a", "child": {"type": "chance", "branches": [
        {"name": "x", "probability": -0.2}, {"name": "y", "probability": 1.2}]}}]}, "probability -0.2 is outside"),
    ({"type": "decision", "branches": [{"name": "a"}, {"name": "a"}]}, "duplicate branch name 'a'"),
    ({"type": "decision", "branches": [{"name": "a", "child": {"type": "chance", "branches": [
        {"name": "x"}]}}]}, "x: missing field 'probability'"),
    ({"type": "decision", "branches": [{"cost": 3}]}, "branch 0 needs a name"),
    ({"type": "decision", "nodes": {"loop": {"type": "decision", "branches": [{"name": "again", "child": {"ref": "loop"}}]}},
      "branches": [{"name": "a", "child": {"ref": "loop"}}]}, "reference cycle through loop -> loop"),
    ({"type": "gamble", "branches": []}, "node type 'gamble'"),
    ({"type": "decision", "branches": [{"name": "a", "cost": "c_x"}]}, "unknown parameter 'c_x'"),
    ({"type": "decision", "objective": "best", "branches": [{"name": "a"}]}, "objective = 'best'"),
])
def test_bad_trees_name_the_node(spec, match):
    with pytest.raises(TreeError, match=match):
        DecisionTree.from_dict(spec, source="tree.json")


def test_public_decision_tree_name():
    assert riskrf.DecisionTree is DecisionTree


def test_share_with_at_least_matches_scipy_binomial():
    from scipy import stats

    from riskrf.risk.road_risk import occupancy_distribution, share_with_at_least
    k, p = occupancy_distribution(1.4)
    v = np.array([0.0, 0.05, 0.3, 0.77, 1.0])
    expected = np.array([[sum(pk * stats.binom.sf(n - 1, kk, vi) for kk, pk in zip(k, p)) for n in range(1, 10)]
                         for vi in v])
    np.testing.assert_allclose(share_with_at_least(v, k, p), expected, rtol=1e-12, atol=1e-15)
