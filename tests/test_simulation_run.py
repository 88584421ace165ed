"""Scenario validation, reproducibility, chunking and convergence of the simulator."""
import numpy as np
import pandas as pd
import pytest

import simulation
from simulation import ScenarioError, load_scenario, scenario_from_dict

from .test_simulation_physics import scenario

SCENARIOS = sorted((__import__("pathlib").Path(simulation.__file__).parent / "scenarios").glob("*.toml"))
BARRIER = next(p for p in SCENARIOS if p.stem == "road_cut_barrier")


def test_at_least_three_shipped_scenarios_load_and_run():
    assert len(SCENARIOS) >= 3
    for path in SCENARIOS:
        sc = load_scenario(path)
        res = simulation.run(sc, n=200, seed=3)
        assert res.stop_reasons.sum() == 200
        assert (path.parent / f"{path.stem}.md").exists()      # each scenario has its README


def test_barrier_scenario_collector_columns():
    res = simulation.run(load_scenario(BARRIER), n=2000, seed=1)
    df = res.collector("barrier")
    for col in ("velocity_ms", "angular_velocity_rads", "height_m", "energy_kj", "energy_translational_kj",
                "energy_rotational_kj", "crossing_angle_deg", "time_s"):
        assert col in df.columns and df[col].notna().all()
    assert (df["energy_kj"] >= df["energy_translational_kj"]).all()
    assert (df["height_m"] >= -1e-9).all()
    env = res.envelopes
    assert (env["velocity_max_ms"] >= env["velocity_mean_ms"]).all()
    rec = simulation.run(load_scenario(BARRIER), n=50, seed=1, record_paths=5)
    for b in range(5):
        sel = rec.paths["block"] == b
        t, x, z = rec.paths["t"][sel], rec.paths["x"][sel], rec.paths["z"][sel]
        assert t[0] == 0.0 and t[-1] > 0.0
        assert np.all(np.diff(t) >= 0)                            # events in time order
        moved = (np.diff(x) != 0) | (np.diff(z) != 0)
        assert moved.any() and np.all(np.diff(t)[moved] > 0)     # moving takes time: no jump between events
        assert t[-1] == rec.per_block["t"][b]                     # the last event is the stop
        assert rec.paths["x"][sel][0] == rec.blocks["x"][b] and rec.paths["z"][sel][0] == rec.blocks["z"][b]
        path = rec.path(b)                                        # the sampled path ends where the block stopped
        assert (path["x_m"].iloc[-1], path["z_m"].iloc[-1]) == (rec.per_block["x"][b], rec.per_block["z"][b])
        assert (path["x_m"].iloc[0], path["z_m"].iloc[0]) == (rec.blocks["x"][b], rec.blocks["z"][b])


def test_same_seed_same_numbers_whatever_the_chunking():
    sc = load_scenario(BARRIER)
    a = simulation.run(sc, n=3000, seed=42, chunk_size=3000).collector("barrier")
    b = simulation.run(sc, n=3000, seed=42, chunk_size=37).collector("barrier")
    pd.testing.assert_frame_equal(a.sort_values(["block", "time_s"]).reset_index(drop=True),
                                  b.sort_values(["block", "time_s"]).reset_index(drop=True))
    c = simulation.run(sc, n=3000, seed=43).collector("barrier")
    assert not np.array_equal(a["velocity_ms"].to_numpy()[:50], c["velocity_ms"].to_numpy()[:50])


def test_crossings_kept_when_their_buffers_must_grow(monkeypatch):
    """Every crossing is kept, in the same order, when the crossing buffers are too small: grown before a chunk
    and, when a chunk overflows them, grown and the chunk run again (a capacity of one row per ten blocks)."""
    from simulation import engine
    sc = load_scenario(BARRIER)
    ref = simulation.run(sc, n=600, seed=8, chunk_size=250)
    assert ref.crossings["block"].size > 250 // 10 * 3          # more crossings than a chunk's rows, per chunk
    monkeypatch.setattr(engine, "crossing_capacity", lambda n, n_collectors: max(n // 10, 1))
    calls = []
    simulate = engine.kernel.simulate
    monkeypatch.setattr(engine.kernel, "simulate", lambda *a: calls.append(1) or simulate(*a))
    small = simulation.run(sc, n=600, seed=8, chunk_size=250)
    assert len(calls) > 4                                       # the empty call, 3 chunks and at least one rerun
    for k in ref.crossings:
        np.testing.assert_array_equal(small.crossings[k], ref.crossings[k])
    for k in ref.per_block:
        np.testing.assert_array_equal(small.per_block[k], ref.per_block[k])
    np.testing.assert_array_equal(small.envelope_acc, ref.envelope_acc)
    for k in ref.paths:
        np.testing.assert_array_equal(small.paths[k], ref.paths[k])


def test_collector_statistics_converge_as_one_over_root_n():
    sc = load_scenario(BARRIER)
    spread = {}
    for n in (250, 4000):
        means = [simulation.run(sc, n=n, seed=s).collector("barrier", first_only=True)["velocity_ms"].mean()
                 for s in range(12)]
        spread[n] = np.std(means, ddof=1)
    ratio = spread[250] / spread[4000]          # sqrt(16) = 4 expected
    assert 2.0 < ratio < 8.0


def test_exceedance_reports_monte_carlo_interval():
    res = simulation.run(load_scenario(BARRIER), n=4000, seed=2)
    tab = res.exceedance("barrier", "energy_kj", [100, 1000, 5000])
    assert (tab["ci_low"] <= tab["probability"]).all() and (tab["probability"] <= tab["ci_high"]).all()
    assert tab["probability"].is_monotonic_decreasing


@pytest.mark.parametrize("patch,match", [
    ({"profile": {"x": [0, 10, 5], "z": [10, 5, 0], "material": "m"}}, "x goes backwards between vertex 1"),
    ({"profile": {"x": [0, 10, 10], "z": [10, 5, 0], "material": "m"}}, "segment 1 .* zero length"),
    ({"profile": {"x": [0, 10], "z": [10, 0], "materials": ["rok"]}}, "profile.materials\\[0\\] = 'rok' is not a defined"),
    ({"materials": {"m": {"normal_restitution": 1.4}}}, "materials.m.normal_restitution.mean = 1.4 is outside"),
    ({"materials": {"m": {"tangential": {"law": "friction", "friction_angle_deg": 95}}}},
     "friction_angle_deg = 95 is outside"),
    ({"materials": {"m": {"roughnes_m": 0.1}}}, "unknown field materials.m.'roughnes_m'; did you mean 'roughness_m'"),
    ({"seeder": {"x": 50.0, "mass_kg": 10}}, "seeder.x = 50 m is outside the profile"),
    ({"seeder": {"x": 1.0, "mass_kg": -10}}, "seeder.mass_kg = -10 is outside"),
    ({"seeder": {"x": 1.0, "mass_kg": 10, "shape": "cube"}}, "seeder.shape = 'cube' is not one of"),
    ({"collectors": [{"name": "c", "x": 99}]}, "collectors\\[0\\].x = 99 m .* is outside the profile"),
    ({"collectors": [{"name": "c", "x": 5, "capacity_kj": 100}]}, "height_m is required for a barrier"),
])
def test_bad_scenarios_name_the_field(patch, match):
    data = {"profile": {"x": [0, 10], "z": [10, 0], "material": "m"}, "materials": {"m": {}},
            "seeder": {"x": 1.0, "mass_kg": 10}}
    data.update(patch)
    with pytest.raises(ScenarioError, match=match) as err:
        scenario_from_dict(data, source="site.toml")
    assert "site.toml" in str(err.value)


def test_bad_run_arguments_and_files(tmp_path):
    sc = scenario([0, 10], [10, 0])
    for n in (0, -5, 2.5):
        with pytest.raises(ValueError, match="n must be a positive whole number"):
            simulation.run(sc, n=n)
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        load_scenario(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[profile\nx = 1")
    with pytest.raises(ScenarioError, match="bad.toml: not valid TOML"):
        load_scenario(bad)
    with pytest.raises(KeyError, match="no collector named 'fence'"):
        simulation.run(sc, n=1).collector("fence")


def test_profile_figure_draws_fences_at_their_height_and_keeps_the_legend_outside():
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from simulation.plotting import plot_profile
    sc = load_scenario(BARRIER)
    res = simulation.run(sc, n=30, seed=1, record_paths=5)
    x = sc.collectors[sc.collector_index("barrier")].x
    ax = plot_profile(res, fences=[(x, 5.0, "fence A, 5 m"), (x, 7.0, "fence B, 7 m")])
    try:
        lines = {ln.get_label(): ln for ln in ax.get_lines()}
        zg = float(sc.profile.ground(x))
        for label, h in (("fence A, 5 m", 5.0), ("fence B, 7 m", 7.0)):
            xs, zs = lines[label].get_data()
            assert list(xs) == [x, x] and list(zs) == pytest.approx([zg, zg + h])
        legend = ax.get_legend()
        ax.figure.canvas.draw()
        box = legend.get_window_extent()
        assert box.x0 >= ax.get_window_extent().x1          # beside the axes: hides no curve or label
        assert {"fence A, 5 m", "fence B, 7 m"} <= {t.get_text() for t in legend.get_texts()}
    finally:
        plt.close(ax.figure)
