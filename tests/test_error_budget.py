"""One error budget: reported standard errors cover the joint samples, the material re-simulations
they share (clustered) and the trajectory ensembles (repeated), and the effort adapts until the ranking is
resolved or the budget is used (riskrf.risk.error_budget)."""
import numpy as np
import pytest

import simulation
from riskrf.risk.error_budget import (EnsembleReplicates, adapt_effort, clustered_se, combined_se,
                                      sources_text)
from riskrf.risk.measures import SimulationContext
from riskrf.risk.mitigation import MitigationError, MitigationStudy, Option, Uncertainty, parse_mitigation

from .test_mitigation import CONSTANT_V, HAZ, TOE

rng = np.random.default_rng(5)


def test_clustered_se_is_the_usual_one_for_independent_samples_and_counts_clusters():
    x = rng.normal(size=(400, 3))
    usual = x.std(axis=0, ddof=1) / np.sqrt(400)
    np.testing.assert_allclose(clustered_se(x), usual)
    np.testing.assert_allclose(clustered_se(x, np.arange(400)), usual)         # every sample its own cluster
    # 8 clusters of 50 identical samples: the information of 8 values, not of 400
    c = np.repeat(np.arange(8), 50)
    v = rng.normal(size=8)[c]
    assert clustered_se(v, c) == pytest.approx(v[::50].std(ddof=1) / np.sqrt(8))
    assert clustered_se(v, c) > 6 * clustered_se(v)
    assert clustered_se(v, np.zeros(400)) == np.inf                             # one cluster: no error estimate
    assert combined_se(3.0, 16.0) == pytest.approx(5.0) and combined_se(3.0) == 3.0


def test_a_latin_hypercube_takes_its_main_effects_out_of_the_error():
    """Additive response over a 3-parameter hypercube of 16 draws: its main effects carry no error of the mean, the
    interaction does; the plain cluster-robust SE counts both and is far wider."""
    G, S = 16, 1600
    D = (np.column_stack([rng.permutation(G) for _ in range(3)]) + rng.uniform(size=(G, 3))) / G
    c = np.repeat(np.arange(G), S // G)
    additive = (3 * D[:, 0] + 2 * D[:, 1] - D[:, 2])[c] + rng.normal(0, 0.01, S)
    assert clustered_se(additive, c, D) < 0.05 * clustered_se(additive, c)
    with_interaction = additive + (4 * (D[:, 0] - 0.5) * (D[:, 1] - 0.5))[c]
    assert clustered_se(with_interaction, c, D) > 3 * clustered_se(additive, c, D)
    few = c % 4                                          # 4 draws of 3 parameters: too few to fit, the plain form
    assert clustered_se(additive, few, D[:4]) == clustered_se(additive, few)


def test_ensemble_replicates_variance_is_scaled_by_the_effort_and_checked():
    names = ("a", "b")
    m = np.array([[1.0, 3.0], [2.0, 5.0], [3.0, 7.0]])
    e = EnsembleReplicates(names, m, np.full((3, 2), 0.5), effort=0.25)
    assert e.cost_variance("b") == pytest.approx(4.0 * 0.25)
    assert e.difference_variance("a", "b") == pytest.approx(1.0 * 0.25)
    assert "3 repeated trajectory ensembles at 25% of the blocks" in sources_text(100, 8, e)
    assert "NOT included" in sources_text(100, 0, None)
    with pytest.raises(ValueError, match="R >= 2"):
        EnsembleReplicates(names, m[:1], m[:1])
    with pytest.raises(ValueError, match="effort"):
        EnsembleReplicates(names, m, m, effort=0.0)


OPTS = (Option("nothing", "none"), Option("scale", "scaling", 4e5, rate_reduction=0.5),
        Option("fence", "fence", 5e5, capacity_kj=2000, height_m=3, repair_days=30))
MATERIALS = {"soil.ground_friction_angle_deg": (2.0, 30.0)}


def _study(u_seed, sim_seed, *, draws=20, samples=400, blocks=300, ensemble=None, **kw):
    sc = simulation.scenario_from_dict(TOE)
    return MitigationStudy(hazard=HAZ, options=OPTS, consequences=CONSTANT_V,
                           uncertainty=Uncertainty(samples=samples, seed=u_seed, material_draws=draws,
                                                   materials=MATERIALS, **kw),
                           context=SimulationContext(sc, n_blocks=blocks, seed=sim_seed), ensemble=ensemble)


def _replicated(seed, R=2):
    """The study at seed ``seed`` with R repeated ensembles (independent simulation seeds, the same samples)."""
    reps = [_study(seed, 10_000 + 10 * seed + r).uncertain for r in range(R)]
    ens = EnsembleReplicates(tuple(reps[0]["names"]), np.array([u["mean"] for u in reps]),
                             np.array([u["probability_best"] for u in reps]), effort=1.0)
    return _study(seed, 500 + seed, ensemble=ens)


def test_seed_repeat_z_scores_have_unit_spread():
    """Over 24 seeds (joint samples, material draws and their trajectory ensembles all
    re-drawn), the z-scores (value - mean over seeds) / reported SE have an sd between 0.7 and 1.4, for the
    difference of the two cheapest options and for the expected cost of doing nothing.  Each material draw is its
    own ensemble, so the clustered SE carries the trajectory noise (the hazard is fixed here; the app adds the
    hazard simulation's part by repeated ensembles).  The draws are a Latin hypercube, whose strata the SE takes
    into account.  Measured: sd of z 0.81 (difference) and 0.85 (doing nothing); 0.36 with the draws counted as
    independent (too wide), 3.05 with the samples counted as independent and independent draws (too narrow; on
    the demo that SE was 10 times too small)."""
    diffs, d_se, naive, nothing, nothing_se = [], [], [], [], []
    for seed in range(24):
        s = _study(seed, 500 + seed)
        u = s.uncertain
        i, j = u["names"].index("nothing"), u["names"].index("fence")
        d = u["total"][:, j] - u["total"][:, i]
        diffs.append(d.mean())
        d_se.append(float(clustered_se(d, u["clusters"], u["design"])))
        naive.append(float(clustered_se(d, u["clusters"])))          # the draws taken as independent
        nothing.append(u["mean"][i])
        nothing_se.append(u["se"][i])
    diffs, nothing = np.array(diffs), np.array(nothing)
    z_d = (diffs - diffs.mean()) / np.array(d_se)
    z_n = (nothing - nothing.mean()) / np.array(nothing_se)
    assert 0.7 <= z_d.std(ddof=1) <= 1.4, z_d.std(ddof=1)
    assert 0.7 <= z_n.std(ddof=1) <= 1.4, z_n.std(ddof=1)
    # the draws are a Latin hypercube: counted as independent draws, the clustered SE is far too wide
    assert ((diffs - diffs.mean()) / np.array(naive)).std(ddof=1) < 0.6


def test_with_ensemble_keeps_the_slope_models_and_gives_the_same_numbers():
    """The ensembles added to a study whose slope models are computed (the assessment computes them while the
    ensembles run beside): the models are kept, not re-simulated, and every sampled cost and error is the one of
    a study built with the ensembles from the start."""
    ens = _replicated(3).ensemble
    first = _study(3, 503)
    first.parameter_ranges()
    added = first.with_ensemble(ens)
    assert added._slopes is first._slopes and added.ensemble is ens and first.ensemble is None
    built = _study(3, 503, ensemble=ens)
    for key in ("mean", "se", "probability_best"):
        np.testing.assert_array_equal(added.uncertain[key], built.uncertain[key])
    assert added.resolution()["text"] == built.resolution()["text"]


def test_resolution_reports_the_sources_and_the_clustered_error():
    s = _replicated(3)
    res = s.resolution()
    assert "400 joint samples in 20 material re-simulations (clustered, a Latin hypercube)" in res["text"]
    assert "2 repeated trajectory ensembles" in res["text"]
    t = s.ranking()
    assert (t["expected_total_cost_se"] > 0).all()
    u = s.uncertain
    k = u["names"].index(res["first"])
    assert 0 < res["probability_best_se"] < 0.5 and np.isfinite(res["difference_se"])


def test_adaptive_effort_doubles_until_resolved_or_budget_and_says_which():
    s = _study(1, 2, draws=3, samples=50, max_samples=200, max_material_draws=12)
    out, effort = adapt_effort(s)
    first, last = effort.rounds[0], effort.rounds[-1]
    assert (first.samples, first.material_draws) == (50, 3)
    assert effort.reached in ("ranking resolved", "precision target", "budget")
    if effort.reached == "budget":
        assert (last.samples, last.material_draws) == (200, 12) and "NOT resolved" in effort.text()
    else:
        assert last.resolved or last.worst_relative_se <= 0.05
    assert out.uncertainty.samples == last.samples and len(effort.rounds) <= 3
    # a budget equal to the start: one round, stopped by the budget unless already resolved
    one, e1 = adapt_effort(_study(1, 2, draws=3, samples=50, max_samples=50, max_material_draws=3))
    assert len(e1.rounds) == 1 and one.uncertainty.samples == 50


@pytest.mark.parametrize("table, match", [
    ({"precision_target": 0}, "precision_target = 0 must be a share of the expected cost > 0 and <= 1"),
    ({"precision_target": 1.5}, "precision_target = 1.5 must be"),
    ({"max_samples": 1}, "max_samples = 1 must be a whole number >= 2"),
    ({"samples": 500, "max_samples": 100}, "max_samples = 100 is below uncertainty.samples = 500"),
    ({"material_draws": 8, "max_material_draws": 4}, "max_material_draws = 4 is below uncertainty.material_draws"),
    ({"ensemble_replicates": 1}, "ensemble_replicates = 1 must be 0 \\(off\\) or a whole number >= 2"),
    ({"ensemble_effort": 0}, "ensemble_effort = 0 must be a share of the blocks > 0 and <= 1"),
])
def test_bad_precision_targets_and_budgets_are_refused_naming_the_field(table, match):
    with pytest.raises(MitigationError, match=match):
        parse_mitigation({"options": [{"name": "n", "kind": "none"}], "uncertainty": table}, "site.toml")


def test_unset_budgets_follow_a_larger_start():
    from riskrf.risk.mitigation_inputs import _uncertainty
    used = []
    u = _uncertainty({"samples": 6000}, "site.toml", used)
    assert u.max_samples == 6000 and u.max_material_draws == 32
    assert any(x.startswith("uncertainty.max_samples = 6000") for x in used)
