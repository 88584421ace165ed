"""Centrelines: chainage <-> coordinates both ways, calibration to register metres, GeoPackage in and out."""
import math

import numpy as np
import pytest

pyogrio = pytest.importorskip("pyogrio")

from riskrf.io import gis  # noqa: E402

#: an L-shaped road: 300 m east, then 400 m north (exact lengths), in ETRS89 / UTM 33N
L_XY = np.array([[220000.0, 6915000.0], [220300.0, 6915000.0], [220300.0, 6915400.0]])


def test_chainage_to_point_exact_on_an_l():
    line = gis.centreline_from_vertices(L_XY, crs="EPSG:25833", chainage_start_m=1000.0)
    assert line.length_m == 700.0 and line.chainage_range_m == (1000.0, 1700.0)
    assert line.point_at(1150.0) == (220150.0, 6915000.0)
    assert line.point_at(1300.0) == (220300.0, 6915000.0)           # the corner
    assert line.point_at(1500.0) == (220300.0, 6915200.0)
    # a point 7 m beside the road at 250 m north: chainage 1000 + 300 + 250, offset 7 m
    c, off = line.chainage_at(220307.0, 6915250.0)
    assert c == pytest.approx(1550.0, abs=1e-9) and off == pytest.approx(7.0, abs=1e-9)


def test_round_trip_chainage_coordinates_chainage():
    rng = np.random.default_rng(4)
    # a winding road: 60 vertices, a random walk with bounded turning (no segment comes back near another)
    ang = np.cumsum(rng.uniform(-0.4, 0.4, 60))
    step = rng.uniform(20, 200, 60)
    xy = np.cumsum(np.column_stack([step * np.cos(ang * 0.5), step * np.sin(ang * 0.5)]), axis=0) + [5e5, 7e6]
    line = gis.centreline_from_vertices(xy, crs="EPSG:25833", chainage_start_m=250.0)
    c = np.sort(rng.uniform(*line.chainage_range_m, 500))
    x, y = line.point_at(c)
    back, off = line.chainage_at(x, y)
    np.testing.assert_allclose(back, c, atol=1e-6)
    assert np.max(off) < 1e-6
    # and coordinates -> chainage -> coordinates for points on the line
    x2, y2 = line.point_at(back)
    np.testing.assert_allclose(np.column_stack([x2, y2]), np.column_stack([x, y]), atol=1e-6)


def test_calibration_keeps_register_metres_at_the_points():
    # the drawn line is 700 m long but the register says the corner is at metre 520 and the end at metre 1100
    cal = [(0.0, *L_XY[0]), (520.0, *L_XY[1]), (1100.0, *L_XY[2])]
    line = gis.centreline_from_vertices(L_XY, crs="EPSG:25833", calibration=cal)
    assert line.point_at(520.0) == pytest.approx((220300.0, 6915000.0))
    assert line.point_at(260.0) == pytest.approx((220150.0, 6915000.0))     # half way in metres = half way drawn
    assert line.point_at(810.0) == pytest.approx((220300.0, 6915200.0))
    assert line.chainage_at(220300.0, 6915100.0)[0] == pytest.approx(520 + 580 / 4)
    bad = [(0.0, *L_XY[0]), (520.0, *L_XY[2]), (1100.0, *L_XY[1])]
    with pytest.raises(gis.GISError, match="must both increase"):
        gis.centreline_from_vertices(L_XY, crs="EPSG:25833", calibration=bad)


def test_cut_gives_the_section_line():
    line = gis.centreline_from_vertices(L_XY, crs="EPSG:25833")
    seg = line.cut(200.0, 500.0)
    np.testing.assert_allclose(seg, [[220200, 6915000], [220300, 6915000], [220300, 6915200]])
    assert np.hypot(*np.diff(seg, axis=0).T).sum() == pytest.approx(300.0)
    with pytest.raises(gis.GISError, match="outside the centreline"):
        line.cut(600.0, 800.0)
    # many at once: the same lines
    many = line.cuts([0.0, 200.0, 650.0], [200.0, 500.0, 700.0])
    for got, (a, b) in zip(many, [(0.0, 200.0), (200.0, 500.0), (650.0, 700.0)]):
        np.testing.assert_array_equal(got, line.cut(a, b))


def test_gpkg_round_trip_and_geographic_crs_refused(tmp_path):
    line = gis.centreline_from_vertices(L_XY, crs="EPSG:25833", chainage_start_m=0.0)
    p = tmp_path / "road.gpkg"
    gis.write_centreline(line, p, calibration_layer="metres", calibration_chainage_m=[0.0, 300.0, 700.0])
    back = gis.read_centreline(p, layer="centreline", calibration_layer="metres")
    np.testing.assert_allclose(back.xy, L_XY)
    assert back.crs == "EPSG:25833" and back.chainage_range_m == pytest.approx((0.0, 700.0))
    geo = tmp_path / "geo.geojson"
    pyogrio.raw.write(geo, np.array([gis.linestring_wkb([[10.0, 62.0], [10.1, 62.1]])], dtype=object), [],
                      fields=[], geometry_type="LineString", crs="EPSG:4326", driver="GeoJSON")
    with pytest.raises(gis.GISError, match="geographic"):
        gis.read_centreline(geo)
    with pytest.raises(gis.GISError, match="not found"):
        gis.read_centreline(tmp_path / "missing.gpkg")


def test_write_lines_gpkg_fields_and_geometry(tmp_path):
    import pandas as pd
    line = gis.centreline_from_vertices(L_XY, crs="EPSG:25833")
    t = pd.DataFrame({"id": ["A", "B"], "rhrs_total": [219, 453], "deaths_per_year": [1e-4, 2.5e-5],
                      "funded": [True, False]})
    p = gis.write_lines_gpkg(tmp_path / "s.gpkg", t, [line.cut(0, 300), line.cut(300, 700)], crs="EPSG:25833")
    info = pyogrio.read_info(p)
    assert info["geometry_type"] == "LineString" and info["crs"] == "EPSG:25833"
    meta, _, geoms, fields = pyogrio.raw.read(p)
    got = dict(zip(meta["fields"], fields))
    assert list(got["id"]) == ["A", "B"] and list(got["rhrs_total"]) == [219, 453] and list(got["funded"]) == [1, 0]
    (kind, xy), = gis._wkb_geoms(bytes(geoms[1]), "t")
    assert kind == "line" and math.isclose(np.hypot(*np.diff(xy, axis=0).T).sum(), 400.0)
