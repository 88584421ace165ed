"""Drape, bench and bund from a site file: accepted by the schema, run through ``riskrf assess``,
each effect derived and labelled; bad geometry refused naming the file, the option and the field."""
import json

import pandas as pd
import pytest

from riskrf.app.site import SiteError, load_site
from riskrf.cli import main

from .test_assess import SITE, _site_copy

DEMO = SITE.read_text()
#: The demo's options (all of them) replaced by these: do nothing, a bench on the talus, a bund above the barrier
#: line, a drape over the face (the demo scenario road_cut_barrier: face x = 5-35 m, releases at x = 6-14 m, talus
#: 35-80 m, barrier line 100 m, road 120 m).
OPTIONS = DEMO[DEMO.index("[[options]]"):DEMO.index("[uncertainty]")]
MEASURES = '''[[options]]
name = "do nothing"
kind = "none"
capital_cost = 0

[[options]]
name = "catch bench"
kind = "bench"
capital_cost = 500000
x_m = 60.0
width_m = 10.0

[[options]]
name = "bund 4 m"
kind = "bund"
capital_cost = 700000
x_m = 88.0
width_m = 10.0
height_m = 4.0

[[options]]
name = "drape"
kind = "drape"
capital_cost = 800000
annual_maintenance = 10000
life_years = 30
zone_x_m = [5.0, 30.0]

'''
#: Small runs: 1,500 blocks per re-simulation, 200 joint samples, 2 material draws, no repeated ensembles, and no
#: closure (the demo's rain-closure option is replaced) so no rate model either.
SMALL = {OPTIONS: MEASURES, "option_blocks = 10000": "option_blocks = 1500",
         "samples = 1000": "samples = 200\nmax_samples = 200\nensemble_replicates = 0\nmax_material_draws = 2",
         "material_draws = 8 ": "material_draws = 2 "}


def _with(tmp_path, option_text):
    """The demo site whose options are do nothing and ``option_text`` (one [[options]] table)."""
    head = '[[options]]\nname = "do nothing"\nkind = "none"\ncapital_cost = 0\n\n'
    return _site_copy(tmp_path, replace={OPTIONS: head + option_text + "\n"})


@pytest.fixture(scope="module")
def assessed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("slope_measures")
    site = _site_copy(tmp, replace=SMALL)
    out = tmp / "out"
    assert main(["assess", str(site), "--out", str(out)]) == 0
    return out


def test_site_file_with_a_drape_a_bench_and_a_bund_runs_through_assess(assessed):
    rank = pd.read_csv(assessed / "ranking.csv").set_index("option")
    assert {"catch bench", "bund 4 m", "drape"} <= set(rank.index)
    for name in ("catch bench", "bund 4 m", "drape"):
        assert 0 < rank.loc[name, "effectiveness"] < 1, name        # derived, never perfect
        assert rank.loc[name, "road_falls_per_year"] < rank.loc["do nothing", "road_falls_per_year"], name
    assert rank.loc["catch bench", "kind"] == "bench" and rank.loc["drape", "kind"] == "drape"


def test_each_effect_is_derived_and_labelled_in_the_ranking_and_the_report(assessed):
    rank = pd.read_csv(assessed / "ranking.csv").set_index("option")
    assert rank.loc["catch bench", "effect_basis"].startswith("derived: the slope re-simulated with the bench")
    assert rank.loc["bund 4 m", "effect_basis"].startswith("derived: the slope re-simulated with the bund")
    drape = rank.loc["drape", "effect_basis"]
    assert drape.startswith("derived share of road falls released under the mesh") and \
        "ASSUMED containment 85% (70%-95%)" in drape and "falls from above not credited" in drape
    # the drape retains at most its ASSUMED containment of the falls (only those starting under the mesh, and no
    # block above a 1 m sphere)
    assert rank.loc["drape", "effectiveness"] <= 0.85 + 1e-9
    html = (assessed / "report.html").read_text()
    assert "ASSUMED containment 85%" in html and "re-simulated with the bund" in html
    from pypdf import PdfReader
    pdf = " ".join(" ".join(p.extract_text() for p in PdfReader(assessed / "report.pdf").pages).split())
    assert "ASSUMED containment 85%" in pdf and "re-simulated with the bench" in pdf
    s = json.loads((assessed / "summary.json").read_text())
    basis = {o["option"]: o["effect_basis"] for o in s["ranking"]}
    assert basis["drape"] == drape and basis["bund 4 m"] == rank.loc["bund 4 m", "effect_basis"]


@pytest.mark.parametrize("option, message", [
    # a drape off the face: on the talus apron (29 deg)
    ('name = "drape"\nkind = "drape"\ncapital_cost = 1\nzone_x_m = [40.0, 60.0]\n',
     r"option 'drape': zone_x_m = \[40, 60\] is not on a rock face.*span x = 5-35 m"),
    # a drape beyond the profile (0-130 m)
    ('name = "drape"\nkind = "drape"\ncapital_cost = 1\nzone_x_m = [5.0, 140.0]\n',
     r"option 'drape': zone_x_m spans 5-140 m, outside the profile \(0, 130\) m"),
    # a drape on the face below every release point (releases at 6-14 m)
    ('name = "drape"\nkind = "drape"\ncapital_cost = 1\nzone_x_m = [20.0, 30.0]\n',
     r"option 'drape': zone_x_m = \[20, 30\]: no block is released under the mesh"),
    # a bench running off the end of the profile
    ('name = "bench"\nkind = "bench"\ncapital_cost = 1\nx_m = 125.0\nwidth_m = 10.0\n',
     r"option 'bench': x_m = 125 m \+ width_m = 10 m spans 125-135 m, outside the profile \(0, 130\) m"),
    # a bund across the road line (x = 120 m)
    ('name = "bund"\nkind = "bund"\ncapital_cost = 1\nx_m = 112.0\nwidth_m = 10.0\nheight_m = 2.0\n',
     r"option 'bund'.*would cover the road line"),
    # missing geometry
    ('name = "bund"\nkind = "bund"\ncapital_cost = 1\nx_m = 88.0\nwidth_m = 10.0\n',
     r"option 'bund': a bund needs height_m \(its geometry"),
    ('name = "bench"\nkind = "bench"\ncapital_cost = 1\nx_m = 60.0\n',
     r"option 'bench': a bench needs width_m \(its geometry"),
    ('name = "drape"\nkind = "drape"\ncapital_cost = 1\n',
     r"option 'drape': a drape needs zone_x_m \(its geometry"),
    # a bad field value is named with its table and option
    ('name = "drape"\nkind = "drape"\ncapital_cost = 1\nzone_x_m = [5.0, 30.0]\ncontainment = 1.5\n',
     r"option 'drape': containment = 1.5 is a share and must lie in \[0, 1\]"),
    ('name = "bund"\nkind = "bund"\ncapital_cost = 1\nx_m = 88.0\nwidth_m = 10.0\nheight_m = 2.0\n'
     'material = "granite"\n', r"option 'bund'.*material = 'granite' is not a material"),
])
def test_bad_slope_measures_in_a_site_file_are_refused_naming_file_and_field(tmp_path, option, message):
    site = _with(tmp_path, "[[options]]\n" + option)
    with pytest.raises(SiteError, match=message) as err:
        load_site(site)
    assert str(site) in str(err.value)


def test_a_drape_on_a_site_without_a_face_is_refused(tmp_path):
    """A scenario with no segment steeper than 40 deg has no face to drape."""
    scen = (SITE.parent / "../../simulation/scenarios/road_cut_barrier.toml").resolve().read_text()
    gentle = scen.replace("z = [80.0, 80.0, 55.0, 38.0, 30.0, 16.0, 6.0, 3.0, 2.0, 0.0, 0.0]",
                          "z = [30.0, 30.0, 25.0, 20.0, 18.0, 12.0, 6.0, 3.0, 2.0, 0.0, 0.0]")
    assert gentle != scen
    (tmp_path / "gentle.toml").write_text(gentle)
    site = _with(tmp_path, '[[options]]\nname = "drape"\nkind = "drape"\ncapital_cost = 1\nzone_x_m = [5.0, 20.0]\n')
    text = site.read_text()
    old = str((SITE.parent / "../../simulation/scenarios/road_cut_barrier.toml").resolve())
    assert old in text
    site.write_text(text.replace(old, str(tmp_path / "gentle.toml")))
    with pytest.raises(SiteError, match="option 'drape': zone_x_m = \\[5, 20\\]: scenario 'road_cut_barrier' has no "
                                        "rock face to drape") as err:
        load_site(site)
    assert str(site) in str(err.value)


def test_the_site_file_drape_with_a_typed_retention_is_an_assumption(tmp_path):
    site = _with(tmp_path, '[[options]]\nname = "drape"\nkind = "drape"\ncapital_cost = 1\nretention = 0.9\n')
    opts = load_site(site).mitigation.options
    from riskrf.risk.options.chain import effect_basis
    drape = [o for o in opts if o.name == "drape"][0]
    assert effect_basis(drape, [drape]) == "ASSUMPTION: typed effectiveness (drape)"
