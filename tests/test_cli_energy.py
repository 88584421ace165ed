"""`riskrf energy`."""
import json

import numpy as np
import pandas as pd

from riskrf.cli import main

from .conftest import INVENTORIES
from .test_simulation_run import BARRIER

LAUTER = INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2018.csv"


def test_energy_from_scenario_on_real_inventory(tmp_path, capsys):
    out = tmp_path / "e"
    rc = main(["energy", "--inventory", str(LAUTER), "--scenario", str(BARRIER), "-n", "5000", "--m-max", "2e6",
               "--rate-scale", "0.05", "--bootstrap", "40", "--out", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "Design energies" in text and "Fence 2000 kJ / 5 m" in text and "Fence 5000 kJ / 5 m" in text
    summary = json.loads((out / "energy_summary.json").read_text())
    assert summary["units"]["energy"] == "kJ"
    table = pd.read_csv(out / "design_energies.csv")
    assert list(table["T_years"]) == [10, 50, 100, 300, 1000]
    assert (table["ci_low_kj"] <= table["energy_kj"]).all() and (table["energy_kj"] <= table["ci_high_kj"]).all()
    for name in ("energy_exceedance.png", "mass_velocity.png", "fence_checks.csv", "design_energy_tornado.png"):
        assert (out / name).stat().st_size > 0
    # the tornado of the design energy, printed and written, its base the 100-year energy
    assert "One-way sensitivity (tornado)" in text and "dominant for the 100-year energy" in text
    tornado = pd.read_csv(out / "design_energy_tornado.csv")
    t100 = tornado[tornado["design_energy"] == "100-year energy at the barrier line"]
    assert set(t100["input"]) == {"maximum credible block m_max [kg]", "rate share of the source above the line",
                                  "power-law exponent b"}
    e100 = table.loc[table["T_years"] == 100, "energy_kj"].item()
    assert np.allclose(t100["energy_base_kj"], e100, rtol=1e-9)
    assert (t100["energy_low_kj"] <= e100).sum() >= 2           # m_max and share low lower the energy, b low raises it


def test_energy_from_velocity_file(tmp_path, capsys):
    vel = tmp_path / "v.csv"
    rng = np.random.default_rng(1)
    pd.DataFrame({"velocity_ms": rng.normal(15, 2, 2000).clip(1), "height_m": rng.exponential(1, 2000)}).to_csv(
        vel, index=False)
    rc = main(["energy", "--inventory", str(LAUTER), "--velocities", str(vel), "--reach-probability", "0.3",
               "--bootstrap", "20", "--fence", "1000", "--design-percentile", "95", "--out", str(tmp_path / "o")])
    assert rc == 0
    text = capsys.readouterr().out
    assert "reach probability 0.3 as given" in text and "Fence 1000 kJ" in text
    # the "Wrote ..." line names every file the command wrote
    wrote = [line for line in text.splitlines() if line.startswith("Wrote ")]
    assert len(wrote) == 1
    files = sorted(p.name for p in (tmp_path / "o").iterdir())
    assert {"design_block.csv", "design_energy_sensitivity.csv", "site_design_masses.csv"} <= set(files)
    assert [f for f in files if f not in wrote[0]] == []
    block = pd.read_csv(tmp_path / "o" / "design_block.csv")
    assert "percentile p95" in set(block.loc[block["chosen"], "rule"])


def test_energy_design_percentile_zero_is_refused_not_replaced(tmp_path, capsys):
    """--design-percentile 0 once ran with p97 in its place."""
    vel = tmp_path / "v.csv"
    pd.DataFrame({"velocity_ms": np.linspace(10, 20, 200)}).to_csv(vel, index=False)
    rc = main(["energy", "--inventory", str(LAUTER), "--velocities", str(vel), "--design-percentile", "0",
               "--out", str(tmp_path / "o")])
    assert rc == 2 and "--design-percentile = 0" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_energy_bad_velocity_file_writes_nothing(tmp_path, capsys):
    vel = tmp_path / "v.csv"
    pd.DataFrame({"speedometer": [1.0, 2.0]}).to_csv(vel, index=False)
    rc = main(["energy", "--inventory", str(LAUTER), "--velocities", str(vel), "--out", str(tmp_path / "o")])
    assert rc == 2 and "no velocity column" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
    rc = main(["energy", "--inventory", str(LAUTER), "--out", str(tmp_path / "o")])
    assert rc == 2 and "exactly one of --scenario" in capsys.readouterr().err


def test_energy_simulates_the_fragment_design_block(tmp_path, capsys):
    """Issue 10 audit b: fractal fragmentation D = 2.9, 5 generations gives a 100-year fragment block far below
    m_min; riskrf energy widens the simulated masses to it, so its speeds are its own, not the lowest class's."""
    out = tmp_path / "e"
    rc = main(["energy", "--inventory", str(LAUTER), "--scenario", str(BARRIER), "-n", "3000", "--m-max", "2e6",
               "--rate-scale", "0.05", "--bootstrap", "5", "--fractal-dimension", "2.9",
               "--fragmentation-iterations", "5", "--out", str(out)])
    assert rc == 0, capsys.readouterr().err
    s = json.loads((out / "energy_summary.json").read_text())
    block = s["design_block"]
    assert block["rule"] == "fragmentation" and block["mass_kg"] < 100.0        # about 24 kg; m_min is 2,836 kg
    assert s["mass_classes"][0]["mass_low_kg"] <= block["mass_kg"] * (1 + 1e-12)
    alt = pd.read_csv(out / "design_block.csv")
    assert not alt["note"].str.contains("outside the simulated masses").any()
