"""Corridor: validation before work, generated cuts, identical results on 1 and 2 dask workers and serially,
resume, failures, unreachable scheduler.  Small: 3 sections x 300 blocks."""
import shutil
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

distributed = pytest.importorskip("distributed")

from riskrf.app import corridor as cr  # noqa: E402
from riskrf.app.corridor import run as corridor_run  # noqa: E402  (the module whose globals the tasks use)
from riskrf.app.corridor.cut import CREST_M, VERGE_M  # noqa: E402
from riskrf.app.corridor.model import _section_seed  # noqa: E402
from riskrf.cli import main  # noqa: E402

DATA = Path(__file__).resolve().parent / "data" / "corridor"
N = 300


@pytest.fixture(scope="module")
def corridor():
    return cr.load_corridor(DATA / "small.toml")


def _client(n):
    cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=False, dashboard_address=":0")
    return distributed.Client(cluster), cluster


@pytest.fixture(scope="module")
def clients():
    """Threaded local clusters of 1 and 2 workers, shared by the tests of this module."""
    made = {n: _client(n) for n in (1, 2)}
    yield {n: c for n, (c, _) in made.items()}
    for client, cluster in made.values():
        client.close()
        cluster.close()


@pytest.fixture(scope="module")
def runs(corridor, clients):
    """The same corridor serially, on 1 worker and on 2 workers."""
    out = {"serial": pd.DataFrame([cr.assess_section(s, corridor, N) for s in corridor.sections])}
    for n in (1, 2):
        out[n] = cr.run_corridor(corridor, client=clients[n], n_blocks=N)
    return out


def _comparable(df):
    return df.drop(columns=["seconds"]).sort_values("id").reset_index(drop=True)


def test_one_and_two_workers_equal_serial(runs):
    ref = _comparable(runs["serial"])
    for n in (1, 2):
        pd.testing.assert_frame_equal(_comparable(runs[n].table), ref, check_exact=True)
    assert runs[2].workers == 2 and runs[1].workers == 1


def test_rates_and_ranking(runs, corridor):
    t = runs[2].table
    # rate_basis "road": the recorded rate is falls reaching the road, so the do-nothing road falls equal it (to the
    # mitigation engine's mass grid: it bins the mass law where the mass-coupled reach uses Gauss-Legendre nodes)
    np.testing.assert_allclose(t["road_falls_per_year"], t["rate_given_per_year"], rtol=1e-3)
    np.testing.assert_allclose(t["release_falls_per_year"] * t["reach_road"], t["rate_given_per_year"], rtol=1e-12)
    s = runs[2].summary()
    assert list(s["rank_risk"]) == sorted(s["rank_risk"])
    assert s["deaths_per_year"].is_monotonic_decreasing
    assert (s["rank_difference"] == s["rank_rhrs"] - s["rank_risk"]).all()
    # RHRS total of each section equals the sum of its category scores (per-row derivation from the table)
    for sec in corridor.sections:
        assert t.set_index("id").loc[sec.id, "rhrs_score"] == pytest.approx(sum(sec.rating.scores.values()))
    b = runs[2].budget_curve()
    assert b["cumulative_spend"].is_monotonic_increasing
    ratio = b["deaths_avoided_per_year"] / b["spend"]
    assert ratio.is_monotonic_decreasing


def test_seed_depends_on_id_not_order(corridor):
    a = _section_seed(7, "A")
    assert a == _section_seed(7, "A") and a != _section_seed(7, "B") and a != _section_seed(8, "A")
    # the child SeedSequence(seed).spawn would give at key crc32(id)
    import zlib
    child = np.random.SeedSequence(7, spawn_key=(zlib.crc32(b"A"),))
    assert a == int(child.generate_state(1, dtype=np.uint64)[0]) >> 1


def test_generated_cut_geometry(corridor):
    sec = corridor.section("A")                    # 25 m at 60 deg, ditch 3 x 1 m, 1 m shoulder, 7 m road
    p = sec.scenario.profile
    toe = CREST_M + 25 / np.tan(np.radians(60))
    assert p.z[0] == 25 and p.z.min() == pytest.approx(-1.0)
    assert p.x[-1] == pytest.approx(toe + 3 + 1 + 7 + VERGE_M)
    road = {c.name: c.x for c in sec.scenario.collectors}
    assert road["road"] == pytest.approx(toe + 3 + 1 + 0.01) and road["barrier"] == pytest.approx(toe + 3 + 0.5)


def _write(tmp_path, rows, extra_toml=""):
    toml = (DATA / "small.toml").read_text().replace('sections = "small_sections.csv"', 'sections = "s.csv"')
    (tmp_path / "c.toml").write_text(toml + extra_toml)
    (tmp_path / "s.csv").write_text(rows)
    return tmp_path / "c.toml"


HEAD = "id,chainage_from,chainage_to,cut_height_m,ditch_width_m,runout_to_road_m,falls_per_year,scenario\n"


def test_bad_rows_named_and_keep_going(tmp_path):
    rows = HEAD + ("A,0,100,20,3,1,0.5,\n"
                   "A,100,200,20,3,1,0.5,\n"             # duplicate id
                   "B,150,300,20,3,1,0.5,\n"             # overlaps A (0-100)? no; overlaps nothing -> C overlaps B
                   "C,250,400,20,3,1,0.5,\n"             # overlaps B
                   "D,400,500,20,3,1,lots,\n"            # not a number
                   "E,500,600,20,3,1,0.5,missing.toml\n"  # scenario file missing
                   "F,600,700,20,0.5,1,0.5,\n")          # ditch too narrow for its depth (1 m)
    path = _write(tmp_path, rows)
    with pytest.raises(cr.CorridorError) as e:
        cr.load_corridor(path)
    msg = str(e.value)
    assert "row 3 (section 'A'): column 'id' = 'A' duplicates row 2" in msg
    assert "row 5 (section 'C'): chainage 250-400 m overlaps row 4 (section 'B'" in msg
    assert "row 6 (section 'D'): column 'falls_per_year' = 'lots' is not a number" in msg
    assert "row 7 (section 'E'): column 'scenario' = 'missing.toml': file not found" in msg
    assert "row 8 (section 'F'): column 'ditch_width_m' = 0.5 is too narrow" in msg
    c = cr.load_corridor(path, keep_going=True)
    assert [s.id for s in c.sections] == ["A", "B"] and len(c.errors) == 5


def test_corridor_file_errors(tmp_path):
    with pytest.raises(cr.CorridorError, match="unknown column 'chainage_form'; did you mean 'chainage_from'"):
        cr.load_corridor(_write(tmp_path, "id,chainage_form,chainage_to\nA,0,1\n"))
    with pytest.raises(cr.CorridorError, match="unknown field corridor.'sead'; did you mean 'seed'"):
        p = _write(tmp_path, HEAD + "A,0,100,20,3,1,0.5,\n")
        p.write_text(p.read_text().replace("seed = 7", "sead = 7"))
        cr.load_corridor(p)
    with pytest.raises(cr.CorridorError, match="exactly one of falls_per_year, falls_per_km_year, falls_per_m2_year or inventory"):
        cr.load_corridor(_write(tmp_path, HEAD.replace(",scenario", ",falls_per_km_year,scenario")
                                .replace("falls_per_year,falls_per_km_year", "falls_per_year,falls_per_km_year")
                                + "A,0,100,20,3,1,0.5,2,\n"))


def test_unreachable_scheduler_fails_fast_and_writes_nothing(tmp_path, capsys):
    # fails fast: the time allowed is the one given (no wall clock asserted: a loaded machine would flake it)
    with pytest.raises(ConnectionError, match="cannot reach the dask scheduler at 'tcp://127.0.0.1:9' within 1 s"):
        cr.connect("tcp://127.0.0.1:9", timeout_s=1)
    out = tmp_path / "out"
    real = cr.connect
    import functools
    corridor_run.connect = functools.partial(real, timeout_s=1)
    try:
        rc = main(["corridor", str(DATA / "small.toml"), "--scheduler", "tcp://127.0.0.1:9", "--out", str(out)])
    finally:
        corridor_run.connect = real
    assert rc == 2 and "cannot reach the dask scheduler" in capsys.readouterr().err
    assert not out.exists() and not any(tmp_path.iterdir())


def test_failure_reported_with_keep_going_and_resume(corridor, tmp_path, monkeypatch, clients):
    client = clients[2]
    real = cr.assess_section
    calls = []

    def flaky(section, cor, n_blocks=None, seed=None):
        calls.append(section.id)
        if section.id == "B":
            raise RuntimeError("simulated worker failure")
        return real(section, cor, n_blocks, seed)

    try:
        monkeypatch.setattr(corridor_run, "assess_section", flaky)
        parts = tmp_path / "parts"
        with pytest.raises(RuntimeError, match="section 'B' failed"):
            cr.run_corridor(corridor, client=client, n_blocks=N, partitions=parts, retries=0)
        res = cr.run_corridor(corridor, client=client, n_blocks=N, partitions=parts, keep_going=True, retries=0)
        assert list(res.table["id"]) == ["A", "C"] and "section 'B'" in res.failures[0]
        assert len(list(parts.glob("*.parquet"))) == 2 and not list(parts.glob("*.partial"))
        monkeypatch.setattr(corridor_run, "assess_section", real)
        calls.clear()
        seen = []
        res2 = cr.run_corridor(corridor, client=client, n_blocks=N, partitions=parts, resume=True,
                               progress=lambda d, t, s: seen.append(s))
        assert seen == ["B"] and list(res2.table["id"]) == ["A", "B", "C"]
    finally:
        monkeypatch.setattr(corridor_run, "assess_section", real)


def test_duplicate_chainage_is_an_overlap(tmp_path):
    # two ids on the same chainage: the second is reported as overlapping the first, by row and section
    path = _write(tmp_path, HEAD + "A,0,100,20,3,1,0.5,\nB,0,100,20,3,1,0.5,\nC,100,200,20,3,1,0.5,\n")
    with pytest.raises(cr.CorridorError, match=r"row 3 \(section 'B'\): chainage 0-100 m overlaps row 2 \(section 'A'"):
        cr.load_corridor(path)
    assert [s.id for s in cr.load_corridor(path, keep_going=True).sections] == ["A", "C"]


def test_worker_dying_mid_run_is_rescheduled_and_nothing_half_written(corridor, runs, tmp_path, monkeypatch):
    """A worker leaves the cluster while it runs section B (closed without waiting for its task, as when its
    process dies): the scheduler reruns B on the other worker, the results equal the serial run, and the
    partition directory holds one whole file per section and no partial file."""
    from distributed.core import Status
    client, cluster = _client(2)
    real = cr.assess_section
    died = []

    def dying(section, cor, n_blocks=None, seed=None):
        if section.id == "B" and not died:
            w = distributed.get_worker()
            died.append(w.address)
            w.loop.add_callback(w.close, executor_wait=False, reason="test: worker dies mid-task")
            # the error is raised only once the worker is closed (its link to the scheduler gone), so that no
            # version of dask can report it before the worker's departure
            t0 = time.perf_counter()
            while w.status != Status.closed and time.perf_counter() - t0 < 60:
                time.sleep(0.02)
            raise RuntimeError("this result must never be seen: its worker is gone")
        return real(section, cor, n_blocks, seed)

    try:
        monkeypatch.setattr(corridor_run, "assess_section", dying)
        parts = tmp_path / "parts"
        res = cr.run_corridor(corridor, client=client, n_blocks=N, partitions=parts, retries=0)
    finally:
        monkeypatch.setattr(corridor_run, "assess_section", real)
        client.close()
        cluster.close()
    assert len(died) == 1 and res.failures == ()
    pd.testing.assert_frame_equal(_comparable(res.table), _comparable(runs["serial"]), check_exact=True)
    assert len(list(parts.glob("*.parquet"))) == 3 and not list(parts.glob("*.partial"))


class _Borrowed:
    """A shared client that the CLI may 'close' without closing it."""

    def __init__(self, client):
        self._c = client

    def __getattr__(self, name):
        return getattr(self._c, name)

    def close(self):
        pass


def test_cli_writes_outputs(tmp_path, monkeypatch, runs, clients):
    # the CLI path on the shared threaded 1-worker cluster (a LocalCluster of processes is the default)
    monkeypatch.setattr(corridor_run, "connect", lambda scheduler=None, n_workers=None, **k: (_Borrowed(clients[1]), None))
    out = tmp_path / "run"
    assert main(["corridor", str(DATA / "small.toml"), "-n", str(N), "--out", str(out)]) == 0
    for f in ("report.html", "corridor.csv", "sections.csv", "budget_curve.csv", "chainage.png", "summary.json"):
        assert (out / f).exists()
    t = pd.read_csv(out / "sections.csv")
    np.testing.assert_allclose(t["deaths_per_year"], runs[2].table["deaths_per_year"], rtol=1e-12)
    assert not (tmp_path / ".run.sections").exists()
    html = (out / "report.html").read_text()
    assert all(sid in html for sid in ("A", "B", "C")) and "Budget curve" in html and "data:image/png;base64" in html
    shutil.rmtree(out)


def test_rate_per_m2_of_face_and_parquet_table(tmp_path):
    rows = ("id,chainage_from,chainage_to,cut_height_m,ditch_width_m,runout_to_road_m,falls_per_m2_year\n"
            "A,0,100,20,3,1,0.0001\n")
    path = _write(tmp_path, rows)
    sec = cr.load_corridor(path).sections[0]
    # face area = 100 m x 20 m / sin(60 deg) = 2309.4 m2 -> 0.23094 falls per year
    assert sec.falls_per_year == pytest.approx(1e-4 * 100 * 20 / np.sin(np.radians(60)))
    pd.read_csv(tmp_path / "s.csv").astype(str).to_parquet(tmp_path / "s.parquet")
    path.write_text(path.read_text().replace('sections = "s.csv"', 'sections = "s.parquet"'))
    assert cr.load_corridor(path).sections[0].falls_per_year == pytest.approx(sec.falls_per_year)
    pd.read_csv(tmp_path / "s.csv").to_excel(tmp_path / "s.xlsx", index=False)
    path.write_text(path.read_text().replace('sections = "s.parquet"', 'sections = "s.xlsx"'))
    assert cr.load_corridor(path).sections[0].falls_per_year == pytest.approx(sec.falls_per_year)


def test_release_rate_basis(tmp_path):
    path = _write(tmp_path, HEAD + "A,0,100,20,3,1,0.5,\n")
    path.write_text(path.read_text().replace("[corridor]", '[corridor]\nrate_basis = "release"'))
    c = cr.load_corridor(path)
    row = cr.assess_section(c.sections[0], c, N)
    # released falls as given; those reaching the road = given x simulated share reaching the road line
    assert row["release_falls_per_year"] == 0.5
    assert row["road_falls_per_year"] == pytest.approx(0.5 * row["reach_road"], rel=1e-3)


def test_hazard_is_mass_coupled_as_in_assess(corridor, runs):
    """Each section's reach probabilities are those of riskrf.energy_hazard (the engine of ``riskrf assess``) on
    the section's scenario with the section's seed: blocks across the mass law, reach by mass class."""
    import riskrf
    from riskrf.hazard.mass_coupling import MassCoupledSamples
    row = runs["serial"].set_index("id").loc["A"]
    sec = corridor.section("A")
    for line, col in (("barrier", "reach_barrier"), ("road", "reach_road")):
        hz = riskrf.energy_hazard(corridor.mass, sec.scenario, line, rate_per_year=0.5, n=N, seed=int(row["seed"]))
        assert isinstance(hz.velocity, MassCoupledSamples)
        assert row[col] == pytest.approx(hz.reach_probability, rel=1e-12)
    # heavier blocks behave differently: the reach probability differs between the lightest and heaviest class
    assert hz.velocity.reach_by_class[0] != hz.velocity.reach_by_class[-1]


E6 = Path(__file__).resolve().parents[1] / "corridors" / "e6_drivdalen"


def test_e6_example_corridor_loads_with_record_rates():
    c = cr.load_corridor(E6 / "e6_drivdalen.toml")
    assert len(c.sections) == 19 and c.rate_basis == "road"
    # 20 NVDB rock falls on main section 1, metres 0-19,000, in 2000-2014; +0.5 per section (Jeffreys mean)
    assert sum(s.falls_per_year for s in c.sections) == pytest.approx((20 + 19 * 0.5) / 15, abs=1e-5)
    assert "fitted to e6_volumes.csv" in c.mass_note and c.mass.n_tail == 34
    assert all(s.rating is not None and max(s.rating.scores.values()) <= 100 for s in c.sections)


def test_e6_builder_reproduces_the_shipped_tables(tmp_path):
    shared = Path(__file__).resolve().parents[1] / ".." / "shared"
    gml = shared / "inventories-raw" / "nvdb-skred-norway" / "Skred_E6_Trondelag_2000_2014.gml"
    if not gml.exists():
        pytest.skip(f"shared NVDB record not present at {gml}")
    import importlib.util
    for f in ("build_e6_corridor.py", "e6_drivdalen.toml"):
        shutil.copy(E6 / f, tmp_path / f)
    spec = importlib.util.spec_from_file_location("build_e6", tmp_path / "build_e6_corridor.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main([str(gml)]) == 0
    for f in ("e6_sections.csv", "e6_rockfalls.csv", "e6_volumes.csv"):
        assert (tmp_path / f).read_text() == (E6 / f).read_text()
    # the centreline: the same vertices and calibration (a GeoPackage is not byte-stable: compare its content)
    from riskrf.io.gis import read_centreline
    a, b = (read_centreline(d / "e6_centreline.gpkg", layer="centreline", calibration_layer="nvdb_metres")
            for d in (tmp_path, E6))
    np.testing.assert_array_equal(a.xy, b.xy)
    assert a.calibration == b.calibration and a.crs == b.crs == "EPSG:25833"


def test_e6_centreline_keeps_register_metres():
    """The register's own road points (Skred_E6_Trondelag_2000_2014.gml, EPSG:25833) are where their NVDB metre
    says: feature 'veglenkeMeterFra' 9394 of main section 1 starts at (221642.786354518, 6923218.28523806)."""
    c = cr.load_corridor(E6 / "e6_drivdalen.toml")
    line = c.centreline
    assert line.crs == "EPSG:25833" and line.chainage_range_m == (0.0, 19000.0)
    assert line.point_at(9394.0) == pytest.approx((221642.786354518, 6923218.28523806), abs=1e-6)
    assert line.chainage_at(221642.786354518, 6923218.28523806)[0] == pytest.approx(9394.0, abs=1e-6)
    # every section carries its line, end to end along the road
    ends = [(s.line[0], s.line[-1]) for s in c.sections]
    for (_, end), (start, _) in zip(ends[:-1], ends[1:]):
        assert end == pytest.approx(start)
    # per-metre option costs are paid on the 200 m cut length (rhrs_slope_length_m), not the 1 km section
    assert all(s.works_length_m == 200.0 and s.length_m == 1000.0 for s in c.sections)


# ---- rates from inventories -----------------------------------------------------------------
REPO = Path(__file__).resolve().parents[1]
E6_VOLUMES = REPO / "corridors" / "e6_drivdalen" / "e6_volumes.csv"       # 34 real NVDB volumes, 1-30 m3, 15 yr
LAUTER_2015 = REPO / "inventories" / "lauterbrunnen" / "lauterbrunnen_tls_2015.csv"   # 122 real TLS falls, 1.5 yr
HEAD_NR = "id,chainage_from,chainage_to,cut_height_m,ditch_width_m,runout_to_road_m"


def test_section_inventory_column_gives_its_rate(tmp_path):
    # small.toml's mass law has m_min = 100 kg: every fall of both files is heavier (the smallest: 1 m3 = 2650 kg
    # and 0.055 m3 x 2650 kg/m3 = 145.75 kg), so the rate is the count over the record length of each sidecar:
    # 34 falls in 2000-01-01..2014-12-31 (5479 days = 15.0007 yr) and 122 falls in 1.5 yr
    rows = (f"{HEAD_NR},falls_per_year,inventory\nA,0,200,25,3,1,,{E6_VOLUMES}\nB,200,350,12,3,1,,{LAUTER_2015}\n"
            "C,400,700,40,2,0,1.5,\n")
    c = cr.load_corridor(_write(tmp_path, rows))
    assert c.section("A").falls_per_year == pytest.approx(34 / (5479 / 365.25), rel=1e-12)
    assert c.section("B").falls_per_year == pytest.approx(122 / 1.5, rel=1e-12)
    assert c.section("C").falls_per_year == 1.5
    assert "e6_volumes.csv: 34 falls >= 100 kg" in c.section("A").rate_source
    # a rate column and an inventory on one row; a missing file; an inventory without a fall >= m_min
    bad = (f"{HEAD_NR},falls_per_year,inventory\nA,0,200,25,3,1,0.5,{E6_VOLUMES}\n"
           f"B,200,350,12,3,1,,{tmp_path / 'nowhere.csv'}\nC,400,700,40,2,0,,{E6_VOLUMES}\n")
    path = _write(tmp_path, bad)
    path.write_text(path.read_text().replace("m_min_kg = 100.0", "m_min_kg = 1.0e5").replace("m_max_kg = 1.0e5",
                                                                                             "m_max_kg = 1.0e7"))
    with pytest.raises(cr.CorridorError) as e:
        cr.load_corridor(path)
    msg = str(e.value)
    assert "row 2 (section 'A'): give exactly one of" in msg and "['falls_per_year', 'inventory']" in msg
    assert "row 3 (section 'B'): column 'inventory' = " in msg and "file not found" in msg
    assert "row 4 (section 'C'): column 'inventory' = " in msg and "is >= m_min = 100000 kg" in msg


def test_corridor_wide_inventory_shared_by_km_and_by_face_area(tmp_path):
    rate = 34 / (5479 / 365.25)                    # e6_volumes.csv: falls >= 100 kg per year (see above)
    rows = f"{HEAD_NR}\nA,0,200,25,3,1\nB,200,350,12,3,1\nC,400,700,40,2,0\n"
    path = _write(tmp_path, rows, f'\n[rates]\ninventory = "{E6_VOLUMES}"\nshare = "km"\n')
    c = cr.load_corridor(path)
    # by km: the 0.65 km of the three sections share the rate
    assert c.section("A").falls_per_year == pytest.approx(rate * 0.200 / 0.650, rel=1e-12)
    assert sum(s.falls_per_year for s in c.sections) == pytest.approx(rate, rel=1e-12)
    assert "share of the corridor inventory e6_volumes.csv" in c.section("B").rate_source
    # the inventory covers 19 km of road, of which these sections are 0.65 km
    path.write_text(path.read_text() + "covered_length_km = 19\n")
    assert cr.load_corridor(path).section("C").falls_per_year == pytest.approx(rate * 0.3 / 19, rel=1e-12)
    # by m2 of rock face: length x height / sin(60 deg) (face_angle_deg 60 in small.toml's defaults)
    path.write_text(path.read_text().replace('share = "km"', 'share = "m2"').replace("covered_length_km = 19\n", ""))
    area = {"A": 200 * 25, "B": 150 * 12, "C": 300 * 40}           # / sin(60 deg) cancels in the shares
    c = cr.load_corridor(path)
    for sid, a in area.items():
        assert c.section(sid).falls_per_year == pytest.approx(rate * a / sum(area.values()), rel=1e-12)
    # a row with its own rate keeps it; bad [rates] fields are named
    path.write_text(path.read_text().replace('share = "m2"', 'share = "miles"'))
    with pytest.raises(cr.CorridorError, match=r"rates.share = 'miles' must be 'km'"):
        cr.load_corridor(path)
    path.write_text(path.read_text().replace('share = "miles"', 'share = "km"\ncovered_length_km = 0.1'))
    with pytest.raises(cr.CorridorError, match="covered_length_km = 0.1 is less than the sharing sections' 0.65 km"):
        cr.load_corridor(path)


# ---- load-only checks of further columns ----------------------------------------------------
def test_chainage_in_km(tmp_path):
    rows = HEAD.replace(",scenario", ",falls_per_km_year,scenario").replace("falls_per_year,", "") + \
        "A,0,0.2,25,3,1,2.5,\nB,0.2,0.35,12,3,1,2.5,\n"
    path = _write(tmp_path, rows)
    path.write_text(path.read_text().replace("[corridor]", '[corridor]\nchainage_unit = "km"'))
    c = cr.load_corridor(path)
    b = c.section("B")
    assert (b.chainage_from_m, b.chainage_to_m) == (pytest.approx(200.0), pytest.approx(350.0))
    assert b.falls_per_year == pytest.approx(2.5 * 0.15)        # falls per km of road x 0.15 km
    (tmp_path / "s.csv").write_text((tmp_path / "s.csv").read_text().replace("B,0.2,0.35", "B,0.15,0.35"))
    with pytest.raises(cr.CorridorError, match=r"chainage 150-350 m overlaps row 2 \(section 'A', 0-200 m\)"):
        cr.load_corridor(path)


def test_face_material_and_options_columns(tmp_path):
    rows = (f"{HEAD_NR},falls_per_year,face_material,options\n"
            "A,0,200,25,3,1,0.5,talus,do nothing;fence 1000 kJ\n"
            "B,200,350,12,3,1,0.5,,\n")
    c = cr.load_corridor(_write(tmp_path, rows))
    a, b = c.section("A"), c.section("B")
    def face(sec):
        pr = sec.scenario.profile
        return pr.material_names[pr.material_index[0]]
    assert face(a) == "talus" and face(b) == "bedrock"
    assert a.options == ("do nothing", "fence 1000 kJ") and b.options == ("do nothing", "fence 1000 kJ")
    bad = (f"{HEAD_NR},falls_per_year,face_material,options\n"
           "A,0,200,25,3,1,0.5,granite,\n"
           "B,200,350,12,3,1,0.5,,fence 1000 kJ\n"
           "C,400,700,40,2,0,1.5,,do nothing;net 500 kJ\n")
    with pytest.raises(cr.CorridorError) as e:
        cr.load_corridor(_write(tmp_path, bad))
    msg = str(e.value)
    assert "row 2 (section 'A'): column 'face_material' = 'granite' is not a material" in msg
    assert "row 3 (section 'B'): column 'options' must name at least two options" in msg
    assert "row 4 (section 'C'): column 'options' names ['net 500 kJ']" in msg


def test_bench_in_generated_cut(tmp_path):
    rows = f"{HEAD_NR},falls_per_year,bench_width_m,bench_height_m\nA,0,200,25,3,1,0.5,2,10\n"
    c = cr.load_corridor(_write(tmp_path, rows))
    p = c.section("A").scenario.profile
    run = 1 / np.tan(np.radians(60))
    x_upper = CREST_M + 15 * run
    np.testing.assert_allclose(p.x[:5], [0, CREST_M, x_upper, x_upper + 2, x_upper + 2 + 10 * run])
    np.testing.assert_allclose(p.z[:5], [25, 25, 10, 10, 0])
    assert p.material_names[p.material_index[2]] == "soil"         # the bench surface: the ditch material
    seeder_x = c.section("A").scenario.seeder
    assert "bench 2 m wide at 10 m" in c.section("A").geometry and seeder_x is not None
    with pytest.raises(cr.CorridorError, match=r"row 2 \(section 'A'\): column 'bench_height_m' = 25 must lie"):
        cr.load_corridor(_write(tmp_path, rows.replace(",2,10", ",2,25")))


def test_dask_scheduler_address_env_unreachable(tmp_path, monkeypatch, capsys):
    import functools
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", "tcp://127.0.0.1:9")
    monkeypatch.setattr(corridor_run, "connect", functools.partial(cr.connect, timeout_s=1))
    out = tmp_path / "out"
    rc = main(["corridor", str(DATA / "small.toml"), "--out", str(out)])
    assert rc == 2
    assert "cannot reach the dask scheduler at 'tcp://127.0.0.1:9' within 1 s" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


# ---- small errors ----------------------------------------------------------------------------------------------
def test_crc32_collision_of_ids_refused(tmp_path):
    # crc32(b"plumless") == crc32(b"buckeroo") == 0x4ddb0c25: they would share a seed and a partition file
    rows = HEAD + "plumless,0,100,20,3,1,0.5,\nbuckeroo,100,200,20,3,1,0.5,\nC,200,300,20,3,1,0.5,\n"
    with pytest.raises(cr.CorridorError, match=r"row 3 \(section 'buckeroo'\): column 'id' = 'buckeroo' has the "
                                               r"same crc32 checksum \(4ddb0c25\) as row 2 \(section 'plumless'\)"):
        cr.load_corridor(_write(tmp_path, rows))
    assert [s.id for s in cr.load_corridor(_write(tmp_path, rows), keep_going=True).sections] == ["plumless", "C"]


def test_ranks_ignore_float_noise_and_are_integers(runs):
    res = runs[2]
    t = res.table.copy()
    a = t.index[t["id"] == "A"][0]
    b = t.index[t["id"] == "B"][0]
    t.loc[b, "deaths_per_year"] = t.loc[a, "deaths_per_year"] * (1 + 1e-15)    # equal but for float noise
    t.loc[b, "rhrs_score"] = t.loc[a, "rhrs_score"]
    s = cr.CorridorResult(corridor=res.corridor, table=t).summary().set_index("id")
    assert s.loc["A", "rank_risk"] == s.loc["B", "rank_risk"]
    assert s.loc["A", "rank_rhrs"] == s.loc["B", "rank_rhrs"]
    assert pd.api.types.is_integer_dtype(s["rank_rhrs"]) and pd.api.types.is_integer_dtype(s["rank_risk"])
    t.loc[b, "deaths_per_year"] = t.loc[a, "deaths_per_year"] * (1 + 1e-9)     # a real difference still counts
    s = cr.CorridorResult(corridor=res.corridor, table=t).summary().set_index("id")
    assert s.loc["B", "rank_risk"] < s.loc["A", "rank_risk"]


def test_defaults_listed_only_where_used(tmp_path, corridor):
    # small.toml's [defaults] give vehicles_per_day and speed_kmh: [traffic]'s defaults are used by no section
    assert not any(u.startswith(("traffic.vehicles_per_day", "traffic.speed_kmh", "traffic.exposed_length_m"))
                   for u in corridor.defaults_used)
    assert any(u.startswith("defaults.seeder_mass_kg") and "ASSUMPTION" in u for u in corridor.defaults_used)
    path = _write(tmp_path, HEAD + "A,0,100,20,3,1,0.5,\n")
    path.write_text(path.read_text().replace("vehicles_per_day = 3000\n", ""))
    used = cr.load_corridor(path).defaults_used
    assert "traffic.vehicles_per_day = 4000.0 (default)" in used
    assert not any(u.startswith("traffic.speed_kmh") for u in used)


def test_report_with_a_section_without_rhrs(runs, tmp_path):
    """Integer RHRS ranks with a section that has no RHRS attributes: blank in the report, null in summary.json."""
    from riskrf.report.corridor_report import render_corridor_html
    t = runs[2].table.copy()
    t.loc[t["id"] == "B", "rhrs_score"] = np.nan
    res = cr.CorridorResult(corridor=runs[2].corridor, table=t)
    s = res.summary().set_index("id")
    assert pd.isna(s.loc["B", "rank_rhrs"]) and s.loc["A", "rank_rhrs"] in (1, 2)
    png = tmp_path / "c.png"
    png.write_bytes(b"\x89PNG\r\n\x1a\n")
    html = render_corridor_html(res, png)
    assert "&lt;NA&gt;" not in html and "NaN" not in html.split("Sections ranked by risk")[1][:3000]
    assert [r["rank_rhrs"] for r in res.to_json()["top"] if r["id"] == "B"] == [None]


def test_too_few_blocks_refused_before_connecting(corridor, tmp_path, capsys):
    with pytest.raises(ValueError, match="n_blocks = 50 must be a whole number >= 100"):
        cr.run_corridor(corridor, scheduler="tcp://127.0.0.1:9", n_blocks=50)
    out = tmp_path / "out"
    assert main(["corridor", str(DATA / "small.toml"), "-n", "50", "--out", str(out)]) == 2
    assert "n_blocks = 50" in capsys.readouterr().err and not any(tmp_path.iterdir())
