"""Sources and materials on 3-D terrain from GIS data: polygon material maps, source points/lines/polygons from
vector files, and the Loye et al. (2009) slope-angle source rule (simulation.sources)."""
import struct

import numpy as np
import pytest

pytest.importorskip("rasterio")
pyogrio = pytest.importorskip("pyogrio")
from pyogrio.raw import write  # noqa: E402

from simulation.engine3d import seed_blocks_3d  # noqa: E402
from simulation.scenario import ScenarioError  # noqa: E402
from simulation.scenario3d import terrain_scenario_from_dict  # noqa: E402
from simulation.sources import _dominance_angle, gaussian_mixture_1d, loye_threshold  # noqa: E402
from simulation.terrain import Terrain  # noqa: E402

CRS = "EPSG:2056"


def _poly_wkb(ring):
    ring = list(ring) + [ring[0]]
    return struct.pack("<BII", 1, 3, 1) + struct.pack("<I", len(ring)) + np.asarray(ring, "<f8").tobytes()


def _line_wkb(pts):
    return struct.pack("<BII", 1, 2, len(pts)) + np.asarray(pts, "<f8").tobytes()


def _point_wkb(p):
    return struct.pack("<BI2d", 1, 1, *p)


def _layer(path, geoms, fields=None, crs=CRS, gtype="Polygon"):
    fields = fields or {}
    write(str(path), np.array(geoms, dtype=object), [np.asarray(v) for v in fields.values()], list(fields),
          geometry_type=gtype, crs=crs, driver="GPKG")
    return path


def _cliff(x, y):
    """A 5 deg plain (x > 120), a 30 deg steep slope (x 40-120) and a 65 deg cliff (x < 40), 0.1 m roughness."""
    rng = np.random.default_rng(0)
    t5, t30, t65 = (np.tan(np.radians(a)) for a in (5, 30, 65))
    z = np.where(x > 120, t5 * (200 - x),
                 np.where(x > 40, t5 * 80 + t30 * (120 - x), t5 * 80 + t30 * 80 + t65 * (40 - x)))
    return z + rng.normal(0, 0.1, x.shape)


CLIFF = Terrain.from_function(_cliff, (0, 200), (0, 100), 1.0)
MATS = {"rock": {"preset": "bedrock"}, "talus": {"preset": "talus"}}


def _sc(sources, terrain=CLIFF, tt=None, base=None):
    return terrain_scenario_from_dict({"terrain": tt or {}, "materials": MATS,
                                       "sources": {"mass_kg": 500, **sources}}, terrain=terrain, base_dir=base)


def test_mixture_threshold_on_a_known_mixture():
    # angles from four Gaussian units (plains, footslopes, steep slopes, cliffs); the fitted decomposition must
    # return the angle where the true cliff unit's weighted density overtakes the steep-slope unit's
    true = [(3.0, 1.5, 0.3), (15.0, 4.0, 0.3), (32.0, 5.0, 0.3), (55.0, 6.0, 0.1)]
    rng = np.random.default_rng(1)
    a = np.concatenate([rng.normal(m, s, int(w * 400_000)) for m, s, w in true])
    mu, sd, w = gaussian_mixture_1d(a[(a > 0) & (a < 90)], 4)
    np.testing.assert_allclose(mu, [t[0] for t in true], atol=0.3)
    expected = _dominance_angle(32.0, 5.0, 0.3, 55.0, 6.0, 0.1)
    assert 40 < expected < 50
    got = _dominance_angle(mu[2], sd[2], w[2], mu[3], sd[3], w[3])
    assert got == pytest.approx(expected, abs=0.3)


def test_loye_sources_are_the_cliff_cells():
    th = loye_threshold(CLIFF, n_units=3)
    assert 30 < th.angle_deg < 65 and th.means_deg[-1] == pytest.approx(65, abs=2)
    sc = _sc({"slope_above_deg": "loye2009", "slope_units": 3})
    xc, _ = CLIFF.cell_centres()
    x_cells = xc.ravel()[sc.sources.cells]
    assert (x_cells <= 41).all() and (x_cells < 39).sum() > 0.9 * 39 * 101
    assert "Loye et al. 2009" in sc.sources.basis and f"{th.angle_deg:.1f} deg" in sc.sources.basis
    b = seed_blocks_3d(sc, 2000, 1)
    assert (b["x"] <= 41.5).all() and (b["x"] >= 0).all()
    # an explicit threshold is the labelled parameter, and it can be combined with a polygon
    sc2 = _sc({"slope_above_deg": 50.0, "polygon": [[0, 0], [100, 0], [100, 50], [0, 50]]})
    assert "(sources.slope_above_deg, given)" in sc2.sources.basis
    _, yc = CLIFF.cell_centres()
    assert (yc.ravel()[sc2.sources.cells] <= 50).all()
    with pytest.raises(ScenarioError, match="no DEM cell is steeper than 80.0 deg"):
        _sc({"slope_above_deg": 80.0})
    with pytest.raises(ScenarioError, match=r"slope_above_deg = 'steep' must be an angle"):
        _sc({"slope_above_deg": "steep"})


def test_material_polygons_are_rasterised_on_the_dem_grid(tmp_path):
    zones = _layer(tmp_path / "zones.gpkg", [_poly_wkb([(-1, -1), (40.2, -1), (40.2, 101), (-1, 101)]),
                                              _poly_wkb([(40.2, -1), (201, -1), (201, 101), (40.2, 101)])],
                   {"zone": np.array(["cliff", "scree"], dtype=object)})
    tt = {"material_polygons": "zones.gpkg", "material_field": "zone",
          "material_values": {"cliff": "rock", "scree": "talus"}}
    sc = _sc({"points": [[150, 50]]}, tt=tt, base=tmp_path)
    idx = sc.material_grid.index
    xc, _ = CLIFF.cell_centres()
    # a cell takes the polygon containing its centre: x <= 40 rock, x >= 41 talus
    assert (idx[xc <= 40] == 0).all() and (idx[xc >= 41] == 1).all()
    # attribute values that are material names need no mapping; uncovered cells take the default material
    part = _layer(tmp_path / "part.gpkg", [_poly_wkb([(-1, -1), (40.2, -1), (40.2, 101), (-1, 101)])],
                  {"name": np.array(["rock"], dtype=object)})
    sc = _sc({"points": [[150, 50]]}, tt={"material_polygons": "part.gpkg", "material_field": "name",
                                          "material": "talus"}, base=tmp_path)
    assert (sc.material_grid.index[xc <= 40] == 0).all() and (sc.material_grid.index[xc >= 41] == 1).all()
    with pytest.raises(ScenarioError, match=r"the cell centred at \(41.00, 0.00\) lies in no polygon"):
        _sc({"points": [[150, 50]]}, tt={"material_polygons": "part.gpkg", "material_field": "name"}, base=tmp_path)
    with pytest.raises(ScenarioError, match="feature 0 has zone = 'cliff', which is not mapped to a material"):
        _sc({"points": [[150, 50]]}, tt={"material_polygons": "zones.gpkg", "material_field": "zone"}, base=tmp_path)
    _layer(tmp_path / "lv95.gpkg", [_poly_wkb([(-1, -1), (201, -1), (201, 101), (-1, 101)])],
           {"name": np.array(["rock"], dtype=object)}, crs="EPSG:21781")
    with pytest.raises(ScenarioError, match=r"the layer's CRS EPSG:21781 is not the DEM's EPSG:2056 .* reproject"):
        _sc({"points": [[150, 50]]}, tt={"material_polygons": "lv95.gpkg", "material_field": "name"}, base=tmp_path)


def test_sources_from_vector_files(tmp_path):
    _layer(tmp_path / "pts.gpkg", [_point_wkb((10.5, 20.5)), _point_wkb((12.5, 80.5))], gtype="Point")
    sc = _sc({"file": "pts.gpkg"}, base=tmp_path)
    b = seed_blocks_3d(sc, 500, 2)
    assert set(zip(b["x"], b["y"])) == {(10.5, 20.5), (12.5, 80.5)}
    _layer(tmp_path / "lines.gpkg", [_line_wkb([(10, 10), (10, 90)])], gtype="LineString")
    b = seed_blocks_3d(_sc({"file": "lines.gpkg"}, base=tmp_path), 2000, 3)
    np.testing.assert_allclose(b["x"], 10.0)
    assert b["y"].min() >= 10 and b["y"].max() <= 90 and abs(np.median(b["y"]) - 50) < 3
    _layer(tmp_path / "area.gpkg", [_poly_wkb([(4.5, 4.5), (24.5, 4.5), (24.5, 44.5), (4.5, 44.5)])])
    sc = _sc({"file": "area.gpkg"}, base=tmp_path)
    assert sc.sources.cells.size == 20 * 40          # the cells whose centres (x 5-24, y 5-44 m) are inside
    b = seed_blocks_3d(sc, 2000, 4)
    assert b["x"].min() >= 4.5 and b["x"].max() <= 24.5 and b["y"].min() >= 4.5 and b["y"].max() <= 44.5
    _layer(tmp_path / "far.gpkg", [_point_wkb((10.5, 20.5)), _point_wkb((500.0, 20.0))], gtype="Point")
    with pytest.raises(ScenarioError, match=r"sources.file .*far.gpkg: point 1 \(500.00, 20.00\) is outside the DEM"):
        _sc({"file": "far.gpkg"}, base=tmp_path)
    with pytest.raises(ScenarioError, match="needs exactly one of points"):
        _sc({"file": "pts.gpkg", "points": [[10, 10]]}, base=tmp_path)


# ---- each release point's own state: velocity vector, mass, radius ------------------------------------------------
PLANE = Terrain.from_function(lambda x, y: 0.2 * (200 - x), (0, 200), (0, 200), 1.0)    # 11.3 deg, fall line +x
SMOOTH = {"rock": {"normal_restitution": 0.3, "tangential": {"law": "constant", "mean": 0.8}, "roughness_m": 0.0,
                   "ground_friction_angle_deg": 9.0}}


def test_a_release_velocity_sets_the_direction_not_only_the_fall_line():
    """On a plane whose fall line is +x, a block launched with a cross-slope velocity is carried to the side of its
    release point; with speed_ms it goes straight down the fall line."""
    import simulation
    base = {"terrain": {}, "materials": SMOOTH, "collectors": []}
    src = {"points": [[20.0, 100.0]], "height_m": 0.5, "mass_kg": 500}
    down = terrain_scenario_from_dict({**base, "sources": {**src, "speed_ms": 4.0}}, terrain=PLANE)
    side = terrain_scenario_from_dict({**base, "sources": {**src, "velocity_ms": [[2.0, 8.0, 0.0]]}}, terrain=PLANE)
    b = seed_blocks_3d(side, 3, seed=1)
    assert b["vx"].tolist() == [2.0] * 3 and b["vy"].tolist() == [8.0] * 3 and b["vz"].tolist() == [0.0] * 3
    y_down = simulation.run_terrain(down, 20, seed=1).stops()["y_m"]
    y_side = simulation.run_terrain(side, 20, seed=1).stops()["y_m"]
    assert np.abs(y_down - 100).max() < 1.0
    assert (y_side > 105).all()                                   # carried to +y: the direction is honoured


def test_each_release_point_gets_its_own_mass_and_radius():
    sc = _sc({"points": [[150.0, 20.0], [150.0, 80.0]], "mass_kg": [50.0, 2000.0], "radius_m": [0.2, 0.6]})
    b = seed_blocks_3d(sc, 400, seed=3)
    near = b["y"] < 50
    assert set(b["mass"][near]) == {50.0} and set(b["mass"][~near]) == {2000.0}
    assert set(b["radius"][near]) == {0.2} and set(b["radius"][~near]) == {0.6}
    assert 150 < near.sum() < 250                                 # points chosen uniformly
    # masses given by the caller (the mass coupling) keep the radius of their own mass
    given = seed_blocks_3d(sc, 4, seed=3, masses_kg=np.full(4, 1000.0))
    assert np.allclose(given["radius"], sc.sources.radius(1000.0))
    # without per-point fields the draw is the one of before (same points for the same seed)
    plain = _sc({"points": [[150.0, 20.0], [150.0, 80.0]]})
    assert np.array_equal(seed_blocks_3d(plain, 400, seed=3)["y"], b["y"])


@pytest.mark.parametrize("sources, message", [
    ({"points": [[150.0, 20.0]], "radius_m": [0.0]}, r"x.toml: sources.radius_m\[0\] = 0.0 must be a finite number > 0"),
    ({"points": [[150.0, 20.0]], "radius_m": -0.3}, r"sources.radius_m\[0\] = -0.3 must be a finite number > 0"),
    ({"points": [[150.0, 20.0], [150.0, 50.0]], "mass_kg": [10.0, 20.0, 30.0]},
     r"sources.mass_kg must be numbers, one per release point \(2\) or one for all; got shape \(3,\)"),
    ({"points": [[150.0, 20.0]], "height_m": 0.0, "velocity_ms": [1.0, 0.0, -2.0]},
     r"sources.velocity_ms\[0\] = \[1.0, 0.0, -2.0\] m/s points into the ground at release point 1 \(150, 20\)"),
    ({"points": [[150.0, 20.0]], "velocity_ms": [[1.0, 0.0]]}, r"sources.velocity_ms must be \[vx, vy, vz\] triples"),
    ({"points": [[150.0, 20.0]], "velocity_ms": [1.0, 0.0, 0.0], "speed_ms": 2.0}, r"remove sources.speed_ms"),
    ({"polygon": [[130, 10], [160, 10], [160, 40]], "velocity_ms": [1.0, 0.0, 0.0]},
     r"sources.velocity_ms gives each release point its own value: it needs sources.points"),
])
def test_bad_release_states_are_refused_with_file_and_field(sources, message):
    with pytest.raises(ScenarioError, match=message):
        terrain_scenario_from_dict({"terrain": {}, "materials": MATS, "sources": {"mass_kg": 500, **sources}},
                                   "x.toml", terrain=CLIFF)
    # a block thrown down from above the ground is allowed
    terrain_scenario_from_dict({"terrain": {}, "materials": MATS, "sources": {
        "mass_kg": 500, "points": [[150.0, 20.0]], "height_m": 2.0, "velocity_ms": [1.0, 0.0, -2.0]}},
        "x.toml", terrain=CLIFF)
