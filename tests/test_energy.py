"""Impact-energy probability, hazard and design standards."""
import numpy as np
import pandas as pd
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy import integrate, stats

import riskrf
from riskrf.hazard.impact_energy import energy_quantile, exceedance_probability, exceedance_probability_mc
from riskrf.hazard.velocity_models import PairedSamples, fit_velocity
from riskrf.hazard.annual_hazard import EnergyHazard
from riskrf.hazard.barriers import check_fence, service_energy_level, uni11211_design_energy

# domain-methods.md 3.1 (E16): median m 1000 kg (sigma_ln 0.8), median v 15 m/s (sigma_ln 0.2)
# => E lognormal with median 112.5 kJ, sigma_ln 0.8944.
MASS = stats.lognorm(0.8, scale=1000.0)
VEL = stats.lognorm(0.2, scale=15.0)
ENERGY = stats.lognorm(np.sqrt(0.8 ** 2 + 4 * 0.2 ** 2), scale=0.5 * 1000 * 15 ** 2 / 1000)


def test_lognormal_case_exact_over_eight_orders_of_magnitude():
    p_target = np.logspace(-8, -0.2, 40)
    e = ENERGY.isf(p_target)
    p = exceedance_probability(e, mass=MASS, velocity=VEL)
    np.testing.assert_allclose(p, p_target, rtol=1e-4)


def test_published_worked_values_and_quantiles():
    # domain-methods.md E16: P(E > 100, 250, 500, 1000 kJ) = 0.5524, 0.1860, 0.04769, 0.007289; E95/E98/E99.
    p = exceedance_probability([100, 250, 500, 1000], MASS, VEL)
    np.testing.assert_allclose(p, [0.5524, 0.1860, 0.04769, 0.007289], atol=5e-5)
    np.testing.assert_allclose(energy_quantile([0.05, 0.02, 0.01], MASS, VEL), [489.9, 706.2, 901.2], atol=0.05)


def test_monte_carlo_agrees_within_its_interval():
    e = np.array([100.0, 500.0, 2000.0])
    p, lo, hi = exceedance_probability_mc(e, MASS, VEL, n_samples=400_000, seed=3)
    exact = ENERGY.sf(e)
    assert np.all((lo <= exact) & (exact <= hi))


def test_velocity_samples_are_averaged_exactly():
    v = np.array([10.0, 20.0, 30.0])
    e = 50.0
    expected = np.mean(MASS.sf(2000 * e / v ** 2))
    assert exceedance_probability(e, MASS, v) == pytest.approx(expected, rel=1e-12)


def test_power_law_mass_and_constant_speed():
    rng = np.random.default_rng(1)
    gr = riskrf.fit_gutenberg_richter(100 * (1 - rng.uniform(size=500)) ** (-1 / 0.7), 10.0, m_min=100)
    e = np.array([10.0, 100.0, 1e4])
    p = exceedance_probability(e, gr, np.array([20.0]))
    np.testing.assert_allclose(p, gr.sf(2000 * e / 400.0))
    assert p[0] == 1.0                   # every fall above m_min carries more than 10 kJ at 20 m/s


def test_rotation_adds_energy_of_a_sphere():
    m, v, w, rho = 2000.0, 12.0, 20.0, 2650.0
    r = (3 * m / (4 * np.pi * rho)) ** (1 / 3)
    e_total = (0.5 * m * v ** 2 + 0.5 * 0.4 * m * r ** 2 * w ** 2) / 1000
    point = stats.uniform(m * 0.999999, m * 2e-6)            # mass (almost) exactly m
    below = exceedance_probability(e_total * 0.999, point, np.array([v]), angular_velocity=np.array([w]))
    above = exceedance_probability(e_total * 1.001, point, np.array([v]), angular_velocity=np.array([w]))
    assert below == 1.0 and above == 0.0


def test_velocity_fit_chooses_by_aic_and_reports_fit():
    v = VEL.rvs(5000, random_state=2)
    fit = fit_velocity(v)
    assert fit.name == "lognormal"
    assert {"aic", "delta_aic", "ks_distance", "ks_p_value"} <= set(fit.table.columns)
    p = exceedance_probability(500, MASS, fit)
    assert p == pytest.approx(0.04769, rel=0.05)


def test_conditioning_on_mass_matches_independent_case_when_independent():
    rng = np.random.default_rng(5)
    v = VEL.rvs(200_000, random_state=rng)
    m = MASS.rvs(200_000, random_state=rng)
    p = exceedance_probability([100, 500], MASS, PairedSamples(v, m))
    np.testing.assert_allclose(p, ENERGY.sf([100, 500]), rtol=0.03)
    from_table = PairedSamples.from_collector(pd.DataFrame({"velocity_ms": v, "mass_kg": m}))
    np.testing.assert_allclose(exceedance_probability([100, 500], MASS, from_table), p)


@settings(max_examples=40, deadline=None)
@given(s_m=st.floats(0.1, 2.0), s_v=st.floats(0.05, 0.6), scale=st.floats(1.01, 3.0))
def test_exceedance_properties(s_m, s_v, scale):
    mass, vel = stats.lognorm(s_m, scale=500.0), stats.lognorm(s_v, scale=10.0)
    e = np.geomspace(1, 1e5, 30)
    p = exceedance_probability(e, mass, vel)
    assert np.all(np.diff(p) <= 1e-15)                                         # non-increasing in e
    more_mass = exceedance_probability(e, stats.lognorm(s_m, scale=500.0 * scale), vel)
    more_speed = exceedance_probability(e, mass, stats.lognorm(s_v, scale=10.0 * scale))
    assert np.all(more_mass >= p - 1e-12) and np.all(more_speed >= p - 1e-12)


@settings(max_examples=25, deadline=None)
@given(rate=st.floats(0.05, 50), reach=st.floats(0.05, 1.0), T=st.floats(30, 5000))
def test_return_period_energy_and_annual_frequency_invert(rate, reach, T):
    assume(T * rate * reach > 1)          # otherwise no energy has a return period of T years
    hz = EnergyHazard(mass=MASS, velocity=VEL, rate_per_year=rate, reach_probability=reach)
    e = hz.energy_at_return_period(T)
    assert hz.annual_frequency(e) == pytest.approx(1 / T, rel=1e-6)
    # Independent of the package's log-space quadrature: P(E > e) = int f_V(v) P(M > 2 e / v^2) dv by adaptive quad.
    p = integrate.quad(lambda v: VEL.pdf(v) * MASS.sf(2000.0 * e / (v * v)), 0, np.inf, epsabs=1e-13, limit=200)[0]
    assert hz.annual_frequency(e) == pytest.approx(rate * reach * p, rel=1e-5)


def test_hazard_intervals_bracket_the_estimate_and_are_seeded():
    rng = np.random.default_rng(7)
    gr = riskrf.fit_gutenberg_richter(100 * (1 - rng.uniform(size=300)) ** (-1 / 0.9), 10.0, m_min=100)
    hz = EnergyHazard(mass=gr, velocity=VEL.rvs(5000, random_state=1), rate_per_year=gr.rate_min,
                      reach_probability=0.4, n_released=5000)
    e = hz.energy_at_return_period([100, 300])
    lo, hi = hz.energy_at_return_period_ci([100, 300], n_bootstrap=150, seed=2)
    assert np.all(lo < e) and np.all(e < hi)
    lo2, hi2 = hz.energy_at_return_period_ci([100, 300], n_bootstrap=150, seed=2)
    np.testing.assert_array_equal(lo, lo2)
    table = hz.design_table(n_bootstrap=50)
    assert table["energy_kj"].is_monotonic_increasing


def test_uni11211_worked_example_and_sel():
    # domain-methods.md E13: Vol 2 m3, rho 2700, v_t 20 m/s -> E_k 1080 kJ; E_d 1192.4 (all 1.02), 1739.4 (all 1.10).
    high = uni11211_design_energy(2.0, 2700, 20.0, gamma_Tr=1.02, gamma_Dp=1.02, gamma_VolF=1.02)
    assert high.characteristic_energy_kj == pytest.approx(1080.0)
    assert high.design_energy_kj == pytest.approx(1192.4, abs=0.05)
    assert uni11211_design_energy(2.0, 2700, 20.0).design_energy_kj == pytest.approx(1739.4, abs=0.05)
    assert high.check(1400, gamma_E=1.2) is False and high.check(1400, gamma_E=1.0) is True
    assert service_energy_level(3000) == 1000
    with pytest.raises(ValueError, match="gamma_Tr = 0.9"):
        uni11211_design_energy(2.0, 2700, 20.0, gamma_Tr=0.9)


def test_fence_check_reports_mel_sel_and_height():
    hz = EnergyHazard(mass=MASS, velocity=VEL.rvs(4000, random_state=3), rate_per_year=2.0, reach_probability=0.5,
                      heights_m=np.random.default_rng(1).exponential(1.5, 4000))
    table = check_fence(hz, 2000, 6.0, T=100, n_bootstrap=50)
    assert list(table["check"]) == ["100-year energy vs MEL", "100-year energy vs SEL",
                                    "p95 bounce height + free board vs height"]
    e100 = hz.energy_at_return_period(100)
    assert table.loc[0, "adequate"] == (e100 <= 2000) and table.loc[1, "capacity"] == pytest.approx(2000 / 3)


@pytest.mark.parametrize("call,match", [
    (lambda: exceedance_probability(-1, MASS, VEL), "energy_kj = -1.0: energies must be finite and >= 0"),
    (lambda: exceedance_probability(np.nan, MASS, VEL), "energies must be finite"),
    (lambda: exceedance_probability(1, MASS, np.array([])), "velocity samples are empty"),
    (lambda: exceedance_probability(1, MASS, np.array([3.0, -2.0])), r"velocity sample \[1\] = -2.0"),
    (lambda: exceedance_probability(1, stats.norm(100, 50), VEL), "has support reaching -inf kg"),
    (lambda: exceedance_probability(1, MASS, VEL, method="exact"), "method = 'exact' is not one of"),
    (lambda: EnergyHazard(mass=MASS, velocity=VEL, rate_per_year=1, reach_probability=1.5),
     "reach_probability must lie in"),
])
def test_bad_inputs(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_velocity_file_columns(tmp_path):
    from riskrf.io.velocities import read_velocities
    f = tmp_path / "rocfall.csv"
    pd.DataFrame({"Translational Velocity (m/s)": [10.0, 12.0], "Bounce Height (m)": [1.0, 2.0]}).to_csv(f, index=False)
    df = read_velocities(f)
    assert list(df.columns) == ["velocity_ms", "height_m"]
    g = tmp_path / "bad.csv"
    pd.DataFrame({"speedy": [1.0]}).to_csv(g, index=False)
    with pytest.raises(ValueError, match=r"bad.csv: no velocity column among \['speedy'\]"):
        read_velocities(g)


def test_rotation_of_a_cylinder_uses_its_inertia_factor():
    """A disc/cylinder (k = 1/2): the threshold follows 1/2 m v^2 + 1/2 (1/2) m r^2 w^2, computed here by hand."""
    m, v, w, rho = 2000.0, 12.0, 20.0, 2650.0
    r = (3 * m / (4 * np.pi * rho)) ** (1 / 3)                 # equivalent-sphere radius, as documented
    e_disc = (0.5 * m * v ** 2 + 0.5 * 0.5 * m * r ** 2 * w ** 2) / 1000
    e_sphere = (0.5 * m * v ** 2 + 0.5 * 0.4 * m * r ** 2 * w ** 2) / 1000
    assert e_disc > e_sphere * 1.001
    point = stats.uniform(m * 0.999999, m * 2e-6)
    args = dict(angular_velocity=np.array([w]), inertia_factor=0.5)
    assert exceedance_probability(e_disc * 0.999, point, np.array([v]), **args) == 1.0
    assert exceedance_probability(e_disc * 1.001, point, np.array([v]), **args) == 0.0
    # between the two: a sphere does not exceed, a disc does
    mid = 0.5 * (e_sphere + e_disc)
    assert exceedance_probability(mid, point, np.array([v]), angular_velocity=np.array([w])) == 0.0
    assert exceedance_probability(mid, point, np.array([v]), **args) == 1.0
    # Monte Carlo agrees with a direct sampled computation
    rng = np.random.default_rng(5)
    mass = stats.lognorm(0.8, scale=1000.0)
    vs, ws = rng.uniform(5, 20, 400), rng.uniform(0, 30, 400)
    p = exceedance_probability(300.0, mass, vs, angular_velocity=ws, inertia_factor=0.5)
    p_mc = exceedance_probability(300.0, mass, vs, angular_velocity=ws, inertia_factor=0.5, method="mc",
                                  n_samples=400_000, seed=1)
    ms = mass.rvs(400_000, random_state=np.random.default_rng(2))
    idx = np.random.default_rng(3).integers(0, 400, ms.size)
    rs = (3 * ms / (4 * np.pi * rho)) ** (1 / 3)
    direct = np.mean((0.5 * ms * vs[idx] ** 2 + 0.25 * ms * rs ** 2 * ws[idx] ** 2) / 1000 > 300.0)
    assert p == pytest.approx(direct, abs=0.005) and p_mc == pytest.approx(direct, abs=0.005)
    with pytest.raises(ValueError, match="inertia_factor"):
        exceedance_probability(300.0, mass, vs, angular_velocity=ws, inertia_factor=-1)
