"""Reading, validating and summarising inventories."""
import hashlib
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import riskrf
from riskrf import RiskrfWarning, read_inventory

from .conftest import INVENTORIES, ROOT

LAUTER = INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2018.csv"
SYNTH = INVENTORIES / "synthetic" / "synthetic_corridor_1985_2024.csv"
NVDB = INVENTORIES / "nvdb-norway" / "nvdb_rockfalls_2015.csv"


def _digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def test_lauterbrunnen_volumes_period_and_default_density():
    with pytest.warns(RiskrfWarning, match="default 2650"):
        inv = read_inventory(LAUTER)
    assert inv.n_events == 317                     # PROVENANCE.md: 317 rows
    assert inv.duration_years == 5.2               # authors' observation period
    assert inv.volumes.min() == 0.03 and inv.volumes.max() == 267.27
    assert inv.volumes.sum() == pytest.approx(1841.7, abs=0.05)   # PROVENANCE.md
    np.testing.assert_allclose(inv.masses, inv.volumes * 2650.0)
    assert inv.density_is_default and "(default)" in inv.summary().loc["density [kg/m3]", "value"]
    assert not inv.is_dated
    with pytest.raises(ValueError, match="annual maxima need a date"):
        inv.annual_maxima()


def test_nvdb_rock_falls_dated_with_missing_sizes_and_out_of_period_rows():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        inv = read_inventory(NVDB)
    messages = " ".join(str(w.message) for w in caught)
    assert "have no size and are left out" in messages
    assert "outside the record period" in messages
    assert inv.start.isoformat() == "2014-09-01" and inv.end.isoformat() == "2015-05-18"
    assert inv.is_dated
    assert inv.volumes.max() == 25 and inv.volumes.min() == 1     # PROVENANCE.md: 1..25 m3
    assert set(inv.events["year"].unique()) == {2014, 2015}


def test_synthetic_corridor_keeps_empty_years_as_nan_and_warns():
    inv = read_inventory(SYNTH)
    assert inv.site.startswith("SYNTHETIC")
    with pytest.warns(RiskrfWarning, match="5 of 40 years have no recorded fall"):
        maxima = inv.annual_maxima()
    assert len(maxima) == 40 and maxima.isna().sum() == 5
    assert maxima.index[0] == 1985 and maxima.index[-1] == 2024
    table = inv.completeness()
    assert table["n_events"].sum() == inv.n_events and (table["n_events"] == 0).sum() == 5


def test_bundled_demo_data_are_the_documented_inventories():
    for name in ("lauterbrunnen_tls_2018", "synthetic_corridor_1985_2024", "hong_kong_rock_cuts_1984_2020"):
        for ext in ("csv", "toml"):
            shipped = ROOT / "riskrf" / "data" / f"{name}.{ext}"
            source = next(INVENTORIES.rglob(f"{name}.{ext}"))
            assert shipped.read_bytes() == source.read_bytes()


@pytest.mark.parametrize("header,scale", [("Masse [kg]", 1.0), ("mass (t)", 1000.0), ("MASS_KG", 1.0)])
def test_mass_column_names_and_units(tmp_path, header, scale):
    f = tmp_path / "inv.csv"
    f.write_text(f"Datum;{header}\n2001-05-01;2\n2003-06-02;3\n")
    inv = read_inventory(f, density_kg_m3=2500)
    np.testing.assert_allclose(inv.masses, np.array([2, 3]) * scale)
    np.testing.assert_allclose(inv.volumes, inv.masses / 2500)
    assert not inv.density_is_default and inv.size_column == "mass"


def test_volume_in_litres_and_year_only_dates(tmp_path):
    f = tmp_path / "inv.csv"
    f.write_text("year,Volume [l],chainage\n1990,500,12.3\n1992,1500,14\n")
    inv = read_inventory(f, start="1990-01-01", end="1994-12-31", density_kg_m3=2700)
    np.testing.assert_allclose(inv.volumes, [0.5, 1.5])
    assert inv.duration_years == pytest.approx(1826 / 365.25)
    with pytest.warns(RiskrfWarning, match="have no recorded fall"):
        m = inv.annual_maxima()
    assert list(m.index) == [1990, 1991, 1992, 1993, 1994] and m.isna().sum() == 3


def test_period_inferred_from_dates_warns(tmp_path):
    f = tmp_path / "inv.csv"
    f.write_text("date,volume_m3\n2001-01-01,1\n2011-01-01,2\n")
    with pytest.warns(RiskrfWarning, match="inferred 2001-01-01 to 2011-01-01"):
        inv = read_inventory(f, density_kg_m3=2650)
    assert inv.period_source == "inferred from the dates"


def test_sidecar_toml_gives_period_and_density(tmp_path):
    f = tmp_path / "site.csv"
    f.write_text("volume_m3\n1\n2\n")
    (tmp_path / "site.toml").write_text('[record]\nduration_years = 3.5\ndensity_kg_m3 = 2600\nsite = "x"\n')
    inv = read_inventory(f)
    assert inv.duration_years == 3.5 and inv.density_kg_m3 == 2600 and inv.site == "x"
    assert inv.period_source.endswith("site.toml")


def test_sidecar_states_what_the_sizes_are_and_the_site_or_cli_wins(tmp_path):
    """Issue 10 audit e: a sidecar's [record] sizes ("event_volumes" or "blocks") is carried on the Inventory and
    used when the site file / --inventory-sizes does not say; a bad value names the sidecar."""
    from riskrf.hazard.design_block import resolve_sizes
    f = tmp_path / "blocks.csv"
    f.write_text("volume_m3\n1\n2\n")
    side = tmp_path / "blocks.toml"
    side.write_text('[record]\nduration_years = 3.5\nsizes = "blocks"\n')
    inv = read_inventory(f)
    assert inv.sizes == "blocks"
    assert resolve_sizes(None, inv) == "blocks" and resolve_sizes("event_volumes", inv) == "event_volumes"
    side.write_text("[record]\nduration_years = 3.5\n")
    unstated = read_inventory(f)
    assert unstated.sizes is None and resolve_sizes(None, unstated) == "event_volumes"
    side.write_text('[record]\nduration_years = 3.5\nsizes = "boulders"\n')
    with pytest.raises(ValueError, match=r"blocks.toml: \[record\] sizes = 'boulders' must be one of"):
        read_inventory(f)


def test_excel_and_parquet_read_like_csv(tmp_path):
    df = pd.DataFrame({"date": ["2001-02-03", "2002-03-04"], "volume_m3": [1.5, 2.5]})
    df.to_excel(tmp_path / "a.xlsx", index=False)
    df.to_parquet(tmp_path / "a.parquet")
    for name in ("a.xlsx", "a.parquet"):
        inv = read_inventory(tmp_path / name, start="2001-01-01", end="2002-12-31", density_kg_m3=2650)
        np.testing.assert_allclose(inv.volumes, [1.5, 2.5])
        assert list(inv.events["year"]) == [2001, 2002]


@pytest.mark.parametrize("text,match", [
    ("date,length_m\n2001-01-01,3\n", r"no volume or mass column found among \['date', 'length_m'\]"),
    ("date,volume_m3\n2001-13-45,3\n", r"row 2, column 'date': cannot read date '2001-13-45'"),
    ("date,volume_m3\n2001-01-01,3\n2999-01-01,3\n", r"row 3, column 'date': date '2999-01-01' is in the future"),
    ("date,volume_m3\n2001-01-01,-3\n", r"row 2, column 'volume_m3': size '-3' must be > 0"),
    ("date,volume_m3\n2001-01-01,1\n2002-01-01,0\n", r"row 3, column 'volume_m3': size '0' must be > 0"),
    ("date,volume_m3\n2001-01-01,big\n", r"row 2, column 'volume_m3': 'big' is not a number"),
    ("date,volume_m3\n", r"has no rows"),
])
def test_bad_files_give_errors_naming_file_row_and_column(tmp_path, text, match):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    before = _digest(f)
    with pytest.raises(ValueError, match=match) as err:
        read_inventory(f, start="2000-01-01", end="2010-12-31", density_kg_m3=2650)
    assert "bad.csv" in str(err.value)
    assert _digest(f) == before          # input never modified


def test_undated_without_period_is_an_error(tmp_path):
    f = tmp_path / "v.csv"
    f.write_text("volume_m3\n1\n2\n")
    with pytest.raises(ValueError, match="record period is unknown"):
        read_inventory(f)


def test_missing_file_and_bad_arguments(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.csv"):
        read_inventory(tmp_path / "nope.csv")
    f = tmp_path / "v.csv"
    f.write_text("volume_m3\n1\n")
    with pytest.raises(ValueError, match="density_kg_m3 must be finite and > 0; got -1"):
        read_inventory(f, duration_years=1, density_kg_m3=-1)
    with pytest.raises(ValueError, match="volume_column = 'vol2' is not a column"):
        read_inventory(f, duration_years=1, volume_column="vol2")


def test_schiers_teaching_file_zero_mass_row_is_rejected():
    raw = ROOT.parent / "shared" / "inventories-raw" / "schiers-challenge" / "out_2.csv"
    if not raw.exists():
        pytest.skip("shared/inventories-raw not present")
    with pytest.raises(ValueError, match=r"out_2.csv: row 25, column 'm \[kg\]': size '0' must be > 0"):
        read_inventory(raw)


def test_public_names_exist():
    for name in ("read_inventory", "fit_gutenberg_richter", "fit_gumbel", "fit_gev"):
        assert hasattr(riskrf, name)
