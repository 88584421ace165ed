"""Profiles extracted from 3-D terrain along a polyline (simulation.profile_from_points), and the Authume build."""
from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import simulation
from simulation.profile_extraction import profile_from_points, read_stl

ROOT = Path(__file__).resolve().parents[1]
AUTHUME_DATA = ROOT / "tests" / "data" / "authume"
AUTHUME_SCEN = ROOT / "simulation" / "scenarios" / "authume"
AUTHUME_SCRIPTS = ROOT / "validation" / "authume"


def _shared_authume():
    for base in (ROOT.parent, ROOT.parent.parent):     # <repo>/../shared, or from a git worktree
        raw = base / "shared" / "experiments-raw" / "authume-quarry"
        if (raw / "Endpoints_P1.txt").exists():
            return raw
    pytest.skip("shared/experiments-raw/authume-quarry not present (needed to rebuild the Authume profiles)")


def plane(x, y):
    return 100.0 - 0.6 * x + 0.25 * y


def grid_cloud(n=21, size=100.0):
    g = np.linspace(0, size, n)
    X, Y = np.meshgrid(g, g)
    return np.column_stack([X.ravel(), Y.ravel(), plane(X.ravel(), Y.ravel())])


def test_planar_point_cloud_is_reproduced_exactly():
    # linear interpolation in any triangulation is exact on a plane: an analytic case
    pts = grid_cloud()
    poly = [[5.0, 10.0], [60.0, 30.0], [90.0, 80.0]]
    prof = profile_from_points(pts, poly, spacing=0.7)
    np.testing.assert_allclose(prof.elevation_m, plane(prof.plan_xy[:, 0], prof.plan_xy[:, 1]), atol=1e-9)
    length = np.hypot(55, 20) + np.hypot(30, 50)
    assert prof.distance_m[0] == 0 and prof.distance_m[-1] == pytest.approx(length)
    assert np.all(np.diff(prof.distance_m) > 0) and np.diff(prof.distance_m)[:-1] == pytest.approx(0.7)


def test_triangles_and_vertical_axis_y():
    # the same plane as an STL-like mesh in a y-up frame (columns x, elevation, z)
    pts = grid_cloud(11)
    from scipy.spatial import Delaunay
    tri = pts[Delaunay(pts[:, :2]).simplices]            # (n, 3, 3) in x, y, z
    yup = tri[:, :, [0, 2, 1]]
    prof = profile_from_points(yup, [[10.0, 50.0], [90.0, 50.0]], spacing=1.0, vertical_axis=1)
    np.testing.assert_allclose(prof.elevation_m, plane(10.0 + prof.distance_m, 50.0), atol=1e-9)


def test_zone_labels_become_segment_materials():
    pts = grid_cloud(41)
    labels = np.where(pts[:, 0] < 50.0, "rock", "soil")
    prof = profile_from_points(pts, [[2.0, 50.0], [98.0, 50.0]], spacing=1.0, labels=labels)
    mats = np.array(prof.materials)
    assert set(mats) == {"rock", "soil"}
    switch = prof.distance_m[1:][mats == "soil"].min()         # first soil segment's far end
    assert 2.0 + switch == pytest.approx(50.0, abs=2.6)        # within a grid step and a segment
    table = prof.to_dict()
    sc = simulation.scenario_from_dict({"profile": table, "materials": {"rock": {}, "soil": {}},
                                        "seeder": {"x": 1.0, "mass_kg": 100.0}})
    assert sc.profile.n_segments == len(prof.distance_m) - 1
    s = prof.summary()
    assert list(s["material"]) == ["rock", "soil"]
    # mean slope along x of z = 100 - 0.6 x: atan(0.6)
    assert s["mean_slope_deg"].iloc[0] == pytest.approx(np.degrees(np.arctan(0.6)), abs=1e-6)


def test_project_distance_and_signed_offset():
    pts = grid_cloud()
    prof = profile_from_points(pts, [[0.0, 0.0], [50.0, 0.0], [50.0, 50.0]], spacing=1.0)
    p = prof.project([[20.0, 3.0], [20.0, -4.0], [53.0, 30.0], [80.0, 0.0]])
    np.testing.assert_allclose(p["distance_m"], [20.0, 20.0, 80.0, 50.0])
    np.testing.assert_allclose(p["offset_m"], [3.0, -4.0, -3.0, 30.0])


def test_path_leaving_terrain_is_an_error_or_trimmed():
    pts = grid_cloud()
    with pytest.raises(ValueError, match=r"leaves the terrain at distance 91\.00 m"):
        profile_from_points(pts, [[10.0, 50.0], [150.0, 50.0]], spacing=1.0)
    prof = profile_from_points(pts, [[10.0, 50.0], [150.0, 50.0]], spacing=1.0, trim=True)
    assert prof.distance_m[-1] == pytest.approx(90.0)


@pytest.mark.parametrize("bad, match", [
    (dict(spacing=0), "spacing must be a positive"),
    (dict(labels=["a", "b"]), r"labels: need one per point \(441\)"),
    (dict(vertical_axis=3), "vertical_axis must be 0, 1 or 2"),
])
def test_bad_arguments_are_named(bad, match):
    with pytest.raises(ValueError, match=match):
        profile_from_points(grid_cloud(), [[10.0, 50.0], [50.0, 50.0]], **bad)


def test_bad_polyline_and_points():
    with pytest.raises(ValueError, match="polyline_xy must be >= 2 plan points"):
        profile_from_points(grid_cloud(), [[10.0, 50.0]])
    with pytest.raises(ValueError, match="vertices 0 and 1 coincide"):
        profile_from_points(grid_cloud(), [[10.0, 50.0], [10.0, 50.0]])
    with pytest.raises(ValueError, match=r"point cloud \(n, 3\) or triangles"):
        profile_from_points(np.zeros((5, 2)), [[0, 0], [1, 1]])


def test_read_stl_ascii_and_binary(tmp_path):
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 1]], [[1, 0, 0], [1, 1, 2], [0, 1, 1]]], dtype=float)
    ascii_lines = ["solid t"]
    for t in tri:
        ascii_lines += ["facet normal 0 0 1", "outer loop"] + [f"vertex {a} {b} {c}" for a, b, c in t] + \
            ["endloop", "endfacet"]
    (tmp_path / "a.stl").write_text("\n".join(ascii_lines + ["endsolid t"]))
    np.testing.assert_array_equal(read_stl(tmp_path / "a.stl"), tri)
    rec = np.zeros(2, dtype=[("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["v"] = tri
    (tmp_path / "b.stl").write_bytes(b"\0" * 80 + np.uint32(2).tobytes() + rec.tobytes())
    np.testing.assert_array_equal(read_stl(tmp_path / "b.stl"), tri)
    (tmp_path / "c.stl").write_bytes(b"\0" * 80 + np.uint32(5).tobytes() + rec.tobytes())
    with pytest.raises(ValueError, match="declares 5 triangles but holds 2"):
        read_stl(tmp_path / "c.stl")


# ---- Authume quarry (Garcia et al. 2022; data richefeu/AuthumeQuarryRockfalls_Data-in-Brief f695c933) -------
def test_authume_observed_runouts_match_the_provenance_figures():
    df = pd.read_csv(AUTHUME_DATA / "observed_runout.csv")
    counts = df["profile"].value_counts()
    assert counts["P1"] == 41 and counts["P2"] == 48             # PROVENANCE.md: 41 and 48 blocks
    p1, p2 = df[df.profile == "P1"], df[df.profile == "P2"]
    # PROVENANCE.md "facts measured here": runout min / median / max 3.5 / 40.7 / 70.5 (P1), 20.3 / 56.3 / 93.0 (P2)
    for part, expect in ((p1, (3.5, 40.7, 70.5)), (p2, (20.3, 56.3, 93.0))):
        got = np.quantile(part["plan_runout_m"], [0, 0.5, 1])
        np.testing.assert_allclose(got, expect, atol=0.051)
    # fall height min / median / max 6.0 / 38.1 / 49.6 (P1), 15.3 / 35.6 / 49.0 (P2)
    np.testing.assert_allclose(np.quantile(p1["fall_height_m"], [0, .5, 1]), (6.0, 38.1, 49.6), atol=0.051)
    np.testing.assert_allclose(np.quantile(p2["fall_height_m"], [0, .5, 1]), (15.3, 35.6, 49.0), atol=0.051)
    # PROVENANCE.md: masses 170-1,869 kg
    assert df["mass_kg"].min() == pytest.approx(170, abs=0.5) and df["mass_kg"].max() == pytest.approx(1869, abs=0.5)
    # the along-path runout of the 2-D model stays close to the straight plan runout
    assert np.median(np.abs(df["x_stop_m"] - df["plan_runout_m"])) < 2.0


@pytest.mark.parametrize("name, zones", [("p1", {"vegetated_slope", "hard_ground"}),
                                         ("p2", {"vegetated_slope", "hard_ground", "rocky_slope"})])
def test_authume_scenarios_load_and_cover_the_observed_stops(name, zones):
    sc = simulation.load_scenario(AUTHUME_SCEN / f"authume_{name}.toml")
    assert set(sc.profile.material_names) == zones
    df = pd.read_csv(AUTHUME_DATA / "observed_runout.csv")
    x = df.loc[df.profile == name.upper(), "x_stop_m"]
    assert sc.profile.x[0] < 0 < x.min() and x.max() + 10 < sc.profile.x[-1]
    dx = np.diff(sc.profile.x)
    assert np.all(dx[:-1] == pytest.approx(0.5)) and 0 < dx[-1] <= 0.5 + 1e-9
    # fall from the release to the lowest stop is of the order of the measured fall heights (< 60 m)
    assert 30 < sc.profile.z[0] - sc.profile.z.min() < 70


def test_authume_build_is_reproducible(tmp_path):
    raw = _shared_authume()
    import importlib.util
    spec = importlib.util.spec_from_file_location("build_authume", AUTHUME_SCRIPTS / "build_authume.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    df = mod.build(raw, out_dir=tmp_path, data_dir=tmp_path)
    shipped = pd.read_csv(AUTHUME_DATA / "observed_runout.csv")
    pd.testing.assert_frame_equal(df.reset_index(drop=True), shipped, check_dtype=False, atol=1e-9)
    for name in ("p1", "p2"):
        built = tomllib.loads((tmp_path / f"authume_{name}.toml").read_text())
        ship = tomllib.loads((AUTHUME_SCEN / f"authume_{name}.toml").read_text())
        assert built["profile"] == ship["profile"] and built["seeder"] == ship["seeder"]
