"""The road share by block mass of the mitigation study (riskrf.risk.slope_models.SlopeModels.road_profile): mass
strata pooled over the mass-coupled run and the seeder's reference run, against hand counts and a known law.

The runs here are synthetic (Bernoulli arrivals and road crossings with a known share by mass), so that the
estimator's counts, its lack of bias and its smaller spread can be checked exactly and fast."""
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from riskrf.hazard.mass_coupling import MassCoupledSamples, stratified_log_uniform
from riskrf.risk.loss_engine import MassGrid
from riskrf.risk.slope_models import SlopeModels

EDGES = np.array([1000.0, 2000.0, 4000.0, 8000.0, 16000.0])      # the mass-coupled run's classes [kg]
P_REACH = 0.5                                                     # P(barrier line), every mass


def true_share(m):
    """P(road | barrier line) of a block of mass m [kg]: 0.1 below 4,000 kg, 0.2 above (a step at a class edge)."""
    return np.where(np.asarray(m) < 4000.0, 0.1, 0.2)


class _Run:
    """A stand-in for simulation.SimulationResult: block masses and the first crossings of two lines."""

    def __init__(self, masses, at, road):
        self.n = masses.size
        self.blocks = {"mass": masses}
        self.scenario = SimpleNamespace(collectors=[SimpleNamespace(name="barrier"), SimpleNamespace(name="road")])
        self._first = {"barrier": np.flatnonzero(at), "road": np.flatnonzero(road)}

    def collector(self, name, first_only=True):
        return pd.DataFrame({"block": self._first[name]})


def _models(seed, *, n_coupled=4000, n_ref=20000, reference=True):
    rng = np.random.default_rng(seed)

    def blocks(m):
        at = rng.uniform(size=m.size) < P_REACH
        return at, at & (rng.uniform(size=m.size) < true_share(m))
    m_c = stratified_log_uniform(EDGES[0], EDGES[-1], n_coupled, rng)
    at_c, road_c = blocks(m_c)
    m_r = np.exp(rng.normal(np.log(1500.0), 1.0, n_ref))           # seeder masses: most below 2,000 kg
    at_r, road_r = blocks(m_r)
    speed = np.where(at_c, 10.0, np.nan)
    vel = MassCoupledSamples(m_c, speed, np.where(at_c, 1.0, np.nan), EDGES, "barrier")
    hazard = SimpleNamespace(mass_coupled=True, velocity=vel, reach_probability=P_REACH)
    ref = _Run(m_r, at_r, road_r)
    overall = road_r.sum() / at_r.sum()
    edges = np.geomspace(100.0, EDGES[-1], 61)
    grid = MassGrid(edges, np.sqrt(edges[:-1] * edges[1:]), np.zeros(60))
    ctx = SimpleNamespace(barrier_collector="barrier", road_collector="road")
    sl = SlopeModels(hazard, ctx, ref if reference else None, None, grid, float(overall), road_c, 100.0, "test")
    return sl, (m_c, at_c, road_c), (m_r, at_r, road_r), overall


def test_each_class_pools_both_runs_blocks_by_mass():
    sl, (m_c, at_c, road_c), (m_r, at_r, road_r), overall = _models(1)
    share = sl.road_profile * overall
    mid = sl.grid.mid
    for c in range(EDGES.size - 1):
        lo, hi = EDGES[c], EDGES[c + 1]
        in_c, in_r = (m_c >= lo) & (m_c < hi), (m_r >= lo) & (m_r < hi)
        expected = (road_c[in_c].sum() + road_r[in_r].sum()) / (at_c[in_c].sum() + at_r[in_r].sum())
        bins = (mid >= lo) & (mid < hi)
        assert bins.any()
        np.testing.assert_allclose(share[bins], expected, rtol=1e-12)


def test_strata_below_the_simulated_masses_are_collapsed_into_groups_of_enough_blocks():
    sl, _, (m_r, at_r, road_r), overall = _models(2)
    stratum_of_bin, in_range, arrivals, road = sl.road_counts()
    assert in_range.sum() == EDGES.size - 1 and (~in_range).sum() == int(np.ceil(np.log(1000 / 100) / np.log(2)))
    light = sl.grid.mid < EDGES[0]
    share = sl.road_profile * overall
    groups = np.unique(share[light])
    need = 20.0 / overall                      # blocks at the barrier line of each group
    for g in groups:
        strata = np.unique(stratum_of_bin[light][share[light] == g])
        assert arrivals[strata].sum() >= need
        assert g == pytest.approx(road[strata].sum() / arrivals[strata].sum(), rel=1e-12)
    # only the reference run's blocks lie below the simulated masses: its own counts there
    n_below = int((~in_range).sum())
    lightest = EDGES[0] / 2.0 ** n_below                  # strata of the classes' width (ln 2) below 1,000 kg
    assert arrivals[~in_range].sum() == at_r[(m_r < EDGES[0]) & (m_r >= lightest)].sum()


def test_pooled_share_is_unbiased_and_spreads_less_than_the_coupled_run_alone():
    """Over 40 synthetic seeds: the lightest class's share (true 0.1) is unbiased, and pooling the reference run's
    many light blocks shrinks its spread about as the binomial law says (sqrt(A_coupled / A_pooled))."""
    pooled, alone, sizes = [], [], []
    for seed in range(40):
        sl, (m_c, at_c, road_c), _, overall = _models(100 + seed)
        pooled.append(sl.road_profile[np.searchsorted(sl.grid.mid, 1500.0)] * overall)
        c0 = (m_c < EDGES[1]) & at_c
        alone.append(road_c[c0].sum() / c0.sum())
        sizes.append((c0.sum(), sl.road_counts()[2][sl.road_counts()[1]][0]))
    pooled, alone = np.array(pooled), np.array(alone)
    assert abs(pooled.mean() - 0.1) < 3 * pooled.std(ddof=1) / np.sqrt(pooled.size)
    ratio = np.sqrt(np.mean([a / p for a, p in sizes]))
    assert pooled.std(ddof=1) < 0.6 * alone.std(ddof=1)
    assert pooled.std(ddof=1) / alone.std(ddof=1) == pytest.approx(ratio, rel=0.35)


def test_without_a_reference_run_the_classes_of_the_coupled_run_alone():
    sl, (m_c, at_c, road_c), _, _ = _models(3, reference=False)
    share = sl.road_profile * sl.road_share
    c0 = (m_c < EDGES[1]) & at_c
    light = sl.grid.mid < EDGES[0]
    # below the simulated masses there are no blocks: the lightest class's share (the stated extrapolation)
    np.testing.assert_allclose(share[light], road_c[c0].sum() / c0.sum(), rtol=1e-12)


# ---- the joint material draws: their design and their blocks -------------------------------------------------
def test_material_design_is_a_latin_hypercube_and_a_net_for_powers_of_two():
    from riskrf.risk.slope_models import material_design
    for p, G in ((3, 32), (3, 8), (2, 16), (3, 12), (1, 20)):
        D = material_design(p, G, np.random.default_rng(7))
        assert D.shape == (G, p) and np.all((D >= 0) & (D < 1))
        for j in range(p):       # every coordinate: one draw in each of its G strata
            assert sorted(np.floor(D[:, j] * G).astype(int)) == list(range(G))
    # a (0, m, 2)-net in base 2 (Sobol's first two coordinates): every box of 1/2^a x 1/2^(m-a) holds one draw,
    # which a random pairing of strata misses; the random hypercube keeps its former stream for G = 20
    D = material_design(3, 32, np.random.default_rng(7))
    for a in range(6):
        boxes = np.floor(D[:, 0] * 2 ** a).astype(int) * 2 ** (5 - a) + np.floor(D[:, 1] * 2 ** (5 - a)).astype(int)
        assert sorted(boxes) == list(range(32)), a
    rng = np.random.default_rng(3)
    old = (rng.permutation(20) + rng.uniform(size=20)) / 20
    np.testing.assert_array_equal(material_design(1, 20, np.random.default_rng(3))[:, 0], old)


def test_draw_blocks_sets_the_blocks_of_the_joint_draws_only():
    import simulation
    from riskrf.risk.measures import SimulationContext
    from riskrf.risk.mitigation import MitigationStudy, Option, Uncertainty, parse_mitigation
    from riskrf.risk.mitigation_inputs import MitigationError

    from .test_mitigation import CONSTANT_V, HAZ, TOE
    sc = simulation.scenario_from_dict(TOE)
    opts = (Option("nothing", "none"), Option("ditch", "ditch", 1.5e6, x_m=31.0, width_m=8.0, depth_m=1.0,
                                               material="gravel"))
    s = MitigationStudy(hazard=HAZ, options=opts, consequences=CONSTANT_V,
                        uncertainty=Uncertainty(samples=50, material_draws=4, draw_blocks=150,
                                                materials={"gravel.ground_friction_angle_deg": (20.0, 45.0)}),
                        context=SimulationContext(sc, n_blocks=400, seed=3))
    ms = s._models
    assert [m.result.n for m in ms[1:5]] == [150] * 4 and [m.result.n for m in ms[5:]] == [400, 400]
    s.central_parameters()                    # the ditch re-simulated on every model with that model's blocks
    assert s._derived["ditch"][2].shape == (7,)
    u = parse_mitigation({"uncertainty": {"draw_blocks": 2500}}, "site.toml", require_options=False)[5]
    assert u.draw_blocks == 2500 and Uncertainty().draw_blocks is None
    with pytest.raises(MitigationError, match="site.toml: uncertainty.draw_blocks = 0 must be a whole number >= 1"):
        parse_mitigation({"uncertainty": {"draw_blocks": 0}}, "site.toml", require_options=False)
