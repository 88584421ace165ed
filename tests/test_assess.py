"""End to end: `riskrf assess` and `riskrf demo`."""
import json
import shutil

import numpy as np
import pytest

import riskrf
import simulation
from riskrf.cli import main
from riskrf.app.site import load_site

from .conftest import ROOT

SITE = ROOT / "riskrf" / "data" / "demo_site.toml"
ARTIFACTS = ROOT / "tests" / "artifacts"
DEMO_NAME = "Demo: road below a limestone rock wall"
HOSTILE_NAME = "<script>alert(1)</script> & road"


def _site_copy(tmp_path, replace=None, drop=None):
    """The demo site with absolute paths, optionally edited, in tmp_path."""
    text = SITE.read_text()
    data_dir = SITE.parent
    for rel in ("lauterbrunnen_tls_2018.csv", "synthetic_corridor_1985_2024.csv", "hong_kong_rock_cuts_1984_2020.csv",
                "hko_daily_rainfall_1983_2020.csv", "../../simulation/scenarios/road_cut_barrier.toml"):
        text = text.replace(f'"{rel}"', f'"{(data_dir / rel).resolve()}"')
    text = text.replace("n_blocks = 50000", "n_blocks = 6000").replace("bootstrap = 200", "bootstrap = 40")
    text = text.replace("\nmaterial_draws = 32", "\nmaterial_draws = 8")      # 8 of the demo's 32 draws
    for old, new in (replace or {}).items():
        assert old in text, old
        text = text.replace(old, new)
    # 3,000 blocks per option re-simulation and 400 joint samples (the demo has 10,000 and 1,000): the tests
    # check structure and consistency, not the demo's numbers
    text = text.replace("option_blocks = 10000", "option_blocks = 3000").replace("\nsamples = 1000", "\nsamples = 400")
    if "ensemble_replicates" not in text:
        # two repeated ensembles (the least that gives a variance) keep the error budget in every run, cheaply
        text = text.replace("\nmaterial_draws = 8", "\nensemble_replicates = 2\nmaterial_draws = 8", 1)
    path = tmp_path / "site.toml"
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def assessed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("assess")
    # One shared assessment for the whole module; its site name is hostile HTML, checked for escaping below.  The
    # report's signature block is edited (author, checker, revision: checked in the PDF below) and the barrier
    # position search re-simulates 600 blocks per candidate position (its default is option_blocks, 3,000 here).
    site = _site_copy(tmp, replace={f'name = "{DEMO_NAME}"': f'name = "{HOSTILE_NAME}"',
                                    'basis = "UNI 11211-4"': 'basis = "UNI 11211-4"\nposition_blocks = 600',
                                    'author = "riskrf demo"': 'author = "A. Engineer"',
                                    'checker = "not checked"': 'checker = "B. Checker"',
                                    'revision = "A"': 'revision = "C"'})
    out = tmp / "out"
    assert main(["assess", str(site), "--out", str(out)]) == 0
    return site, out


def test_assess_writes_everything(assessed):
    site, out = assessed
    for name in ("report.html", "summary.json", "ranking.csv", "design_energies.csv", "whole_wall_design_masses.csv",
                 "site_design_masses.csv",
                 "break_even.csv", "tornado.csv", "fence_checks.csv", "inputs/run.json", "inputs/site.toml",
                 "figures/energy_exceedance.png", "figures/tree.png", "figures/profile_trajectories.png"):
        assert (out / name).exists(), name
    run = json.loads((out / "inputs" / "run.json").read_text())
    assert run["seed"] == 1 and run["riskrf_version"] == riskrf.__version__ and run["n_blocks"] == 6000
    html = (out / "report.html").read_text()
    assert "http://" not in html.replace("http://www.w3.org", "") and "https://" not in html   # no network needed
    assert html.count("data:image/png;base64,") >= 10


def test_assess_writes_the_pdf_and_the_design_entries(assessed):
    """report.pdf beside report.html (title block, page numbers, >= 10 pages), its text naming the design basis and
    the required barrier; summary.json with the basis, required MEL and height, deflection check and chart
    comparison."""
    from pypdf import PdfReader

    site, out = assessed                  # the shared assessment: UNI 11211-4, 600 blocks per position
    s = json.loads((out / "summary.json").read_text())
    assert s["design_basis"]["basis"] == "UNI 11211-4"
    rb = s["required_barrier"]
    assert rb["required_mel_kj"] == pytest.approx(1.2 * rb["E_d_kj"]) or "SEL" in rb["governs"]
    assert rb["required_net_height_m"] >= rb["required_height_m"]
    assert s["deflection_check"]["permitted_max_elongation_m"] == pytest.approx(20.0 / 1.3)   # road 120, line 100
    assert "width_for_retention_m" in s["ditch_chart_comparison"]
    ditch = s["ditch_chart_comparison"]          # the Modified Ritchie width W = 0.2 H + 4.5 m beside the retention
    assert ditch["modified_ritchie_criterion"]["width_m"] == pytest.approx(0.2 * ditch["cut_height_m"] + 4.5)
    assert len(s["position_search"]) >= 5
    reader = PdfReader(out / "report.pdf")
    assert len(reader.pages) >= 10
    text = "\n".join(p.extract_text() for p in reader.pages)
    flat = " ".join(text.split())
    assert "UNI 11211-4 governs" in flat and "required MEL" in flat and "REQUIRED net height" in flat
    assert f"page 3 of {len(reader.pages)}" in flat and "revision C" in flat and "checker B. Checker" in flat
    assert "Contents" in flat and "Appendix A" in flat
    assert "impacts per second" not in flat and "2,020" not in flat
    for name in ("options_profile.png", "stop_points.png", "barrier_positions.png", "catchment_retention.png"):
        assert (out / "figures" / name).exists(), name


def test_outputs_name_no_directory_of_the_machine(assessed):
    """Paths in the JSON outputs are relative to the site file (or the bundled data's name in the package)."""
    site, out = assessed
    for path in out.rglob("*.json"):
        if path.parent.name == "inputs":            # the inputs and the command as typed, kept for reruns
            continue
        text = path.read_text()
        assert str(ROOT) not in text and str(site.parent) not in text and '"/' not in text, path
    s = json.loads((out / "summary.json").read_text())
    assert s["inventory"]["source"] == "riskrf/data/lauterbrunnen_tls_2018.csv"


def test_summary_matches_the_modules(assessed):
    site, out = assessed
    s = json.loads((out / "summary.json").read_text())
    inv = riskrf.read_inventory(SITE.parent / "lauterbrunnen_tls_2018.csv")
    gr = riskrf.fit_gutenberg_richter(inv)
    assert s["power_law"]["b"] == pytest.approx(gr.b) and s["power_law"]["m_min_kg"] == pytest.approx(gr.m_min)
    # The hazard from the same seeded simulation, built directly with the modules:
    grt = riskrf.fit_gutenberg_richter(inv, m_max=2.0e6)
    sc = simulation.load_scenario(ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml")
    # mass-coupled (the default): simulated over m_min to the largest m_max of the sensitivity study (4,000 t)
    hz = riskrf.energy_hazard(grt, sc, "barrier", rate_per_year=0.05 * grt.rate_min, n=6000, seed=1,
                              design_masses_kg=[4.0e6])
    assert s["hazard"]["mass_coupled"] and s["hazard"]["arrivals_per_year"] == pytest.approx(hz.arrival_rate)
    e = {row["T_years"]: row["energy_kj"] for row in s["design_energies"]}
    np.testing.assert_allclose([e[100.0], e[300.0]], hz.energy_at_return_period([100, 300]), rtol=1e-9)
    assert s["hazard"]["energy_p95_kj"] == pytest.approx(hz.energy_percentile(95)[0], rel=1e-9)
    assert s["units"]["energy"] == "kJ" and s["units"]["money"] == "CHF"
    assert s["best_option"] == s["ranking"][0]["option"]
    assert "annual_maxima" in s and s["annual_maxima"]["deviance_test"]["p_value"] < 0.05
    assert "hong_kong_rock_cuts" in s["annual_maxima"]["source"]          # the real record, not the synthetic one
    assert s["annual_maxima"]["preferred_model"]["model"] == "power law"  # GEV xi = 1.71: implausible


def test_design_block_site_masses_and_sensitivity_in_outputs(assessed):
    """Issue 10: the site's own design masses (never above m_max), the design block with its alternatives and the
    assumption behind it, the sensitivity to m_max and rate share, and what the interval covers."""
    site, out = assessed
    s = json.loads((out / "summary.json").read_text())
    m_max = s["hazard"]["power_law_for_hazard"]["m_max_kg"]
    assert all(r["source_mass_kg"] <= m_max and r["line_mass_kg"] <= m_max for r in s["site_design_masses"])
    block = s["design_block"]
    assert block["rule"] == "percentile" and any("EVENT volumes" in a for a in block["assumptions"])
    inv = riskrf.read_inventory(SITE.parent / "lauterbrunnen_tls_2018.csv")
    assert block["volume_m3"] == pytest.approx(np.percentile(inv.masses / inv.density_kg_m3, 97))
    assert {"percentile p95", "percentile p98", "return period 100 yr at the source",
            "fragmentation of the 100-yr event, p97"} <= {r["rule"] for r in block["alternatives"]}
    assert all(r["mass_kg"] <= m_max for r in block["alternatives"])
    sens = s["design_energy_sensitivity"]
    assert {r["m_max_kg"] for r in sens} == {1e6, 2e6, 4e6} and {r["rate_share"] for r in sens} == {0.025, 0.05, 0.1}
    central = [r["energy_kj"] for r in sens if r["m_max_kg"] == 2e6 and r["rate_share"] == 0.05][0]
    e100 = [r["energy_kj"] for r in s["design_energies"] if r["T_years"] == 100.0][0]
    assert central == pytest.approx(e100, rel=1e-6)
    assert "NOT the maximum credible block" in s["design_energy_interval_covers"]
    html = (out / "report.html").read_text()
    for text in ("Design block", "Sensitivity of the 100-year energy", "Design masses of the site",
                 "whole monitored wall", "EVENT volumes", "Reach, speed and bounce height by block mass"):
        assert text in html, text
    assert (out / "design_energy_sensitivity.csv").exists() and (out / "design_block.csv").exists()
    assert (out / "figures" / "design_energy_sensitivity.png").exists()


def _design_mass_values(obj, where=""):
    """(where, key, value) of every mass [kg] in a JSON value, skipping subtrees labelled as reference fits
    (keys whole_wall_* / record_*, or records whose basis says "reference only").  Input bounds (m_min, m_max, the
    simulated classes' edges) are not design masses."""
    bounds = ("m_max_kg", "m_min_kg", "mass_low_kg", "mass_high_kg", "m_max_kg_range")
    if isinstance(obj, dict):
        if "reference only" in str(obj.get("basis", "")):
            return
        for k, v in obj.items():
            if str(k).startswith(("whole_wall_", "record_")):
                continue
            if str(k).endswith("_kg") and str(k) not in bounds and isinstance(v, (int, float)):
                yield where, k, v
            else:
                yield from _design_mass_values(v, f"{where}/{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _design_mass_values(v, f"{where}[{i}]")


def test_no_design_mass_above_m_max_unless_labelled_whole_wall(assessed):
    """Issue 10 audit a: every mass in every output (CSV and JSON) is at most m_max, except the tables labelled as the
    whole monitored wall's (or another record's) untruncated fit; the site's own design masses are written."""
    import pandas as pd
    site, out = assessed
    s = json.loads((out / "summary.json").read_text())
    m_max = s["hazard"]["power_law_for_hazard"]["m_max_kg"]
    assert not (out / "design_masses.csv").exists() and "design_masses" not in s
    whole = pd.read_csv(out / "whole_wall_design_masses.csv")
    assert whole["basis"].str.contains("whole monitored wall.*untruncated.*reference only").all()
    assert whole["mass_kg"].max() > m_max                     # the labelled table is the one above m_max
    freq = json.loads((out / "frequency_summary.json").read_text())
    assert "design_masses" not in freq and freq["whole_wall_design_masses"][0]["basis"] == s[
        "whole_wall_design_masses_basis"]
    site_masses = pd.read_csv(out / "site_design_masses.csv")
    assert list(site_masses["T_years"]) == [10, 50, 100, 300, 1000]
    assert site_masses.loc[site_masses["T_years"] == 100, "source_mass_kg"].item() == pytest.approx(
        [r["source_mass_kg"] for r in s["site_design_masses"] if r["T_years"] == 100][0])
    checked = 0
    for f in sorted(out.rglob("*.csv")):
        if f.name.startswith(("whole_wall_", "record_")) or f.name == "completeness.csv":
            continue                        # labelled reference fits; recorded (observed) falls per year
        table = pd.read_csv(f)
        labelled = "basis" in table and table["basis"].astype(str).str.contains("reference only")
        for col in (c for c in table.columns if c.endswith("_kg") and c not in ("m_max_kg", "m_min_kg",
                                                                                 "mass_low_kg", "mass_high_kg")):
            values = table.loc[~labelled, col] if "basis" in table else table[col]
            assert not (values > m_max * (1 + 1e-9)).any(), (f.relative_to(out), col, values.max())
            checked += int(values.notna().sum())
    for f in sorted(out.rglob("*.json")):
        for where, key, value in _design_mass_values(json.loads(f.read_text())):
            assert value <= m_max * (1 + 1e-9), (f.relative_to(out), where, key, value)
            checked += 1
    assert checked > 20


def test_options_recommendation_and_fence_heights_in_outputs(assessed):
    """Issue 13 audit k: every option in summary.json carries the required keys, P(best) sums to 1, a ditch's and each
    fence's derived retention is there, the recommendation gives a reason, and each fence option is checked at its
    own height_m.  Audit i, j: the report states what the loss engine does with fragmentation and queued vehicles."""
    import pandas as pd
    site, out = assessed
    s = json.loads((out / "summary.json").read_text())
    required = {"name", "kind", "expected_total_cost", "cost_p05", "cost_p95", "probability_best",
                "road_falls_per_year", "individual_risk_per_year", "deaths_per_year"}
    for o in s["options"]:
        assert required <= set(o), (o["name"], required - set(o))
        assert o["cost_p05"] <= o["expected_total_cost"] <= o["cost_p95"] or o["cost_p05"] == o["cost_p95"]
    assert abs(sum(o["probability_best"] for o in s["options"]) - 1.0) <= 1e-9
    kinds = {o["kind"] for o in s["options"]}
    assert {"ditch", "fence"} <= kinds
    for o in s["options"]:
        if o["kind"] in ("ditch", "fence"):
            assert o.get("retention") is not None and 0.0 <= o["retention"] <= 1.0, o["name"]
    rec = s["recommendation"]
    assert rec["option"] in {o["name"] for o in s["options"]} and rec["reason"].strip()
    # the recommendation passes its design checks; the rejected fences are named; the required
    # barrier is reported (on the demo the required MEL is above every certified class: none can be placed)
    ranked = {r["option"]: r for r in s["ranking"]}
    assert ranked[rec["option"]]["design_adequate"] and "NOT ADEQUATE" not in str(rec["design_check"])
    assert set(rec["not_recommended"]) == {n for n, r in ranked.items() if not r["design_adequate"]} != set()
    # the presets are not calibrated on this slope, and every output says so first
    assert s["trajectory_model"]["status"] == "uncalibrated" and s["warnings"][0].startswith("UNCALIBRATED")
    assert "UNCALIBRATED trajectory model" in (out / "report.html").read_text()
    # ... and what a release campaign is worth is priced beside the ranking, from the study's material draws
    campaign = s["release_campaign"]
    assert campaign["draws"] == s["effort"]["rounds"][-1]["material_draws"] >= 8
    assert campaign["calibration_releases"] == 20 and campaign["calibration_cost_is_assumption"]
    assert 0.0 <= campaign["evsi"] <= campaign["evpi_upper_bound_97_5"]
    assert "EVSI of a field calibration with 20 released blocks" in campaign["verdict"]
    assert "Value of a release campaign" in (out / "report.html").read_text()
    rb = s["required_barrier_option"]
    assert rb["placeable"] is False and "above the largest certified class" in rb["reason"]
    assert rb["alternatives"] and "No certified barrier meets" in rec["reason"]
    fences = [o for o in load_site(site).mitigation.options if o.kind == "fence" and o.x_m is None]
    assert len({o.height_m for o in fences}) > 1                  # the demo's fences differ in height
    checks = pd.read_csv(out / "fence_checks.csv")
    for o in fences:
        rows = checks[checks["fence"] == f"{o.capacity_kj:g} kJ / {o.height_m:g} m"]
        heights = rows[rows["unit"] == "m"]
        assert len(heights) >= 2 and (heights["capacity"] == o.height_m).all(), (o.name, heights)
    html = (out / "report.html").read_text()
    for text in ("queued or stopped vehicles behind a blockage", "each event volume one intact block",
                 "fragmentation: the loss engine takes every event volume as one intact block"):
        assert text in html, text
    assert "no fragmentation model" not in html


def test_design_energy_tornado_in_outputs(assessed):
    """Issue 10 item 4: the one-way sensitivity of the design energies, in the CSV, the summary and the report."""
    import pandas as pd
    site, out = assessed
    s = json.loads((out / "summary.json").read_text())
    t = pd.read_csv(out / "design_energy_tornado.csv")
    assert {"design_energy", "input", "low", "base", "high", "energy_low_kj", "energy_base_kj", "energy_high_kj",
            "swing_kj", "range_basis"} <= set(t.columns)
    e100 = [r["energy_kj"] for r in s["design_energies"] if r["T_years"] == 100.0][0]
    t100 = t[t["design_energy"] == "100-year energy at the barrier line"].set_index("input")
    assert np.allclose(t100["energy_base_kj"], e100, rtol=1e-9)
    # the site's uncertainty ranges (m_max 1,000-4,000 t, rate factor 0.5-2) and the grid's corners agree
    sens = pd.DataFrame(s["design_energy_sensitivity"]).set_index(["m_max_kg", "rate_share"])["energy_kj"]
    row = t100.loc["maximum credible block m_max [kg]"]
    assert (row["low"], row["high"]) == (1e6, 4e6)
    assert row["energy_low_kj"] == pytest.approx(sens[(1e6, 0.05)]) and row["energy_high_kj"] == pytest.approx(
        sens[(4e6, 0.05)])
    b = t100.loc["power-law exponent b"]
    assert b["energy_low_kj"] > b["energy_base_kj"] > b["energy_high_kj"]        # lower b: heavier tail
    block = t[t["design_energy"].str.startswith("design-block energy")]
    assert list(block["input"]) == ["velocity percentile of the block energy [%]"]   # percentile rule
    chosen = [r for r in s["design_block"]["alternatives"] if r["chosen"]][0]
    assert block["energy_base_kj"].item() == pytest.approx(chosen["energy_at_v95_kj"], rel=1e-12)
    frag = t[t["design_energy"].str.startswith("fragmentation alternative")]
    assert {"fractal dimension D", "fragmentation generations"} <= set(frag["input"])
    assert s["design_energy_tornado"]["dominant"][0]["design_energy"] == "100-year energy at the barrier line"
    assert (out / "figures" / "design_energy_tornado.png").exists()
    html = (out / "report.html").read_text()
    assert "One-way sensitivity of the design energies (tornado)" in html and "dominates" in html


@pytest.mark.parametrize("edit, match", [
    ({"percentile = 97\n": "percentile = 100\n"}, "design_block.percentile = 100"),
    ({"percentile = 97\n": "percentile = 0\n"}, "design_block.percentile = 0"),
    ({'rule = "percentile"': 'rule = "fragments"'}, "design_block.rule = 'fragments'"),
    ({'sizes = "event_volumes"': 'sizes = "events"'}, "inventory.sizes = 'events'"),
    ({'mass_coupling = "simulated"': 'mass_coupling = "yes"'}, "hazard.mass_coupling = 'yes'"),
    ({"percentile = 97\n": 'percentile = 97\nsurvey = "nowhere.csv"\n'}, "design_block.survey = 'nowhere.csv'"),
    ({"fractal_dimension = 2.5": "fractal_dimension = 3.2"}, "design_block.fractal_dimension = 3.2"),
    ({"iterations = 3": "iterations = 0"}, "design_block.iterations = 0"),
    ({'rule = "percentile"': 'rule = "fragmentation"', "fractal_dimension = 2.5\n": "", "iterations = 3\n": ""},
     "needs design_block.fractal_dimension and design_block.iterations"),
])
def test_design_block_site_fields_are_checked(tmp_path, edit, match):
    from riskrf.app.site import SiteError
    with pytest.raises(SiteError, match=match):
        load_site(_site_copy(tmp_path, replace=edit))


def test_copied_inputs_rerun_to_the_same_numbers(assessed, tmp_path):
    site, out = assessed
    inputs = tmp_path / "inputs"
    shutil.copytree(out / "inputs", inputs)
    rerun = tmp_path / "rerun"
    rerun.mkdir()
    # From Python this time: the figures are all drawn by write_assessment (the command line draws them beside
    # the computation); the same files and numbers either way.
    from riskrf.app.assess.outputs import write_assessment
    from riskrf.app.assess.run import run_assessment
    write_assessment(run_assessment(load_site(inputs / "site.toml")), rerun)
    a = json.loads((out / "summary.json").read_text())
    b = json.loads((rerun / "summary.json").read_text())
    assert a["design_energies"] == b["design_energies"] and a["ranking"] == b["ranking"]
    files = lambda d: sorted(str(p.relative_to(d)) for p in d.rglob("*") if p.is_file())  # noqa: E731
    assert files(out) == files(rerun)


def test_report_in_headless_chromium(assessed):
    """Open report.html in a real browser at 1,400 and 400 px and print it to PDF.

    No console errors, every figure has a size, no horizontal scroll on a phone, no absolute path of
    the machine and no Python exponent notation in the text; screenshots and the PDF are kept in
    tests/artifacts/ for a person to look at.
    """
    import base64
    import re
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver_path = shutil.which("chromedriver")
    if not chromium or not driver_path:
        pytest.skip("headless Chromium and chromedriver are not installed here (.ci/run installs them "
                    "from Debian's chromium and chromium-driver packages)")
    webdriver = pytest.importorskip("selenium.webdriver")
    from selenium.webdriver.chrome.service import Service
    site, out = assessed
    opts = webdriver.ChromeOptions()
    opts.binary_location = chromium
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--no-first-run", "--window-size=1400,2000"):
        opts.add_argument(arg)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(driver_path), options=opts)
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    try:
        driver.get((out / "report.html").resolve().as_uri())
        assert "rock fall hazard and mitigation" in driver.title
        sizes = driver.execute_script(
            "return Array.from(document.images).map(i => [i.complete, i.naturalWidth, i.naturalHeight, "
            "i.getBoundingClientRect().width, i.getBoundingClientRect().height]);")
        assert len(sizes) >= 10
        assert all(c and w > 0 and h > 0 and rw > 0 and rh > 0 for c, w, h, rw, rh in sizes), sizes
        errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        assert errors == []
        text = driver.execute_script("return document.body.innerText;")
        # no Python float formatting ("6e+05", "3.044e+05"), raw booleans/None or tuple/dict reprs
        assert not re.search(r"\de[+-]?\d", text), re.findall(r".{0,30}\de[+-]?\d.{0,10}", text)
        cells = driver.execute_script("return Array.from(document.querySelectorAll('td, th'))"
                                      ".map(c => c.innerText.trim());")
        assert not [c for c in cells if c in ("True", "False", "None")]
        assert "((" not in text and "{'" not in text, re.findall(r".{0,40}(?:\(\(|\{').{0,20}", text)
        assert str(ROOT) not in text and "/home/" not in text and "/tmp/" not in text
        assert "Table 1." in text and "Figure 1." in text and "Contents" in text
        driver.save_screenshot(str(ARTIFACTS / "report_1400px.png"))
        driver.set_window_size(400, 900)
        overflow = driver.execute_script("return document.documentElement.scrollWidth - window.innerWidth;")
        assert overflow <= 0, f"horizontal scroll of {overflow} px at 400 px"
        driver.save_screenshot(str(ARTIFACTS / "report_400px.png"))
        pdf = base64.b64decode(driver.print_page())
        (ARTIFACTS / "report.pdf").write_bytes(pdf)
        assert pdf[:5] == b"%PDF-" and len(pdf) > 50_000
        for name in ("report_1400px.png", "report_400px.png"):
            assert (ARTIFACTS / name).stat().st_size > 10_000
    finally:
        driver.quit()


@pytest.mark.parametrize("replace,match", [
    ({"fence_height_m = [5.0, 7.0]": "fence_hieght_m = [5.0, 7.0]"}, "unknown field hazard.'fence_hieght_m'; did you mean "
                                                         "'fence_height_m'"),
    ({'lauterbrunnen_tls_2018.csv"': 'no_such_inventory.csv"'}, "inventory.path = .*no_such_inventory.csv.*file not "
                                                                 "found"),
    ({'capital_cost = 600000\n': ''}, "option 'catch ditch': missing field 'capital_cost'"),
    ({'collector = "barrier"': 'collector = "fence line"'}, "has no collector named 'fence line'"),
])
def test_bad_site_files_fail_before_computing_and_leave_nothing(tmp_path, capsys, replace, match):
    site = _site_copy(tmp_path, replace=replace)
    out = tmp_path / "out"
    rc = main(["assess", str(site), "--out", str(out)])
    err = capsys.readouterr()
    assert rc == 2
    assert __import__("re").search(match, err.err), err.err
    assert "[2/5]" not in err.out          # failed before the simulation started
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] == ["site.toml"]


def test_missing_site_file(tmp_path, capsys):
    assert main(["assess", str(tmp_path / "none.toml")]) == 2
    assert "site file not found" in capsys.readouterr().err


def test_user_text_is_escaped(assessed):
    """The site's name is user text: the rendered report shows it as text, never as markup."""
    site, out = assessed
    assert load_site(site).name == HOSTILE_NAME
    html = (out / "report.html").read_text()
    assert "&lt;script&gt;alert(1)&lt;/script&gt; &amp; road" in html
    assert "<script>alert(1)" not in html


def _html_sections(page: str) -> dict:
    """Heading -> flat text of each <h2> section of report.html (after the table of contents)."""
    import html as _html
    import re
    body = page.split("</nav>", 1)[1]
    parts = re.split(r"<h2[^>]*>(.*?)</h2>", body)[1:]
    flat = lambda t: " ".join(_html.unescape(re.sub(r"<[^>]+>", " ", t)).split())   # noqa: E731
    return {flat(h): flat(t) for h, t in zip(parts[::2], parts[1::2])}


def _pdf_sections(path) -> dict:
    """Heading -> flat text of each top-level outline entry of report.pdf (from its page to the next's)."""
    from pypdf import PdfReader
    reader = PdfReader(path)
    tops = [o for o in reader.outline if not isinstance(o, list)]
    starts = [reader.get_destination_page_number(o) for o in tops] + [len(reader.pages)]
    pages = [p.extract_text() for p in reader.pages]
    return {o.title: " ".join(" ".join(pages[a:max(b, a + 1)]).split())
            for o, a, b in zip(tops, starts, starts[1:])}


def test_html_and_pdf_carry_the_same_sections_and_tables(assessed):
    """report.html and report.pdf have the same sections in the same order (the HTML headings are
    the PDF's outline), and the same tables in the same section: road-user risk, Bunce per lane, the F-N chart, the
    design checks of every option, the catchment widths beside the Modified Ritchie Criterion, and the
    recommendation with the options not recommended because they fail their design checks and the required
    barrier."""
    from riskrf.report import sections as S
    site, out = assessed
    html = _html_sections((out / "report.html").read_text())
    pdf = _pdf_sections(out / "report.pdf")
    assert list(html) == list(pdf)
    assert len(html) >= 15 and list(html)[-1] == "Appendix B. Run record"
    for caption in (S.T_CANDIDATES, S.T_POSITIONS, S.T_CATCHMENT_WIDTHS, S.T_RITCHIE, S.T_BUNCE, S.T_RISK,
                    S.T_DESIGN_CHECKS, S.T_RANKING, S.T_BREAK_EVEN, S.F_FN, S.F_CATCHMENT):
        where = [h for h, text in html.items() if caption in text]
        assert where, caption
        assert caption in pdf[where[0]], (caption, where[0])
    risk = next(h for h in html if h.split(". ", 1)[1].startswith("Risk to road users"))
    decision = next(h for h in html if "Mitigation decision" in h)
    catchment = next(h for h in html if "Catchment ditch" in h)
    for doc in (html, pdf):
        assert "P(S:T)" in doc[risk] and "towards slope side" in doc[risk]
        assert "0.2 H + 4.5 m" in doc[catchment]
        assert "NOT ADEQUATE" in doc[decision] and "design adequate" in doc[decision].lower()
    s = json.loads((out / "summary.json").read_text())
    rec = s["recommendation"]
    assert rec["not_recommended"]                    # the demo's fences fail the governing basis
    said = ["Not recommended, whatever their cost, because they fail their design checks",
            " ".join(str(rec["required_barrier"]).split())[:60]]
    for words in said:
        assert words in html[decision] and words in pdf[decision], words
