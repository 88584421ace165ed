"""The `riskrf fit` and `riskrf demo` commands."""
import json

import pandas as pd
import pytest

from riskrf.cli import main

from .conftest import INVENTORIES


def test_fit_on_real_inventory_writes_summary_and_figures(tmp_path, capsys):
    out = tmp_path / "out"
    rc = main(["fit", str(INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2018.csv"), "--out", str(out),
               "--bootstrap", "50"])
    assert rc == 0
    text = capsys.readouterr().out
    assert "b        0.7434 ± 0.0696" in text and "Kolmogorov-Smirnov search" in text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["power_law"]["b"] == pytest.approx(0.7434, abs=1e-4)
    assert summary["units"]["mass"] == "kg"
    table = pd.read_csv(out / "design_masses.csv")
    assert set(table["T_years"]) == {10, 50, 100, 300, 1000}
    assert (out / "magnitude_frequency.png").stat().st_size > 10_000


def test_fit_on_dated_inventory_includes_gumbel_and_gev(tmp_path, capsys):
    out = tmp_path / "o"
    rc = main(["fit", str(INVENTORIES / "synthetic" / "synthetic_corridor_1985_2024.csv"), "--out", str(out),
               "--bootstrap", "20", "--gumbel-method", "moments"])
    assert rc == 0
    text = capsys.readouterr().out
    assert "Gumbel of annual maxima (moments; 35 maxima in 40 years, p0 = 0.125" in text
    assert "deviance Gumbel vs GEV" in text
    models = set(pd.read_csv(out / "design_masses.csv")["model"])
    assert {"Gumbel (moments)", "GEV (mle)", "power law annual max"} <= models
    for name in ("gumbel_plot.png", "return_levels.png", "completeness.csv"):
        assert (out / name).exists()


def test_fit_error_names_the_problem_and_writes_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("date,volume_m3\n2001-01-01,1\n2002-01-01,x\n")
    out = tmp_path / "never"
    rc = main(["fit", str(bad), "--out", str(out)])
    assert rc == 2
    assert "row 3, column 'volume_m3': 'x' is not a number" in capsys.readouterr().err
    assert not out.exists() and not any(p.name.startswith(".never") for p in tmp_path.iterdir())


def test_m_min_above_every_event_is_reported(tmp_path, capsys):
    rc = main(["fit", str(INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2015.csv"), "--m-min", "1e9",
               "--out", str(tmp_path / "x")])
    assert rc == 2 and "m_min = 1e+09 kg lies above every value" in capsys.readouterr().err


def test_help_explains_units(capsys):
    with pytest.raises(SystemExit):
        main(["fit", "--help"])
    text = capsys.readouterr().out
    assert "completeness threshold in kg" in text and "Units: mass kg" in text
