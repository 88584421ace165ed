"""The trajectory model's uncertainty carried to the decision: material draws, the design-energy split, the
ranking over draws, EVPI and the EVSI of a field calibration, and `[model_uncertainty]` in `riskrf assess`."""
import json

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

import simulation
from riskrf.app.site import SiteError, load_site
from riskrf.hazard.annual_hazard import EnergyHazard
from riskrf.hazard.model_uncertainty import ModelUncertaintyError, design_energy_split
from riskrf.risk.model_decision import DecisionValueError, ModelUncertainRanking

from .conftest import ROOT

SCENARIO = ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml"
INVENTORY = ROOT / "riskrf" / "data" / "lauterbrunnen_tls_2018.csv"


# ---- an exact decision: two options, a two-point prior, Gaussian observations -------------------------------------
# Costs C[theta, option]: option A costs 10 if theta_1 and 20 if theta_2, option B 14 either way; prior 1/2 each.
# Prior means A 15, B 14: choose B (14).  Perfect information: min(10, 14) = 10, min(20, 14) = 14, mean 12, so
# EVPI = 2.  A calibration stop x ~ N(mu_theta, h) with mu = 40, 42 m and h = 1 m (every simulated stop of a draw at
# mu: the kernel density is N(mu, h), h = obs_error_m).  After N stops with mean xbar, A is chosen when
# P(theta_1 | x) > 0.6, i.e. L1/L2 > 1.5, i.e. N (mu2 - mu1)(mu1 + mu2 - 2 xbar) / (2 h^2) > ln 1.5, i.e.
# xbar < 41 - ln(1.5) / (2 N); xbar ~ N(mu, h / sqrt N).  EVSI = 1/2 (14 - 10) P(A | theta_1) - 1/2 (20 - 14)
# P(A | theta_2) (Raiffa & Schlaifer 1961, ch. 4: the preposterior value of a normal sample, two actions).
COSTS = np.array([[10.0, 14.0], [20.0, 14.0]])
STOPS = [np.full(40, 40.0), np.full(40, 42.0)]


def _hand_evsi(n):
    x_star = 41.0 - np.log(1.5) / (2 * n)
    return 0.5 * 4 * stats.norm.cdf((x_star - 40) * np.sqrt(n)) - 0.5 * 6 * stats.norm.cdf((x_star - 42) * np.sqrt(n))


def test_exact_two_option_two_point_prior():
    r = ModelUncertainRanking(("A", "B"), COSTS, currency="CHF")
    assert r.evpi() == pytest.approx(2.0, abs=1e-12)
    assert r.best_now() == "B"
    assert r.probability_best().tolist() == [0.5, 0.5]
    for n, hand in ((1, 1.2311), (3, 1.7971)):
        assert _hand_evsi(n) == pytest.approx(hand, abs=1e-4)
        v = r.calibration_value(STOPS, n_releases=n, profile_range_m=(0, 100), obs_error_m=1.0, n_datasets=20_000,
                                seed=1)
        # the defensive uniform share (1e-3 of the density) moves the exact value by < 0.006
        assert v.evsi_estimate == pytest.approx(hand, abs=4 * v.standard_error + 0.006), (n, v.evsi_estimate)
        assert v.standard_error < 0.015
    none = r.calibration_value(STOPS, n_releases=0, profile_range_m=(0, 100), obs_error_m=1.0, n_datasets=50)
    assert none.evsi == 0.0 and none.probability_decision_changes == 0.0          # no data, no value
    many = r.calibration_value(STOPS, n_releases=60, profile_range_m=(0, 100), obs_error_m=1.0, n_datasets=200)
    assert many.evsi == pytest.approx(2.0, abs=1e-9)                                # identifying data: the EVPI


def test_verdict_weighs_the_evsi_against_the_calibration_cost():
    r = ModelUncertainRanking(("A", "B"), COSTS, currency="CHF")
    kw = dict(n_releases=1, profile_range_m=(0, 100), obs_error_m=1.0, n_datasets=4000, seed=2)
    cheap = r.calibration_value(STOPS, calibration_cost=0.5, **kw)
    dear = r.calibration_value(STOPS, calibration_cost=1.9, cost_is_assumption=True, **kw)
    assert cheap.calibrate_first and cheap.verdict().startswith("calibrate first, then decide")
    assert not dear.calibrate_first and dear.verdict().startswith("decide now")
    assert "ASSUMED default" in dear.verdict() and "(stated)" in cheap.verdict()
    assert json.loads(json.dumps(cheap.to_dict()))["calibrate_first"] is True


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), J=st.integers(2, 5), K=st.integers(2, 4), n=st.integers(0, 6))
def test_evsi_lies_between_zero_and_the_evpi(seed, J, K, n):
    rng = np.random.default_rng(seed)
    costs = rng.uniform(0, 10, (J, K))
    weights = rng.uniform(0.1, 1, J)
    stops = [rng.normal(rng.uniform(20, 80), rng.uniform(0.5, 8), 30) for _ in range(J)]
    r = ModelUncertainRanking(tuple("ABCD"[:K]), costs, weights=weights)
    v = r.calibration_value(stops, n_releases=n, profile_range_m=(0, 100), n_datasets=60, seed=seed)
    evpi = r.evpi()
    assert evpi == pytest.approx(float((r.weights @ costs).min() - r.weights @ costs.min(axis=1)))
    assert 0.0 <= v.evsi <= evpi + 1e-9
    assert v.evsi_estimate <= evpi + 1e-9                       # the paired estimator can never exceed the EVPI
    if np.isfinite(v.standard_error) and v.standard_error > 0:
        assert v.evsi_estimate >= -4 * v.standard_error          # the Bayes choice does not lose on average
    assert sum(v.after_calibration.values()) == pytest.approx(1.0)


def test_ranking_summary_splits_each_options_cost_variance():
    rng = np.random.default_rng(3)
    means = np.array([[1.0, 2.0], [3.0, 2.5], [2.0, 2.2]])
    samples = means[:, None, :] + rng.normal(0, 0.3, (3, 400, 2))
    r = ModelUncertainRanking(("A", "B"), samples.mean(axis=1), sample_costs=samples)
    t = r.summary().set_index("option")
    s = samples[:, :, 0]
    between = np.var(s.mean(axis=1))
    assert t.loc["A", "share_of_variance_from_trajectory_model"] == pytest.approx(between / s.var(), rel=1e-9)
    assert t["probability_best_given_model"].sum() == pytest.approx(1.0)
    assert t["probability_best_joint"].sum() == pytest.approx(1.0)
    assert t.loc["A", "probability_best_given_model"] == pytest.approx(2 / 3)     # draws 0 and 2
    per = r.per_draw()
    assert per["best_option"].tolist() == ["A", "B", "A"]
    with pytest.raises(DecisionValueError, match="costs must be a table"):
        ModelUncertainRanking(("A", "B", "C"), means)
    with pytest.raises(DecisionValueError, match="stops: give the simulated stops of each of the 3 draws"):
        r.calibration_value(STOPS, n_releases=1, profile_range_m=(0, 100))


# ---- the design-energy split --------------------------------------------------------------------------------------
def _hazard(scale=1.0):
    gr = pytest.importorskip("riskrf").fit_gutenberg_richter(
        np.random.default_rng(1).pareto(0.8, 300) * 100 + 100, 10.0, m_min=100.0)
    v = np.random.default_rng(2).gamma(9.0, 2.0, 400)
    return EnergyHazard(mass=gr, velocity=v * scale, rate_per_year=gr.rate_min, reach_probability=0.4)


def test_design_energy_split_by_the_law_of_total_variance():
    """Two draws whose speeds differ by sqrt 2 have T-year energies (and bootstrap replicates, same seed) in the
    ratio 2, so with one draw's replicate mean m and variance v: between = (2m - m)^2 / 4, within = (v + 4v) / 2."""
    base = _hazard()
    reps = base.energy_at_return_period_replicates([50.0], 60, seed=4)[:, 0]
    m, v = reps.mean(), reps.var()
    split = design_energy_split([base, _hazard(np.sqrt(2.0))], [50.0], n_bootstrap=60, seed=4, reference=base)
    r = split.row(50.0)
    assert r["variance_trajectory_model_kj2"] == pytest.approx(m ** 2 / 4, rel=0.02)
    assert r["variance_statistical_kj2"] == pytest.approx(2.5 * v, rel=0.02)
    assert r["share_from_trajectory_model"] == pytest.approx((m ** 2 / 4) / (m ** 2 / 4 + 2.5 * v), rel=0.02)
    assert r["energy_kj_reference"] == pytest.approx(float(base.energy_at_return_period(50.0)))
    assert r["combined_low_kj"] <= r["model_low_kj"] <= r["model_high_kj"] <= r["combined_high_kj"]
    same = design_energy_split([base, base, base], [50.0], n_bootstrap=30, seed=4).row(50.0)
    assert same["share_from_trajectory_model"] == pytest.approx(0.0, abs=1e-12)
    assert same["model_low_kj"] == same["model_high_kj"]
    assert any("trajectory model" in t for t in split.text())
    with pytest.raises(ModelUncertaintyError, match="at least 2 draws"):
        design_energy_split([base], [50.0])


# ---- material draws -----------------------------------------------------------------------------------------------
def test_preset_spread_is_labelled_and_latin_hypercube_draws_fill_every_slice():
    spread = simulation.preset_spread(SCENARIO)
    assert spread.loc["materials.talus.ground_friction_angle_deg", ["low", "high"]].tolist() == [34.0, 42.0]
    assert "materials.talus.normal_restitution.mean" not in spread.index          # Wyllie's law has no mean
    assert spread["assumption"].all() and spread["basis"].str.startswith("ASSUMPTION").all()
    d = simulation.material_draws(SCENARIO, 7, seed=3)
    assert "ASSUMPTIONS" in d.attrs["basis"]
    for col in d:
        lo, hi = spread.loc[col, ["low", "high"]]
        slices = np.floor((d[col] - lo) / (hi - lo) * 7).astype(int)
        assert sorted(slices) == list(range(7)), col                                 # one draw per slice
    sc = simulation.scenario_with_values(SCENARIO, d.iloc[0].to_dict())
    talus = next(m for m in sc.materials if m.name == "talus")
    assert talus.ground_friction_deg == pytest.approx(d.iloc[0]["materials.talus.ground_friction_angle_deg"])


def test_the_rocks_bench_landing_scale_is_spread_where_a_data_derived_table_carries_it():
    # the data-derived bedrock carries CRSP's vt0 = 76.2 m/s; the validation (docs/validation/presets_vt0.csv) puts
    # Authume P1's bench landings near 30 m/s, so the ASSUMED range runs from 30 m/s up to the table's value
    odot = ROOT / "simulation" / "scenarios" / "odot_catchment_cut.toml"
    spread = simulation.preset_spread(odot)
    row = spread.loc["materials.rock.tangential.normal_scale_ms"]
    assert (row["low"], row["high"]) == (30.0, pytest.approx(76.2)) and row["assumption"]
    assert "bench" in row["basis"] and "materials.catchment.tangential.normal_scale_ms" not in spread.index
    # and its fitted e_T (Coulomb law) by +-0.15 as the soil's, where the published bedrock (Stronge) has none
    e_t = spread.loc["materials.rock.tangential.mean"]
    assert [e_t["low"], e_t["high"]] == pytest.approx([e_t["value"] - 0.15, e_t["value"] + 0.15])
    d = simulation.material_draws(odot, 4, seed=2)
    assert d["materials.rock.tangential.normal_scale_ms"].between(30.0, 76.2).all()
    rock = next(m for m in simulation.scenario_with_values(odot, d.iloc[0].to_dict()).materials if m.name == "rock")
    assert rock.et_normal_scale_ms == pytest.approx(d.iloc[0]["materials.rock.tangential.normal_scale_ms"])
    # the published bedrock (Stronge's law) has no vt0: nothing to spread; nor has a bedrock whose vt0 is at or
    # below the range's low end (one-sided: it only ever removes energy at a landing)
    assert not simulation.preset_spread(SCENARIO).index.str.endswith("normal_scale_ms").any()
    from simulation.calibration import scenario_dict
    low, _ = scenario_dict(odot)
    low["materials"]["rock"]["tangential"] = {"normal_scale_ms": 25.0}
    assert "materials.rock.tangential.normal_scale_ms" not in simulation.preset_spread(low).index


def test_a_data_derived_spread_plugs_in_first(monkeypatch):
    from simulation import material_uncertainty as mu

    def data_source(preset, table):
        return {"ground_friction_angle_deg": (30.0, 31.0, "data: a test source")} if preset == "talus" else {}
    monkeypatch.setattr(mu, "PRESET_SPREAD_SOURCES", [data_source] + mu.PRESET_SPREAD_SOURCES)
    spread = simulation.preset_spread(SCENARIO)
    row = spread.loc["materials.talus.ground_friction_angle_deg"]
    assert (row["low"], row["high"], row["assumption"]) == (30.0, 31.0, False)
    assert spread.loc["materials.talus.tangential.mean", "assumption"]               # the rest stays assumed


def test_posterior_draws_keep_rows_whole():
    post = pd.DataFrame({"materials.talus.ground_friction_angle_deg": np.arange(10.0) + 30,
                         "materials.talus.tangential.mean": np.arange(10.0) / 20 + 0.3})
    d = simulation.material_draws(SCENARIO, 4, posterior=post, seed=1)
    assert len(d) == 4 and "posterior" in d.attrs["basis"]
    for _, row in d.iterrows():
        i = int(row.iloc[0] - 30)
        assert row.iloc[1] == pytest.approx(post.iloc[i, 1])


# ---- the site file: bad input before any work, and the assessment ------------------------------------------------
def _posterior_file(path, columns):
    with open(path, "w") as fh:
        fh.write("# simulation pooled posterior; bounds = "
                 + json.dumps({c: [0.0, 60.0] for c in columns}) + "\n")
        pd.DataFrame({c: np.linspace(0.4, 0.6, 6) if c.endswith("mean") else np.linspace(35, 40, 6)
                      for c in columns}).to_csv(fh, index=False)
    return path


def _site(tmp_path, extra="", options=None):
    opts = options or """
[[options]]
name = "do nothing"
kind = "none"
capital_cost = 0

[[options]]
name = "fence 2000 kJ"
kind = "fence"
capital_cost = 900000
annual_maintenance = 10000
life_years = 25
repair_cost_per_impact = 40000
replacement_cost = 250000
capacity_kj = 2000
height_m = 5.0
"""
    text = f"""
[inventory]
path = "{INVENTORY}"
m_max_kg = 2.0e6
rate_scale = 0.05

[hazard]
scenario = "{SCENARIO}"
n_blocks = 1500
option_blocks = 500
bootstrap = 20
fences_kj = [2000]

[uncertainty]
samples = 200
{opts}
{extra}
"""
    p = tmp_path / "site.toml"
    p.write_text(text)
    return p


def test_bad_posterior_refused_before_any_work(tmp_path):
    good = _posterior_file(tmp_path / "post.csv", ["materials.talus.ground_friction_angle_deg"])
    assert load_site(_site(tmp_path, '[model_uncertainty]\nposterior = "post.csv"')).model_uncertainty is not None
    _posterior_file(tmp_path / "clay.csv", ["materials.clay.ground_friction_angle_deg"])
    with pytest.raises(SiteError, match=r"model_uncertainty.posterior = 'clay.csv'.*clay.csv.*"
                                        r"'materials.clay.ground_friction_angle_deg'.*does not define"):
        load_site(_site(tmp_path, '[model_uncertainty]\nposterior = "clay.csv"'))
    (tmp_path / "plain.csv").write_text("a,b\n1,2\n")
    with pytest.raises(SiteError, match="plain.csv: not a posterior written by PooledCalibration.write"):
        load_site(_site(tmp_path, '[model_uncertainty]\nposterior = "plain.csv"'))
    with pytest.raises(SiteError, match="model_uncertainty.posterior = 'none.csv': file not found"):
        load_site(_site(tmp_path, '[model_uncertainty]\nposterior = "none.csv"'))
    with pytest.raises(SiteError, match="unknown field model_uncertainty.'draw'; did you mean 'draws'"):
        load_site(_site(tmp_path, "[model_uncertainty]\ndraw = 4"))
    with pytest.raises(SiteError, match="model_uncertainty.draws = 1 must be a whole number >= 2"):
        load_site(_site(tmp_path, "[model_uncertainty]\ndraws = 1"))
    assert good.exists()


def test_off_by_default(tmp_path):
    site = load_site(_site(tmp_path))
    assert site.model_uncertainty is None
    assert not any(d.startswith("model_uncertainty") for d in site.defaults_used)


@pytest.fixture(scope="module")
def carried(tmp_path_factory):
    from riskrf.app.assess.run import run_assessment
    tmp = tmp_path_factory.mktemp("model_uncertainty")
    site = load_site(_site(tmp, "[model_uncertainty]\ndraws = 3\nmax_draws = 3\nn_blocks = 600\n"
                                "option_blocks = 300\nbootstrap = 20\nsynthetic_calibrations = 40\n"
                                "calibration_releases = 10"))
    return run_assessment(site)


def test_assess_carries_the_model_uncertainty_to_the_decision(carried, tmp_path):
    mu = carried.model_uncertainty
    s = carried.summary()["model_uncertainty"]
    assert s["draws"] == 3 and len(s["parameters"]) == 9 and "ASSUMPTIONS" in s["basis"]
    d = s["design_energy"]
    assert 0.0 <= d["share_of_variance_from_trajectory_model"] <= 1.0
    assert d["interval_kj"][0] <= d["trajectory_model_interval_kj"][0] <= d["trajectory_model_interval_kj"][1] \
        <= d["interval_kj"][1]
    assert d["energy_kj_reference"] == pytest.approx(
        float(carried.energy.hazard.energy_at_return_period(100.0)))
    assert {r["option"] for r in s["ranking"]} == {"do nothing", "fence 2000 kJ"}
    assert sum(r["probability_best_given_model"] for r in s["ranking"]) == pytest.approx(1.0)
    cal = s["calibration"]
    assert 0.0 <= cal["evsi"] <= s["evpi_material_parameters"] + 1e-9
    assert cal["calibration_cost"] == 100_000.0 and cal["calibration_cost_is_assumption"]
    assert s["verdict"].startswith(("calibrate first, then decide", "decide now"))
    assert any("calibration_cost" in u for u in carried.site.defaults_used)
    # the draws differ: the materials move the reach of the barrier line
    assert mu.per_draw["reach_probability"].nunique() == 3
    files = mu.write(tmp_path)
    draws = pd.read_csv(files[1])
    assert len(draws) == 3 and "cost:do nothing" in draws and "materials.talus.ground_friction_angle_deg" in draws
    json.dumps(carried.summary(), default=str)


def test_stop_density_is_the_pooled_calibrations_per_stop_likelihood():
    """Every simulated stop at 50 m: the kernel is N(50, obs_error) (Silverman's width of no spread is 0), mixed
    with the uniform share 1e-3 over the profile length (simulation.pooled.DEFENSIVE_SHARE)."""
    x = np.array([48.0, 50.0, 53.0])
    got = simulation.stop_density(np.full(30, 50.0), x, 100.0, obs_error_m=2.0)
    assert got == pytest.approx(0.999 * stats.norm.pdf(x, 50.0, 2.0) + 1e-3 / 100.0, rel=1e-12)
    import riskrf
    assert riskrf.ModelUncertainRanking is ModelUncertainRanking and callable(riskrf.energy_hazard_ensemble)


def test_a_road_record_is_reproduced_in_every_draw(tmp_path):
    """rate_basis = "road": each draw's release rate is recomputed so that doing nothing reproduces the falls
    recorded on the road (the draws move the reach, not the record)."""
    from functools import partial

    from riskrf.app.assess.decision import draw_evaluator
    from riskrf.app.model_uncertainty import _without_material_draws
    from riskrf.frequency.inventory.reader import read_inventory
    path = _site(tmp_path, "[model_uncertainty]\ndraws = 2")
    path.write_text(path.read_text().replace("rate_scale = 0.05", 'rate_scale = 0.05\nrate_basis = "road"'))
    site = load_site(path)
    inv = read_inventory(site.resolve(site.inventory.path))
    evaluate = partial(draw_evaluator, site, inv, rate_scale=0.05, rate_note=None, mitigation=site.mitigation,
                       design_masses=())
    draws = simulation.material_draws(SCENARIO, 2, seed=5)
    recorded = []
    gr = None
    for _, row in draws.iterrows():
        hz, study, result, share = evaluate(simulation.scenario_with_values(SCENARIO, row.to_dict()), 600, 300, 1,
                                            _without_material_draws(site.mitigation.uncertainty))
        gr = hz.mass
        recorded.append(study.evaluate("do nothing").road_falls_per_year)
    small = np.sum(inv.masses < gr.m_min)
    expected = (len(inv.masses[inv.masses >= gr.m_min]) + small) / inv.duration_years * 0.05
    assert recorded == pytest.approx([expected, expected], rel=1e-6)


def test_report_section_and_figures(carried, tmp_path):
    from types import SimpleNamespace

    from riskrf.report.format import Document
    from riskrf.report.html import _model_uncertainty_body
    mu = carried.model_uncertainty
    figs = mu.figures(tmp_path)
    assert all(f.exists() and f.stat().st_size > 1000 for f in figs)
    doc = Document(title="t")
    _model_uncertainty_body(doc, SimpleNamespace(model_uncertainty=mu, study=SimpleNamespace(currency="CHF")),
                            tmp_path, None)
    html = doc.render()
    assert "share of the variance from the trajectory model" in html     # (the title is the section list's)
    assert mu.verdict().split(":")[0] in html and html.count("data:image/png;base64,") == 2


def test_energy_hazard_ensemble_from_a_posterior_file(tmp_path):
    import riskrf
    from riskrf.hazard.model_uncertainty import energy_hazard_ensemble, read_model_posterior
    path = _posterior_file(tmp_path / "post.csv", ["materials.talus.ground_friction_angle_deg"])
    inv = riskrf.read_inventory(INVENTORY)
    gr = riskrf.fit_gutenberg_richter(inv.masses, inv.duration_years, m_max=2e6)
    ens = energy_hazard_ensemble(gr, SCENARIO, posterior=path, draws=3, n=300, seed=2, reference=False,
                                 rate_per_year=0.05 * gr.rate_min)
    post = read_model_posterior(path, SCENARIO)
    assert len(ens.hazards) == 3 and "posterior" in ens.basis
    assert set(ens.draws["materials.talus.ground_friction_angle_deg"]) <= set(post.iloc[:, 0])
    # a steeper rolling-resistance angle on the talus stops more blocks before the barrier line
    s = ens.summary().sort_values("materials.talus.ground_friction_angle_deg")
    assert s["reach_probability"].iloc[0] >= s["reach_probability"].iloc[-1]
    with pytest.raises(ModelUncertaintyError, match="post.csv.*materials.clay"):
        _posterior_file(tmp_path / "post.csv", ["materials.clay.ground_friction_angle_deg"])
        energy_hazard_ensemble(gr, SCENARIO, posterior=path, draws=2, n=300)


def test_a_posterior_table_is_checked_before_any_simulation():
    from riskrf.hazard.model_uncertainty import energy_hazard_ensemble
    bad = pd.DataFrame({"materials.clay.ground_friction_angle_deg": [20.0, 25.0]})
    with pytest.raises(ModelUncertaintyError, match="posterior column 'materials.clay.ground_friction_angle_deg'"):
        energy_hazard_ensemble(None, SCENARIO, posterior=bad, draws=2)
    steep = pd.DataFrame({"materials.talus.ground_friction_angle_deg": [20.0, 95.0]})
    with pytest.raises(ModelUncertaintyError, match="posterior draw 1: .*ground_friction_angle_deg"):
        energy_hazard_ensemble(None, SCENARIO, posterior=steep, draws=2)


# ---- EVPI with its Monte Carlo error: two options, a normal prior, the closed form ----------------------------------
# Option A costs 0, option B costs D ~ N(mu, sigma^2) with mu > 0, so A is chosen now; with perfect information B
# is chosen when D < 0.  EVPI = E[max(-D, 0)] = sigma phi(mu / sigma) - mu Phi(-mu / sigma) (Raiffa & Schlaifer
# 1961, ch. 4: the value of perfect information about a normal difference of two actions).
def _normal_evpi(mu, sigma):
    return sigma * stats.norm.pdf(mu / sigma) - mu * stats.norm.cdf(-mu / sigma)


@pytest.mark.parametrize("mu, sigma", [(1.0, 2.0), (3.0, 1.5)])
def test_evpi_estimate_recovers_the_closed_form_within_its_standard_error(mu, sigma):
    from riskrf.risk.model_decision import evpi_estimate
    exact = _normal_evpi(mu, sigma)                              # 0.396 and 0.0127
    rng = np.random.default_rng(7)
    J, seeds = 400, 300
    D = mu + sigma * rng.standard_normal((seeds, J))
    est = [evpi_estimate(np.column_stack([np.zeros(J), d])) for d in D]
    values = np.array([e.value for e in est])
    assert values.mean() == pytest.approx(exact, rel=0.05)       # unbiased at this size
    assert np.mean([e.upper_bound >= exact for e in est]) > 0.95
    z = np.array([(e.value - exact) / e.standard_error for e in est])
    if mu / sigma < 1:          # a choice that many draws change: the stated error is the real spread
        assert abs(z.mean()) < 0.25 and 0.8 < z.std() < 1.2 and np.mean(np.abs(z) <= 2) > 0.9
    else:                       # 2.3 % of draws change it (about 9 of 400): the regret is skewed and its s.e.
        assert z.std() > 1.5    # understates the spread (sd of z 2.6) -- why the bound, not 2 s.e., is reported
    r = ModelUncertainRanking(("A", "B"), np.column_stack([np.zeros(J), D[0]]))
    assert est[0].value == pytest.approx(r.evpi()) and r.evpi() > 0


def test_an_evpi_of_zero_from_few_draws_is_reported_with_its_upper_bound():
    """Eight draws of a case whose true EVPI is small but not 0: no draw changes the choice, the estimate is 0 with
    a standard error of 0 -- the text gives an upper bound above the true value instead of a bare 0."""
    from riskrf.risk.model_decision import evpi_estimate
    mu, sigma = 3.0, 1.0                                         # P(B cheaper) = 0.13 %
    d = mu + sigma * np.array([-1.2, -0.8, -0.3, 0.0, 0.2, 0.5, 0.9, 1.4])
    costs = np.column_stack([np.zeros(8), d])
    e = evpi_estimate(costs)
    assert e.value == 0.0 and e.standard_error == 0.0
    assert e.upper_bound > _normal_evpi(mu, sigma) > 0
    text = e.text("CHF")
    assert text.startswith("0 CHF (at most ") and "no draw of 8 changes the choice" in text
    r = ModelUncertainRanking(("A", "B"), costs, currency="CHF")
    assert "at most" in r.text()[-1]
    v = r.calibration_value([np.full(20, 40.0 + j) for j in range(8)], n_releases=5, profile_range_m=(0, 100),
                            n_datasets=20)
    assert v.evsi == 0.0 and v.to_dict()["evpi_upper_bound_97_5"] > 0
    assert "0 CHF, as is the EVPI of the material parameters (no draw of 8 changes the choice; both at most" \
        in v.verdict()


def test_more_draws_until_the_value_of_calibrating_is_resolved():
    """The trajectory model's draws are added (doubling, up to max_draws) until the choice between
    calibrating first and deciding now is resolved; the outputs say which stopped them."""
    from riskrf.app.model_uncertainty import calibration_resolved, effort_text
    from riskrf.risk.model_decision import CalibrationValue

    def value(evsi, se, bound, cost=100_000.0):
        return CalibrationValue(evsi=max(evsi, 0.0), evsi_estimate=evsi, standard_error=se, evpi=evsi, n_releases=20,
                                n_datasets=200, best_now="a", probability_decision_changes=0.0, after_calibration={},
                                calibration_cost=cost, evpi_upper_bound=bound)
    assert calibration_resolved(value(0.0, 0.0, 51_000.0)) == "decide now"            # even the bound is cheaper
    assert calibration_resolved(value(0.0, 0.0, 150_000.0)) == ""                     # 8 draws cannot tell
    assert calibration_resolved(value(300_000.0, 50_000.0, 400_000.0)) == "calibrate first"
    assert calibration_resolved(value(120_000.0, 50_000.0, 400_000.0)) == ""
    assert calibration_resolved(value(0.0, 0.0, 1e9, cost=None)) == "no cost stated"
    text = effort_text([(8, ""), (16, ""), (32, "")], 32, value(0.0, 0.0, 150_000.0))
    assert "8 -> 16 -> 32" in text and "NOT resolved" in text
    assert "decide now" in effort_text([(8, ""), (16, "decide now")], 32, value(0.0, 0.0, 51_000.0))


def test_a_draw_budget_below_the_draws_is_refused(tmp_path):
    with pytest.raises(SiteError, match="max_draws = 4 is below model_uncertainty.draws = 8"):
        load_site(_site(tmp_path, "[model_uncertainty]\nmax_draws = 4"))
