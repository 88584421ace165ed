"""Authume quarry: simulated vs observed runout, a priori (presets) and calibrated (README "Validation").

Observed stops: tests/data/authume/observed_runout.csv (Garcia et al. 2022, Engineering Geology 310:106855;
data richefeu/AuthumeQuarryRockfalls_Data-in-Brief f695c933, see its README).  The calibrated scenarios are
written by validation/authume/calibrate_authume.py (n 2,000, seed 1); these tests re-run them with
the same n and seed and check the figures quoted in the README and results.md.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

import simulation

from .conftest import ROOT

SCEN = ROOT / "simulation" / "scenarios" / "authume"
OBSERVED = pd.read_csv(ROOT / "tests" / "data" / "authume" / "observed_runout.csv")


def runout(name):
    sc = simulation.load_scenario(SCEN / f"{name}.toml")
    return simulation.run(sc, n=2000, seed=1, record_paths=0).per_block["x"]


def observed(profile):
    return OBSERVED.loc[OBSERVED.profile == profile, "x_stop_m"].to_numpy()


def test_p1_calibrated_reproduces_the_observed_runout():
    """Figures of validation/authume/calibrate_authume.py re-run on 2026-12-07 after the hop height began to default
    to the roughness (issue 38 item 4): W1 2.2 m, KS p 0.73, p10 / p50 / p90 35.8 / 39.6 / 57.5 m against
    36.1 / 40.4 / 60.2 m observed.  The bounds were W1 < 2 m and quantiles within 2 m (W1 1.5 m, KS p 0.65) when the
    contact velocity decided the hops; they were widened to 3 m for that change alone."""
    sim, obs = runout("authume_p1_calibrated"), observed("P1")
    assert obs.size == 41
    assert stats.wasserstein_distance(sim, obs) < 3.0                     # 2.2 m
    assert stats.ks_2samp(sim, obs).pvalue > 0.05                         # 0.73
    assert np.percentile(sim, [10, 50, 90]) == pytest.approx(np.percentile(obs, [10, 50, 90]), abs=3.0)


def test_p2_calibrated_is_only_partly_reproduced():
    """Calibration brings P2 close in its lower quantiles and in W1 (34.2 m a priori, 4.3 m calibrated) but not in
    its tail: the calibrated p90 is 85.5 m against 73.2 m observed, and the KS test is borderline (p 0.053, D 0.19).
    The fitted values sit at their bounds (e_T 0.21 of 0.2-1, the hard ground's phi_g 49.8 of 5-50 deg).
    Re-run 2026-12-07 with the hop height defaulting to the roughness (issue 38 item 4); before it (the contact
    velocity deciding the hops) W1 was 2.9 m, the quantiles within 2 m and KS p 0.04, which this test asserted.  If
    a better fit ever matches the tail, the README's "only partly reproduced" is wrong and must be rewritten with
    this test."""
    sim, obs = runout("authume_p2_calibrated"), observed("P2")
    w_calibrated = stats.wasserstein_distance(sim, obs)
    w_prior = stats.wasserstein_distance(runout("authume_p2"), obs)
    assert w_calibrated < 0.2 * w_prior                                   # 4.3 m against 34.2 m
    assert np.percentile(sim, [10, 50]) == pytest.approx(np.percentile(obs, [10, 50]), abs=3.5)  # 3.1, 1.5 m
    assert np.percentile(sim, 90) > np.percentile(obs, 90) + 5.0          # 85.5 m against 73.2 m: not in full


@pytest.mark.parametrize("name, profile", [("authume_p1", "P1"), ("authume_p2", "P2")])
def test_presets_a_priori_stop_far_short_of_the_observations(name, profile):
    """W1 28.4 m (P1) and 34.2 m (P2), n 2,000, seed 1 (2026-12-07).  The bound was 30 m until the hop height began
    to default to the roughness (issue 38 item 4), which moved P1's a-priori median from 7.4 to 16.2 m (W1 from
    32.8 m); lowered to 25 m for that change alone."""
    sim, obs = runout(name), observed(profile)
    assert np.percentile(sim, 90) < np.percentile(obs, 10)               # every quantile short
    assert stats.wasserstein_distance(sim, obs) > 25.0
