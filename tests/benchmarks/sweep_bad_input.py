"""Sweep of bad (and borderline valid) inputs across every ``riskrf`` command; not run by the test suite.

Each case copies small real inputs into a fresh folder (the Lauterbrunnen TLS inventory, Strunden et al.
2015; the shipped road-cut scenario; the bundled demo site; the synthetic test corridor), changes one thing,
runs ``riskrf.cli.main`` in this process and classifies the outcome:

* ``clear error``: exit 2 and the message names what was wrong (the case's needle: file, field, argument);
* ``unclear error``: exit 2 but the needle is missing from the message;
* ``correct reading``: exit 0 and the case's check of the outputs holds;
* ``refused valid``: exit 2 on an input the case expects to be accepted;
* ``traceback``: an exception escaped, a ``Traceback`` was printed, or exit 3 (internal error);
* ``silently wrong``: exit 0 but the check of the outputs fails;
* ``silently accepted``: exit 0 on an input that must be refused;
* ``leftovers``: a ``.partial-*``/``.replaced-*`` file or folder remains (counted besides the outcome);
* ``input modified``: an input file's bytes changed (counted besides the outcome).

Run: ``python tests/benchmarks/sweep_bad_input.py [--family NAME] [--list]``; prints one line per case that
is not a clear error or correct reading, then a table of outcomes by family.
"""
from __future__ import annotations

import argparse
import contextlib
import hashlib
import io
import json
import os
import shutil
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
DEMO = ROOT / "riskrf" / "data"
SCENARIO = ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml"
CORRIDOR = ROOT / "tests" / "data" / "corridor"


@dataclass
class Case:
    family: str
    name: str
    argv: list
    files: dict = field(default_factory=dict)     # name -> text or bytes, written into the case folder
    needle: str | None = None                     # expected refusal: text the message must hold
    check: object = None                          # expected success: function(folder) -> bool


def _inventory_files(text=None, sidecar="[record]\nduration_years = 5.2\n"):
    return {"inv.csv": text if text is not None else (DEMO / "lauterbrunnen_tls_2018.csv").read_text(),
            "inv.toml": sidecar}


def _site_text(**replace):
    text = (DEMO / "demo_site.toml").read_text()
    for name in ("lauterbrunnen_tls_2018.csv", "hong_kong_rock_cuts_1984_2020.csv",
                 "hko_daily_rainfall_1983_2020.csv"):
        text = text.replace(f'"{name}"', f'"{(DEMO / name).as_posix()}"')
    text = text.replace('"../../simulation/scenarios/road_cut_barrier.toml"', f'"{SCENARIO.as_posix()}"')
    for old, new in replace.items():
        assert old in text, old
        text = text.replace(old, new)
    return text


def _set_field(text, table, key, value):
    """``text`` (a TOML document) with ``key`` of ``[table]`` set to ``value`` (TOML literal)."""
    lines = text.splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.strip() == f"[{table}]")
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("[")), len(lines))
    for i in range(start + 1, end):
        if lines[i].split("=")[0].strip() == key:
            lines[i] = f"{key} = {value}"
            break
    else:
        lines.insert(start + 1, f"{key} = {value}")
    return "\n".join(lines) + "\n"


def _options_text(**kw):
    text = "[traffic]" + _site_text(**kw).split("[traffic]")[1]
    return "[[options]]".join(b for b in text.split("[[options]]") if 'kind = "closure"' not in b)


def _json_ok(name, key, want):
    def check(folder):
        data = json.loads((folder / "out" / name).read_text())
        return data.get(key) == want
    return check


def _exists(*names):
    return lambda folder: all((folder / n).exists() for n in names)


def cases() -> list:
    out = []
    inv = ["inv.csv"]
    energy = ["energy", "--inventory", "inv.csv", "--scenario", str(SCENARIO), "-n", "300", "--bootstrap", "0"]
    decide = ["decide", "--options", "opts.toml", "--inventory", "inv.csv", "--scenario", str(SCENARIO)]
    rates = ["rates", "inv.csv", "--rainfall", "rain.csv"]
    commands = {
        "fit": (["fit", "inv.csv", "--bootstrap", "0"], _inventory_files(), ["inv.csv", "inv.toml"]),
        "simulate": (["simulate", "slope.toml", "-n", "50"], {"slope.toml": SCENARIO.read_text()}, ["slope.toml"]),
        "energy": (energy, _inventory_files(), ["inv.csv"]),
        "decide": (decide, {**_inventory_files(), "opts.toml": _options_text()}, ["opts.toml", "inv.csv"]),
        "assess": (["assess", "site.toml", "-n", "2000"], {"site.toml": _site_text()}, ["site.toml"]),
        "rates": (rates, {**_inventory_files(), "rain.csv": "date,rainfall_mm\n2018-01-01,3\n"}, ["inv.csv"]),
        "calibrate": (["calibrate", "slope.toml", "stops.csv", "--parameter",
                       "materials.talus.ground_friction_angle_deg=20:40"],
                      {"slope.toml": SCENARIO.read_text(), "stops.csv": "x_stop_m\n100\n110\n"}, ["slope.toml"]),
        "corridor": (["corridor", "c.toml"], {"c.toml": (CORRIDOR / "small.toml").read_text(),
                                              "small_sections.csv": (CORRIDOR / "small_sections.csv").read_text()},
                     ["c.toml"]),
    }
    # --- family: outputs and inputs -----------------------------------------------------------------------------
    for cmd, (argv, files, own) in commands.items():
        moved = {f"in/{k}": v for k, v in files.items()}
        a = [f"in/{x}" if x in files else x for x in argv]
        for target in ("in", ".", "", f"in/{own[0]}", f"in/{own[0]}/x", "..", "in/.."):
            if cmd == "simulate" and target == f"in/{own[0]}":
                target = "in/slope.toml"
            out.append(Case("outputs vs inputs", f"{cmd} --out {target!r} --overwrite",
                            a + ["--out", target, "--overwrite"], moved, "--out"))
        if cmd == "simulate":
            out.append(Case("outputs vs inputs", "simulate --figures in", a + ["--out", "c.csv", "--figures", "in",
                                                                                "--overwrite"], moved, "--figures"))
    named = _site_text(**{f'"{(DEMO / "lauterbrunnen_tls_2018.csv").as_posix()}"': '"data/inv.csv"'})
    out.append(Case("outputs vs inputs", "assess --out the folder of a file the site names",
                    ["assess", "site.toml", "--out", "data", "--overwrite"],
                    {"site.toml": named, **{f"data/{k}": v for k, v in _inventory_files().items()}}, "--out"))
    out.append(Case("outputs vs inputs", "assess --out '' ", ["assess", "site.toml", "--out", ""],
                    {"site.toml": named, **{f"data/{k}": v for k, v in _inventory_files().items()}}, "--out"))
    # --- family: numbers in inventories --------------------------------------------------------------------------
    def inv_case(name, text, needle=None, check=None, extra=(), sidecar="[record]\nduration_years = 5\n",
                 command="fit"):
        argv = {"fit": ["fit", "inv.csv", "--bootstrap", "0"], "energy": energy, "rates": rates}[command]
        files = {"inv.csv": text, "inv.toml": sidecar, "rain.csv": "date,rainfall_mm\n2018-01-01,3\n"}
        out.append(Case("inventory numbers", f"{command}: {name}", argv + list(extra), files, needle, check))

    us = "mass_kg\n" + "\n".join(f'"{v}"' for v in ("146,402", "2,500", "1,250", "3,000", "12,750", "5,125"))
    for command in ("fit", "energy", "rates"):
        inv_case("US thousands, three digits", us, "every number with a comma has exactly three digits",
                 command=command)
        inv_case("US volumes, three digits", us.replace("mass_kg", "volume_m3"), "exactly three digits",
                 command=command)
        inv_case("1,234,567 mixed with 1,5", 'mass_kg\n"1,5"\n"1,234,567"\n"2,5"\n', "separates thousands",
                 command=command)
        for bad, needle in (("-5", "must be > 0"), ("0", "must be > 0"), ("abc", "is not a number"),
                            ("inf", "not finite"), ("nan", "is not a number"), ("1e30", "larger than any rock fall"),
                            ("1e400", "not finite")):
            inv_case(f"volume {bad}", f"volume_m3\n1.5\n{bad}\n2.5\n", needle, command=command)
        for density in ("2.65", "0", "-2650", "1e9", "nan", "inf", "7000", "100"):
            inv_case(f"--density {density}", "volume_m3\n1.5\n2.5\n3.5\n", "--density", extra=["--density", density],
                     command=command)
            inv_case(f"sidecar density {density}", "volume_m3\n1.5\n2.5\n3.5\n", "density_kg_m3",
                     sidecar=f"[record]\nduration_years = 5\ndensity_kg_m3 = {density}\n", command=command)
    thousands_ok = "mass_kg\n" + "\n".join(f'"{v}"' for v in ("1,234,567", "146,402", "12", "2,500", "7,300", "1,100",
                                                                "45", "860", "3,300", "15", "2,100", "640", "9,900"))

    us12 = "mass_kg\n" + "\n".join(f'"{v}"' for v in ("146,402", "2,500", "1,250", "3,000", "12,750", "5,125",
                                                         "1,010", "2,020", "4,400", "8,800", "16,500", "33,100"))

    def largest(want):
        return lambda folder: abs(__import__("pandas").read_csv(folder / "out" / "completeness.csv")[
            "largest_kg"].max() - want) < 1e-6 * want
    inv_case("--decimal . confirms thousands", us12, check=largest(146402.0), extra=["--decimal", ".",
                                                                                     "--mass-unit", "kg"])
    inv_case("--decimal , confirms decimals", us12, check=largest(146.402), extra=["--decimal", ","])
    inv_case("sidecar decimal", us12, check=largest(146402.0),
             sidecar='[record]\nduration_years = 5\ndecimal = "."\nmass_unit = "kg"\n')
    inv_case("1,234,567 reads as thousands", thousands_ok, check=largest(1234567.0), extra=["--mass-unit", "kg"])
    inv_case("header only", "volume_m3\n", "no rows")
    inv_case("empty file", "", "inv.csv")
    inv_case("binary", bytes(range(256)) * 4, "inv.csv")
    inv_case("no size column", "date,location\n2019-01-01,a\n", "no volume or mass column")
    inv_case("future date", "date,volume_m3\n2099-01-01,1.5\n2019-01-01,2\n", "in the future")
    inv_case("ambiguous dates", "date,volume_m3\n01/02/2019,1.5\n03/04/2019,2\n", "ambiguous")
    partial = "date,volume_m3\n" + "\n".join(("" if i % 5 == 0 else f"20{10 + i // 8:02d}-0{1 + i % 8}-15") +
                                              f",{1 + (i * 37) % 23 / 4}" for i in range(88))

    def undated_said(folder):
        data = (folder / "out" / "summary.json").read_text()
        return "18 of 88 events have no date" in data and "the inventory has no dates" not in data
    inv_case("18 of 88 undated", partial, check=undated_said, sidecar="")
    inv_case("tonnes in mass_kg (warned)", "mass_kg\n" + "\n".join(f"{0.05 * (i + 1):.2f}" for i in range(14)),
             check=lambda f: "below 1 kg" in (f / "out" / "summary.json").read_text())
    inv_case("litres in volume_m3", "volume_m3\n" + "\n".join(str(200 + i) for i in range(30)), "litres")
    # --- family: command-line numbers ---------------------------------------------------------------------------
    def arg_case(cmd, option, value, needle=None):
        argv, files, _ = commands[cmd]
        out.append(Case("command-line arguments", f"{cmd} {option} {value}", argv + [option, value], files,
                        needle or option))
    for cmd in ("simulate", "energy", "decide", "assess", "calibrate"):
        for v in ("0", "-5", "10000000000"):
            arg_case(cmd, "-n", v)
    for cmd in ("fit", "simulate", "energy", "decide", "assess", "calibrate", "demo"):
        if cmd == "demo":
            out.append(Case("command-line arguments", "demo --seed -1", ["demo", "--seed", "-1"], {}, "--seed"))
            out.append(Case("command-line arguments", "demo -n 0", ["demo", "-n", "0"], {}, "-n"))
            continue
        arg_case(cmd, "--seed", "-1")
    for cmd in ("energy", "decide"):
        for option, values in (("--rate-scale", ("0", "-1", "5", "nan")), ("--reach-probability", ("0", "2", "-0.5")),
                               ("--m-min", ("0", "-1")), ("--m-max", ("0", "inf")), ("--bootstrap", ("-1",)),
                               ("--duration-years", ("0", "-3"))):
            for v in values:
                arg_case(cmd, option, v)
    for option, values in (("--fence", ("0", "-2000")), ("--fence-height", ("0", "-1")), ("--free-board", ("-1",)),
                           ("--design-period", ("1", "0.5")), ("--design-percentile", ("0", "100", "150")),
                           ("--fractal-dimension", ("0", "3", "5"))):
        for v in values:
            arg_case("energy", option, v)
    for v in ("0", "-2"):
        arg_case("corridor", "--workers", v)
    arg_case("corridor", "-n", "10")
    for option, v in (("--m-min", "0"), ("--workers", "0"), ("--bootstrap-grid", "1"), ("--header-row", "0")):
        arg_case("fit", option, v)
    for option, v in (("--closure-mm", "0"), ("--closure-window", "0"), ("--windows", "0,3"), ("--windows", "a"),
                      ("--heavy-day-change", "-2")):
        arg_case("rates", option, v)
    # --- family: site fields ------------------------------------------------------------------------------------
    site_fields = {
        "traffic": {"vehicles_per_day": ("0", "-10", '"many"'), "vehicle_length_m": ("0", "-5"),
                    "speed_kmh": ("0", "-80"), "occupants_per_vehicle": ("0", "0.5"),
                    "commuter_trips_per_day": ("-1",), "hours_rock_on_road": ("-1",),
                    "p_cannot_stop": ("1.5", "-0.1"), "share_stopping_on_road": ("2.0", "-0.3"),
                    "exposed_length_m": ("0", "-100")},
        "consequences": {"value_of_statistical_life": ("-1",), "vehicle_damage": ("-1",),
                         "closure_days_per_fall": ("-1",), "closure_cost_per_day": ("-5",), "detour_hours": ("-1",),
                         "value_of_time_per_hour": ("-1",), "cleanup_cost_per_fall": ("-1",),
                         "vulnerability_moving_vehicle": ("1.5",)},
        "economics": {"discount_rate": ("-0.5", "1.5"), "horizon_years": ("0", "-50")},
        "criteria": {"individual_risk_per_year": ("0", "2")},
        "inventory": {"rate_scale": ("5", "0", "-0.05"), "density_kg_m3": ("2.65", "0", "1e6"),
                      "m_max_kg": ("0", "-1"), "m_min_kg": ("-1",), "duration_years": ("0",), "decimal": ('";"',)},
        "hazard": {"n_blocks": ("0", "-5"), "reach_probability": ("0", "1.5"), "fences_kj": ("[0]", "[-1000]"),
                   "fence_height_m": ("0", "[1, 2, 3]"), "free_board_m": ("-1",), "design_period_years": ("1", "0"),
                   "bootstrap": ("0",), "option_blocks": ("0",), "mass_coupling": ('"both"',),
                   "collector": ('"nowhere"',), "drop_height_m": ("0",)},
        "design_block": {"percentile": ("0", "100"), "fractal_dimension": ("3.5",), "rule": ('"biggest"',)},
        "uncertainty": {"samples": ("0",), "rate_factor": ("[2, 1]",), "discount_rate": ("[0.01, 1.5]",),
                        "material_draws": ("0",)},
    }
    for table, fields_ in site_fields.items():
        for key, values in fields_.items():
            for v in values:
                text = _set_field(_site_text(), table, key, v)
                out.append(Case("site fields", f"{table}.{key} = {v}", ["assess", "site.toml", "-n", "2000"],
                                {"site.toml": text}, key))
    for key, v, needle in (("vehicles_per_day", "0", "vehicles_per_day"), ("speed_kmh", "-1", "speed_kmh"),
                           ("share_stopping_on_road", "3", "share_stopping_on_road")):
        text = _set_field(_options_text(), "traffic", key, v)
        out.append(Case("site fields", f"decide --options traffic.{key} = {v}", decide,
                        {**_inventory_files(), "opts.toml": text}, needle))
    for old, new, needle in (('capacity_kj = 2000', 'capacity_kj = 0', "capacity_kj"),
                             ('capital_cost = 350000', 'capital_cost = -1', "capital_cost"),
                             ('width_m = 8.0', 'width_m = -8', "width_m"),
                             ('x_m = 85.0', 'x_m = 5000', "x_m"),
                             ('kind = "fence"', 'kind = "wall"', "kind"),
                             ('max_mass_kg = 26500', 'max_mass_kg = -5', "max_mass_kg")):
        out.append(Case("site fields", f"option {new}", ["assess", "site.toml"],
                        {"site.toml": _site_text(**{old: new})}, needle))
    out.append(Case("site fields", "unknown field typo", ["assess", "site.toml"],
                    {"site.toml": _site_text(**{"vehicles_per_day = 6000": "vehicle_per_day = 6000"})},
                    "did you mean"))
    out.append(Case("site fields", "site file missing", ["assess", "nosite.toml"], {}, "nosite.toml"))
    out.append(Case("site fields", "site file binary", ["assess", "site.toml"], {"site.toml": bytes(range(256))},
                    "site.toml"))
    # --- family: scenarios ----------------------------------------------------------------------------------------
    sc = SCENARIO.read_text()
    for old, new, needle in (("median = 3000", "median = -3000", "median"), ("max = 700000", "max = 10", "max"),
                             ("sigma = 1.0", "sigma = -1.0", "spread"), ("density_kg_m3 = 2650", "density_kg_m3 = 2.65",
                                                                          "density_kg_m3"),
                             ("density_kg_m3 = 2650", "density_kg_m3 = 0", "density_kg_m3"),
                             ("x = 100.0", "x = 1000.0", "x"), ("max_events = 5000", "max_events = 0", "max_events"),
                             ("stop_velocity_ms = 0.05", "stop_velocity_ms = 0", "stop_velocity_ms"),
                             ("contact_velocity_ms = 0.5", "contact_velocity_ms = -1", "contact_velocity_ms"),
                             ('preset = "talus"', 'preset = "cheese"', "cheese"),
                             ("x = [6.0, 14.0]", "x = [14.0, 6.0]", "x"),
                             ("low = 0.5, high = 1.5 }\nmass_kg", "low = 1.5, high = 0.5 }\nmass_kg", "low")):
        for cmd, argv in (("simulate", ["simulate", "slope.toml", "-n", "50"]),
                          ("energy", ["energy", "--inventory", "inv.csv", "--scenario", "slope.toml", "-n", "300"])):
            out.append(Case("scenarios", f"{cmd}: {new}", argv, {"slope.toml": sc.replace(old, new, 1),
                                                                   **_inventory_files()}, needle))
    out.append(Case("scenarios", "simulate: binary scenario", ["simulate", "slope.toml"],
                    {"slope.toml": bytes(range(256)) * 3}, "slope.toml"))
    out.append(Case("scenarios", "simulate: valid, 200 blocks", ["simulate", "slope.toml", "-n", "200", "--out",
                                                                  "out.csv"], {"slope.toml": sc},
                    check=_exists("out.csv", "out-figures/runout.csv")))
    # --- family: decision trees ------------------------------------------------------------------------------------
    def tree_case(name, tree, needle=None, check=None):
        data = tree if isinstance(tree, (bytes, str)) else json.dumps(tree)
        out.append(Case("decision trees", name, ["decide", "t.json"], {"t.json": data}, needle, check))

    def ranking_is(rows):
        def check(folder):
            import pandas as pd
            r = pd.read_csv(folder / "out" / "ranking.csv")
            return r["option"].tolist() == rows
        return check
    tree_case("one-branch chance root", {"type": "chance", "name": "storm", "branches": [
        {"name": "only", "probability": 1.0, "cost": 5}]}, check=ranking_is(["storm"]))
    tree_case("one option", {"type": "decision", "branches": [{"name": "a", "cost": 1}]}, check=ranking_is(["a"]))
    tree_case("probabilities sum 0.9", {"type": "decision", "branches": [{"name": "a", "child": {
        "type": "chance", "branches": [{"name": "x", "probability": 0.5}, {"name": "y", "probability": 0.4}]}},
        {"name": "b"}]}, "sum")
    tree_case("negative probability", {"type": "decision", "branches": [{"name": "a", "child": {
        "type": "chance", "branches": [{"name": "x", "probability": -0.5}, {"name": "y", "probability": 1.5}]}},
        {"name": "b"}]}, "probability")
    tree_case("no branches", {"type": "decision", "branches": []}, "branch")
    tree_case("unknown node type", {"type": "maybe", "branches": []}, "maybe")
    tree_case("not JSON", "{type: decision", "t.json")
    tree_case("binary", bytes(range(256)) * 3, "t.json")
    tree_case("20,000 options", {"type": "decision", "objective": "max", "branches": [
        {"name": f"o{i}", "payoff": -float(i)} for i in range(20000)]}, check=lambda f: (
            __import__("pandas").read_csv(f / "out" / "ranking.csv")["expected_value"].min() == -19999))
    # --- family: velocity files -----------------------------------------------------------------------------------
    vel = ["energy", "--inventory", "inv.csv", "--velocities", "v.csv", "--bootstrap", "0"]
    for name, text, needle in (("header only", "velocity_ms\n", "no velocity samples"),
                               ("header only, RocFall", "Translational Velocity (m/s)\n", "v.csv"),
                               ("negative", "velocity_ms\n5\n-3\n", "v.csv"),
                               ("text", "velocity_ms\nfast\n", "not a number"),
                               ("km/h as m/s", "velocity_ms\n" + "\n".join(["90"] * 50), "km/h"),
                               ("binary", bytes(range(256)) * 3, "v.csv"),
                               ("no velocity column", "colour\nred\n", "v.csv")):
        out.append(Case("velocity files", name, vel, {**_inventory_files(), "v.csv": text}, needle))
    # --- family: corridor -----------------------------------------------------------------------------------------
    ctext = (CORRIDOR / "small.toml").read_text()
    csv = (CORRIDOR / "small_sections.csv").read_text()
    for old, new, needle in (("vehicles_per_day = 3000", "vehicles_per_day = 0", "vehicles_per_day"),
                             ("speed_kmh = 80", "speed_kmh = -1", "speed_kmh"),
                             ("n_blocks = 400", "n_blocks = 5", "n_blocks"),
                             ("b = 0.7", "b = -0.7", "b"),
                             ("discount_rate = 0.03", "discount_rate = 3", "discount_rate"),
                             ("face_angle_deg = 60", "face_angle_deg = 120", "face_angle_deg"),
                             ('sections = "small_sections.csv"', 'sections = "missing.csv"', "missing.csv")):
        out.append(Case("corridor", f"{new}", ["corridor", "c.toml"], {"c.toml": ctext.replace(old, new, 1),
                                                                       "small_sections.csv": csv}, needle))
    for name, table, needle in (("falls_per_year -1", csv.replace("0.5\n", "-1\n", 1), "falls_per_year"),
                                ("falls_per_year 1e6", csv.replace("0.5\n", "1000000\n", 1), "falls_per_year"),
                                ("cut height 0", csv.replace("A,0,200,25", "A,0,200,0"), "cut_height_m"),
                                ("chainage backwards", csv.replace("A,0,200", "A,200,0"), "chainage")):
        out.append(Case("corridor", name, ["corridor", "c.toml"], {"c.toml": ctext, "small_sections.csv": table},
                        needle))
    return out


def digest(folder: Path) -> dict:
    return {p.relative_to(folder): hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.rglob("*"))
            if p.is_file() and "out" not in p.relative_to(folder).parts[:1]}


def run_case(case: Case, base: Path):
    from riskrf.cli import main
    folder = Path(tempfile.mkdtemp(prefix="case-", dir=base))
    for name, content in case.files.items():
        p = folder / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(content) if isinstance(content, bytes) else p.write_text(content)
    before = digest(folder)
    argv = list(case.argv)
    if "--out" not in argv:
        argv += ["--out", "out.csv" if argv[0] == "simulate" else "out"]
    stdout, stderr = io.StringIO(), io.StringIO()
    here = os.getcwd()
    os.chdir(folder)
    t0 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                rc = main(argv)
            except SystemExit as exc:                      # argparse refusals
                rc = exc.code if isinstance(exc.code, int) else 2
            except BaseException as exc:                   # noqa: BLE001 (an escaped exception is the finding)
                rc = f"escaped {type(exc).__name__}: {exc}"
    finally:
        os.chdir(here)
    seconds = time.perf_counter() - t0
    err = stderr.getvalue()
    if isinstance(rc, str) or rc == 3 or "Traceback" in err or rc not in (0, 2):
        outcome = "traceback"
    elif case.needle is not None:
        outcome = "silently accepted" if rc == 0 else ("clear error" if case.needle in err else "unclear error")
    else:
        if rc == 2:
            outcome = "refused valid"
        else:
            try:
                ok = bool(case.check(folder))
            except Exception:                             # noqa: BLE001
                ok = False
            outcome = "correct reading" if ok else "silently wrong"
    leftovers = [p.name for p in folder.rglob(".*") if ".partial-" in p.name or ".replaced-" in p.name]
    modified = [str(k) for k, v in before.items() if digest(folder).get(k) != v]
    shutil.rmtree(folder, ignore_errors=True)
    return outcome, bool(leftovers), bool(modified), err.strip().splitlines()[-1:] or [""], rc, seconds


OUTCOMES = ("clear error", "correct reading", "unclear error", "refused valid", "traceback", "silently wrong",
            "silently accepted")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--family", default=None)
    ap.add_argument("--list", action="store_true")
    args = ap.parse_args()
    os.environ.setdefault("MPLBACKEND", "Agg")
    todo = [c for c in cases() if args.family is None or c.family == args.family]
    if args.list:
        for c in todo:
            print(f"{c.family}: {c.name}")
        print(len(todo), "cases")
        return 0
    import pandas as pd
    rows = []
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="riskrf-sweep-") as base:
        for i, case in enumerate(todo):
            outcome, left, modified, last, rc, sec = run_case(case, Path(base))
            rows.append({"family": case.family, "case": case.name, "outcome": outcome, "leftovers": left,
                         "input modified": modified, "seconds": sec})
            if outcome not in ("clear error", "correct reading") or left or modified:
                print(f"[{i + 1}/{len(todo)}] {case.family}: {case.name}: {outcome} (exit {rc}) {last[0][:220]}",
                      flush=True)
    df = pd.DataFrame(rows)
    table = pd.crosstab(df["family"], df["outcome"]).reindex(columns=[o for o in OUTCOMES if o in set(df["outcome"])],
                                                            fill_value=0)
    table["leftovers"] = df.groupby("family")["leftovers"].sum()
    table["input modified"] = df.groupby("family")["input modified"].sum()
    table["cases"] = df.groupby("family").size()
    table.loc["all"] = table.sum()
    print()
    print(table.to_string())
    print(f"\n{len(df)} cases in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
