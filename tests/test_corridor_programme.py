"""Corridor outputs for asset managers: whole-point RHRS columns, per-metre costs on the cut length, the exact
budget programme on real section results, sections.gpkg on a centreline (line geometry, projected CRS, RHRS
columns, the same columns as sections.csv), the map, rating sheets, and the scalable chainage figure.
Small: 3 sections x 300 blocks, run serially."""
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pyogrio = pytest.importorskip("pyogrio")

from riskrf.app import corridor as cr  # noqa: E402
from riskrf.app.corridor.result import _pv  # noqa: E402
from riskrf.io import gis  # noqa: E402
from riskrf.risk.programme import optimise_programme  # noqa: E402

DATA = Path(__file__).resolve().parent / "data" / "corridor"
N = 300
#: a road 700 m long in ETRS89 / UTM 33N: 300 m east then 400 m north (the small corridor's sections: 0-200,
#: 200-350, 400-700 m)
ROAD = np.array([[220000.0, 6915000.0], [220300.0, 6915000.0], [220300.0, 6915400.0]])


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    d = tmp_path_factory.mktemp("road")
    gis.write_centreline(gis.centreline_from_vertices(ROAD, crs="EPSG:25833"), d / "road.gpkg")
    toml = (DATA / "small.toml").read_text().replace('sections = "small_sections.csv"',
                                                      f'sections = "{DATA / "small_sections.csv"}"\n'
                                                      f'centreline = "{d / "road.gpkg"}"')
    (d / "c.toml").write_text(toml)
    c = cr.load_corridor(d / "c.toml")
    table = pd.DataFrame([cr.assess_section(s, c, N) for s in c.sections])
    return cr.CorridorResult(corridor=c, table=table.sort_values("chainage_from_m").reset_index(drop=True),
                             workers=0, n_blocks=N)


def test_rows_carry_whole_point_rhrs_categories(result):
    t = result.table.set_index("id")
    for sec in result.corridor.sections:
        pts = sec.rating.integer_scores
        assert t.loc[sec.id, "rhrs_total"] == sum(pts.values()) == sec.rating.integer_total
        for cat, p in pts.items():
            assert t.loc[sec.id, f"rhrs_{cat}"] == p
        assert np.isnan(t.loc[sec.id, "rhrs_difference_in_erosion_rates"])     # case 1 geology: not rated


def test_per_metre_costs_on_the_works_length(result, tmp_path):
    # small.toml: fence 1200 per m; no cut length given -> the section length
    for _, r in result.table.iterrows():
        fence = [o for o in json.loads(r["options_json"]) if o["kind"] == "fence"][0]
        assert fence["capital"] == pytest.approx(1200 * r["length_m"]) and r["cut_length_m"] == r["length_m"]
    # a cut length, or the RHRS slope length, sets it; beyond the section it is refused by row
    rows = ("id,chainage_from,chainage_to,cut_height_m,ditch_width_m,runout_to_road_m,falls_per_year,cut_length_m,"
            "rhrs_slope_length_m\nA,0,1000,25,3,1,0.5,200,\nB,1000,2000,25,3,1,0.5,,150\nC,2000,2100,25,3,1,0.5,,\n")
    (tmp_path / "s.csv").write_text(rows)
    (tmp_path / "c.toml").write_text((DATA / "small.toml").read_text().replace("small_sections.csv", "s.csv"))
    c = cr.load_corridor(tmp_path / "c.toml")
    assert [s.works_length_m for s in c.sections] == [200.0, 150.0, 100.0]
    # the AVR uses the cut length too: ADT 3000 x 0.2 km / 24 h / 80 km/h x 100 = 31.25 %
    assert c.section("A").rating.inputs["avr_percent"] == pytest.approx(3000 * 0.2 / 24 / 80 * 100)
    (tmp_path / "s.csv").write_text(rows.replace("A,0,1000,25,3,1,0.5,200,", "A,0,1000,25,3,1,0.5,1200,"))
    with pytest.raises(cr.CorridorError, match=r"row 2 \(section 'A'\): column 'cut_length_m' .* = 1200 m must lie"):
        cr.load_corridor(tmp_path / "c.toml")


def test_programme_on_section_results_is_the_brute_force_best(result):
    opts = result.options_table()
    assert set(opts["kind"]) == {"fence"} and len(opts) == 3
    np.testing.assert_allclose(opts["present_value"], opts["equivalent_annual_cost"] * _pv(result.corridor))
    caps = opts.set_index("id")["capital"]
    avoided = opts.set_index("id")["deaths_avoided_per_year"]
    for budget in (0.0, caps.min(), caps.sum() - caps.min(), caps.sum()):
        p = result.programme(budget, objective="risk")          # the old default, by name
        best = max((sum(avoided[list(s)]), -sum(caps[list(s)]))          # every subset of the three sections
                   for k in range(4) for s in __import__("itertools").combinations(caps.index, k)
                   if sum(caps[list(s)]) <= budget + 1e-9 and all(avoided[list(s)] > 0))
        assert p.benefit == pytest.approx(best[0], rel=1e-9, abs=1e-15) and p.cost == pytest.approx(-best[1])
    yearly = result.programme(opts["equivalent_annual_cost"].sum(), basis="year", objective="risk")
    assert len(yearly.chosen) == (opts["deaths_avoided_per_year"] > 0).sum()
    with pytest.raises(ValueError, match="budget basis = 'month'"):
        result.programme(1.0, basis="month")


def test_write_outputs_gpkg_and_csv_agree(result, tmp_path):
    out = tmp_path / "out"
    budget = float(result.options_table()["capital"].min())
    cr.write_corridor(result, out, budget=budget, objective="risk")
    for f in ("report.html", "sections.csv", "sections.gpkg", "map.png", "programme.csv", "frontier.csv",
              "frontier.png", "rating_sheets.html", "chainage.png", "summary.json"):
        assert (out / f).exists(), f
    info = pyogrio.read_info(out / "sections.gpkg")
    assert info["geometry_type"] == "LineString" and info["crs"] == "EPSG:25833" and info["features"] == 3
    csv = pd.read_csv(out / "sections.csv")
    assert list(info["fields"]) == list(csv.columns)
    for c in ("rhrs_total", "rhrs_slope_height", "rhrs_ditch_effectiveness", "rhrs_rockfall_history",
              "programme_option", "programme_capital"):
        assert c in csv.columns
    meta, _, geoms, fields = pyogrio.raw.read(out / "sections.gpkg")
    got = dict(zip(meta["fields"], fields))
    assert list(got["id"]) == list(csv["id"]) and list(got["rhrs_total"]) == list(csv["rhrs_total"])
    # each line starts and ends on the road where its chainage says (section B: 200-350 m -> (220200, y0)-(220300, y0+50))
    (kind, xy), = gis._wkb_geoms(bytes(geoms[1]), "B")
    np.testing.assert_allclose(xy[[0, -1]], [[220200, 6915000], [220300, 6915050]])
    prog = pd.read_csv(out / "programme.csv").fillna({"programme_option": ""})
    assert (prog["programme_option"] != "").sum() == 1 and prog["programme_capital"].sum() <= budget + 1e-6
    summ = json.loads((out / "summary.json").read_text())
    s = summ["programme"]
    assert s["budget_caps"] == "capital" and s["sections_funded"] == 1 and s["objective"] == "risk"
    assert summ["other_programme"]["objective"] == "alarp" and s["disagreement"]
    assert "other_programme_option_alarp" in prog.columns
    html = (out / "report.html").read_text()
    assert "Programme within the budget" in html and "<b>Capital</b>" in html and "sections.gpkg" in html
    sheets = (out / "rating_sheets.html").read_text()
    assert sheets.count("<section id=") == 3 and "<b>" + str(int(csv["rhrs_total"].iloc[0])) + "</b>" in sheets


def test_chainage_figure_aggregates_many_sections(result):
    import matplotlib.pyplot as plt

    from riskrf.report.corridor_report import AGGREGATE_ABOVE, CHAINAGE_BINS, plot_corridor
    row = result.table.iloc[0]
    n = AGGREGATE_ABOVE + 200
    big = pd.DataFrame([row] * n).reset_index(drop=True)
    big["id"] = [f"S{i}" for i in range(n)]
    big["chainage_from_m"] = np.arange(n) * 100.0
    big["chainage_to_m"] = big["chainage_from_m"] + 100.0
    big["length_m"] = 100.0
    fig = plot_corridor(replace(result, table=big))
    try:
        # a few artists, not one bar and one label per section
        assert sum(len(ax.patches) for ax in fig.axes) <= 5 and sum(len(ax.texts) for ax in fig.axes) == 0
        assert str(CHAINAGE_BINS) in fig._suptitle.get_text()
    finally:
        plt.close(fig)
    # deaths per km in a bin: the bin's deaths over its length, equal to each section's own (all identical)
    from riskrf.report.corridor_report import _binned
    edges, b = _binned(big, 50)
    per_km = row["deaths_per_year"] / 0.1
    assert np.nanmax(np.abs(b["d"] / per_km - 1)) < 1e-12


def test_variant_and_centreline_errors_named(tmp_path):
    toml = (DATA / "small.toml").read_text().replace('sections = "small_sections.csv"',
                                                      f'sections = "{DATA / "small_sections.csv"}"')
    (tmp_path / "a.toml").write_text(toml.replace("seed = 7", 'seed = 7\nrhrs_variant = "colorado"'))
    with pytest.raises(cr.CorridorError, match="rhrs_variant = 'colorado' must be one of \\['fhwa'\\] .*Santi"):
        cr.load_corridor(tmp_path / "a.toml")
    (tmp_path / "a2.toml").write_text(toml.replace("seed = 7", 'seed = 7\nrhrs_variant = "odot"'))
    with pytest.raises(cr.CorridorError, match=r"a2.toml: corridor.rhrs_variant = 'odot' must be one of \['fhwa'\] "
                                               r"\(not implemented: .*FHWA-OR-GI-92-05"):
        cr.load_corridor(tmp_path / "a2.toml")
    (tmp_path / "a3.toml").write_text(toml.replace("seed = 7", 'seed = 7\nrhrs_varient = "fhwa"'))
    with pytest.raises(cr.CorridorError, match=r"unknown field corridor.'rhrs_varient'; did you mean 'rhrs_variant'"):
        cr.load_corridor(tmp_path / "a3.toml")
    (tmp_path / "a4.toml").write_text(toml.replace("seed = 7", 'seed = 7\ncentreline = "r.gpkg"\n'
                                                               'centreline_chainage_start_m = "zero"'))
    with pytest.raises(cr.CorridorError, match=r"corridor.centreline_chainage_start_m = 'zero' must be a number m"):
        cr.load_corridor(tmp_path / "a4.toml")
    # a field the variant needs, empty in the row and in [defaults]: the column is named, with the row and section
    (tmp_path / "a5.toml").write_text(toml.replace('rhrs_rockfall_history = "occasional"\n', ""))
    with pytest.raises(cr.CorridorError, match=r"small_sections.csv: row 2 \(section 'A'\): RHRS \(fhwa\) needs "
                                               r"column\(s\) 'rhrs_rockfall_history', empty in this row and in "
                                               r"\[defaults\]"):
        cr.load_corridor(tmp_path / "a5.toml")
    (tmp_path / "b.toml").write_text(toml.replace("seed = 7", 'seed = 7\ncentreline = "nowhere.gpkg"'))
    with pytest.raises(cr.CorridorError, match="corridor.centreline = 'nowhere.gpkg': centreline not found"):
        cr.load_corridor(tmp_path / "b.toml")
    short = tmp_path / "short.gpkg"
    gis.write_centreline(gis.centreline_from_vertices(ROAD[:2], crs="EPSG:25833"), short)   # 300 m only
    (tmp_path / "c.toml").write_text(toml.replace("seed = 7", f'seed = 7\ncentreline = "{short}"'))
    with pytest.raises(cr.CorridorError, match=r"section 'C'\): chainage 400-700 m lies beyond the centreline"):
        cr.load_corridor(tmp_path / "c.toml")


def test_cli_refuses_a_bad_budget_before_any_work(tmp_path, capsys):
    from riskrf.cli import main
    out = tmp_path / "out"
    assert main(["corridor", str(DATA / "small.toml"), "--budget", "-5", "--out", str(out)]) == 2
    assert "--budget = -5 must be a finite amount >= 0" in capsys.readouterr().err and not out.exists()


# ---- the default objective: tolerability first, then net benefit at the VSL with the GDF -----
def _fake(result, rows):
    """The small corridor's result with a made-up table: ``rows`` of (id, individual risk of doing nothing,
    [(option, capital, deaths per year, individual risk, expected total cost)]); doing nothing costs 1e6 of
    expected loss and kills 1e-4 a year on every section.  No simulation: the programme only reads the table."""
    recs = []
    for k, (sid, ir, opts) in enumerate(rows):
        js = [{"option": "do nothing", "kind": "none", "capital": 0.0, "pv_renewals": 0.0, "pv_maintenance": 0.0,
               "deaths_per_year": 1e-4, "individual_risk": ir, "expected_total_cost": 1e6, "meets_criteria": True}]
        js += [{"option": o, "kind": "fence", "capital": c, "pv_renewals": 0.0, "pv_maintenance": 0.0,
                "deaths_per_year": d, "individual_risk": i, "expected_total_cost": e, "meets_criteria": True}
               for o, c, d, i, e in opts]
        rec = result.table.iloc[k % len(result.table)].to_dict()      # every other column from a real row
        rec.update({"id": sid, "chainage_from_m": 100.0 * k, "chainage_to_m": 100.0 * k + 100, "length_m": 100.0,
                    "deaths_per_year": 1e-4, "individual_risk": ir, "do_nothing_total_cost": 1e6,
                    "options_json": json.dumps(js)})
        recs.append(rec)
    return replace(result, table=pd.DataFrame(recs), corridor=replace(result.corridor, centreline=None))


#: (id, IR now, options): loss avoided / cost = (1e6 - (etc - c)) / c for each option
ROWS = [("P", 5e-4, [("cheap", 50_000.0, 9e-5, 4e-4, 1.01e6),        # does not reach the 1e-4 line
                     ("safe", 900_000.0, 1e-6, 5e-6, 1.85e6)]),     # reaches it; worth 0.05 of its cost
        ("Q", 1e-6, [("f", 200_000.0, 1e-5, 1e-7, 0.5e6)]),          # worth 3.5x its cost
        ("R", 1e-6, [("f", 400_000.0, 1e-5, 1e-7, 1.2e6)]),          # worth 0.5 of its cost
        ("S", 1e-6, [("f", 300_000.0, 1e-5, 1e-7, 1.05e6)])]         # worth 0.83 of its cost


def test_default_programme_funds_the_intolerable_first_then_only_what_is_worth_it(result):
    res = _fake(result, ROWS)
    assert res.required_sections() == {"P": ["safe"]}                # HK GEO existing slope: 1e-4 /yr
    for budget in (0.0, 1.0e6, 5.0e6):
        for gdf in (1.0, 1.5, 2.5):
            p = res.programme(budget, gdf=gdf)
            ch = p.chosen.set_index("id")
            assert ch.loc["P", "option"] == "safe" and bool(ch.loc["P", "required_by_tolerability"])
            assert p.overrun == pytest.approx(max(0.0, p.cost - budget))
            others = ch.drop(index="P")
            assert (others["benefit_cost_ratio"] >= 1 / gdf).all()     # the Must-show, with the GDF
            # brute force over Q, R, S with the money left: the best sum of gdf * B - C
            left = max(budget - 900_000.0, 0.0)
            best = max(sum(gdf * (1e6 - dict(zip("QRS", (0.5e6, 1.2e6, 1.05e6)))[s] + c) - c
                           for s, c in zip("QRS", (2e5, 4e5, 3e5)) if s in sub)
                       for k in range(4) for sub in __import__("itertools").combinations("QRS", k)
                       if sum(dict(zip("QRS", (2e5, 4e5, 3e5)))[s] for s in sub) <= left
                       and all(gdf * (1e6 - dict(zip("QRS", (0.5e6, 1.2e6, 1.05e6)))[s] + c) > c
                               for s, c in zip("QRS", (2e5, 4e5, 3e5)) if s in sub)) if left > 0 else 0
            assert others["alarp_net_benefit"].sum() == pytest.approx(best, abs=1e-6)
    # at 0 budget only the required section, paid beyond the budget; at GDF 1.5 (1/GDF 0.67) with money S (worth
    # 0.83 of its cost) but not R (0.5); at GDF 2.5 (0.4) R too
    assert list(res.programme(0.0).chosen["id"]) == ["P"] and res.programme(0.0).overrun == 900_000.0
    assert set(res.programme(5e6, gdf=1.5).chosen["id"]) == {"P", "Q", "S"}
    assert set(res.programme(5e6, gdf=2.5).chosen["id"]) == {"P", "Q", "R", "S"}
    assert set(res.programme(5e6, gdf=1.0).chosen["id"]) == {"P", "Q"}
    # the old objective, by name: no tolerability step, deaths avoided (funds R and S too)
    assert set(res.programme(5e6, objective="risk").chosen["id"]) == {"P", "Q", "R", "S"}
    cmp = res.compare_programmes(res.programme(1.5e6), res.programme(1.5e6, objective="risk"))
    assert cmp["only_other"] and "Where they disagree" in cmp["line"]


def test_outputs_name_the_other_programme(result, tmp_path):
    res = _fake(result, ROWS)
    cr.write_corridor(res, tmp_path / "o", budget=1.5e6, gdf=2.5)
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    p, o = s["programme"], s["other_programme"]
    assert p["objective"] == "alarp" and p["gross_disproportion_factor"] == 2.5 and o["objective"] == "risk"
    assert p["required_by_tolerability"] == ["P"] and p["disagreement"].startswith("Where they disagree")
    assert all(f["benefit_cost_ratio"] >= 1 / 2.5 or f["required_by_tolerability"] for f in p["funded"])
    html = (tmp_path / "o" / "report.html").read_text()
    assert "objective &#x27;risk&#x27;" in html or "objective 'risk'" in html
    assert "intolerable individual-risk line" in html and "Where they disagree" in html
    prog = pd.read_csv(tmp_path / "o" / "programme.csv")
    assert set(prog.loc[prog["programme_required_by_tolerability"], "id"]) == {"P"}
    assert "other_programme_option_risk" in prog.columns


def test_gdf_below_one_is_refused_naming_file_field_and_argument(result, tmp_path, capsys):
    toml = (DATA / "small.toml").read_text().replace('sections = "small_sections.csv"',
                                                      f'sections = "{DATA / "small_sections.csv"}"')
    (tmp_path / "g.toml").write_text(toml + "\n[criteria]\ndisproportion_factor = 0.5\n")
    with pytest.raises(cr.CorridorError, match=r"g.toml: criteria.disproportion_factor = 0.5 must be a number >= 1"):
        cr.load_corridor(tmp_path / "g.toml")
    (tmp_path / "g3.toml").write_text(toml + "\n[criteria]\ndisproportion_factor = 3\n")
    assert cr.load_corridor(tmp_path / "g3.toml").study["criteria"].disproportion_factor == 3
    with pytest.raises(ValueError, match=r"gdf = 0.9 must be a number >= 1"):
        _fake(result, ROWS).programme(1e6, gdf=0.9)
    from riskrf.cli import main
    out = tmp_path / "out"
    assert main(["corridor", str(DATA / "small.toml"), "--budget", "1e6", "--gdf", "0.5", "--out", str(out)]) == 2
    assert "--gdf = 0.5 must be a number >= 1" in capsys.readouterr().err and not out.exists()
