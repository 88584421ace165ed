"""Road-user risk per lane (Bunce, Cruden & Morgenstern 1997) and its check against the Hong Kong register.

Reference numbers: hand calculations written beside each assertion; the register's counts are measured from
../shared/inventories-raw/hong-kong-cedd/cedd_incidents_1984_2020.csv (CEDD/GEO via DATA.GOV.HK; caveats in its
PROVENANCE.md: regional record, mechanisms mixed, reporting changed over 37 years, SCALE read as m³).
"""
import os
from pathlib import Path

import numpy as np
import pytest

from riskrf.risk.road_users import (
    DEFAULT_VULNERABILITY,
    LITERATURE_VULNERABILITY,
    Lane,
    Vulnerability,
    lane_hit_probability,
    lane_strike_probability,
    lanes_from_traffic,
    per_fall_risk,
)
from riskrf.risk.road_validation import hong_kong_road_validation, poisson_interval, read_hong_kong_road_records
from riskrf.risk.road_risk import VULNERABILITY_DIRECT_BY_MASS, VULNERABILITY_STRIKE_BY_MASS, spatial_temporal_probability

from .conftest import ROOT

SHARED = Path(os.environ.get("RISKRF_SHARED_DIR", ROOT / ".." / "shared"))
REGISTER = SHARED / "inventories-raw" / "hong-kong-cedd" / "cedd_incidents_1984_2020.csv"


def _register():
    if not REGISTER.exists():
        pytest.skip(f"{REGISTER} not present (shared raw records)")
    return REGISTER


def test_per_lane_bunce_against_a_hand_calculation():
    # two-lane road, 6,000 vehicles/day, 50:50, 80 km/h, 5 m vehicles: each lane 3,000/day;
    # a fall lands in one lane: P = 3000 x 5 / (24 x 1000 x 80) = 15000 / 1,920,000 = 0.0078125
    lanes = lanes_from_traffic(6000, 80, lanes=2)
    assert [la.vehicles_per_day for la in lanes] == [3000.0, 3000.0]
    assert lane_hit_probability(lanes, 5.0) == pytest.approx(0.0078125, rel=1e-12)
    # Bunce's two-way form counts all 6,000 vehicles at the impact point: twice as much
    assert spatial_temporal_probability(6000, 5.0, 80) == pytest.approx(2 * 0.0078125, rel=1e-12)


def test_per_lane_bunce_uneven_lanes_and_fall_shares_by_hand():
    # 4 lanes, 70 % of the traffic towards the slope side, 60 % of the falls in the nearest lane, 20/10/10 beyond:
    # near lanes 20000 x 0.7 / 2 = 7000 each; far lanes 20000 x 0.3 / 2 = 3000 each; 60 km/h, 5 m
    lanes = lanes_from_traffic(20000, 60, lanes=4, directional_split=0.7, fall_shares=[0.6, 0.2, 0.1, 0.1])
    per_vehicle = 5.0 / (24 * 1000 * 60)
    hand = (0.6 * 7000 + 0.2 * 7000 + 0.1 * 3000 + 0.1 * 3000) * per_vehicle      # = 6200 x 5 / 1,440,000
    assert hand == pytest.approx(0.021527777, rel=1e-6)
    assert lane_hit_probability(lanes, 5.0) == pytest.approx(hand, rel=1e-12)
    # lanes of different speeds, built by hand
    mixed = (Lane("north", 4000, 100, 0.5), Lane("south", 2000, 50, 0.5))
    assert lane_hit_probability(mixed, 5.0) == pytest.approx(0.5 * 4000 * 5 / 2.4e6 + 0.5 * 2000 * 5 / 1.2e6)


def test_strike_on_a_rock_lying_in_the_lane_by_hand():
    # first vehicle of the lane arrives within 0.5 h: 1 - exp(-3000 x 0.5 / 24) = 1 - exp(-62.5) ~ 1; x p = 0.002
    lanes = lanes_from_traffic(6000, 80)
    assert lane_strike_probability(lanes, 0.5, 0.002) == pytest.approx(0.002 * -np.expm1(-62.5))
    # a quiet road: 48 vehicles/day in one lane, 0.25 h: 1 - exp(-48 x 0.25 / 24) = 1 - exp(-0.5) = 0.393469
    quiet = (Lane("both", 48, 50),)
    assert lane_strike_probability(quiet, 0.25, 0.01) == pytest.approx(0.01 * 0.39346934, rel=1e-7)


def test_direct_hits_and_strikes_reported_separately_and_add_up():
    r = per_fall_risk(lanes_from_traffic(6000, 80), [50.0, 500.0, 5000.0])
    t = r.summary()
    assert t.loc["total", "deaths"] == pytest.approx(t.loc["direct hit on a moving vehicle", "deaths"]
                                                     + t.loc["vehicle strikes a rock on the road", "deaths"])
    v = DEFAULT_VULNERABILITY.probability([50.0, 500.0, 5000.0], "direct").mean()
    assert r.deaths_direct == pytest.approx(1.5 * 0.0078125 * v)
    assert 0 < r.deaths_strike < r.deaths_direct


def test_vulnerability_model_is_monotone_bounded_and_inside_the_stated_literature_range():
    m = np.geomspace(1, 1e8, 200)
    for which in ("direct", "strike"):
        v = DEFAULT_VULNERABILITY.probability(m, which)
        assert np.all(np.diff(v) >= 0) and np.all((v >= 0) & (v <= 1))
    assert np.all(DEFAULT_VULNERABILITY.probability(m, "direct", factor=10) <= 1)
    # up to 10 t the direct-hit value lies in the AGS (2000) "vehicle damaged only" range 0-0.3 (p. 47)
    damaged = LITERATURE_VULNERABILITY.set_index("situation").loc["person in vehicle, vehicle damaged only"]
    assert np.all(DEFAULT_VULNERABILITY.probability(m[m <= 1e4], "direct") <= damaged["high"])
    assert set(LITERATURE_VULNERABILITY["evidence"]) <= {"V", "R"}


def test_hong_kong_register_counts():
    rec = read_hong_kong_road_records(_register())
    # measured from the register: rock cut + soil/rock cut incidents with a road affected, 1984-2020
    assert rec.falls == 703 and rec.years == 37
    assert rec.deaths == 1 and rec.injuries == 15 and rec.vehicles_involved == 12
    assert set(rec.incidents["feature"]) == {"rock cut", "soil/rock cut"}


def test_poisson_interval_garwood():
    # Garwood 95 % for k = 1: (0.0253, 5.5716); k = 0: (0, 3.6889)
    assert poisson_interval(1) == pytest.approx((0.025318, 5.571643), rel=1e-4)
    assert poisson_interval(0) == pytest.approx((0.0, 3.688879), rel=1e-5)


def test_predicted_casualties_match_the_hong_kong_register():
    v = hong_kong_road_validation(_register(), samples=1500, seed=3)
    s = v.summary()
    # recorded per fall reaching a road: 12/703 vehicles, 1/703 deaths, 15/703 injuries
    assert s.loc["deaths", "recorded_per_fall"] == pytest.approx(1 / 703)
    assert s.loc["injuries", "recorded_per_fall"] == pytest.approx(15 / 703)
    # the default model: each recorded count is a plausible draw from the prediction (both tails > 2.5 %) and the
    # predicted mean per fall lies inside the record's 95 % Poisson interval
    assert s["consistent"].all()
    for q in ("vehicles involved", "deaths", "injuries"):
        assert s.loc[q, "recorded_low_95"] <= s.loc[q, "predicted_per_fall"] <= s.loc[q, "recorded_high_95"], q
    # the numbers quoted in docs/validation/road-risk.md (4,000 samples, seed 1)
    assert 0.0015 < s.loc["deaths", "predicted_per_fall"] < 0.008


def test_the_former_model_predicts_far_more_deaths_than_recorded():
    # Bunce's two-way traffic in one lane, the former vulnerability curve (0.3 at 100 kg, 1.0 from 10 t):
    # the register's single death is then implausible (P(count <= 1) < 0.1 %)
    old = Vulnerability(VULNERABILITY_DIRECT_BY_MASS, VULNERABILITY_STRIKE_BY_MASS)
    s = hong_kong_road_validation(_register(), vulnerability=old, samples=800, two_way=True).summary()
    assert s.loc["deaths", "p_count_at_most_recorded"] < 1e-3
    assert s.loc["deaths", "predicted_per_fall"] > 20 * s.loc["deaths", "recorded_per_fall"]


def test_bad_lane_input_is_refused_with_the_field():
    with pytest.raises(ValueError, match="vehicles_per_day"):
        Lane("north", -5, 80)
    with pytest.raises(ValueError, match="fall_shares"):
        lanes_from_traffic(6000, 80, lanes=2, fall_shares=[1.0])
    with pytest.raises(ValueError, match="sum to 1"):
        lane_hit_probability((Lane("a", 100, 50, 0.5), Lane("b", 100, 50, 0.2)), 5.0)
