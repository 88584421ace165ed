"""One-way sensitivity (tornado) of the design energies.

Small synthetic hazards, no simulation: a constant speed makes the T-year energy exact
(E_T = 1/2 m_T v0^2 with m_T from the truncated power law's closed-form inverse), and velocity samples
give the design-block energy at a percentile exactly (1/2 m v_p^2, v_p = numpy's percentile).
"""
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from scipy import stats

import riskrf
from riskrf.hazard.annual_hazard import EnergyHazard
from riskrf.hazard.design_block import design_block
from riskrf.hazard.energy_study import design_energy_sensitivity
from riskrf.hazard.energy_tornado import DesignEnergyTornado, design_energy_tornado

LO, HI, B = 1.0e3, 1.0e6, 0.7
V0 = 20.0                      # m/s, every arriving block (the exact case)
DURATION = 4.0                 # years
SHARE = 0.1
T = 100.0
RHO = 2650.0


@pytest.fixture(scope="module")
def masses():
    with np.errstate(all="ignore"):
        return stats.truncpareto(B, HI / LO, scale=LO).rvs(400, random_state=np.random.default_rng(7))


@pytest.fixture(scope="module")
def fit(masses):
    return riskrf.fit_gutenberg_richter(masses, DURATION, m_min=LO, m_max=2.0e6)


def _hazard(fit, velocity):
    return EnergyHazard(mass=fit, velocity=velocity, rate_per_year=SHARE * fit.rate_min, reach_probability=0.8)


@pytest.fixture(scope="module")
def constant(fit):
    return _hazard(fit, np.full(64, V0))


@pytest.fixture(scope="module")
def spread(fit):
    return _hazard(fit, V0 * np.exp(0.25 * np.random.default_rng(3).standard_normal(4000)))


def _truncated_isf(p, b, m_min, m_max):
    """Closed-form inverse of P(M > m) = ((m/m_min)^-b - r) / (1 - r), r = (m_max/m_min)^-b (independent of riskrf)."""
    r = (m_max / m_min) ** -b
    return m_min * (p * (1.0 - r) + r) ** (-1.0 / b)


def _exact_T_energy(b, rate, m_max, reach=0.8):
    m_T = _truncated_isf(1.0 / (T * rate * reach), b, LO, m_max)
    return 0.5 * m_T * V0 ** 2 / 1000.0


def _row(tornado, output_prefix, input_prefix):
    t = tornado.table
    sel = t[t["design_energy"].str.startswith(output_prefix) & t["input"].str.startswith(input_prefix)]
    assert len(sel) == 1, (output_prefix, input_prefix, t[["design_energy", "input"]])
    return sel.iloc[0]


def test_b_interval_rows_are_exact_and_a_lower_b_gives_more_energy(constant, fit):
    tor = design_energy_tornado(constant, design_T=T, rate_share=SHARE)
    r = _row(tor, "100-year energy", "power-law exponent b")
    assert (r["low"], r["high"]) == pytest.approx(fit.b_ci)
    assert r["energy_base_kj"] == pytest.approx(_exact_T_energy(fit.b, constant.rate_per_year, 2.0e6), rel=1e-6)
    # b fixed at the ends of its interval, the rate at m_min kept: a heavier tail (low b) -> more energy
    assert r["energy_low_kj"] == pytest.approx(_exact_T_energy(fit.b_ci[0], constant.rate_per_year, 2.0e6), rel=1e-6)
    assert r["energy_high_kj"] == pytest.approx(_exact_T_energy(fit.b_ci[1], constant.rate_per_year, 2.0e6), rel=1e-6)
    assert r["energy_low_kj"] > r["energy_base_kj"] > r["energy_high_kj"]


def test_rate_share_rows_are_exact_and_monotone(constant):
    tor = design_energy_tornado(constant, design_T=T, rate_share=SHARE, rate_share_range=(0.05, 0.3))
    r = _row(tor, "100-year energy", "rate share")
    rate = constant.rate_per_year
    assert r["energy_low_kj"] == pytest.approx(_exact_T_energy(constant.mass.b, rate * 0.5, 2.0e6), rel=1e-6)
    assert r["energy_high_kj"] == pytest.approx(_exact_T_energy(constant.mass.b, rate * 3.0, 2.0e6), rel=1e-6)
    assert r["energy_low_kj"] < r["energy_base_kj"] < r["energy_high_kj"]


def test_m_max_rows_refit_the_law_and_agree_with_the_grid(constant, masses, fit):
    grid = design_energy_sensitivity(constant, masses, DURATION, m_min=LO, m_max_values=[1.0e6, 2.0e6, 4.0e6],
                                     rate_shares=[0.05, SHARE, 0.2], T=T)
    fresh = design_energy_tornado(constant, design_T=T, masses_kg=masses, duration_years=DURATION,
                                  m_max_range=(1.0e6, 4.0e6), rate_share=SHARE, rate_share_range=(0.05, 0.2))
    reused = design_energy_tornado(constant, design_T=T, masses_kg=masses, duration_years=DURATION,
                                   m_max_range=(1.0e6, 4.0e6), rate_share=SHARE, rate_share_range=(0.05, 0.2),
                                   sensitivity=grid)
    pd.testing.assert_frame_equal(fresh.table, reused.table, rtol=1e-9)
    r = _row(fresh, "100-year energy", "maximum credible block")
    g = grid.set_index(["m_max_kg", "rate_share"])["energy_kj"]
    assert r["energy_low_kj"] == pytest.approx(g[(1.0e6, SHARE)], rel=1e-9)
    assert r["energy_high_kj"] == pytest.approx(g[(4.0e6, SHARE)], rel=1e-9)
    # exact: the refitted law with m_max = 4e6 kg, its own b
    b4 = riskrf.fit_gutenberg_richter(masses, DURATION, m_min=LO, m_max=4.0e6).b
    assert r["energy_high_kj"] == pytest.approx(_exact_T_energy(b4, constant.rate_per_year, 4.0e6), rel=1e-6)
    assert r["energy_low_kj"] < r["energy_base_kj"] < r["energy_high_kj"]
    assert "refitted" in r["range_basis"]


def test_velocity_percentile_moves_the_block_energy_exactly(spread):
    vols = np.random.default_rng(5).lognormal(0.0, 1.0, 500)          # a block survey [m3]
    block = design_block(spread, rule="percentile", percentile=97, survey_volumes_m3=vols, sizes="blocks",
                         density_kg_m3=RHO)
    tor = design_energy_tornado(spread, design_T=T, block=block, rate_share=SHARE, velocity_percentile=95,
                                velocity_percentile_range=(90, 99))
    r = _row(tor, "design-block energy", "velocity percentile")
    v = spread.velocity
    m = np.percentile(vols, 97) * RHO
    for col, p in (("energy_low_kj", 90), ("energy_base_kj", 95), ("energy_high_kj", 99)):
        assert r[col] == pytest.approx(0.5 * m * np.percentile(v, p) ** 2 / 1000.0, rel=1e-12), col
    assert r["energy_low_kj"] < r["energy_base_kj"] < r["energy_high_kj"]
    # the base equals the design block's own energy at v95 (one number, two places)
    chosen = block.alternatives.loc[block.alternatives["chosen"]].iloc[0]
    assert r["energy_base_kj"] == pytest.approx(chosen["energy_at_v95_kj"], rel=1e-12)
    # the percentile block does not depend on the law: m_max, share and b do not move it, and the velocity
    # percentile does not enter the T-year energy (which integrates over every speed)
    block_rows = tor.table[tor.table["design_energy"].str.startswith("design-block energy")]
    assert list(block_rows["input"].str.split(" ").str[0]) == ["velocity"]
    t_rows = tor.table[tor.table["design_energy"].str.startswith("100-year energy")]
    assert not t_rows["input"].str.contains("velocity").any()


def test_fragmentation_rows_monotone_and_base_between(spread):
    block = design_block(spread, rule="fragmentation", percentile=97, sizes="event_volumes", design_T=T,
                         density_kg_m3=RHO, fractal_dimension=2.5, iterations=3)
    tor = design_energy_tornado(spread, design_T=T, block=block, rate_share=SHARE,
                                fractal_dimension_range=(2.2, 2.8), iterations_range=(2, 4))
    d = _row(tor, "design-block energy", "fractal dimension")
    n = _row(tor, "design-block energy", "fragmentation generations")
    # more splitting (higher D) or more generations -> smaller fragments -> less energy
    for r in (d, n):
        assert r["energy_low_kj"] >= r["energy_base_kj"] >= r["energy_high_kj"]
        assert r["energy_low_kj"] > r["energy_high_kj"]
    # the law moves the fragmentation block too (it breaks up the T-year event): a lower b -> larger event
    rb = _row(tor, "design-block energy", "power-law exponent b")
    assert rb["energy_low_kj"] >= rb["energy_base_kj"] >= rb["energy_high_kj"]
    # exact: base = 1/2 m v95^2 of the chosen fragment block at the speed percentile of all arriving blocks
    assert d["energy_base_kj"] == pytest.approx(0.5 * block.mass_kg * np.percentile(spread.velocity, 95) ** 2 / 1e3,
                                                rel=1e-12)
    assert "ASSUMPTION" in d["range_basis"] or "given" in d["range_basis"]


def test_fragmentation_alternative_is_its_own_output_when_not_chosen(spread):
    vols = np.random.default_rng(5).lognormal(0.0, 1.0, 500)
    block = design_block(spread, rule="percentile", percentile=97, survey_volumes_m3=vols, sizes="blocks",
                         density_kg_m3=RHO, fractal_dimension=2.5, iterations=3)
    tor = design_energy_tornado(spread, design_T=T, block=block, rate_share=SHARE)
    outputs = list(dict.fromkeys(tor.table["design_energy"]))
    assert len(outputs) == 3 and outputs[2].startswith("fragmentation alternative")
    frag_inputs = set(tor.table.loc[tor.table["design_energy"] == outputs[2], "input"].str.split(" ").str[0])
    assert {"fractal", "fragmentation", "rate", "power-law", "velocity"} <= frag_inputs
    dominant = tor.dominant()
    assert list(dominant["design_energy"]) == outputs
    for _, row in dominant.iterrows():
        sub = tor.table[tor.table["design_energy"] == row["design_energy"]]
        assert row["input"] == sub.loc[sub["swing_kj"].idxmax(), "input"]
    assert isinstance(tor, DesignEnergyTornado) and tor.summary().equals(tor.table)
    assert {"energy_low_kj", "energy_base_kj", "energy_high_kj", "swing_kj"} <= set(tor.table.columns)


def test_tornado_figure_one_panel_per_design_energy(spread, tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    from riskrf.report.fit_figures import plot_design_energy_tornado
    vols = np.random.default_rng(5).lognormal(0.0, 1.0, 500)
    block = design_block(spread, rule="percentile", percentile=97, survey_volumes_m3=vols, sizes="blocks",
                         density_kg_m3=RHO)
    tor = design_energy_tornado(spread, design_T=T, block=block, rate_share=SHARE)
    axes = plot_design_energy_tornado(tor)
    assert len(axes) == tor.table["design_energy"].nunique() == 2
    assert all("kJ" in ax.get_xlabel() for ax in axes)


@pytest.mark.parametrize("kwargs, match", [
    ({"velocity_percentile": 100.0}, "velocity_percentile = 100.0"),
    ({"velocity_percentile_range": (90, 100.5)}, r"velocity_percentile_range\[1\] = 100.5"),
    ({"velocity_percentile_range": (0, 99)}, r"velocity_percentile_range\[0\] = 0"),
    ({"rate_share": -0.1}, "rate_share = -0.1"),
    ({"rate_share_range": (0.05, np.nan)}, r"rate_share_range\[1\] = nan"),
    ({"m_max_range": (1.0e5, 4.0e6)}, r"m_max_range\[0\] = 100000"),
    ({"fractal_dimension_range": (2.2, 3.1)}, r"fractal_dimension_range\[1\] = 3.1"),
    ({"iterations_range": (0, 4)}, r"iterations_range\[0\] = 0"),
    ({"design_T": 0.5}, "design_T = 0.5"),
])
def test_bad_input_names_the_argument_and_value(spread, masses, kwargs, match):
    block = design_block(spread, rule="fragmentation", percentile=97, design_T=T, density_kg_m3=RHO,
                         fractal_dimension=2.5, iterations=3)
    args = dict(design_T=T, block=block, rate_share=SHARE, masses_kg=masses, duration_years=DURATION)
    args.update(kwargs)
    with pytest.raises((ValueError, TypeError), match=match):
        design_energy_tornado(spread, **args)


def test_unchanged_base_when_b_is_at_its_estimate(constant, fit):
    """Sanity: re-scaling the law with b at its own estimate reproduces the hazard's energy."""
    same = constant.with_mass(replace(fit, b=fit.b), constant.rate_per_year)
    assert float(same.energy_at_return_period(T)) == pytest.approx(float(constant.energy_at_return_period(T)))
