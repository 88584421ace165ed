"""`riskrf simulate`."""
import pandas as pd

from riskrf.cli import main

from .test_simulation_run import BARRIER


def test_simulate_writes_crossings_and_figures(tmp_path, capsys):
    out = tmp_path / "run.csv"
    assert main(["simulate", str(BARRIER), "-n", "3000", "--seed", "4", "--out", str(out), "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "barrier: reach probability" in text and "stopped: left profile" in text
    df = pd.read_csv(out)
    assert {"collector", "velocity_ms", "height_m", "energy_kj", "angular_velocity_rads"} <= set(df.columns)
    figs = tmp_path / "run-figures"
    for name in ("profile_trajectories.png", "collector_barrier.png", "envelopes.png", "runout.csv"):
        assert (figs / name).stat().st_size > 0


def test_simulate_bad_inputs(tmp_path, capsys):
    assert main(["simulate", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "a.csv")]) == 2
    assert "scenario file not found" in capsys.readouterr().err
    assert main(["simulate", str(BARRIER), "-n", "0", "--out", str(tmp_path / "a.csv")]) == 2
    assert "n must be a positive whole number" in capsys.readouterr().err
    assert main(["simulate", str(BARRIER), "-n", "10", "--out", str(tmp_path / "a.txt")]) == 2
    assert "use a .parquet or .csv" in capsys.readouterr().err
    assert not (tmp_path / "a.csv").exists()
