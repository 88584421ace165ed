"""Every public result class of ``riskrf.__all__`` and ``simulation.__all__`` is pleasant in a notebook: a short
``repr`` (one line, under 300 characters), ``_repr_html_`` (Jupyter's table), ``summary()`` returning a pandas
DataFrame, and ``plot()`` returning matplotlib axes where it has one.  The objects are built from the shipped
inventories and scenario with small sizes and fixed seeds.
"""
from __future__ import annotations

import inspect
import warnings
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
import pytest

import riskrf
import simulation

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FRICTION = "materials.talus.ground_friction_angle_deg"

#: Result classes reached through a public function or method rather than ``__all__`` (e.g.
#: ``MitigationStudy.evaluate`` returns an :class:`~riskrf.risk.mitigation.OptionResult`): they are walked too.
RESULTS_OUTSIDE_ALL = ["OptionResult", "EnergyHazardEnsemble", "DesignEnergySplit"]

#: Public classes that are not results (errors, warnings) or whose module another change owns right now; each
#: with the reason.  The walk fails if a new public class is neither built below nor listed here.
EXEMPT = {
}


def _public_classes():
    for package in (riskrf, simulation):
        for name in package.__all__:
            value = getattr(package, name)
            if inspect.isclass(value) and not issubclass(value, (BaseException, Warning)):
                yield name, value


@pytest.fixture(scope="module")
def objects():
    """One instance of every public result class, by class name."""
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = riskrf.read_inventory(ROOT / "inventories" / "lauterbrunnen" / "lauterbrunnen_tls_2015.csv")
        gr = riskrf.fit_gutenberg_richter(inv.masses, inv.duration_years)
        hk = riskrf.read_inventory(ROOT / "inventories" / "hong-kong" / "hong_kong_rock_cuts_1984_2020.csv")
        rain = riskrf.read_rainfall(ROOT / "inventories" / "hong-kong" / "hko_daily_rainfall_1983_2020.csv")
        out.update(Inventory=inv, GutenbergRichterFit=gr, GumbelFit=riskrf.fit_gumbel(hk.annual_maxima()),
                   GEVFit=riskrf.fit_gev(hk.annual_maxima()), Rainfall=rain,
                   FrequencyAnalysis=riskrf.analyse_inventory(inv, n_bootstrap=0),
                   RateModel=riskrf.rate_model(hk, rain, trend=False))
        sc = simulation.load_scenario(ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml")
        res = simulation.run(sc, n=200, seed=1, record_paths=5)
        out.update(Scenario=sc, SimulationResult=res, EnergyHazard=riskrf.EnergyHazard.from_simulation(gr, res, "barrier"))
        rng = np.random.default_rng(1)
        m = np.exp(rng.uniform(np.log(100.0), np.log(1e5), 400))
        speed = np.where(rng.uniform(size=400) < 0.6, rng.uniform(5, 20, 400), np.nan)
        out["MassCoupledSamples"] = riskrf.MassCoupledSamples(m, speed, np.where(np.isnan(speed), np.nan, 1.0),
                                                              np.geomspace(100.0, 1e5, 5), collector="barrier")
        out["DecisionTree"] = riskrf.DecisionTree.from_dict({"type": "decision", "name": "mitigation", "branches": [
            {"name": "do nothing", "child": {"type": "chance", "branches": [
                {"name": "vehicle hit", "probability": 0.02, "cost": 2500000},
                {"name": "no hit", "probability": 0.98, "cost": 0}]}},
            {"name": "fence 2000 kJ", "cost": 45000}]})
        stops = res.runout
        observed = stops.loc[stops["reason"] == "stopped", "x_stop_m"].to_numpy()[:30]   # the run's own stops
        out["Calibration"] = simulation.calibrate(sc, observed, {FRICTION: (20, 40)}, n=60, maxiter=1, popsize=3,
                                                  n_bootstrap=0, seed=1)
        scenario_file = ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml"
        releases = [simulation.Release(f"stops {k}", scenario_file, observed[k::2], source="the run above")
                    for k in range(2)]
        out["Release"] = releases[0]
        out["ReachConstraint"] = simulation.ReachConstraint("far limit", scenario_file, 0.0, 0.0, 27.5, 2.0,
                                                            source="Evans & Hungr 1993 (a shape check only)")
        out["PooledCalibration"] = simulation.calibrate_pooled(
            releases, {FRICTION: (20.0, 40.0)}, n_per_release=20, n_initial=16, n_per_iteration=8, iterations=1,
            n_posterior=100, n_predictive=4, seed=1)
        from riskrf.risk.mitigation import Economics, MitigationStudy, Option, Uncertainty
        study = MitigationStudy(hazard=out["EnergyHazard"], options=(
            Option("nothing", "none", 0.0), Option("fence", "fence", 5e5, 1e4, 25, 2e4, capacity_kj=2000,
                                                   height_m=4, repair_days=30)),
            economics=Economics(0.03, 50), uncertainty=Uncertainty(samples=40))
        out.update(MitigationStudy=study, OptionResult=study.evaluate("fence"))
        draws = np.array([[3.1e5, 2.9e5, 6.0e5], [2.7e5, 3.3e5, 6.1e5], [3.0e5, 3.0e5, 5.9e5]])  # draws x options
        out["ModelUncertainRanking"] = riskrf.ModelUncertainRanking(("nothing", "fence", "shed"), draws,
                                                                    currency="CHF")
        res2 = simulation.run(sc, n=200, seed=2)        # a second draw of the slope (another seed) for the ensemble
        from riskrf.hazard.model_uncertainty import EnergyHazardEnsemble
        ens = EnergyHazardEnsemble(draws=pd.DataFrame({FRICTION: [30.0, 31.0]}), hazards=(
            out["EnergyHazard"], riskrf.EnergyHazard.from_simulation(gr, res2, "barrier")), basis="two seeds", n=200)
        out.update(EnergyHazardEnsemble=ens, DesignEnergySplit=ens.design_energies([10.0, 100.0], n_bootstrap=20))
        try:                    # the 3-D classes need rasterio (an optional extra)
            import rasterio  # noqa: F401
        except ImportError:
            return out
        tan = np.tan(np.radians(35.0))
        ter = simulation.Terrain.from_function(lambda x, y: 100 - tan * x, (0, 60), (0, 20), 1.0)
        out["Terrain"] = ter
        out["TerrainProfile"] = simulation.profile_from_grid(ter, [(0.0, 10.0), (60.0, 10.0)], spacing=1.0)
        tsc = simulation.terrain_scenario_from_dict(
            {"terrain": {}, "materials": {"rock": {"normal_restitution": 0.3, "tangential": {"law": "constant",
                                                                                               "mean": 0.8},
                                                    "roughness_m": 0.0, "ground_friction_angle_deg": 33.0}},
             "sources": {"points": [[5.0, 10.0]], "height_m": 1.0, "mass_kg": 1000},
             "collectors": [{"name": "line", "line": [[40.0, 0.0], [40.0, 20.0]]}]}, terrain=ter)
        out["TerrainScenario"] = tsc
        out["TerrainResult"] = simulation.run_terrain(tsc, 5, seed=1)
    return out


def test_every_public_class_is_covered(objects):
    """Each public class is built here (or exempt with a reason): a new result class joins the walk."""
    names = {name for name, _ in _public_classes()}
    optional = {"Terrain", "TerrainProfile", "TerrainScenario", "TerrainResult"} - set(objects)
    assert names - set(objects) - set(EXEMPT) - optional == set()


@pytest.mark.parametrize("name", [n for n, _ in _public_classes() if n not in EXEMPT] + RESULTS_OUTSIDE_ALL)
def test_notebook_protocol(objects, name):
    if name not in objects:
        pytest.skip(f"{name}: needs the optional rasterio package")
    obj = objects[name]
    text = repr(obj)
    assert len(text) < 300 and text.count("\n") == 0, f"{name} repr is {len(text)} characters: {text[:400]}"
    assert text.startswith(type(obj).__name__ + "(")
    html = obj._repr_html_()
    assert isinstance(html, str) and "<table" in html and type(obj).__name__ in html
    table = obj.summary()
    assert isinstance(table, pd.DataFrame) and len(table) > 0
    if hasattr(obj, "plot"):
        ax = obj.plot()
        assert isinstance(ax, Axes) and ax.has_data(), name
        plt.close(ax.figure)


def test_power_law_interval_has_the_annual_maximum_fits_name(objects):
    """``GutenbergRichterFit.return_level_ci`` (the name GumbelFit and GEVFit use); the old name
    ``mass_at_return_period_ci`` gives the same numbers with a DeprecationWarning."""
    gr = objects["GutenbergRichterFit"]
    T = np.array([10.0, 100.0])
    lo, hi = gr.return_level_ci(T)
    np.testing.assert_array_equal(gr.return_level(T), gr.mass_at_return_period(T))
    assert np.all(lo < gr.return_level(T)) and np.all(gr.return_level(T) < hi)
    with pytest.warns(DeprecationWarning, match="return_level_ci"):
        old = gr.mass_at_return_period_ci(T)
    np.testing.assert_array_equal(old, (lo, hi))


def test_energy_hazard_has_the_return_level_names(objects):
    """``EnergyHazard.return_level``/``return_level_ci``: the T-year energy under the mass models' names."""
    hz = objects["EnergyHazard"]
    T = np.array([100.0, 1000.0])
    np.testing.assert_array_equal(hz.return_level(T), hz.energy_at_return_period(T))
    np.testing.assert_array_equal(hz.return_level_ci(T, n_bootstrap=20, seed=3),
                                  hz.energy_at_return_period_ci(T, n_bootstrap=20, seed=3))


def test_mitigation_study_ranking_plot_and_bad_kind(objects):
    """``MitigationStudy.plot("ranking")`` draws one expected total cost per option at the ranking's numbers;
    an unknown kind is refused with its value named."""
    from riskrf.risk.mitigation import MitigationError
    study = objects["MitigationStudy"]
    rank = study.summary()
    ax = study.plot("ranking")
    xs = ax.lines[0].get_xdata()          # the error bar's centre points
    np.testing.assert_allclose(xs, rank["expected_total_cost"].to_numpy(dtype=float))
    plt.close(ax.figure)
    with pytest.raises(MitigationError, match="'pie'"):
        study.plot("pie")


def test_model_uncertain_ranking_repr_names_the_best_option_and_evpi_by_hand(objects):
    """Costs 3 draws x 3 options: expected costs 293,333 / 306,667 / 600,000, so 'nothing' is best now; with
    perfect information the mean of the per-draw minima is (290,000 + 270,000 + 300,000) / 3 = 286,667, so
    EVPI = 6,667 (computed by hand)."""
    text = repr(objects["ModelUncertainRanking"])
    assert "best='nothing'" in text and "evpi=6667" in text
