"""Inputs as practitioners export them, outputs that never clobber, impossible values refused first.

A table-driven sweep: every case names what it feeds riskrf and what must come back.  Refused
cases assert that the message names the place (file, row, column or argument) and the value, that
no work started, and that no input file was modified.  Accepted cases assert the values read.
"""
from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from riskrf.cli import main
from riskrf.frequency.inventory.reader import read_inventory
from riskrf.core.validation import RiskrfWarning
from riskrf.io.velocities import read_velocities

from .conftest import DEMO, LAUTER, ROOT, SCENARIO, digest


# ---------------------------------------------------------------- helpers
@pytest.fixture
def inputs(tmp_path):
    d = tmp_path / "in"
    d.mkdir()
    return d


def write(path: Path, text: str, encoding="utf-8") -> Path:
    path.write_bytes(text.encode(encoding))
    return path


def site_file(directory: Path, *, name="site.toml", hazard=None, inventory=None, economics=None,
              consequences=None) -> Path:
    """The bundled demo site with fields replaced, its paths made absolute."""
    import tomllib
    data = tomllib.loads((DEMO / "demo_site.toml").read_text())
    data["inventory"]["path"] = str(DEMO / "lauterbrunnen_tls_2018.csv")
    data["inventory"]["annual_maxima"] = str(DEMO / "synthetic_corridor_1985_2024.csv")
    data["hazard"]["scenario"] = str(SCENARIO)
    if "rates" in data:
        for key in ("record", "rainfall", "warnings"):
            if key in data["rates"]:
                data["rates"][key] = str(DEMO / data["rates"][key])
    for table, extra in (("hazard", hazard), ("inventory", inventory), ("economics", economics),
                         ("consequences", consequences)):
        if extra:
            data.setdefault(table, {}).update(extra)
    path = directory / name
    path.write_text(_toml(data))
    return path


def _toml(data: dict) -> str:
    def val(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, float) and math.isnan(v):
            return "nan"
        if isinstance(v, list):
            return "[" + ", ".join(val(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{" + ", ".join(f"{json.dumps(k)} = {val(x)}" for k, x in v.items()) + "}"
        return repr(v)
    lines = []
    for table, body in data.items():
        if isinstance(body, list):
            for item in body:
                lines.append(f"[[{table}]]")
                lines += [f"{json.dumps(k)} = {val(v)}" for k, v in item.items()]
            continue
        lines.append(f"[{table}]")
        for k, v in body.items():
            if v is None:
                continue
            if isinstance(v, dict) and all(not isinstance(x, dict) for x in v.values()) and table == "uncertainty":
                continue
            lines.append(f"{json.dumps(k)} = {val(v)}")
        if table == "uncertainty" and "materials" in body:
            lines.append("[uncertainty.materials]")
            lines += [f"{json.dumps(k)} = {val(v)}" for k, v in body["materials"].items()]
    return "\n".join(lines) + "\n"


# ================================================================ 1. readers: accepted exports
SEMICOLON_COMMA = "Datum;Volumen [m3];Ort\n05.03.2019;1,192;Km 12,3\n31.12.2019;0,25;Km 14\n20.06.2020;12,5;Km 15\n"


@pytest.mark.parametrize("name,text,encoding,kwargs,volumes", [
    ("semicolon + decimal comma", SEMICOLON_COMMA, "utf-8", {}, [1.192, 0.25, 12.5]),
    ("semicolon + decimal comma + BOM", "\ufeff" + SEMICOLON_COMMA, "utf-8", {}, [1.192, 0.25, 12.5]),
    ("cp1252 with m³ in the header", SEMICOLON_COMMA.replace("[m3]", "[m³]"), "cp1252", {}, [1.192, 0.25, 12.5]),
    ("thousands dot + decimal comma", "Datum;Volumen [m3]\n05.03.2019;1.192,5\n06.03.2019;0,5\n07.03.2019;0,25\n", "utf-8",
     {}, [1192.5, 0.5, 0.25]),
    ("Swiss apostrophe thousands", "date;volume_m3\n2019-03-05;1'192.5\n2019-03-06;0.5\n2019-03-07;0.25\n", "utf-8", {},
     [1192.5, 0.5, 0.25]),
    ("comma file, quoted decimal commas", 'date,volume_m3\n2019-03-05,"1,5"\n2019-03-06,"0,5"\n', "utf-8", {},
     [1.5, 0.5]),
    ("explicit decimal=','", "date;volume_m3\n2019-03-05;1.192\n2019-03-06;2,5\n2019-03-07;0,5\n", "utf-8",
     {"decimal": ","}, [1192, 2.5, 0.5]),
    ("tab-separated", "date\tvolume_m3\n2019-03-05\t1.5\n2019-03-06\t0.5\n", "utf-8", {}, [1.5, 0.5]),
])
def test_inventory_exports_are_read(inputs, name, text, encoding, kwargs, volumes):
    f = write(inputs / "inv.csv", text, encoding)
    before = digest(inputs)
    inv = read_inventory(f, start="2019-01-01", end="2020-12-31", density_kg_m3=2650, **kwargs)
    np.testing.assert_allclose(inv.volumes, volumes)
    assert digest(inputs) == before


def test_day_first_dotted_dates_are_read_day_first_throughout(inputs):
    f = write(inputs / "inv.csv", SEMICOLON_COMMA)
    with pytest.warns(RiskrfWarning, match="inferred 2019-03-05 to 2020-06-20"):
        inv = read_inventory(f, density_kg_m3=2650)
    assert [d.strftime("%Y-%m-%d") for d in inv.events["date"]] == ["2019-03-05", "2019-12-31", "2020-06-20"]
    assert inv.start.isoformat() == "2019-03-05"


@pytest.mark.parametrize("rows,kwargs,expected", [
    # slashes: one day above 12 decides the order for the whole file
    (["05/03/2019", "31/12/2019"], {}, ["2019-03-05", "2019-12-31"]),
    (["03/05/2019", "12/31/2019"], {}, ["2019-03-05", "2019-12-31"]),
    # an explicit format resolves an ambiguous file
    (["05/03/2019", "06/04/2019"], {"date_format": "%d/%m/%Y"}, ["2019-03-05", "2019-04-06"]),
    (["05/03/2019", "06/04/2019"], {"date_format": "%m/%d/%Y"}, ["2019-05-03", "2019-06-04"]),
    # ISO and dotted dates are never ambiguous; a time of day is kept
    (["2019-03-05", "05.04.2019 14:30"], {}, ["2019-03-05", "2019-04-05"]),
    (["2019", "05.04.2019"], {}, ["NaT", "2019-04-05"]),
])
def test_date_rules(inputs, rows, kwargs, expected):
    f = write(inputs / "inv.csv", "date;volume_m3\n" + "".join(f"{r};1,5\n" for r in rows))
    inv = read_inventory(f, start="2019-01-01", end="2019-12-31", density_kg_m3=2650, **kwargs)
    got = [("NaT" if pd.isna(d) else d.strftime("%Y-%m-%d")) for d in inv.events["date"]]
    assert got == expected


def test_date_format_from_the_sidecar(inputs):
    f = write(inputs / "inv.csv", "date;volume_m3\n05/03/2019;1\n06/04/2019;2\n")
    write(inputs / "inv.toml", '[record]\nstart = 2019-01-01\nend = 2019-12-31\ndate_format = "%d/%m/%Y"\n')
    inv = read_inventory(f)
    assert inv.events["date"].iloc[0].strftime("%Y-%m-%d") == "2019-03-05"


def test_excel_second_sheet_below_three_title_rows(inputs):
    f = inputs / "export.xlsx"
    body = pd.DataFrame({"Datum": ["05.03.2019", "31.12.2019"], "Volumen [m³]": ["1,5", 2.25]})
    with pd.ExcelWriter(f) as xl:
        pd.DataFrame({"x": [1]}).to_excel(xl, sheet_name="Info", index=False)
        title = pd.DataFrame([["Felssturzkataster"], ["Kanton Bern"], [""]])
        title.to_excel(xl, sheet_name="Ereignisse", index=False, header=False)
        body.to_excel(xl, sheet_name="Ereignisse", index=False, startrow=3)
    before = digest(inputs)
    inv = read_inventory(f, sheet="Ereignisse", header_row=4, start="2019-01-01", end="2019-12-31",
                         density_kg_m3=2650)
    np.testing.assert_allclose(inv.volumes, [1.5, 2.25])
    assert inv.events["date"].iloc[0].strftime("%Y-%m-%d") == "2019-03-05"
    inv2 = read_inventory(f, sheet=2, header_row=4, start="2019-01-01", end="2019-12-31", density_kg_m3=2650)
    np.testing.assert_allclose(inv2.volumes, [1.5, 2.25])
    assert digest(inputs) == before
    with pytest.raises(ValueError, match=r"export.xlsx.*sheet = 'Nope'.*Info.*Ereignisse"):
        read_inventory(f, sheet="Nope", duration_years=1)
    with pytest.raises(ValueError, match=r"export.xlsx.*no volume or mass column.*--header-row"):
        read_inventory(f, sheet=2, duration_years=1)


def test_parquet_with_string_columns(inputs):
    f = inputs / "inv.parquet"
    pd.DataFrame({"date": pd.array(["05.03.2019", "31.12.2019"], dtype="string"),
                  "volume_m3": pd.array(["1,5", "0,25"], dtype="string")}).to_parquet(f)
    inv = read_inventory(f, start="2019-01-01", end="2019-12-31", density_kg_m3=2650)
    np.testing.assert_allclose(inv.volumes, [1.5, 0.25])


@pytest.mark.parametrize("text,kwargs,velocities,heights", [
    ("velocity_ms;height_m\n12,5;1,25\n14,0;0,5\n", {}, [12.5, 14.0], [1.25, 0.5]),
    ("\ufeffvelocity_ms;height_m\n1,5;0,1\n2,5;0,2\n", {}, [1.5, 2.5], [0.1, 0.2]),
    ("Velocity (km/h);height_m\n36;1\n72;2\n", {}, [10.0, 20.0], [1.0, 2.0]),
    ("velocity_ms,height_m\n36,1\n72,2\n", {"velocity_unit": "km/h"}, [10.0, 20.0], [1.0, 2.0]),
    ("Translational Velocity (m/s)\tBounce Height (m)\n10.5\t1\n", {}, [10.5], [1.0]),
])
def test_velocity_exports_are_read(inputs, text, kwargs, velocities, heights):
    f = write(inputs / "v.csv", text)
    before = digest(inputs)
    df = read_velocities(f, **kwargs)
    np.testing.assert_allclose(df["velocity_ms"], velocities)
    np.testing.assert_allclose(df["height_m"], heights)
    assert digest(inputs) == before


def test_cli_fit_reads_a_european_export(inputs, tmp_path, capsys):
    rng = np.random.default_rng(3)
    lines = [f"{1 + i % 12:02d}/{1 + (i * 5) % 12:02d}/{2019 + i // 12};{v:.3f}".replace(".", ",")
             for i, v in enumerate(np.exp(rng.normal(0, 1.5, 40)))]
    f = write(inputs / "kataster.csv", "Datum;Volumen [m³]\n" + "\n".join(lines) + "\n", "cp1252")
    before = digest(inputs)
    rc = main(["fit", str(f), "--date-format", "%d/%m/%Y", "--density", "2650", "--bootstrap", "0",
               "--out", str(tmp_path / "o")])
    assert rc == 0, capsys.readouterr().err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert "2019-01-01" in json.dumps(summary)      # 01/01/2019 .. ; day first as declared
    last = max(pd.Timestamp(int(x[6:10]), int(x[3:5]), int(x[0:2])) for x in lines)   # day first
    assert last.strftime("%Y-%m-%d") in json.dumps(summary)
    assert digest(inputs) == before


# ================================================================ 2. readers: refused, naming place and value
BAD_TABLES = [
    # (case, file name, text, kwargs, error regex naming place and value)
    ("ambiguous slash dates", "inv.csv", "date;volume_m3\n05/03/2019;1\n06/04/2019;2\n", {},
     r"inv.csv: column 'date'.*'05/03/2019'.*ambiguous.*date_format"),
    ("day and month both above 12", "inv.csv", "date;volume_m3\n13/03/2019;1\n03/14/2019;2\n", {},
     r"inv.csv: row 3, column 'date'.*'03/14/2019'"),
    ("date not matching the declared format", "inv.csv", "date;volume_m3\n05.03.2019;1\n2019-04-06;2\n",
     {"date_format": "%d.%m.%Y"}, r"inv.csv: row 3, column 'date'.*'2019-04-06'.*%d.%m.%Y"),
    ("decimal marks mixed in a column", "inv.csv", "date;volume_m3\n2019-03-05;1,5\n2019-03-06;1.192\n", {},
     r"inv.csv: row 3, column 'volume_m3'.*'1.192'.*decimal"),
    ("text in a size column", "inv.csv", "date;volume_m3\n2019-03-05;Minor\n", {},
     r"inv.csv: row 2, column 'volume_m3'.*'Minor' is not a number"),
    ("unknown decimal argument", "inv.csv", "date;volume_m3\n2019-03-05;1\n", {"decimal": ":"},
     r"decimal = ':'"),
    ("volumes that look like litres", "inv.csv",
     "date,volume_m3\n" + "".join(f"2019-0{1 + i % 9}-1{i % 9},{v}\n" for i, v in
                                  enumerate([30, 50, 120, 400, 800, 2500, 12000, 250000, 600000, 40])), {},
     r"inv.csv: column 'volume_m3'.*median 600 m3.*(litres|cm3).*volume_unit"),
    ("volumes that look like cm3", "inv.csv",
     "volume_m3\n" + "".join(f"{v}\n" for v in [30000, 50000, 120000, 400000, 80000, 2500000]),
     {"duration_years": 5}, r"inv.csv: column 'volume_m3'.*(litres|cm3).*volume_unit"),
    ("every row duplicated", "inv.csv",
     "date,volume_m3,location\n" + "2019-03-05,1.5,km 3\n2019-04-06,2.5,km 4\n" * 2, {},
     r"inv.csv: 2 of 4 rows.*duplicate.*rows 4, 5.*duplicates"),
    ("sheet beyond the workbook", "inv.xlsx", None, {"sheet": 5}, r"inv.xlsx: sheet = 5.*1 sheet"),
    ("corrupt xlsx", "broken.xlsx", "PK\x03\x04 this is not a zip", {}, r"broken.xlsx: cannot read"),
    ("csv that is really binary", "inv.csv", "\x00\x01\x02", {}, r"inv.csv"),
    ("header row beyond the file", "inv.csv", "date;volume_m3\n2019-03-05;1\n", {"header_row": 9},
     r"inv.csv: header_row = 9"),
]


@pytest.mark.parametrize("case,name,text,kwargs,match", BAD_TABLES, ids=[c[0] for c in BAD_TABLES])
def test_bad_inventories_are_refused_naming_place_and_value(inputs, case, name, text, kwargs, match):
    f = inputs / name
    if text is None:
        pd.DataFrame({"volume_m3": [1.0]}).to_excel(f, index=False)
    else:
        write(f, text)
    before = digest(inputs)
    kw = {"start": "2019-01-01", "end": "2019-12-31", "density_kg_m3": 2650}
    if "duration_years" in kwargs:
        kw = {"density_kg_m3": 2650}
    with pytest.raises(ValueError, match=match):
        read_inventory(f, **{**kw, **kwargs})
    assert digest(inputs) == before


def test_declared_units_accept_large_volumes_and_duplicates_can_be_dropped(inputs):
    f = write(inputs / "inv.csv", "volume_m3\n" + "".join(f"{v}\n" for v in [300, 500, 1200, 4000, 80000]))
    inv = read_inventory(f, duration_years=100, density_kg_m3=2650, volume_unit="m3")
    assert inv.volumes.max() == 80000
    inv = read_inventory(f, duration_years=100, density_kg_m3=2650, volume_unit="l")
    assert inv.volumes.max() == pytest.approx(80.0)
    g = write(inputs / "dup.csv", "date,volume_m3\n" + "2019-03-05,1.5\n2019-04-06,2.5\n" * 2)
    inv = read_inventory(g, start="2019-01-01", end="2019-12-31", density_kg_m3=2650, duplicates="drop")
    assert inv.n_events == 2 and any("2 duplicate" in n for n in inv.notes)
    inv = read_inventory(g, start="2019-01-01", end="2019-12-31", density_kg_m3=2650, duplicates="keep")
    assert inv.n_events == 4
    h = write(inputs / "few.csv", "date,volume_m3\n2019-03-05,1.5\n2019-03-05,1.5\n2019-04-06,2.5\n"
              "2019-05-06,2.5\n2019-06-06,3\n")
    with pytest.warns(RiskrfWarning, match=r"few.csv: 1 of 5 rows .*duplicate.*row 3"):
        inv = read_inventory(h, start="2019-01-01", end="2019-12-31", density_kg_m3=2650)
    assert inv.n_events == 5


def test_litres_with_a_median_between_10_and_100_warn(inputs):
    """300 falls in litres (median 40 L) typed into volume_m3: too small to refuse, too large to pass in silence."""
    rng = np.random.default_rng(11)
    litres = np.round(40 * np.exp(rng.normal(0, 1.4, 300)), 1)
    litres[0] = 2857.0
    dates = pd.date_range("2010-01-01", periods=300, freq="11D").strftime("%Y-%m-%d")
    f = inputs / "litres.csv"
    pd.DataFrame({"date": dates, "volume_m3": litres}).to_csv(f, index=False)
    med = float(np.median(litres))
    assert 10 < med <= 100 and litres.max() < 1e5
    kw = {"start": "2010-01-01", "end": "2019-12-31", "density_kg_m3": 2650}
    with pytest.warns(RiskrfWarning, match=rf"litres.csv: column 'volume_m3': median volume {med:.3g} m3 .*"
                                           r"litres.*volume_unit='l'.*volume_unit='m3'") as rec:
        inv = read_inventory(f, **kw)
    assert inv.volumes.max() == 2857.0                     # a warning, not a refusal: read as m3 as written
    assert any("median volume" in n for n in inv.notes)
    with __import__("warnings").catch_warnings():
        __import__("warnings").simplefilter("error", RiskrfWarning)
        assert read_inventory(f, volume_unit="l", **kw).volumes.max() == pytest.approx(2.857)
        read_inventory(f, volume_unit="m3", **kw)          # declared: no warning
        small = inputs / "m3.csv"
        pd.DataFrame({"date": dates, "volume_m3": litres / 10}).to_csv(small, index=False)   # median 4 m3
        read_inventory(small, **kw)
    assert len([w for w in rec if "median volume" in str(w.message)]) == 1


def test_undated_real_inventory_with_repeated_sizes_is_not_a_duplicate_error():
    inv = read_inventory(LAUTER)      # volumes only: equal rows are different falls of equal measured size
    assert inv.n_events == 317


BAD_VELOCITIES = [
    ("negative bounce height", "velocity_ms,height_m\n10,1\n12,-0.5\n", {}, r"v.csv: row 3, column 'height_m'.*-0.5"),
    ("NaN bounce height", "velocity_ms,height_m\n10,1\n12,nan\n", {}, r"v.csv: row 3, column 'height_m'.*nan"),
    ("empty bounce height", "velocity_ms;height_m\n10;1\n12;\n", {}, r"v.csv: row 3, column 'height_m'.*''"),
    ("negative velocity", "velocity_ms\n10\n-2\n", {}, r"v.csv: row 3, column 'velocity_ms'.*-2"),
    ("velocities that look like km/h", "velocity_ms\n" + "".join(f"{v}\n" for v in (60, 72, 90, 110, 85)), {},
     r"v.csv: column 'velocity_ms'.*median 85 m/s.*km/h.*velocity_unit"),
    ("unknown velocity unit", "velocity_ms\n10\n", {"velocity_unit": "mph"}, r"velocity_unit = 'mph'"),
    ("text velocity", "velocity_ms\n10\nfast\n", {}, r"v.csv: row 3, column 'velocity_ms'.*'fast'"),
]


@pytest.mark.parametrize("case,text,kwargs,match", BAD_VELOCITIES, ids=[c[0] for c in BAD_VELOCITIES])
def test_bad_velocity_files_are_refused(inputs, case, text, kwargs, match):
    f = write(inputs / "v.csv", text)
    before = digest(inputs)
    with pytest.raises(ValueError, match=match):
        read_velocities(f, **kwargs)
    assert digest(inputs) == before


# ================================================================ 3. impossible values refused before work
def energy_args(inputs, *extra):
    vel = inputs / "v.csv"
    if not vel.exists():
        rng = np.random.default_rng(1)
        pd.DataFrame({"velocity_ms": rng.normal(15, 2, 200).clip(1), "height_m": rng.exponential(1, 200)}).to_csv(
            vel, index=False)
    return ["energy", "--inventory", str(LAUTER), "--velocities", str(vel), "--bootstrap", "5", *extra]


CLI_REFUSALS = [
    ("design period 0", ["--design-period", "0"], r"--design-period = 0.*> 1"),
    ("design period negative", ["--design-period", "-100"], r"--design-period = -100"),
    ("design period half a year", ["--design-period", "0.5"], r"--design-period = 0.5"),
    ("design period one year", ["--design-period", "1"], r"--design-period = 1\b"),
    ("fence height 0", ["--fence-height", "0"], r"--fence-height = 0"),
    ("negative free board", ["--free-board", "-1"], r"--free-board = -1"),
    ("NaN free board", ["--free-board", "nan"], r"--free-board = nan"),
    ("fence capacity 0", ["--fence", "0"], r"--fence = 0"),
    ("reach probability above 1", ["--reach-probability", "1.5"], r"--reach-probability = 1.5"),
    ("rate scale 0", ["--rate-scale", "0"], r"--rate-scale = 0"),
    ("negative bootstrap", ["--bootstrap", "-1"], r"--bootstrap = -1"),
    ("zero density", ["--density", "0"], r"--density = 0"),
    ("m_min above m_max", ["--m-min", "1e5", "--m-max", "10"], r"--m-min = 100000.*--m-max = 10"),
    ("unknown collector in a scenario", ["--collector", "nope"], r"collector.*'nope'.*barrier"),
    # the design block's percentile and fragmentation parameters, before the simulation
    ("design percentile 0", ["--design-percentile", "0"], r"--design-percentile = 0\b.*> 0 and < 100"),
    ("design percentile 100", ["--design-percentile", "100"], r"--design-percentile = 100\b"),
    ("design percentile NaN", ["--design-percentile", "nan"], r"--design-percentile = nan"),
    ("fractal dimension 3", ["--fractal-dimension", "3", "--fragmentation-iterations", "3"],
     r"--fractal-dimension = 3\b.*< 3"),
    ("fractal dimension 0", ["--fractal-dimension", "0", "--fragmentation-iterations", "3"],
     r"--fractal-dimension = 0\b"),
    ("fragmentation generations 0", ["--fractal-dimension", "2.5", "--fragmentation-iterations", "0"],
     r"--fragmentation-iterations = 0\b"),
    ("fragmentation generations 13", ["--fractal-dimension", "2.5", "--fragmentation-iterations", "13"],
     r"--fragmentation-iterations = 13\b"),
    ("fractal dimension without generations", ["--fractal-dimension", "2.5"],
     r"--fractal-dimension = 2.5: .*needs --fragmentation-iterations"),
]


@pytest.mark.parametrize("case,extra,match", CLI_REFUSALS, ids=[c[0] for c in CLI_REFUSALS])
def test_energy_refuses_impossible_values_before_work(inputs, tmp_path, capsys, no_work, case, extra, match):
    args = energy_args(inputs, *extra, "--out", str(tmp_path / "o"))
    if case.startswith("unknown collector"):
        i = args.index("--velocities")
        args[i:i + 2] = ["--scenario", str(SCENARIO)]
    before = digest(inputs)
    rc = main(args)
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.startswith("riskrf energy: error:") and len(err.strip().splitlines()) == 1
    assert __import__("re").search(match, err), err
    assert not (tmp_path / "o").exists()
    assert digest(inputs) == before


RATES_REFUSALS = [
    ("closure threshold negative", ["--closure-mm", "-5"], r"--closure-mm = -5:"),
    ("closure threshold 0", ["--closure-mm", "0"], r"--closure-mm = 0:"),
    ("closure threshold NaN", ["--closure-mm", "nan"], r"--closure-mm = nan:"),
    ("closure window 0", ["--closure-mm", "50", "--closure-window", "0"], r"--closure-window = 0:"),
    ("negative cost per hour", ["--closure-mm", "50", "--cost-per-hour", "-1"], r"--cost-per-hour = -1:"),
    ("heavy day 0 mm", ["--heavy-day-mm", "0", "--heavy-day-change", "0.1"], r"--heavy-day-mm = 0:"),
    ("heavy day change -1", ["--heavy-day-mm", "50", "--heavy-day-change", "-1"], r"--heavy-day-change = -1:"),
    ("window 0 days", ["--windows", "1,0"], r"--windows = 0:"),
    ("rainfall header row 0", ["--rainfall-header-row", "0"], r"--rainfall-header-row = 0:"),
]


@pytest.mark.parametrize("case,extra,match", RATES_REFUSALS, ids=[c[0] for c in RATES_REFUSALS])
def test_rates_refuses_impossible_options_before_reading_files(inputs, tmp_path, capsys, monkeypatch, case, extra,
                                                              match):
    """`riskrf rates` checks its numbers first, naming the option (not the Python argument) and the value."""
    import riskrf.cli.steps
    import riskrf.io.rainfall
    import riskrf.frequency.rates.fit  # noqa: F401  (the module ``riskrf rates`` takes rate_model from)

    def boom(*a, **k):
        raise AssertionError("a file was read or a model fitted before the option was refused")
    monkeypatch.setattr(riskrf.io.rainfall, "read_rainfall", boom)
    monkeypatch.setattr(sys.modules["riskrf.frequency.rates.fit"], "rate_model", boom)
    monkeypatch.setattr(riskrf.cli.steps, "_read", boom)      # the inventory reader of ``riskrf rates``
    inv = write(inputs / "falls.csv", "date,volume_m3\n2001-02-03,1.0\n")
    rain = write(inputs / "rain.csv", "date,rainfall_mm\n2001-02-03,1.0\n")
    before = digest(inputs)
    rc = main(["rates", str(inv), "--rainfall", str(rain), "--out", str(tmp_path / "o"), *extra])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.startswith("riskrf rates: error:") and len(err.strip().splitlines()) == 1, err
    assert __import__("re").search(match, err), err
    assert "threshold_mm" not in err and "cost_per_hour" not in err
    assert not (tmp_path / "o").exists()
    assert digest(inputs) == before


def test_energy_with_fewer_than_one_fall_in_the_design_period_says_so(inputs, tmp_path, capsys):
    """--rate-scale 0.0001: 21.92 falls a year x 1e-4 x reach 1 = 0.00219 a year, 0.219 in 100 years.

    No fence check may say OK against a 0 kJ 100-year energy, and the UNI 11211-4 line says why it is absent.
    """
    rc = main(energy_args(inputs, "--rate-scale", "0.0001", "--out", str(tmp_path / "o")))
    out = capsys.readouterr().out
    assert rc == 0, out
    assert "[OK  ] 100-year energy" not in out and "0 kJ vs" not in out
    assert out.count("[N/A ] 100-year energy vs MEL: not defined vs") == 2
    assert "fewer than one fall reaches the line in 100 years (0.219 expected at 0.00219 arrivals per year)" in out
    assert "UNI 11211-4 design energy not computed: the 100-year block is not defined because fewer than one " \
           "fall is expected in 100 years (0.219" in out
    checks = pd.read_csv(tmp_path / "o" / "fence_checks.csv")
    assert checks.loc[checks["unit"] == "kJ", "demand"].isna().all()
    summary = json.loads((tmp_path / "o" / "energy_summary.json").read_text())
    assert "fewer than one fall" in summary["uni11211"]["not_computed"]
    # control: at the inventory's own rate the 100-year energy exists and is checked
    rc = main(energy_args(inputs, "--out", str(tmp_path / "p")))
    out = capsys.readouterr().out
    assert rc == 0 and "N/A" not in out and "UNI 11211-4 design energy for the 100-year block" in out


def test_python_api_refuses_design_periods_of_a_year_or_less():
    from riskrf.hazard.energy_study import analyse_energy
    for T in (0, 1, -100, 0.5, float("nan")):
        with pytest.raises(ValueError, match=r"design_T = .*> 1 year"):
            analyse_energy(None, design_T=T)


SITE_REFUSALS = [
    ("design period 0", {"hazard": {"design_period_years": 0}}, r"hazard.design_period_years = 0 .*> 1"),
    ("design period 1", {"hazard": {"design_period_years": 1}}, r"hazard.design_period_years = 1 "),
    ("fence height 0", {"hazard": {"fence_height_m": 0}}, r"hazard.fence_height_m = 0"),
    ("negative free board", {"hazard": {"free_board_m": -1}}, r"hazard.free_board_m = -1"),
    ("horizon 0", {"economics": {"horizon_years": 0}}, r"economics.horizon_years = 0"),
    ("vulnerability 1.5", {"consequences": {"vulnerability_moving_vehicle": 1.5}},
     r"consequences.vulnerability_moving_vehicle = 1.5"),
    ("unknown road collector", {"hazard": {"road_collector": "nope"}}, r"hazard.road_collector = 'nope'"),
    ("reach probability 2", {"hazard": {"reach_probability": 2.0}}, r"hazard.reach_probability = 2.0"),
    ("NaN m_max", {"inventory": {"m_max_kg": float("nan")}}, r"inventory.m_max_kg = nan"),
    ("negative density", {"inventory": {"density_kg_m3": -2650}}, r"inventory.density_kg_m3 = -2650"),
    ("negative drop height", {"hazard": {"drop_height_m": -5}}, r"hazard.drop_height_m = -5 must be a height > 0"),
]


def _assess_is_refused(site, inputs, tmp_path, capsys, match):
    """``riskrf assess site`` exits 2 with a one-line error naming site.toml and matching ``match``, before any
    work: no output folder, inputs untouched."""
    before = digest(inputs)
    rc = main(["assess", str(site), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert "site.toml" in err and __import__("re").search(match, err), err
    assert not (tmp_path / "o").exists()
    assert digest(inputs) == before


@pytest.mark.parametrize("case,fields,match", SITE_REFUSALS, ids=[c[0] for c in SITE_REFUSALS])
def test_assess_refuses_impossible_site_values_before_work(inputs, tmp_path, capsys, no_work, case, fields, match):
    site = site_file(inputs, **fields)
    _assess_is_refused(site, inputs, tmp_path, capsys, match)


BARRIER_REFUSALS = [   # (option index in the demo site, field, value): the demo's options[3] is a 2,000 kJ fence
    ("fence 0 m high", 3, "height_m", 0, r"options\[3\]\.height_m = 0 must be > 0 m \(option '.*', a fence\)"),
    ("fence 0 kJ", 3, "capacity_kj", 0, r"options\[3\]\.capacity_kj = 0 must be > 0 kJ"),
    ("fence negative height", 4, "height_m", -7.0, r"option 'fence 5000 kJ': height_m = -7.0 must be a number >= 0"),
    ("shed 0 kJ", 5, "capacity_kj", 0, r"options\[5\]\.capacity_kj = 0 must be > 0 kJ \(option '.*', a shed\)"),
]


@pytest.mark.parametrize("case,i,key,value,match", BARRIER_REFUSALS, ids=[c[0] for c in BARRIER_REFUSALS])
def test_assess_refuses_a_barrier_of_zero_height_or_capacity_before_work(inputs, tmp_path, capsys, no_work, case, i,
                                                                        key, value, match):
    import tomllib
    site = site_file(inputs)
    data = tomllib.loads(site.read_text())
    assert data["options"][i]["kind"] in ("fence", "shed") and key in data["options"][i]
    data["options"][i][key] = value
    site.write_text(_toml(data))
    _assess_is_refused(site, inputs, tmp_path, capsys, match)


def test_attenuator_of_zero_height_is_refused_by_the_option_parser():
    from riskrf.risk.mitigation_inputs import MitigationError, parse_option
    spec = {"name": "att", "kind": "attenuator", "capital_cost": 1, "capacity_kj": 500, "height_m": 0}
    with pytest.raises(MitigationError, match=r"corridor.toml: options\[2\]\.height_m = 0 must be > 0 m"):
        parse_option(spec, 2, "corridor.toml")
    spec.update(height_m=4, capacity_kj=0.0)
    with pytest.raises(MitigationError, match=r"corridor.toml: options\[2\]\.capacity_kj = 0.0 must be > 0 kJ"):
        parse_option(spec, 2, "corridor.toml")
    spec.update(capacity_kj=500)
    assert parse_option(spec, 2, "corridor.toml").height_m == 4


def test_site_file_and_inventory_with_the_same_stem(inputs):
    """A site file 'x.toml' beside its inventory 'x.csv' is not read as the inventory's sidecar."""
    from riskrf.app.site import load_site
    inv = inputs / "lauter.csv"
    inv.write_bytes(LAUTER.read_bytes())
    site = site_file(inputs, name="lauter.toml", inventory={"path": "lauter.csv", "duration_years": 5.2})
    s = load_site(site)
    assert s.inventory.duration_years == 5.2
    with pytest.warns(RiskrfWarning, match=r"lauter.toml is a site file, not a \[record\] sidecar"):
        got = read_inventory(inv, duration_years=5.2)
    assert got.n_events == 317 and got.period_source == "argument"


def test_assess_on_a_directory_and_decide_without_inventory(inputs, tmp_path, capsys):
    rc = main(["assess", str(inputs)])
    err = capsys.readouterr().err
    assert rc == 2 and "is a directory" in err and str(inputs) in err
    rc = main(["decide", "--options", str(site_file(inputs)), "--scenario", str(SCENARIO),
               "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "--inventory" in err and "NoneType" not in err


def test_decide_refuses_an_unknown_road_collector_before_work(inputs, tmp_path, capsys, no_work):
    rc = main(["decide", "--options", str(site_file(inputs)), "--inventory", str(LAUTER), "--scenario",
               str(SCENARIO), "--road-collector", "raod", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "--road-collector = 'raod'" in err and "'road'" in err


def test_scenario_distribution_with_min_above_max(inputs):
    import simulation
    text = SCENARIO.read_text().replace('height_m = { dist = "uniform", low = 0.5, high = 1.5 }',
                                        'height_m = { dist = "normal", mean = 1, std = 0.2, min = 2, max = 0.5 }')
    f = write(inputs / "s.toml", text)
    with pytest.raises(ValueError, match=r"s.toml: seeder.height_m.*min = 2.*max = 0.5"):
        simulation.load_scenario(f)
    f = write(inputs / "s.toml", SCENARIO.read_text().replace("low = 0.5, high = 1.5 }", "low = 1.5, high = 0.5 }", 1))
    with pytest.raises(ValueError, match=r"s.toml: seeder.height_m needs low <= mode <= high"):
        simulation.load_scenario(f)


TREE_REFUSALS = [
    ("NaN payoff", '{"type": "decision", "branches": [{"name": "a", "payoff": NaN}, {"name": "b"}]}',
     r"tree.json.*> a: payoff.*nan"),
    ("infinite cost", '{"type": "decision", "branches": [{"name": "a", "cost": Infinity}, {"name": "b"}]}',
     r"tree.json.*> a: cost.*inf"),
    ("overflowing expression", '{"type": "decision", "branches": [{"name": "a", "payoff": "9**9**9**9"}, '
     '{"name": "b"}]}', r"> a: payoff.*'9\*\*9\*\*9\*\*9'.*(overflow|not finite)"),
    ("huge integer", '{"type": "decision", "branches": [{"name": "a", "cost": 1' + "0" * 400 + '}, {"name": "b"}]}',
     r"> a: cost.*not a finite number"),
    ("division by zero", '{"type": "decision", "branches": [{"name": "a", "cost": "1/0"}, {"name": "b"}]}',
     r"> a: cost.*'1/0'.*division by zero"),
    ("NaN terminal value", '{"type": "decision", "branches": [{"name": "a", "child": {"type": "terminal", '
     '"value": NaN}}, {"name": "b"}]}', r"> a: value.*nan"),
]


@pytest.mark.parametrize("case,text,match", TREE_REFUSALS, ids=[c[0] for c in TREE_REFUSALS])
def test_decision_trees_with_impossible_numbers(inputs, tmp_path, capsys, case, text, match):
    f = write(inputs / "tree.json", text)
    before = digest(inputs)
    rc = main(["decide", str(f), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and __import__("re").search(match, err), err
    assert not (tmp_path / "o").exists() and digest(inputs) == before


@pytest.mark.parametrize("value", ["0", "-5", "nan", "inf"])
def test_risk_tolerance_must_be_positive_and_finite(inputs, tmp_path, capsys, value):
    f = write(inputs / "t.json", '{"type": "decision", "branches": [{"name": "a", "cost": 5}, {"name": "b"}]}')
    rc = main(["decide", str(f), "--risk-tolerance", value, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and f"--risk-tolerance = {value}" in err and not (tmp_path / "o").exists(), err


def test_deep_tree_is_refused_without_a_traceback(inputs, tmp_path, capsys):
    text = '{"type": "terminal", "value": 1}'
    for i in range(1500):
        text = '{"type": "decision", "branches": [{"name": "d%d", "child": %s}, {"name": "stop"}]}' % (i, text)
    f = write(inputs / "deep.json", text)
    rc = main(["decide", str(f), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "deep.json" in err and "nested" in err and "Traceback" not in err


# ================================================================ 4. outputs never clobber
def fit_args(out, *extra):
    return ["fit", str(LAUTER), "--bootstrap", "0", "--out", str(out), *extra]


def test_existing_output_directory_is_refused_then_replaced_with_overwrite(tmp_path, capsys, monkeypatch):
    out = tmp_path / "o"
    out.mkdir()
    (out / "old_figure.png").write_text("old")
    import riskrf.frequency.study

    def boom(*a, **k):
        raise AssertionError("work started")
    real = riskrf.frequency.study.analyse_inventory
    monkeypatch.setattr(riskrf.frequency.study, "analyse_inventory", boom)
    rc = main(fit_args(out))
    err = capsys.readouterr().err
    assert rc == 2 and f"--out {out}" in err and "already exists" in err and "--overwrite" in err
    assert sorted(p.name for p in out.iterdir()) == ["old_figure.png"]
    monkeypatch.setattr(riskrf.frequency.study, "analyse_inventory", real)
    rc = main(fit_args(out, "--overwrite"))
    assert rc == 0
    names = sorted(p.name for p in out.iterdir())
    assert "old_figure.png" not in names and "summary.json" in names
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]     # no partial siblings left


def test_empty_existing_output_directory_is_used(tmp_path):
    out = tmp_path / "o"
    out.mkdir()
    assert main(fit_args(out)) == 0 and (out / "summary.json").exists()


@pytest.mark.parametrize("command", ["fit", "energy", "assess"])
def test_out_naming_an_existing_file_is_refused_before_work(inputs, tmp_path, capsys, no_work, command):
    out = tmp_path / "results.txt"
    out.write_text("someone's notes")
    args = {"fit": fit_args(out), "energy": energy_args(inputs, "--out", str(out)),
            "assess": ["assess", str(site_file(inputs)), "--out", str(out)]}[command]
    for extra in ([], ["--overwrite"]):
        rc = main(args + extra)
        err = capsys.readouterr().err
        assert rc == 2 and f"--out {out}" in err and "is a file" in err, err
    assert out.read_text() == "someone's notes"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_simulate_never_replaces_an_existing_table(tmp_path, capsys, no_work):
    out = tmp_path / "existing.csv"
    out.write_text("unrelated\n")
    rc = main(["simulate", str(SCENARIO), "-n", "20", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and f"--out {out}" in err and "--overwrite" in err
    assert out.read_text() == "unrelated\n"
    d = tmp_path / "x.parquet"
    d.mkdir()
    rc = main(["simulate", str(SCENARIO), "-n", "20", "--out", str(d), "--overwrite"])
    err = capsys.readouterr().err
    assert rc == 2 and "is a directory" in err and d.is_dir()


def test_simulate_overwrite_replaces_table_and_figures_together(tmp_path, capsys):
    out = tmp_path / "c.csv"
    out.write_text("old\n")
    rc = main(["simulate", str(SCENARIO), "-n", "30", "--out", str(out), "--overwrite"])
    assert rc == 0, capsys.readouterr().err
    assert pd.read_csv(out)["collector"].notna().all()
    assert (tmp_path / "c-figures" / "runout.csv").exists()


def test_simulate_failure_in_figures_leaves_neither_table_nor_figures(tmp_path, capsys, monkeypatch):
    import riskrf.report.files

    def fail(*a, **k):
        raise ValueError("figure failed")
    monkeypatch.setattr(riskrf.report.files, "write_simulation_figures", fail)
    out = tmp_path / "c.parquet"
    rc = main(["simulate", str(SCENARIO), "-n", "30", "--out", str(out)])
    assert rc == 2 and "figure failed" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_outputs_follow_the_umask(tmp_path):
    old = os.umask(0o022)
    try:
        assert main(fit_args(tmp_path / "o")) == 0
        assert main(["simulate", str(SCENARIO), "-n", "20", "--out", str(tmp_path / "c.csv")]) == 0
    finally:
        os.umask(old)
    assert (tmp_path / "o").stat().st_mode & 0o777 == 0o755
    assert (tmp_path / "o" / "summary.json").stat().st_mode & 0o777 == 0o644
    assert (tmp_path / "c.csv").stat().st_mode & 0o777 == 0o644
    assert (tmp_path / "c-figures").stat().st_mode & 0o777 == 0o755


def test_spreadsheet_formulas_are_neutralised_in_csv(inputs, tmp_path):
    tree = {"type": "decision", "branches": [
        {"name": "=HYPERLINK(\"http://x\")", "cost": 5},
        {"name": "+cmd", "cost": -3}, {"name": "@SUM(A1)", "cost": 7}]}
    f = write(inputs / "t.json", json.dumps(tree))
    assert main(["decide", str(f), "--out", str(tmp_path / "o")]) == 0
    ranking = pd.read_csv(tmp_path / "o" / "ranking.csv")
    assert set(ranking["option"]) == {"'=HYPERLINK(\"http://x\")", "'+cmd", "'@SUM(A1)"}
    assert -3 in set(ranking.iloc[:, 1])      # negative numbers are numbers, untouched


def test_unexpected_errors_are_one_line_unless_debug(inputs, tmp_path, capsys, monkeypatch):
    import riskrf.frequency.study

    def oserror(*a, **k):
        raise PermissionError(13, "Permission denied", str(tmp_path / "x"))
    monkeypatch.setattr(riskrf.frequency.study, "analyse_inventory", oserror)
    rc = main(fit_args(tmp_path / "o"))
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "Permission denied" in err
    rc = main(["--debug"] + fit_args(tmp_path / "o"))
    assert rc == 2 and "Traceback" in capsys.readouterr().err


def test_ctrl_c_ends_with_one_line_and_nothing_written(tmp_path):
    out = tmp_path / "c.parquet"
    code = textwrap.dedent(f"""
        import sys
        from riskrf.cli import main
        import simulation
        print("ready", flush=True)
        sys.exit(main(["simulate", {str(SCENARIO)!r}, "-n", "5000000", "--out", {str(out)!r}]))
    """)
    # the child gets the default SIGINT action even when pytest runs with SIGINT ignored (nohup, background
    # jobs): Python only turns SIGINT into KeyboardInterrupt when it starts with the default action
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=tmp_path,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert proc.stdout.readline().strip() == "ready"
    time.sleep(1.5)
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stderr
    assert stderr.strip().splitlines() == ["riskrf simulate: interrupted; nothing was written "
                                          "(outputs appear only when complete)"]
    assert list(tmp_path.iterdir()) == []


def test_real_day_first_export_hong_kong_cedd():
    """A real government export: dd/mm/yyyy dates, three rows of non-UTF-8 bytes, '-' for unknown dates.

    Data: CEDD/GEO, Hong Kong SAR Government, via DATA.GOV.HK ("Landslide incidents" 1984-2020), copied
    unmodified in shared/inventories-raw/hong-kong-cedd (see its PROVENANCE.md: a regional record of
    incidents on all man-made slopes, not one slope).
    """
    from riskrf.io.tables import parse_dates, read_table
    path = ROOT / ".." / "shared" / "inventories-raw" / "hong-kong-cedd" / "cedd_incidents_1984_2020.csv"
    if not path.exists():
        pytest.skip("shared/inventories-raw/hong-kong-cedd not present")
    table, first, notes = read_table(path)
    assert len(table) == 9840 and any("cp1252" in n for n in notes)
    rows = np.arange(len(table)) + first
    with pytest.raises(ValueError, match=r"row 2096, column 'CALLDATE': cannot read date '-'"):
        parse_dates(table["CALLDATE"], path, "CALLDATE", rows)
    known = table["CALLDATE"].str.strip() != "-"
    dates, _ = parse_dates(table["CALLDATE"].where(known, ""), path, "CALLDATE", rows)
    assert (dates.dt.day > 12).sum() > 1000                  # the day-first order is decided by the data
    assert dates.iloc[0] == pd.Timestamp("2021-01-12")       # '12/01/2021', first row: 12 January, not 1 December
    assert dates.min() >= pd.Timestamp("1984-01-01") and dates.isna().sum() == (~known).sum()


def test_site_with_a_bad_velocity_file_is_refused_before_the_fits(inputs, tmp_path, capsys, no_work):
    vel = write(inputs / "v.csv", "velocity_ms;height_m\n12,5;1\n14;-2\n")
    site = site_file(inputs, hazard={"scenario": None, "velocities": str(vel), "collector": None})
    before = digest(inputs)
    rc = main(["assess", str(site), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "hazard.velocities" in err and "row 3, column 'height_m'" in err and "'-2'" in err, err
    assert digest(inputs) == before and not (tmp_path / "o").exists()


HOSTILE = [
    # (case, file name, bytes, command builder, what the one-line message must contain)
    ("empty file", "inv.csv", b"", lambda f, o: ["fit", str(f), "--out", o], "inv.csv"),
    ("BOM only", "inv.csv", b"\xef\xbb\xbf", lambda f, o: ["fit", str(f), "--out", o], "inv.csv"),
    ("header only", "inv.csv", b"date;volume_m3\n", lambda f, o: ["fit", str(f), "--out", o], "has no rows"),
    ("old .xls", "inv.xls", b"\xd0\xcf\x11\xe0", lambda f, o: ["fit", str(f), "--out", o], "unsupported"),
    ("inventory is a directory", "dir", None, lambda f, o: ["fit", str(f), "--out", o], "is a directory"),
    ("missing inventory", "nope.csv", False, lambda f, o: ["fit", str(f), "--out", o], "nope.csv"),
    ("tree is a directory", "dir", None, lambda f, o: ["decide", str(f), "--out", o],
     "is a directory, not a decision tree file"),
    ("tree not JSON", "t.json", b"{not json", lambda f, o: ["decide", str(f), "--out", o], "cannot parse"),
    ("corrupt parquet", "inv.parquet", b"PAR1garbage", lambda f, o: ["fit", str(f), "--out", o], "cannot read"),
    ("out below a file", "inv.csv", b"volume_m3\n1\n",
     lambda f, o: ["fit", str(f), "--duration-years", "1", "--out", str(f) + "/sub"], "is a file"),
]


@pytest.mark.parametrize("case,name,data,build,needle", HOSTILE, ids=[c[0] for c in HOSTILE])
def test_hostile_files_give_one_line_errors(inputs, tmp_path, capsys, case, name, data, build, needle):
    f = inputs / name
    if data is None:
        f.mkdir()
    elif data is not False:
        f.write_bytes(data)
    before = digest(inputs)
    rc = main(build(f, str(tmp_path / "o")))
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and needle in err and "Traceback" not in err, err
    assert digest(inputs) == before and not (tmp_path / "o").exists()


def test_nan_probability_and_tonnes_given_as_kg(inputs):
    from riskrf.risk.decision_tree import DecisionTree
    spec = {"type": "chance", "branches": [{"name": "a", "probability": float("nan")},
                                           {"name": "b", "probability": 1.0}]}
    with pytest.raises(ValueError, match=r"> a: probability.*nan"):
        DecisionTree.from_dict(spec, source="t.json")
    f = write(inputs / "inv.csv", "date,mass_kg\n2019-03-05,0.5\n2019-04-06,0.2\n2019-05-07,0.8\n")
    with pytest.warns(RiskrfWarning, match=r"inv.csv: column 'mass_kg': median mass 0.5 kg.*tonnes.*mass_unit"):
        read_inventory(f, start="2019-01-01", end="2019-12-31", density_kg_m3=2650)


def test_observed_stops_with_semicolons_and_decimal_commas(inputs, monkeypatch, capsys, tmp_path):
    """`riskrf calibrate` reads observed stops by the same rules (the calibration itself is stubbed)."""
    import simulation
    f = write(inputs / "stops.csv", "profile;x_stop_m\nP1;101,5\nP1;98,25\nP2;120\n")
    seen = {}

    def fake(scenario, observed, parameters, **kw):
        seen["x"] = observed["x_stop_m"].tolist()
        raise ValueError("stop here")
    monkeypatch.setattr(simulation, "calibrate", fake)
    rc = main(["calibrate", str(SCENARIO), str(f), "--parameter", "materials.talus.ground_friction_angle_deg=15:40",
               "--select", "profile=P1", "--out", str(tmp_path / "o")])
    assert rc == 2 and "stop here" in capsys.readouterr().err
    assert seen["x"] == [101.5, 98.25]
