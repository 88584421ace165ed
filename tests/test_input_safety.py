"""No way to lose or misread data: outputs never touch inputs, SIGTERM cleans up, numbers read as meant,
impossible values refused before any work, and internal faults named as such.

Every refusal asserts that the message names the argument (or file, table and field) and the value, and
that the inputs are byte-identical afterwards.
"""
from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pandas as pd
import pytest

from riskrf.cli import main

from .conftest import DEMO, LAUTER, ROOT, SCENARIO, digest


@pytest.fixture
def victim(tmp_path, monkeypatch):
    """A folder ``victim`` holding a real inventory (Lauterbrunnen TLS, Strunden et al. 2015) as base.csv with its
    sidecar base.toml, a scenario, an options file and a site file naming them; the working folder is tmp_path."""
    d = tmp_path / "victim"
    d.mkdir()
    shutil.copy(LAUTER, d / "base.csv")
    shutil.copy(LAUTER.with_suffix(".toml"), d / "base.toml")
    shutil.copy(SCENARIO, d / "slope.toml")
    site = (DEMO / "demo_site.toml").read_text()
    site = site.replace('path = "lauterbrunnen_tls_2018.csv"', 'path = "base.csv"')
    site = site.replace('scenario = "../../simulation/scenarios/road_cut_barrier.toml"', 'scenario = "slope.toml"')
    site = site.split("[rates]")[0] + "[traffic]" + site.split("[traffic]")[1]
    site = site.replace('annual_maxima = "hong_kong_rock_cuts_1984_2020.csv"', "")
    (d / "site.toml").write_text(_without_closure(site))
    options = "[traffic]" + _without_closure(site).split("[traffic]")[1]
    (d / "options.toml").write_text(options)
    pd.DataFrame({"x_stop_m": [100.0, 110.0, 120.0]}).to_csv(d / "stops.csv", index=False)
    pd.DataFrame({"date": ["2020-01-01", "2020-01-02"], "rainfall_mm": [1.0, 2.0]}).to_csv(d / "rain.csv",
                                                                                           index=False)
    monkeypatch.chdir(tmp_path)
    return d


def _without_closure(site: str) -> str:
    """The demo site without its rain-closure option (it needs the [rates] table removed here)."""
    blocks = site.split("[[options]]")
    return "[[options]]".join(b for b in blocks if 'kind = "closure"' not in b)


# ------------------------------------------------------------------ 1. outputs never touch inputs
def test_fit_with_out_the_inventory_folder_and_overwrite_refused_and_inputs_survive(victim, capsys, no_work):
    before = digest(victim)
    rc = main(["fit", "victim/base.csv", "--out", "victim", "--overwrite"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "--out = 'victim'" in err and "inventory victim/base.csv" in err and "delete" in err
    assert digest(victim) == before


COMMANDS = {
    "fit": ["fit", "victim/base.csv"],
    "rates": ["rates", "victim/base.csv", "--rainfall", "victim/rain.csv"],
    "energy": ["energy", "--inventory", "victim/base.csv", "--scenario", "victim/slope.toml"],
    "decide": ["decide", "--options", "victim/options.toml", "--inventory", "victim/base.csv", "--scenario",
               "victim/slope.toml"],
    "assess": ["assess", "victim/site.toml"],
    "simulate": ["simulate", "victim/slope.toml"],
    "calibrate": ["calibrate", "victim/slope.toml", "victim/stops.csv", "--parameter",
                  "materials.talus.ground_friction_angle_deg=20:40"],
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
@pytest.mark.parametrize("out", ["victim", ".", "", "INPUT", "INPUT/x"])
def test_every_command_refuses_an_out_that_would_touch_its_inputs(victim, capsys, no_work, command, out):
    """--out the inputs' folder, the working folder, empty, an input file itself, a path inside an input file."""
    own = "victim/base.csv" if command in ("fit", "rates") else "victim/site.toml" if command == "assess" \
        else "victim/slope.toml"
    out = out.replace("INPUT", own)
    before = digest(victim)
    rc = main(COMMANDS[command] + ["--out", out, "--overwrite"])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert f"--out = {out!r}" in err, err
    assert digest(victim) == before
    assert sorted(p.name for p in victim.parent.iterdir()) == ["victim"]      # nothing written beside


def test_out_above_the_input_folder_is_refused(victim, capsys, no_work):
    (victim / "deeper").mkdir()
    shutil.move(victim / "base.csv", victim / "deeper" / "base.csv")
    shutil.move(victim / "base.toml", victim / "deeper" / "base.toml")
    rc = main(["fit", "victim/deeper/base.csv", "--out", "victim", "--overwrite"])
    err = capsys.readouterr().err
    assert rc == 2 and "holds the inventory victim/deeper/base.csv" in err


def test_the_site_files_named_inside_a_site_are_protected(victim, tmp_path, capsys, no_work):
    """The site file names its inventory elsewhere: an --out that is that folder is refused too."""
    other = tmp_path / "data"
    other.mkdir()
    shutil.move(victim / "base.csv", other / "base.csv")
    shutil.move(victim / "base.toml", other / "base.toml")
    text = (victim / "site.toml").read_text().replace('path = "base.csv"', 'path = "../data/base.csv"')
    (victim / "site.toml").write_text(text)
    before = digest(tmp_path)
    rc = main(["assess", "victim/site.toml", "--out", "data", "--overwrite"])
    err = capsys.readouterr().err
    assert rc == 2 and "--out = 'data' holds the inventory.path of site.toml" in err, err
    assert digest(tmp_path) == before


def test_simulate_figures_folder_is_guarded_too(victim, capsys, no_work):
    rc = main(["simulate", "victim/slope.toml", "--out", "c.parquet", "--figures", "victim", "--overwrite"])
    assert rc == 2 and "--figures = 'victim' holds the scenario" in capsys.readouterr().err


def test_corridor_out_and_workers_refused_before_reading(tmp_path, capsys, monkeypatch):
    import riskrf.app.corridor
    monkeypatch.setattr(riskrf.app.corridor, "load_corridor", lambda *a, **k: (_ for _ in ()).throw(
        AssertionError("read before the arguments were checked")))
    d = tmp_path / "c"
    d.mkdir()
    (d / "corridor.toml").write_text("[corridor]\n")
    monkeypatch.chdir(tmp_path)
    assert main(["corridor", "c/corridor.toml", "--out", "c", "--overwrite"]) == 2
    assert "holds the corridor file c/corridor.toml" in capsys.readouterr().err
    assert main(["corridor", "c/corridor.toml", "--workers", "0"]) == 2
    assert "--workers = 0" in capsys.readouterr().err


def test_sigterm_cleans_up_like_ctrl_c(tmp_path):
    """SIGTERM (what timeout, schedulers and CI send) while the outputs are being written: exit 143, one line,
    no .partial-* folder left."""
    out = tmp_path / "run"
    code = textwrap.dedent(f"""
        import sys
        from riskrf.cli import main
        sys.exit(main(["demo", "--out", {str(out)!r}, "-n", "3000000"]))
    """)
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True, cwd=tmp_path)
    try:
        deadline = time.monotonic() + 300
        while not list(tmp_path.glob(".run.partial-*")):       # inside the all-or-nothing output
            assert proc.poll() is None, proc.stderr.read()
            assert time.monotonic() < deadline, "the run never started writing"
            time.sleep(0.2)
        proc.send_signal(signal.SIGTERM)
        _, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 143, stderr
    assert stderr.strip().splitlines()[-1] == ("riskrf demo: terminated (SIGTERM); nothing was written (outputs "
                                               "appear only when complete)")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("when", ["at work", "just forked"])
@pytest.mark.parametrize("how", ["SIGTERM to riskrf", "Ctrl-C at the terminal"])
def test_a_background_child_leaves_the_signal_to_riskrf(tmp_path, how, when):
    """A background child forked during a run (figures, the rate model) inherits riskrf's SIGTERM handler; it
    must not answer the signal itself: riskrf prints its one line and stops the child, which ends silently (no
    'Process ForkProcess-1: Traceback ... KeyboardInterrupt' after riskrf's line).  Ctrl-C at a terminal
    reaches the whole process group, the child included.  "just forked": the signal comes while the child is
    still in multiprocessing's start-up, before its own code has run (held there for a second)."""
    started = tmp_path / "started"
    code = textwrap.dedent(f"""
        import multiprocessing.util, pathlib, sys, time
        from riskrf.cli import _terminate_as_interrupt
        from riskrf.cli.runner import InBackground
        STARTED = pathlib.Path({str(started)!r})

        def work():
            STARTED.write_text("")
            time.sleep(60)

        if {when == "just forked"!r}:             # the child's start-up, before the work, held for a second
            close_stdin = multiprocessing.util._close_stdin

            def held():
                STARTED.write_text("")
                time.sleep(1.0)
                close_stdin()
            multiprocessing.util._close_stdin = held

        try:
            with _terminate_as_interrupt():
                child = InBackground(work)
                assert child.proc is not None, "no child was forked"
                time.sleep(60)
        except KeyboardInterrupt:
            print("riskrf: stopped", file=sys.stderr)
            sys.exit(143)
    """)
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True, cwd=tmp_path, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 120
        while not started.exists():
            assert proc.poll() is None, proc.stderr.read()
            assert time.monotonic() < deadline, "the child never started"
            time.sleep(0.05)
        if how == "SIGTERM to riskrf":
            proc.send_signal(signal.SIGTERM)
        else:
            os.killpg(proc.pid, signal.SIGINT)
        _, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 143, stderr
    assert stderr.strip().splitlines() == ["riskrf: stopped"], stderr


# ------------------------------------------------------------------ 2. numbers read as the user meant
def _inventory(tmp_path, column, values, *, name="inv.csv", dates=None, sidecar="duration_years = 10\n"):
    d = {column: values} if dates is None else {"date": dates, column: values}
    path = tmp_path / name
    pd.DataFrame(d).to_csv(path, index=False)
    if sidecar:
        path.with_suffix(".toml").write_text("[record]\n" + sidecar)
    return path


@pytest.mark.parametrize("column", ["mass_kg", "volume_m3"])
def test_us_thousands_with_exactly_three_digits_refused_naming_the_column(tmp_path, column):
    """'146,402' from an en-US export is 146,402, not 146.402: ambiguous alone, so refused with the remedy."""
    from riskrf.frequency.inventory.reader import read_inventory
    path = _inventory(tmp_path, column, ["146,402", "2,500", "1,250", "3,000"])
    with pytest.raises(ValueError, match=rf"column '{column}': every number with a comma has exactly three "
                                         r"digits after it \(such as '146,402', row 2\).*--decimal"):
        read_inventory(path)
    unit = {"volume_unit": "m3"} if column == "volume_m3" else {"mass_unit": "kg"}     # large, and meant
    inv = read_inventory(path, decimal=".", **unit)             # the commas separate thousands
    assert sorted(inv.events[column]) == [1250.0, 2500.0, 3000.0, 146402.0]
    inv = read_inventory(path, decimal=",", **unit)
    assert sorted(inv.events[column]) == [1.25, 2.5, 3.0, 146.402]


def test_a_column_holding_1_234_567_reads_every_three_digit_comma_as_thousands(tmp_path):
    from riskrf.frequency.inventory.reader import read_inventory
    path = _inventory(tmp_path, "mass_kg", ["1,234,567", "146,402", "12", "2,500"])
    inv = read_inventory(path)
    assert sorted(inv.masses) == [12.0, 2500.0, 146402.0, 1234567.0]


def test_decimal_commas_with_other_digit_counts_still_read_as_decimals(tmp_path):
    from riskrf.frequency.inventory.reader import read_inventory
    inv = read_inventory(_inventory(tmp_path, "volume_m3", ["1,5", "0,125", "2,25", "12,5"]))
    assert sorted(inv.volumes) == [0.125, 1.5, 2.25, 12.5]


def test_grouped_and_decimal_commas_mixed_refused(tmp_path):
    from riskrf.frequency.inventory.reader import read_inventory
    with pytest.raises(ValueError, match=r"row 3, column 'mass_kg': '1,234,567' separates thousands.*row 2 "
                                         r"\('1,5'\) has a decimal comma"):
        read_inventory(_inventory(tmp_path, "mass_kg", ["1,5", "1,234,567"]))


def test_the_decimal_choice_from_the_sidecar_is_used(tmp_path):
    from riskrf.frequency.inventory.reader import read_inventory
    path = _inventory(tmp_path, "mass_kg", ["146,402", "2,500"], sidecar='duration_years = 10\ndecimal = "."\n')
    assert sorted(read_inventory(path).masses) == [2500.0, 146402.0]


@pytest.mark.parametrize("density", [2.65, 0.0027, 100.0, 7000.0, 2.65e6])
def test_density_outside_500_6000_refused_everywhere(tmp_path, capsys, density, no_work):
    from riskrf.frequency.inventory.reader import read_inventory
    path = _inventory(tmp_path, "volume_m3", [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=rf"density_kg_m3 = {density!r}: a rock density must lie between 500 and "
                                         r"6,000 kg/m3"):
        read_inventory(path, density_kg_m3=density)
    path.with_suffix(".toml").write_text(f"[record]\nduration_years = 10\ndensity_kg_m3 = {density!r}\n")
    with pytest.raises(ValueError, match=r"inv.toml: \[record\] density_kg_m3"):
        read_inventory(path)
    path.with_suffix(".toml").write_text("[record]\nduration_years = 10\n")
    for argv in (["fit", str(path)], ["energy", "--inventory", str(path), "--scenario", str(SCENARIO)],
                 ["decide", "--options", str(DEMO / "demo_site.toml"), "--inventory", str(path), "--scenario",
                  str(SCENARIO)], ["rates", str(path), "--rainfall", str(path)]):
        assert main(argv + ["--density", repr(density), "--out", str(tmp_path / "o")]) == 2
        assert f"--density = {density!r}: a rock density" in capsys.readouterr().err.replace("'", "")


def test_g_per_cm3_density_message_says_so():
    from riskrf.core.validation import check_density
    with pytest.raises(ValueError, match=r"2.65 looks like g/cm3 or t/m3: 2.65 g/cm3 is 2650 kg/m3"):
        check_density(2.65, "--density")
    assert check_density(2650, "--density") == 2650.0


def test_a_fall_beyond_any_recorded_rock_avalanche_is_refused_even_with_the_unit_declared(tmp_path):
    """Seymareh (about 4.4e10 m3, Roberts & Evans 2013) is the largest known; 1e30 m3 is a typing mistake."""
    from riskrf.frequency.inventory.reader import read_inventory
    path = _inventory(tmp_path, "volume_m3", ["2.5", "1e30", "3"])
    with pytest.raises(ValueError, match=r"row 3, column 'volume_m3': a fall of 1e\+30 m3, larger than any rock "
                                         r"fall"):
        read_inventory(path, volume_unit="m3")
    ok = _inventory(tmp_path, "volume_m3", ["2.5", "4e10", "3"], name="ok.csv")   # Seymareh-size: possible
    assert read_inventory(ok, volume_unit="m3").volumes.max() == 4e10


def test_tonnes_typed_into_mass_kg_are_warned(tmp_path):
    from riskrf.frequency.inventory.reader import read_inventory
    from riskrf.core.validation import RiskrfWarning
    path = _inventory(tmp_path, "mass_kg", ["0.2", "0.5", "1.5", "0.05"])
    with pytest.warns(RiskrfWarning, match=r"median mass 0.35 kg is below 1 kg, implausibly small.*mass_unit='t'"):
        read_inventory(path)


def test_volumes_below_a_litre_are_warned(tmp_path):
    from riskrf.frequency.inventory.reader import read_inventory
    from riskrf.core.validation import RiskrfWarning
    path = _inventory(tmp_path, "volume_l", ["0.2", "0.5", "0.3"])
    with pytest.warns(RiskrfWarning, match=r"median volume 0.0003 m3 is below one litre"):
        read_inventory(path)


def test_partly_undated_inventory_uses_its_dated_rows_and_says_how_many_were_left_out(tmp_path, capsys):
    """18 of 88 undated: the 70 dated give the annual maxima; every output names the 18 and their rows."""
    rng = np.random.default_rng(3)
    dates = pd.date_range("1990-01-01", "2019-12-31", periods=88).strftime("%Y-%m-%d").tolist()
    undated = list(range(0, 88, 5))[:18]
    for i in undated:
        dates[i] = ""
    volumes = np.round(0.1 * (1 + rng.pareto(1.0, 88)), 4)
    path = _inventory(tmp_path, "volume_m3", volumes, dates=dates,
                      sidecar='start = "1990-01-01"\nend = "2019-12-31"\n')
    from riskrf.frequency.study import analyse_inventory
    from riskrf.frequency.inventory.reader import read_inventory
    inv = read_inventory(path)
    assert inv.n_undated == 18 and inv.undated_rows == [i + 2 for i in undated]
    maxima = inv.annual_maxima()
    dated = inv.events.dropna(subset=["year"])
    expected = dated.groupby(dated["year"].astype(int))["mass_kg"].max()
    pd.testing.assert_series_equal(maxima.dropna(), expected.reindex(maxima.dropna().index), check_names=False)
    analysis = analyse_inventory(inv, n_bootstrap=0)
    assert analysis.gumbel is not None and "Gumbel/GEV" not in analysis.skipped
    text = "18 of 88 events have no date (rows 2, 7, 12"
    assert text in analysis.summary_text()
    out = tmp_path / "fit"
    assert main(["fit", str(path), "--bootstrap", "0", "--out", str(out)]) == 0
    assert text in capsys.readouterr().out
    assert text in (out / "summary.json").read_text()


# ------------------------------------------------------------------ 3. one typed schema, checked before work
def _site_with(tmp_path, old, new):
    text = (DEMO / "demo_site.toml").read_text()
    assert old in text
    site = tmp_path / "site.toml"
    text = text.replace(old, new)
    for name in ("lauterbrunnen_tls_2018.csv", "hong_kong_rock_cuts_1984_2020.csv", "hko_daily_rainfall_1983_2020.csv"):
        text = text.replace(f'"{name}"', f'"{(DEMO / name).as_posix()}"')
    text = text.replace('"../../simulation/scenarios/road_cut_barrier.toml"', f'"{SCENARIO.as_posix()}"')
    site.write_text(text)
    return site


@pytest.mark.parametrize("old,new,message", [
    ("vehicles_per_day = 6000", "vehicles_per_day = 0", r"traffic.vehicles_per_day = 0 must be a number > 0 "
                                                          r"vehicles/day"),
    ("speed_kmh = 80.0 ", "speed_kmh = 0 ", r"traffic.speed_kmh = 0 must be a number > 0 km/h"),
    ("p_cannot_stop = 0.002 ", "p_cannot_stop = 1.5 ", r"traffic.p_cannot_stop = 1.5 must be a number >= 0 and "
                                                        r"<= 1"),
    ("exposed_length_m = 100.0 ", "exposed_length_m = 0 ", r"traffic.exposed_length_m = 0 must be a number > 0 m"),
    ("share_stopping_on_road = 0.3 ", "share_stopping_on_road = 2.0 ",
     r"traffic.share_stopping_on_road = 2.0 must be a number >= 0 and <= 1"),
    ("rate_scale = 0.05 ", "rate_scale = 5 ", r"inventory.rate_scale = 5 must be a number > 0 and <= 1"),
    ("discount_rate = 0.02", "discount_rate = -0.5", r"economics.discount_rate = -0.5 must be a number >= 0"),
    ("individual_risk_per_year = 1e-4", "individual_risk_per_year = 2", r"criteria.individual_risk_per_year = 2"),
])
def test_site_fields_checked_before_stage_one_naming_file_and_field(tmp_path, capsys, no_work, old, new, message):
    site = _site_with(tmp_path, old, new)
    rc = main(["assess", str(site), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2
    assert f"{site}: " in err and pytest.approx(1) == 1
    import re
    assert re.search(message, err), err


def test_schema_defaults_are_the_readers_defaults():
    """One declaration: the site reader's defaults are built from it, the mitigation dataclasses agree."""
    from dataclasses import fields

    from riskrf.core import file_schemas as fs
    from riskrf.risk.mitigation_inputs import Consequences, Criteria, Economics, Exposure
    from riskrf.app.site import SITE_FIELDS
    assert SITE_FIELDS["inventory"]["rate_scale"] == 1.0 and SITE_FIELDS == {
        t.name: t.defaults() for t in (fs.SITE, fs.INVENTORY, fs.HAZARD, fs.DESIGN_BLOCK, fs.DESIGN, fs.REPORT)}
    for table, cls in ((fs.TRAFFIC, Exposure), (fs.CONSEQUENCES, Consequences), (fs.ECONOMICS, Economics),
                       (fs.CRITERIA, Criteria)):
        declared = table.defaults()
        for f in fields(cls):
            if declared[f.name] is not None:
                assert declared[f.name] == getattr(cls(), f.name), (table.name, f.name)
        assert {f.name for f in fields(cls)} == set(declared)


def test_schema_checker_messages_and_every_kind():
    from riskrf.core.schema import REQUIRED, Field, FileSchema, Table, problems
    schema = FileSchema("f", (Table("t", (Field("n", "integer", "", "", 1, low=1), Field("p", "number", "", "", 0.5,
                                                                                          low=0, high=1),
                                          Field("r", "range", "m"), Field("k", "text", choices=("a", "b")),
                                          Field("req", "path", default=REQUIRED))),
                              Table("o", (Field("x", "number", "m", low=0, low_open=True),), array=True)))
    good = {"t": {"n": 3, "p": 1.0, "r": [1, 2], "k": "a", "req": "x.csv"}, "o": [{"name": "u", "x": 1}]}
    assert problems(good, schema, "f.toml") == []
    bad = {"t": {"n": 2.5, "p": float("nan"), "r": [2, 1], "k": "c"}, "o": [{"name": "u", "x": 0}]}
    assert problems(bad, schema, "f.toml") == [
        "f.toml: t.n = 2.5 must be a whole number >= 1", "f.toml: t.p = nan must be a number >= 0 and <= 1",
        "f.toml: t.r = [2, 1] must be [low, high] with low <= high m", "f.toml: t.k = 'c' must be one of 'a', 'b'",
        "f.toml: t.req missing must be a file name (relative to this file)", "f.toml: o[0] ('u').x = 0 must be a "
        "number > 0 m"]


def test_committed_file_format_reference_is_up_to_date():
    from riskrf.core.file_schemas import ALL_SCHEMAS
    from riskrf.core.schema import render_markdown
    committed = (ROOT / "docs" / "reference" / "file-formats-generated.md").read_text(encoding="utf-8")
    assert committed == render_markdown(ALL_SCHEMAS), ("docs/reference/file-formats-generated.md is stale: run "
                                                       "python -c 'from riskrf.core.file_schemas import "
                                                       "write_reference; write_reference()'")


def test_options_file_and_corridor_use_the_schema(tmp_path, capsys, no_work):
    opts = tmp_path / "options.toml"
    text = "[traffic]" + (DEMO / "demo_site.toml").read_text().split("[traffic]")[1]
    text = "[[options]]".join(b for b in text.split("[[options]]") if 'kind = "closure"' not in b)
    opts.write_text(text.replace("speed_kmh = 80.0 ", "speed_kmh = -80 "))
    rc = main(["decide", "--options", str(opts), "--inventory", str(LAUTER), "--scenario", str(SCENARIO),
               "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "speed_kmh = -80" in err, err
    cor = ROOT / "tests" / "data" / "corridor" / "small.toml"
    d = tmp_path / "c"
    shutil.copytree(cor.parent, d)
    (d / "small.toml").write_text(cor.read_text().replace("vehicles_per_day = 3000", "vehicles_per_day = 0"))
    assert main(["corridor", str(d / "small.toml"), "--out", str(tmp_path / "co")]) == 2
    assert "defaults.vehicles_per_day = 0 must be a number > 0 vehicles/day" in capsys.readouterr().err


# ------------------------------------------------------------------ 4. internal exceptions named, or fixed
def test_a_one_branch_chance_tree_ranks_as_one_course(tmp_path, capsys):
    """A valid tree whose root is a chance node with one branch: expected value 5 (one outcome of cost 5)."""
    import json
    tree = tmp_path / "one.json"
    tree.write_text(json.dumps({"type": "chance", "name": "storm", "branches": [
        {"name": "only", "probability": 1.0, "cost": 5}]}))
    assert main(["decide", str(tree), "--out", str(tmp_path / "o")]) == 0
    ranking = pd.read_csv(tmp_path / "o" / "ranking.csv")
    assert ranking.to_dict("records") == [{"option": "storm", "expected_value": 5, "difference_from_best": 0,
                                           "rank": 1}]


def test_negative_lognormal_median_refused_naming_the_field(tmp_path, capsys):
    sc = tmp_path / "neg.toml"
    sc.write_text(SCENARIO.read_text().replace("median = 3000", "median = -3000"))
    assert main(["simulate", str(sc), "-n", "10", "--out", str(tmp_path / "c.csv")]) == 2
    assert "seeder.mass_kg.median = -3000 must be > 0" in capsys.readouterr().err


def test_lognormal_max_far_below_its_median_refused(tmp_path, capsys):
    sc = tmp_path / "low.toml"
    sc.write_text(SCENARIO.read_text().replace("max = 700000", "max = 10"))
    assert main(["simulate", str(sc), "-n", "10", "--out", str(tmp_path / "c.csv")]) == 2
    assert "seeder.mass_kg.max = 10 lies below the median = 3000" in capsys.readouterr().err


@pytest.mark.parametrize("argv", [["fit", "BIN.csv"], ["simulate", "BIN.toml", "--out", "OUT.csv"],
                                  ["assess", "BIN.toml"],
                                  ["decide", "BIN.json"], ["corridor", "BIN.toml"]])
def test_binary_files_are_named(tmp_path, capsys, argv):
    data = bytes(range(256)) * 8
    for suffix in (".csv", ".toml", ".json"):
        (tmp_path / f"bin{suffix}").write_bytes(data)
    argv = [a.replace("BIN", str(tmp_path / "bin")).replace("OUT", str(tmp_path / "o")) for a in argv]
    assert main(argv + ([] if "--out" in argv else ["--out", str(tmp_path / "o")])) == 2
    err = capsys.readouterr().err
    assert str(tmp_path / "bin") in err and "internal error" not in err, err


def test_huge_n_refused_up_front_with_a_memory_estimate(capsys, no_work, tmp_path):
    assert main(["simulate", str(SCENARIO), "-n", "10000000000", "--out", str(tmp_path / "c.csv")]) == 2
    err = capsys.readouterr().err
    assert "-n = 10,000,000,000: simulating that many blocks needs about 2,000 GB of memory" in err


@pytest.mark.parametrize("command", [["simulate", str(SCENARIO)], ["fit", str(LAUTER)], ["demo"]])
def test_negative_seed_names_seed(command, capsys, no_work, tmp_path):
    assert main(command + ["--seed", "-1", "--out", str(tmp_path / "o")]) == 2
    assert "--seed = -1: must be a finite number >= 0" in capsys.readouterr().err


@pytest.mark.parametrize("header", ["velocity_ms", "velocity_ms,height_m", "Translational Velocity (m/s)"])
def test_header_only_velocity_file_is_not_reported_at_row_2(tmp_path, header):
    from riskrf.io.velocities import read_velocities
    path = tmp_path / "v.csv"
    path.write_text(header + "\n")
    with pytest.raises(ValueError) as info:
        read_velocities(path)
    assert "row 2" not in str(info.value) and str(path) in str(info.value) and "no velocity samples" in str(info.value)


def test_corridor_workers_zero_refused(capsys):
    assert main(["corridor", str(ROOT / "tests" / "data" / "corridor" / "small.toml"), "--workers", "0"]) == 2
    assert "--workers = 0: must be a finite number >= 1" in capsys.readouterr().err


def test_a_20000_branch_tree_prints_19999_and_skips_unreadable_diagrams(tmp_path, capsys):
    import json
    tree = tmp_path / "big.json"
    tree.write_text(json.dumps({"type": "decision", "name": "big", "objective": "max", "branches": [
        {"name": f"o{i}", "payoff": -float(i)} for i in range(20000)]}))
    assert main(["decide", str(tree), "--out", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    assert "o19999         −19,999                19,999 20000" in out
    assert "tree.png not drawn: 20,000 end branches" in out
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == ["decision.json", "ranking.csv",
                                                                  "risk_profiles.csv"]


def test_a_failure_inside_the_computation_is_an_internal_error_naming_stage_and_inputs(tmp_path, capsys,
                                                                                      monkeypatch):
    import riskrf.frequency.study

    def broken(*a, **k):
        return [][0]                          # a fault of the code, not of the input
    monkeypatch.setattr(riskrf.frequency.study, "analyse_inventory", broken)
    assert main(["fit", str(LAUTER), "--out", str(tmp_path / "o")]) == 3
    err = capsys.readouterr().err
    assert err.startswith("riskrf fit: internal error (a fault of riskrf, not of the inputs) in stage ")
    assert f"inventory {LAUTER}" in err and "IndexError: list index out of range" in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("signum,status,line", [
    (signal.SIGINT, 130, "riskrf fit: interrupted; nothing was written (outputs appear only when complete)"),
    (signal.SIGTERM, 143, "riskrf fit: terminated (SIGTERM); nothing was written (outputs appear only when "
                          "complete)")])
def test_an_interrupt_that_compiled_code_turned_into_another_error_is_still_an_interrupt(
        tmp_path, capsys, monkeypatch, signum, status, line):
    """Ctrl-C during a numba compilation surfaces as ``RuntimeError: no compiled object yet for <Library ...>``
    (the compiler catches the KeyboardInterrupt): reported as the interrupt it is, not as an internal error."""
    import riskrf.cli
    import riskrf.frequency.study

    def compiling(*a, **k):
        stopped = False
        try:
            signal.raise_signal(signum)       # the handler runs before raise_signal returns
        except KeyboardInterrupt:
            stopped = True                    # swallowed; the compiler fails later, outside this handler
        assert stopped, "the signal did not interrupt"
        raise RuntimeError("no compiled object yet for <Library 'stronge_body'>")
    monkeypatch.setattr(riskrf.frequency.study, "analyse_inventory", compiling)
    ended = []
    monkeypatch.setattr(riskrf.cli, "_end_if_terminated", lambda status, signals: ended.append(status) or status)
    # Python's own Ctrl-C action, even where this test process started with SIGINT ignored (nohup, a background
    # job): there riskrf, like Python, leaves SIGINT ignored
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        assert main(["fit", str(LAUTER), "--out", str(tmp_path / "o")]) == status
    finally:
        signal.signal(signal.SIGINT, previous)
    assert capsys.readouterr().err.strip().splitlines() == [line] and ended == [status]
    assert not (tmp_path / "o").exists()


def test_corridor_section_with_a_million_falls_a_year_refused(tmp_path, capsys):
    d = tmp_path / "c"
    shutil.copytree(ROOT / "tests" / "data" / "corridor", d)
    table = (d / "small_sections.csv").read_text().replace("A,0,200,25,3,1,0.5\n", "A,0,200,25,3,1,1000000\n")
    (d / "small_sections.csv").write_text(table)
    assert main(["corridor", str(d / "small.toml"), "--out", str(tmp_path / "o")]) == 2
    assert "row 2 (section 'A'): column 'falls_per_year' gives 1e+06 falls a year" in capsys.readouterr().err


def test_the_command_lines_log_goes_to_stdout_as_it_is_when_a_line_is_written(monkeypatch, capsys):
    """The 'riskrf' logger's handler, installed by the first :func:`main` of a process, writes to the current
    ``sys.stdout``: a notebook or a test that replaces it later gets the lines, and a stream closed since (the
    capture of an earlier test) is never written to."""
    import io
    import logging
    logger = logging.getLogger("riskrf")
    monkeypatch.setattr(logger, "handlers", [])
    first, second = io.StringIO(), io.StringIO()
    monkeypatch.setattr(sys, "stdout", first)
    with pytest.raises(SystemExit):
        main(["--help"])
    logger.info("stage 1")
    first.close()
    monkeypatch.setattr(sys, "stdout", second)
    logger.info("stage 2")
    assert second.getvalue() == "stage 2\n" and "Logging error" not in capsys.readouterr().err
