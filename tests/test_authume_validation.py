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
    sim, obs = runout("authume_p1_calibrated"), observed("P1")
    assert obs.size == 41
    assert stats.wasserstein_distance(sim, obs) < 2.0                     # README: 1.5 m
    assert stats.ks_2samp(sim, obs).pvalue > 0.05                         # README: 0.65
    assert np.percentile(sim, [10, 50, 90]) == pytest.approx(np.percentile(obs, [10, 50, 90]), abs=2.0)


def test_p2_calibrated_is_only_partly_reproduced():
    """Stated in the README: calibration brings the quantiles to the observed ones (W1 34.4 m a priori, 2.9 m
    calibrated), yet the two-sample KS test still rejects the calibrated runout at 5 % (p 0.04).  If a better fit
    ever passes the KS test, the README's "only partly reproduced" is wrong and must be rewritten with this test."""
    sim, obs = runout("authume_p2_calibrated"), observed("P2")
    w_calibrated = stats.wasserstein_distance(sim, obs)
    w_prior = stats.wasserstein_distance(runout("authume_p2"), obs)
    assert w_calibrated < 0.2 * w_prior                                   # 2.9 m against 34.4 m
    assert np.percentile(sim, [10, 50, 90]) == pytest.approx(np.percentile(obs, [10, 50, 90]), abs=2.0)
    assert stats.ks_2samp(sim, obs).pvalue < 0.05                         # 0.04: not reproduced in full


@pytest.mark.parametrize("name, profile", [("authume_p1", "P1"), ("authume_p2", "P2")])
def test_presets_a_priori_stop_far_short_of_the_observations(name, profile):
    sim, obs = runout(name), observed(profile)
    assert np.percentile(sim, 90) < np.percentile(obs, 10)               # every quantile short
    assert stats.wasserstein_distance(sim, obs) > 30.0
