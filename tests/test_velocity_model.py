"""The velocity-model interface: one adapter at the API boundary, protocol calls everywhere else."""
import ast
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

import riskrf
from riskrf.hazard.annual_hazard import EnergyHazard
from riskrf.hazard.impact_energy import exceedance_probability, exceedance_probability_mc
from riskrf.hazard.mass_models import mass_model
from riskrf.hazard.velocity_models import PairedSamples, VelocityModel, fit_velocity, velocity_model
from riskrf.hazard.mass_coupling import MassCoupledSamples

ROOT = Path(__file__).resolve().parents[1]
VEL = stats.lognorm(0.2, scale=15.0)
V = VEL.rvs(2000, random_state=1)
M = stats.lognorm(0.8, scale=1000.0).rvs(2000, random_state=2)


def _coupled():
    rng = np.random.default_rng(3)
    m = np.exp(rng.uniform(np.log(1e3), np.log(1e6), 4000))
    v = 12.0 * (m / 1e3) ** 0.12 * np.exp(0.15 * rng.standard_normal(m.size))
    v[rng.uniform(size=m.size) < 0.4] = np.nan
    return MassCoupledSamples(m, v, np.where(np.isfinite(v), 1.0, np.nan), np.geomspace(1e3, 1e6, 11))


def test_every_accepted_kind_is_wrapped_once_and_answers_percentiles():
    coupled = _coupled()
    expected = {id(VEL): float(VEL.ppf(0.9)), id(V): float(np.percentile(V, 90))}
    fit = fit_velocity(V)
    expected[id(fit)] = float(fit.dist.ppf(0.9))
    paired = PairedSamples(V, M)
    expected[id(paired)] = float(np.percentile(V, 90))
    expected[id(coupled)] = float(np.percentile(coupled.velocity_ms, 90))
    for obj in (VEL, V, fit, paired, coupled):
        vm = velocity_model(obj)
        assert isinstance(vm, VelocityModel)
        assert velocity_model(vm) is vm                       # wrapping is idempotent
        assert vm.mass_coupled == (obj is coupled)
        assert vm.percentile(90.0) == expected[id(obj)]
    # a mass-coupled model answers for blocks of one mass from that mass class only
    vm = velocity_model(coupled)
    cls = coupled.class_of(coupled.mass_kg) == coupled.class_of(5e5)
    assert vm.percentile(50.0, 5e5) == pytest.approx(np.nanpercentile(coupled.speed_ms[cls], 50), rel=1e-12)


def test_a_new_velocity_model_needs_only_the_protocol():
    """A constant speed v: E = m v^2 / 2000 exactly, so P(E > e) = P(M > 2000 e / v^2) (power-law sf)."""
    class ConstantSpeed(VelocityModel):
        def __init__(self, v):
            self.v = v

        def exceedance(self, energy_kj, mass):
            return mass.sf(2000.0 * energy_kj / self.v ** 2)

        def sample_energy_kj(self, mass_kg, rng):
            return 0.5 * mass_kg * self.v ** 2 / 1000.0, mass_kg.size

        def percentile(self, q, mass_kg=None):
            return self.v

    rng = np.random.default_rng(1)
    gr = riskrf.fit_gutenberg_richter(100 * (1 - rng.uniform(size=500)) ** (-1 / 0.7), 10.0, m_min=100)
    e = np.array([10.0, 100.0, 1e4])
    np.testing.assert_array_equal(exceedance_probability(e, gr, ConstantSpeed(20.0)),
                                  exceedance_probability(e, gr, np.array([20.0])))
    np.testing.assert_allclose(exceedance_probability(e, gr, ConstantSpeed(20.0)), gr.sf(2000 * e / 400.0))
    e = e[1:]                                              # (P = 1 at 10 kJ: the interval's end is 1 - 1e-16)
    p, lo, hi = exceedance_probability_mc(e, gr, ConstantSpeed(20.0), n_samples=20_000, seed=2)
    assert np.all((lo <= gr.sf(2000 * e / 400.0)) & (gr.sf(2000 * e / 400.0) <= hi))
    hz = EnergyHazard(mass=gr, velocity=ConstantSpeed(20.0), rate_per_year=gr.rate_min)
    assert hz.velocity_percentile(95) == 20.0
    # E(T) for T = 100 yr: rate x P(M > m) = 1/100 at m = 2000 E / v^2
    m_T = float(mass_model(gr).isf(1.0 / (100 * gr.rate_min)))
    assert hz.energy_at_return_period(100.0) == pytest.approx(m_T * 400.0 / 2000.0, rel=1e-9)


def test_distribution_refuses_angular_velocity_and_pooled_samples():
    with pytest.raises(ValueError, match="angular_velocity needs velocity samples"):
        exceedance_probability(100.0, M, VEL, angular_velocity=np.ones(3))
    with pytest.raises(ValueError, match="has no speed samples"):
        velocity_model(VEL).speed_samples_ms()


def test_velocity_types_are_switched_on_in_one_place_only():
    """No isinstance on VelocityFit/PairedSamples and no is_mass_coupled call in riskrf.hazard or riskrf.risk
    outside the adapter :func:`velocity_model`."""
    names = {"VelocityFit", "PairedSamples", "MassCoupledSamples", "is_mass_coupled"}
    found = []
    for path in sorted((ROOT / "riskrf").glob("*/*.py")):
        if path.parent.name not in ("hazard", "risk"):
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        allowed = {id(n) for f in ast.walk(tree) if isinstance(f, ast.FunctionDef) and f.name == "velocity_model"
                   for n in ast.walk(f)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and id(node) not in allowed and isinstance(node.func, ast.Name) \
                    and node.func.id in ("isinstance", "is_mass_coupled"):
                used = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
                if node.func.id == "is_mass_coupled" or used & names:
                    found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert found == []
