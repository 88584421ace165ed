"""The same reading rules for every table riskrf reads: one European export per reader family.

Inventories and velocity files are covered in test_bad_input.py; here the readers moved onto
riskrf.io.tables: corridor sections, generic rainfall, block surveys and observed stops.  Each gets a
semicolon-separated export with decimal commas, written with a UTF-8 byte-order mark or in
Windows-1252 (``m³`` in a header), and an Excel workbook with the table on sheet 2 below three
title rows.
"""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from riskrf.hazard.design_block import read_block_survey
from riskrf.io.rainfall import read_rainfall
from riskrf.io.tables import read_numeric_table
from simulation.calibration import read_observed

DATA = Path(__file__).resolve().parent / "data" / "corridor"


def _excel_sheet2(path, body: pd.DataFrame, titles=("Kataster Kanton X", "Export 2024-05-01", "")):
    """``body`` on sheet 2 ("Daten") with its header on spreadsheet row 4, below three title rows."""
    with pd.ExcelWriter(path) as xl:
        pd.DataFrame({"Hinweis": ["siehe Blatt 2"]}).to_excel(xl, sheet_name="Info", index=False)
        pd.DataFrame({"t": list(titles)}).to_excel(xl, sheet_name="Daten", index=False, header=False)
        body.to_excel(xl, sheet_name="Daten", index=False, startrow=3)


# -- corridor sections ----------------------------------------------------------------------------------
def _corridor(tmp_path, table_name, extra=""):
    toml = (DATA / "small.toml").read_text().replace('sections = "small_sections.csv"',
                                                      f'sections = "{table_name}"{extra}')
    (tmp_path / "c.toml").write_text(toml)
    return tmp_path / "c.toml"


def test_corridor_sections_from_a_european_export(tmp_path):
    from riskrf.app import corridor as cr
    reference = cr.load_corridor(DATA / "small.toml")
    text = ("# Abschnitte E6, Export Strassenverwaltung (Höhe in m)\n"
            "id;chainage_from;chainage_to;cut_height_m;ditch_width_m;runout_to_road_m;falls_per_year\n"
            "A;0;200;25;3;1;0,5\n"
            "B;200;350;12;3;1;0,2\n"
            "\n"
            "C;400;700;40;2;0;1,5\n")
    (tmp_path / "s.csv").write_bytes(text.encode("cp1252"))
    c = cr.load_corridor(_corridor(tmp_path, "s.csv"))
    assert [(s.id, s.falls_per_year, s.chainage_from_m) for s in c.sections] == \
        [(s.id, s.falls_per_year, s.chainage_from_m) for s in reference.sections]
    # rows are the file's lines: the comment line 1 and the header line 2 count
    (tmp_path / "s.csv").write_bytes(text.replace("C;400;700;40;2;0;1,5", "C;400;700;40;2;0;viel").encode("cp1252"))
    with pytest.raises(cr.CorridorError, match=r"row 6 \(section 'C'\): column 'falls_per_year' = 'viel' is not a"):
        cr.load_corridor(_corridor(tmp_path, "s.csv"))
    # a column mixing decimal marks is refused as a whole, naming the row
    (tmp_path / "s.csv").write_bytes(text.replace("0;1,5", "0;1.25").encode("cp1252"))
    with pytest.raises(cr.CorridorError, match=r"row 6, column 'falls_per_year': '1.25'.*decimal"):
        cr.load_corridor(_corridor(tmp_path, "s.csv"))


def test_corridor_sections_on_sheet_2_below_title_rows_from_cli_options_or_the_toml(tmp_path, capsys):
    from riskrf.app import corridor as cr
    from riskrf.cli import main
    body = pd.read_csv(DATA / "small_sections.csv")
    _excel_sheet2(tmp_path / "s.xlsx", body)
    path = _corridor(tmp_path, "s.xlsx", '\nsections_sheet = 2\nsections_header_row = 4')
    c = cr.load_corridor(path)
    assert [s.id for s in c.sections] == list(body["id"])
    assert c.sections[0].row == 5                                   # first data row of the sheet
    plain = _corridor(tmp_path, "s.xlsx")
    with pytest.raises(cr.CorridorError, match=r"s.xlsx: .*missing column 'id'|unknown column"):
        cr.load_corridor(plain)                                     # sheet 1 holds no sections
    assert [s.id for s in cr.load_corridor(plain, sheet="Daten", header_row=4).sections] == list(body["id"])
    rc = main(["corridor", str(plain), "--sheet", "Daten", "--header-row", "40", "--out", str(tmp_path / "o")])
    assert rc == 2 and "header_row" in capsys.readouterr().err and not (tmp_path / "o").exists()


# -- rainfall --------------------------------------------------------------------------------------------
def test_generic_rainfall_from_a_european_export(tmp_path):
    f = tmp_path / "regen.csv"
    f.write_bytes(("\ufeffdate;rainfall_mm;note\n"
                   "04.03.2019;0;\n05.03.2019;12,4;Gewitter\n06.03.2019;Trace;\n07.03.2019;-;Ausfall\n"
                   "08.03.2019;1.234,5;\n").encode("utf-8"))
    with pytest.warns(Warning, match="1 gap"):
        rain = read_rainfall(f)
    assert rain.daily.index[0] == pd.Timestamp("2019-03-04")          # 04.03: day first, 4 March
    assert rain.daily["2019-03-05"] == pytest.approx(12.4) and rain.daily["2019-03-06"] == 0.0
    assert np.isnan(rain.daily["2019-03-07"]) and rain.daily["2019-03-08"] == pytest.approx(1234.5)
    assert list(rain.rows.loc["2019-03-05":"2019-03-06"]) == [3, 4]   # file lines, header = line 1
    # 31.12 and 05.03 in one cp1252 file: both day first
    g = tmp_path / "regen2.csv"
    g.write_bytes("Date;Rainfall_mm;Bemerkung\n31.12.2018;3,5;Schnee (≈ 2 cm)\n01.01.2019;0;\n".replace("≈", "~")
                  .encode("cp1252"))
    r2 = read_rainfall(g)
    assert r2.daily.index[0] == pd.Timestamp("2018-12-31") and r2.daily.iloc[0] == 3.5
    # slashes: refused when nothing decides, read with --rainfall-date-format
    h = tmp_path / "regen3.csv"
    h.write_text("date,rainfall_mm\n05/03/2019,1\n06/03/2019,2\n")
    with pytest.raises(ValueError, match=r"ambiguous.*date_format"):
        read_rainfall(h)
    assert read_rainfall(h, date_format="%d/%m/%Y").daily.index[0] == pd.Timestamp("2019-03-05")
    # Excel, sheet 2 below three title rows
    body = pd.DataFrame({"date": ["05.03.2019", "06.03.2019"], "rainfall_mm": [1.5, 0.0]})
    _excel_sheet2(tmp_path / "regen.xlsx", body)
    r3 = read_rainfall(tmp_path / "regen.xlsx", sheet=2, header_row=4)
    assert list(r3.daily) == [1.5, 0.0] and list(r3.rows) == [5, 6]


def test_cli_rates_reads_a_european_rainfall_export_and_passes_the_reading_options(tmp_path, capsys):
    from riskrf.cli import main
    rng = np.random.default_rng(2)
    days = pd.date_range("2019-02-01", "2019-04-30")
    rain = rng.gamma(0.5, 8, len(days)).round(1)
    rng = np.random.default_rng(2)
    events = pd.DatetimeIndex(rng.choice(days[20:], 30))
    inv = tmp_path / "inv.csv"
    pd.DataFrame({"date": events.strftime("%Y-%m-%d"), "volume_m3": rng.uniform(0.1, 2, 30).round(2)}).to_csv(
        inv, index=False)
    eu = tmp_path / "regen.csv"
    eu.write_bytes(("\ufeffdate;rainfall_mm\n" + "".join(f"{d:%d.%m.%Y};{str(r).replace('.', ',')}\n"
                                                         for d, r in zip(days, rain))).encode("utf-8"))
    common = ["rates", str(inv), "--start", "2019-02-21", "--end", "2019-04-30", "--no-trend", "--season", "none"]
    assert main(common + ["--rainfall", str(eu), "--out", str(tmp_path / "a")]) == 0
    assert "rainfall  " in capsys.readouterr().out
    slash = tmp_path / "regen_slash.csv"          # 01/02/2019 ... 12/04/2019: nothing decides the order
    slash.write_text("date,rainfall_mm\n" + "".join(f"{d:%d/%m/%Y},{r}\n" for d, r in zip(days, rain)
                                                    if d.day <= 12))
    assert main(common + ["--rainfall", str(slash), "--out", str(tmp_path / "b")]) == 2
    assert "ambiguous" in capsys.readouterr().err and not (tmp_path / "b").exists()
    # read day first as told (1 February to 12 April, with gaps): the rate model then names what is missing
    assert main(common + ["--rainfall", str(slash), "--rainfall-date-format", "%d/%m/%Y",
                          "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert "regen_slash.csv (2019-02-01 to 2019-04-12" in err


# -- block surveys ---------------------------------------------------------------------------------------
def test_block_survey_from_a_european_export(tmp_path):
    f = tmp_path / "bloecke.csv"
    f.write_bytes("Block;Volumen [m³];Bemerkung\n1;0,85;Kante\n2;2,4;\n3;1.250,0;Felssturz\n".encode("cp1252"))
    v = read_block_survey(f, 2650.0)
    np.testing.assert_allclose(v, [0.85, 2.4, 1250.0])
    f.write_bytes("\ufeffBlock;Volumen [dm3]\n1;850\n2;2400\n".encode("utf-8"))
    np.testing.assert_allclose(read_block_survey(f, 2650.0), [0.85, 2.4])          # dm3 -> m3
    f.write_bytes("Block;Masse [t]\n1;2,65\n2;0\n".encode("cp1252"))
    with pytest.raises(ValueError, match=r"bloecke.csv: row 3, column 'Masse \[t\]': value 0 is not a block size"):
        read_block_survey(f, 2650.0)
    _excel_sheet2(tmp_path / "b.xlsx", pd.DataFrame({"volume_m3": [0.5, 1.5]}))
    np.testing.assert_allclose(read_block_survey(tmp_path / "b.xlsx", 2650.0, sheet=2, header_row=4), [0.5, 1.5])
    pd.DataFrame({"mass_kg": ["2650", "5300"]}).to_parquet(tmp_path / "b.parquet")
    np.testing.assert_allclose(read_block_survey(tmp_path / "b.parquet", 2650.0), [1.0, 2.0])


# -- observed stops (riskrf calibrate) -------------------------------------------------------------------
def test_observed_stops_from_a_european_export(tmp_path):
    f = tmp_path / "stops.csv"
    f.write_bytes("\ufeffProfil;x_stop_m;Bemerkung\nP1;52,5;\nP1;61,25;Baum\nP2;70;\nP1;48,0;\n".encode("utf-8"))
    table = read_numeric_table(f, what="observed stops")
    obs = read_observed(f, select={"Profil": "P1"}, table=table)
    assert list(obs["x_stop_m"]) == [52.5, 61.25, 48.0]
    assert list(obs.index) == [2, 3, 5]                              # file lines, for messages
    bad = tmp_path / "bad.csv"
    bad.write_bytes("x_stop_m;y\n52,5;1\nweit;2\n".encode("cp1252"))
    with pytest.raises(ValueError, match=r"bad.csv: row 3, column 'x_stop_m': 'weit' is not a number"):
        read_numeric_table(bad, numeric=("x_stop_m",))          # as riskrf calibrate reads it
    _excel_sheet2(tmp_path / "stops.xlsx", pd.DataFrame({"x_stop_m": [52.5, 61.0]}))
    obs = read_observed(tmp_path / "stops.xlsx", table=read_numeric_table(tmp_path / "stops.xlsx", sheet=2,
                                                                             header_row=4))
    assert list(obs["x_stop_m"]) == [52.5, 61.0] and list(obs.index) == [5, 6]


# -- velocity files (riskrf energy --velocities) ---------------------------------------------------------
def test_cli_energy_reads_velocities_on_sheet_2_below_title_rows(tmp_path, capsys):
    from riskrf.cli import main

    from .conftest import INVENTORIES
    rng = np.random.default_rng(4)
    body = pd.DataFrame({"Translational Velocity (m/s)": rng.normal(15, 2, 300).clip(1).round(2),
                         "Bounce Height (m)": rng.exponential(1, 300).round(2)})
    _excel_sheet2(tmp_path / "v.xlsx", body)
    inv = str(INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2018.csv")
    base = ["energy", "--inventory", inv, "--velocities", str(tmp_path / "v.xlsx"), "--bootstrap", "5",
            "--fence", "1000"]
    assert main(base + ["--out", str(tmp_path / "a")]) == 2                  # sheet 1 has no velocities
    assert "no velocity column" in capsys.readouterr().err
    assert main(base + ["--velocities-sheet", "Daten", "--velocities-header-row", "4",
                        "--out", str(tmp_path / "b")]) == 0
    assert "300 samples" in capsys.readouterr().out
    eu = tmp_path / "v.csv"
    eu.write_bytes(("\ufeffvelocity_ms;height_m\n" + "".join(f"{v:.2f};{h:.2f}\n".replace(".", ",") for v, h in
                                                             body.to_numpy())).encode("utf-8"))
    base[4] = str(eu)
    assert main(base + ["--out", str(tmp_path / "c")]) == 0
    assert "300 samples" in capsys.readouterr().out
