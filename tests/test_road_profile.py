"""Falls reaching a road line and road-user risk per metre (riskrf.risk.road_profile), against exact sums."""
import numpy as np
import pytest
from scipy import stats

from riskrf.hazard.mass_models import mass_model
from riskrf.hazard.mass_coupling import MassCoupledSamples, stratified_log_uniform
from riskrf.risk.road_profile import RoadProfileError, block_weights_per_year, road_risk_along_line
from riskrf.risk.road_users import (Vulnerability, lane_hit_probability, lane_strike_probability,
                                   lanes_from_traffic)

LAW = stats.truncpareto(b=0.7, c=1000.0, scale=10.0)      # masses 10 kg - 10 t, a power law
RATE = 3.0                                                   # falls per year at the source


def _run(n=4000, seed=0, length=50.0):
    """Blocks over 10 kg - 10 t; a block reaches the road with probability rising with log mass, at a position
    that depends on its mass (heavier blocks at the far end)."""
    rng = np.random.default_rng(seed)
    m = stratified_log_uniform(10.0, 10_000.0, n, rng)
    u = np.log(m / 10) / np.log(1000)
    reached = rng.uniform(size=n) < 0.2 + 0.6 * u
    pos = np.where(reached, np.clip(length * u + rng.normal(0, 2, n), 0, length), np.nan)
    speed = np.where(reached, 10.0, np.nan)
    edges = np.geomspace(10.0, 10_000.0, 7)
    return MassCoupledSamples(m, speed, np.where(reached, 0.5, np.nan), edges, "road"), pos


def test_weights_sum_to_the_rate_and_the_reach_to_the_mass_coupled_reach():
    s, pos = _run()
    w = block_weights_per_year(s, LAW, RATE)
    # every block stands for rate x P(class) / n_class falls a year: together the whole rate
    assert w.sum() == pytest.approx(RATE * s.class_weights(mass_model(LAW)).sum(), rel=1e-12)
    assert w.sum() == pytest.approx(RATE, rel=1e-9)
    prof = road_risk_along_line(s, LAW, RATE, pos, 50.0)
    # the per-metre shares add up to the mass-averaged reach probability of the same samples
    assert prof.totals()["reach_share"] == pytest.approx(s.reach_probability(mass_model(LAW)), rel=1e-9)
    assert prof.totals()["falls_per_year"] == pytest.approx(RATE * s.reach_probability(mass_model(LAW)), rel=1e-9)
    t = prof.summary()
    assert len(t) == 50 and t["blocks"].sum() == np.isfinite(pos).sum()
    # small falls outnumber large ones (b = 0.7) and land near the start: the first metres carry the most
    assert t["falls_per_year_per_m"].iloc[:10].sum() > 3 * t["falls_per_year_per_m"].iloc[-10:].sum()
    assert np.isnan(t["deaths_per_year_per_m"]).all()              # no traffic given


def test_deaths_per_metre_add_up_to_the_per_fall_risk_for_a_constant_vulnerability():
    s, pos = _run()
    lanes = lanes_from_traffic(6000, 80.0)
    v = Vulnerability(direct=((1.0, 0.1),), strike=((1.0, 0.03),))
    prof = road_risk_along_line(s, LAW, RATE, pos, 50.0, bin_m=2.5, lanes=lanes, occupants=1.4,
                                hours_on_road=0.5, p_cannot_stop=0.002, share_stopping_on_road=0.3, vulnerability=v)
    # mass-independent vulnerability: deaths/yr = falls/yr reaching the road x occupants x
    # (P(hit) V_direct + P(strike) s V_strike), Bunce et al. (1997) per lane
    per_fall = 1.4 * (lane_hit_probability(lanes, 5.0) * 0.1
                      + 0.3 * lane_strike_probability(lanes, 0.5, 0.002) * 0.03)
    tot = prof.totals()
    assert tot["deaths_per_year"] == pytest.approx(tot["falls_per_year"] * per_fall, rel=1e-9)
    assert len(prof.summary()) == 20


def test_bad_inputs_are_named():
    s, pos = _run(n=400)
    with pytest.raises(RoadProfileError, match="position_m has 3 values; the run released 400 blocks"):
        road_risk_along_line(s, LAW, RATE, pos[:3], 50.0)
    with pytest.raises(RoadProfileError, match="position_m = 60 lies outside the road line"):
        road_risk_along_line(s, LAW, RATE, np.where(np.isfinite(pos), 60.0, np.nan), 50.0)
    with pytest.raises(RoadProfileError, match="bin_m = 0 must lie in"):
        road_risk_along_line(s, LAW, RATE, pos, 50.0, bin_m=0)
