"""Deposition below a cliff: simulation/scenarios/cliff_talus_deposition.toml (80 m cliff at 70 deg over a 34 deg
talus 60 m high, blocks of 10 kg to 100 t detaching from the top of the face).

What a talus below a cliff shows (Evans & Hungr 1993, Can. Geotech. J. 30:620-636; Wyllie 2014, fig. 1.1;
Statham 1976, Earth Surf. Process. 1:43): most fallen blocks rest on the talus or near its toe, spread along it
(the talus exists because they stop on it), with the largest blocks farthest (fall sorting), and the farthest
at minimum shadow angles of about 22-30 deg measured from the top of the talus.

The contact values of the scenario marked [D] in its .md file were chosen, not fitted to a data set: this test shows
the contact model can produce a talus deposit and that the parts of the model the deposit depends on matter (the
steep-face rule; the presets' constant e_T), not that the chosen values are right for a given site.
"""
import tomllib

import numpy as np
import pytest
from scipy import stats

import simulation

from .conftest import ROOT

SCENARIO = ROOT / "simulation" / "scenarios" / "cliff_talus_deposition.toml"
TALUS_TOP = (39.118, 60.0)
TALUS_TOE_X = 128.072


def _data():
    return tomllib.loads(SCENARIO.read_text())


def _run(data, n=2000, seed=1):
    res = simulation.run(simulation.scenario_from_dict(data, source=str(SCENARIO)), n=n, seed=seed, record_paths=0)
    stopped = res.per_block["reason"] == 1
    return res, stopped


def _deposit(res, stopped):
    x, z = res.per_block["x"][stopped], res.per_block["z"][stopped]
    shadow = np.degrees(np.arctan2(TALUS_TOP[1] - z, x - TALUS_TOP[0]))
    counts, _ = np.histogram(x, bins=np.arange(0.0, 452.0, 2.0))
    return x, shadow, counts.max() / x.size


@pytest.fixture(scope="module")
def deposit():
    return _run(_data())


def test_geometry_is_the_stated_one():
    sc = simulation.load_scenario(SCENARIO)
    slopes = np.degrees(np.arctan2(-np.diff(sc.profile.z), np.diff(sc.profile.x)))
    assert slopes[1:3] == pytest.approx([70.0, 34.0], abs=0.01)
    assert sc.profile.z[1] - sc.profile.z[2] == 80.0 and sc.profile.z[2] - sc.profile.z[3] == 60.0


def test_most_blocks_stop_on_the_talus_or_near_its_toe(deposit):
    """Measured (n 2,000, seed 1): 72 % on the talus, 96 % on it or within 20 m of its toe."""
    res, stopped = deposit
    assert stopped.all()
    x, _, _ = _deposit(res, stopped)
    assert np.mean((x > TALUS_TOP[0]) & (x <= TALUS_TOE_X)) > 0.6
    assert np.mean(x <= TALUS_TOE_X + 20.0) > 0.9


def test_no_two_metre_band_holds_more_than_five_percent_of_the_stops(deposit):
    """Measured: the fullest 2 m bin holds 3.6 %."""
    _, _, fullest = _deposit(*deposit)
    assert fullest <= 0.05


def test_farthest_blocks_stop_at_the_evans_and_hungr_shadow_angles(deposit):
    """Measured: minimum shadow angle 23.9 deg; the 1st percentile 26.9 deg."""
    x, shadow, _ = _deposit(*deposit)
    farthest = shadow[np.argsort(x)[-20:]]
    assert 22.0 <= shadow.min() <= 30.0
    assert np.all((farthest >= 22.0) & (farthest <= 30.0))
    assert np.mean(shadow >= 27.5) > 0.9            # the 27.5 deg rule of thumb holds for most blocks


def test_larger_blocks_travel_farther(deposit):
    """Fall sorting: runout rises with mass (Spearman rho measured 0.56); the farthest reach of the heaviest
    quarter (p99 165 m) beyond that of the lightest quarter (135 m)."""
    res, stopped = deposit
    x, _, _ = _deposit(res, stopped)
    m = res.blocks["mass"][stopped]
    q1, q3 = np.quantile(m, [0.25, 0.75])
    assert stats.spearmanr(m, x).statistic > 0.4
    assert np.percentile(x[m >= q3], 99) > np.percentile(x[m <= q1], 99) + 20.0
    assert x[m >= q3].max() > x[m <= q1].max()


def test_the_deposit_needs_the_steep_face_rule():
    """The check can fail: when blocks may roll in contact down the 70 deg face (no steep-face limit) they reach
    the talus without an impact and run across it (15 % stop on it, measured)."""
    data = _data()
    data["settings"]["max_rolling_slope_deg"] = 90.0
    res, stopped = _run(data, n=1000)
    x, _, _ = _deposit(res, stopped)
    assert np.mean((x > TALUS_TOP[0]) & (x <= TALUS_TOE_X)) < 0.3
    assert res.per_block["impacts"].mean() < 0.5


def test_presets_as_documented_pile_every_block_in_one_band():
    """The former model (the presets with their constant e_T, rolling allowed on any slope): every block rolls
    down the face in contact and 65 % stop in one 2 m bin beyond the toe (measured, n 1,000, seed 1)."""
    data = _data()
    data["settings"].pop("max_rolling_slope_deg")
    data["materials"] = {"cliff": {"preset": "bedrock"}, "talus": {"preset": "talus"}, "runout": {"preset": "meadow"}}
    res, stopped = _run(data, n=1000)
    x, _, fullest = _deposit(res, stopped)
    assert fullest > 0.3
    assert np.mean((x > TALUS_TOP[0]) & (x <= TALUS_TOE_X)) < 0.05
