"""The mass-model interface: one adapter at the API boundary, protocol calls everywhere else."""
import ast
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

import riskrf
from riskrf.hazard.annual_hazard import EnergyHazard
from riskrf.hazard.energy_study import analyse_energy
from riskrf.hazard.impact_energy import exceedance_probability
from riskrf.hazard.mass_models import MassModel, mass_model
from riskrf.risk.loss_engine import mass_pmf

ROOT = Path(__file__).resolve().parents[1]
RNG = np.random.default_rng(1)
GR = riskrf.fit_gutenberg_richter(100 * (1 - RNG.uniform(size=500)) ** (-1 / 0.7), 10.0, m_min=100)
GUMBEL = riskrf.fit_gumbel(stats.gumbel_r(loc=2000, scale=800).rvs(30, random_state=3))


class Pareto(MassModel):
    """An untruncated power law written by a user: P(M > m) = (m / m_min)^-b above m_min [kg], ``rate`` falls/yr."""

    def __init__(self, m_min, b, rate):
        self.m_min, self.b, self.rate_per_year = m_min, b, rate
        self.description = f"user Pareto b = {b}"

    def sf(self, mass_kg):
        return np.minimum((np.asarray(mass_kg, dtype=float) / self.m_min) ** -self.b, 1.0)

    def isf(self, p):
        return self.m_min * np.asarray(p, dtype=float) ** (-1.0 / self.b)

    def rvs(self, n, rng):
        return self.isf(1.0 - rng.uniform(size=n))


def test_every_accepted_kind_is_wrapped_once_and_answers_the_protocol():
    kinds = [GR, GUMBEL, riskrf.fit_gev(stats.gumbel_r(loc=2000, scale=800).rvs(30, random_state=3)),
             stats.lognorm(1.0, scale=3000), stats.lognorm(1.0, scale=3000).rvs(200, random_state=4)]
    for obj in kinds:
        mm = mass_model(obj)
        assert isinstance(mm, MassModel)
        assert mass_model(mm) is mm                               # wrapping is idempotent
        assert (mm.rate_per_year is not None) == (obj is GR)      # only the fitted power law carries its rate
        assert (mm.power_law is obj) if obj is GR else mm.power_law is None
        p = mm.bin_probabilities(np.geomspace(1.0, 1e8, 40))
        assert p.shape == (1, 39) and p.sum() == pytest.approx(1.0, abs=1e-6)
    assert mass_model(GR).rate_per_year == GR.rate_min
    # the power law's bootstrap replicate: b and rate x Gamma(n)/n, the same draws as by hand
    law, rate = mass_model(GR).perturbed(np.random.default_rng(5), 3.0)
    g = np.random.default_rng(5).gamma(GR.n_tail, size=2) / GR.n_tail
    assert (law.b, rate, law.rate_min) == (GR.b * g[0], 3.0 * g[1], 3.0 * g[1])
    # the annual-maximum fit's replicate draws its parameters from their covariance; a scipy law has none
    law, rate = mass_model(GUMBEL).perturbed(np.random.default_rng(5), 3.0)
    assert rate == 3.0 and law.params != GUMBEL.params
    mm = mass_model(stats.lognorm(1.0, scale=3000))
    assert mm.perturbed(np.random.default_rng(5), 3.0) == (mm, 3.0)


def test_a_user_written_mass_model_needs_only_the_protocol():
    """A user Pareto law and a constant speed v: E = m v^2 / 2000 exactly, so P(E > e) = (2000 e / v^2 m_min)^-b,
    the T-year block is m_min (T rate)^(1/b), and the loss engine's bins hold the exact sf differences."""
    law = Pareto(m_min=50.0, b=0.8, rate=4.0)
    e = np.array([10.0, 100.0, 1e4])
    exact = (2000 * e / 400.0 / 50.0) ** -0.8
    np.testing.assert_allclose(exceedance_probability(e, law, np.array([20.0])), exact, rtol=1e-13)
    hz = EnergyHazard(mass=law, velocity=np.array([20.0]), rate_per_year=law.rate_per_year)
    m_T = 50.0 * (100 * 4.0) ** (1 / 0.8)                         # rate x (m/m_min)^-b = 1/100
    assert hz.energy_at_return_period(100.0) == pytest.approx(m_T * 400.0 / 2000.0, rel=1e-9)
    assert hz.summary().loc["mass model"].iloc[0] == "user Pareto b = 0.8"
    # it carries its rate, so the energy study defines the 100-year block from it (the UNI 11211-4 energy)
    assert analyse_energy(hz, n_bootstrap=20)._uni_missing_reason() == ""
    # default bootstrap: no parameters to resample, and one speed: every replicate is the same hazard
    lo, hi = hz.energy_at_return_period_ci(np.array([100.0]), 0.9, 20, 1)
    assert lo[0] == hi[0]
    edges = np.geomspace(50.0, 5e6, 11)
    sf = (edges / 50.0) ** -0.8
    np.testing.assert_allclose(mass_pmf(edges, law)[0], np.append(-np.diff(sf[:-1]), sf[-2]), rtol=1e-12)
    assert law.grid_bounds_kg() == pytest.approx((50.0 * (1 - 1e-9) ** -1.25, 50.0 * 1e-9 ** -1.25), rel=1e-12)


def test_mass_types_are_switched_on_in_one_place_only():
    """No isinstance on the mass-model classes anywhere in riskrf outside the adapter :func:`mass_model`."""
    names = {"GutenbergRichterFit", "_AnnualMaximumFit", "GumbelFit", "GEVFit"}
    found = []
    for path in sorted((ROOT / "riskrf").rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        allowed = {id(n) for f in ast.walk(tree) if isinstance(f, ast.FunctionDef) and f.name == "mass_model"
                   for n in ast.walk(f)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and id(node) not in allowed and isinstance(node.func, ast.Name) \
                    and node.func.id in ("isinstance", "issubclass"):
                used = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)} \
                    | {n.attr for n in ast.walk(node) if isinstance(n, ast.Attribute)}
                if used & names:
                    found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert found == []
