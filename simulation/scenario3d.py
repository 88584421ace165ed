"""Scenarios on 3-D terrain: a ``[terrain]`` table (a DEM raster and its materials), ``[sources]`` and plan
collectors, read from TOML.

::

    name = "authume_p1_3d"
    [terrain]
    dem = "authume_dem.tif"          # GeoTIFF or ESRI ASCII grid, path relative to this file
    crs = "EPSG:2154"                # only when the DEM has no CRS of its own
    # nodata = "leave"               # a block reaching a nodata hole leaves there (default), or "error": refuse
                                     # a DEM whose fall lines from the sources meet a hole, before any work
    material = "soil"                # one material everywhere (or the default where no polygon lies), or:
    # material_raster = "materials.tif"        # integer codes on the DEM's grid
    # roughness_raster = "roughness.tif"      # roughness height per cell [m] on the DEM's grid (nodata: the material's)
    # material_codes = { 1 = "soil", 2 = "bedrock" }
    # material_polygons = "zones.gpkg"         # or polygons (GeoPackage, shapefile), rasterised on the grid
    # material_field = "zone"                  # the attribute naming each polygon's class
    # material_values = { scree = "soil", cliff = "bedrock" }   # class -> material (default: same names)
    # material_layer = "zones"                 # optional

    [materials.soil]                 # as in 2-D scenarios (presets, laws, roughness, ground friction)
    preset = "soil"

    [sources]                        # release points (chosen uniformly) or a polygon (uniform inside)
    points = [[x, y], ...]           # or polygon = [[x, y], ...], or line = [[x, y], ...] (uniform along), or
                                     # file = "sources.gpkg" (points, lines or polygons; layer = "...")
    # slope_above_deg = 55.0         # or "loye2009": sources in the cells steeper than this (inside the
    # slope_units = 4                # polygon(s) if given); Loye et al. 2009 threshold (simulation.sources)
    height_m = 1.0                   # above the ground [m]; numbers or distribution tables as in 2-D
    mass_kg = { dist = "lognormal", median = 800, sigma = 0.5 }
    density_kg_m3 = 2650
    speed_ms = 0.5                   # initial horizontal speed along the local fall line [m/s]
    vz_ms = 0.0
    angular_velocity_rads = 0.0
    # with points (given or from a file), each point's own release state instead (one entry per point, or one
    # for all): velocity_ms = [[vx, vy, vz], ...] [m/s] (direction as well as speed; replaces speed_ms and
    # vz_ms), mass_kg = [m1, m2, ...] [kg], radius_m = [r1, r2, ...] [m] (default: from mass, density, shape)

    [[collectors]]                   # polylines in plan: crossings are recorded (position along the line,
    name = "road"                    # velocity, height above ground, mass)
    line = [[x, y], [x, y], ...]

    [[collectors]]                   # a barrier: a net height_m above the ground along the line; blocks
    name = "fence"                   # below its top are caught up to capacity_kj (left out: every one,
    line = [[x, y], [x, y]]          # stated as an assumption) and go through with the excess above it
    height_m = 4.0
    capacity_kj = 2000

    [settings]                       # gravity_ms2, contact_velocity_ms, stop_velocity_ms, max_events,
                                     # max_rolling_slope_deg (no rolling in contact on steeper faces)

Every error names the file and the field; sources or collector vertices off the DEM (or on a nodata
hole) and a material raster on another grid are refused before any simulation.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._display import Displayed, short_repr
from .scenario import (Distribution, ScenarioError, Settings, _check_keys, _number, parse_settings,
                       parse_tables_and_materials)
from .terrain import MaterialGrid, Terrain, TerrainError, read_dem, read_material_raster, read_roughness_raster
from .units import DEFAULT_DENSITY_KG_M3, DENSITY_RANGE_KG_M3, INERTIA_FACTORS, block_radius

#: Contact steps are events in 3-D (one per half cell rolled), so the default limit is higher than in 2-D.
DEFAULT_MAX_EVENTS_3D = 200_000

#: Default per-block factor s_b [-] of the lateral deviation at impacts (``sources.deviation_factor``;
#: :func:`simulation.kernel3d_contact.deviation_sd`): lognormal, median 1, sigma of ln 0.3 [D], the block-to-block
#: variation of shape: the log-sd of the aspect ratio L1/L3 of the surveyed Authume blocks is 0.25 (P1) and
#: 0.18 (P2) (tests/data/authume/observed_runout.csv), widened for sites with less uniform blocks.
DEFAULT_DEVIATION_FACTOR = {"dist": "lognormal", "median": 1.0, "sigma": 0.3, "max": 5.0}


@dataclass(frozen=True)
class Sources:
    """Where blocks start: ``points`` (n, 2) chosen uniformly, or inside ``polygon`` (k, 2) uniformly, or along
    ``lines`` (a list of (k, 2) polylines, uniformly by length), or in ``cells`` (flat indices of DEM cells in
    internal order, a cell chosen uniformly and a point uniformly in it: source polygons from a file, or the
    cells steeper than ``threshold``).  ``basis`` says which, in words, for outputs."""

    points: np.ndarray | None = field(repr=False)
    polygon: np.ndarray | None = field(repr=False)
    height_m: Distribution
    mass_kg: Distribution
    density_kg_m3: float
    speed_ms: Distribution
    vz_ms: Distribution
    angular_velocity_rads: Distribution
    shape: str = "sphere"
    lines: tuple | None = field(repr=False, default=None)
    cells: np.ndarray | None = field(repr=False, default=None)
    threshold: object = None
    basis: str = ""
    #: Per release point (with ``points`` only; None: the distributions above): velocity (n, 3) [m/s], mass (n,)
    #: [kg] and radius (n,) [m].
    point_velocity: np.ndarray | None = field(repr=False, default=None)
    point_mass: np.ndarray | None = field(repr=False, default=None)
    point_radius: np.ndarray | None = field(repr=False, default=None)
    #: Per-block factor s_b [-] of the lateral deviation at impacts (:func:`simulation.kernel3d_contact.deviation_sd`).
    deviation_factor: Distribution = field(
        default_factory=lambda: Distribution("lognormal", dict(DEFAULT_DEVIATION_FACTOR)))

    def radius(self, mass):
        """Radius [m] of spheres (or cylinders of aspect ratio 1) of the given masses [kg].

        Parameters
        ----------
        mass : float or array_like
            Block mass [kg].

        Returns
        -------
        float or numpy.ndarray
            Block radius [m].
        """
        return block_radius(mass, self.density_kg_m3, self.shape)

    @property
    def inertia_factor(self) -> float:
        """I / (m r^2) of the block shape."""
        return INERTIA_FACTORS[self.shape]


@dataclass(frozen=True)
class PlanCollector:
    """A polyline in plan [m, the DEM's CRS]; crossings are recorded with their distance along it.

    With ``height_m`` it is a barrier: a net of that height [m] above the ground along the line, holding
    blocks whose underside is below its top up to ``capacity_kj`` [kJ] (None: every such block, an infinite
    capacity, stated in :meth:`description`); see :mod:`simulation.kernel3d`."""

    name: str
    line: np.ndarray = field(repr=False)
    height_m: float | None = None
    capacity_kj: float | None = None

    @property
    def is_barrier(self) -> bool:
        """True when the line is a barrier (it has a net height)."""
        return self.height_m is not None

    def description(self) -> str:
        """One line: what the line is (collector, or barrier with its height and capacity).

        Returns
        -------
        str
            The description, lengths and heights in metres, capacity in kJ.
        """
        if not self.is_barrier:
            return f"collector {self.name!r} ({self.length_m:.1f} m)"
        cap = ("capacity not given: ASSUMED to hold every block below the net's top" if self.capacity_kj is None
               else f"capacity {self.capacity_kj:g} kJ")
        return f"barrier {self.name!r} ({self.length_m:.1f} m, net {self.height_m:g} m above ground, {cap})"

    @property
    def length_m(self) -> float:
        """Length of the polyline in plan [m]."""
        return float(np.sum(np.hypot(*np.diff(self.line, axis=0).T)))


@dataclass(frozen=True, repr=False)
class TerrainScenario(Displayed):
    """A checked 3-D scenario: ``terrain`` (DEM), ``materials``, ``material_grid`` (material per cell),
    ``sources``, plan ``collectors`` and ``settings``, and ``roughness_grid``, the roughness per cell [m] of a
    ``terrain.roughness_raster`` (NaN where the material's applies; None: the materials' everywhere); run it with
    :func:`simulation.run_terrain`."""

    name: str
    description: str
    terrain: Terrain
    materials: tuple
    material_grid: MaterialGrid
    sources: Sources
    collectors: tuple
    settings: Settings
    source: str = "<dict>"
    roughness_grid: np.ndarray | None = None

    def __repr__(self) -> str:
        ny, nx = self.terrain.z.shape
        return short_repr(self, repr(self.name), f"terrain {ny} x {nx} cells of {self.terrain.dx:g} m",
                          f"{len(self.materials)} materials",
                          "collectors " + (", ".join(c.name for c in self.collectors) or "none"))

    def summary(self):
        """The scenario at a glance (one-column table): source, terrain, materials, release and collectors
        (plan length [m]).

        Returns
        -------
        pandas.DataFrame
            Index: quantity; column ``value``.
        """
        import pandas as pd
        src = self.sources
        rows = {"source": self.source, "terrain": repr(self.terrain),
                "materials": ", ".join(m.name for m in self.materials),
                "release": (f"{len(src.points)} points" if src.points is not None else
                            f"polygon of {len(src.polygon)} vertices")}
        for c in self.collectors:
            rows[f"collector {c.name} length [m]"] = round(c.length_m, 2)
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    def collector_index(self, name: str) -> int:
        """Index of collector ``name``; a KeyError listing the collectors when there is none.

        Parameters
        ----------
        name : str
            Name of a collector or barrier.

        Returns
        -------
        int
            Its index among the scenario's collectors.
        """
        names = [c.name for c in self.collectors]
        if name not in names:
            raise KeyError(f"{self.source}: no collector named {name!r}; collectors are {names}")
        return names.index(name)


def _plan_points(value, where: str, source: str, min_points: int = 1) -> np.ndarray:
    try:
        p = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"{source}: {where} must be a list of [x, y] plan points; got {value!r}") from None
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < min_points or not np.all(np.isfinite(p)):
        raise ScenarioError(f"{source}: {where} must be a list of at least {min_points} [x, y] plan points; "
                            f"got {value!r}")
    return p


def terrain_scenario_from_dict(data: dict, source: str = "<dict>", base_dir: Path | None = None, *,
                               terrain: Terrain | None = None, crs=None) -> TerrainScenario:
    """Build and check a :class:`TerrainScenario` from a parsed TOML dictionary.

    ``terrain`` gives the DEM directly (then ``[terrain] dem`` may be left out); ``crs`` states the DEM's CRS
    when the file has none (it overrides ``[terrain] crs``).

    Parameters
    ----------
    data : dict
        The parsed scenario TOML.
    source : str, optional
        Where the dictionary came from, for error messages.
    base_dir : pathlib.Path, optional
        Directory against which relative file paths (the DEM) are resolved.
    terrain : Terrain, optional
        The DEM, given directly.
    crs : str or rasterio.crs.CRS, optional
        The DEM's coordinate reference system when the file has none.

    Returns
    -------
    TerrainScenario
        The checked scenario.
    """
    materials = parse_tables_and_materials(data, ("terrain", "materials", "sources"), ("collectors", "settings"),
                                           source)
    names = [m.name for m in materials]
    tt = data["terrain"]
    nodata_rule = _check_terrain_table(tt, source)
    base = Path(base_dir) if base_dir is not None else Path(".")
    try:
        if terrain is None:
            terrain = _read_terrain_dem(tt, base, crs, source)
        grid = _material_grid(tt, terrain, base, names, source)
        rough = read_roughness_raster(base / str(tt["roughness_raster"]), terrain) if "roughness_raster" in tt else None
    except TerrainError as exc:
        raise ScenarioError(f"{source}: [terrain]: {exc}") from None
    sources = _parse_sources(data["sources"], terrain, base, nodata_rule, source)
    collectors = _parse_collectors(data.get("collectors", []), source)
    settings = parse_settings(data.get("settings", {}), source, max_events=DEFAULT_MAX_EVENTS_3D, envelopes=False)
    return TerrainScenario(name=str(data.get("name", Path(source).stem)), description=str(data.get("description", "")),
                           terrain=terrain, materials=materials, material_grid=grid, sources=sources,
                           collectors=collectors, settings=settings, source=source, roughness_grid=rough)


def _check_terrain_table(tt: dict, source: str) -> str:
    """Check the keys of the ``[terrain]`` table, its nodata rule and that one material map at most is given.

    Parameters
    ----------
    tt : dict
        The ``[terrain]`` table.
    source : str
        Where the scenario came from, for error messages.

    Returns
    -------
    str
        The nodata rule, "leave" or "error".
    """
    _check_keys(tt, {"dem", "crs", "material", "material_raster", "material_codes", "material_polygons",
                     "material_field", "material_layer", "material_values", "nodata", "roughness_raster"},
                "terrain.", source)
    nodata_rule = tt.get("nodata", "leave")
    if nodata_rule not in ("leave", "error"):
        raise ScenarioError(f"{source}: terrain.nodata = {nodata_rule!r} must be \"leave\" (a block reaching a hole "
                            "leaves the simulation there, counted) or \"error\" (refuse a DEM whose fall lines from "
                            "the sources meet a hole)")
    if "material_raster" in tt and "material_polygons" in tt:
        raise ScenarioError(f"{source}: give terrain.material_raster or terrain.material_polygons, not both")
    return nodata_rule


def _read_terrain_dem(tt: dict, base: Path, crs, source: str) -> Terrain:
    """Read the DEM named by ``terrain.dem`` (relative to ``base``); ``crs`` overrides ``terrain.crs``.

    Parameters
    ----------
    tt : dict
        The ``[terrain]`` table.
    base : pathlib.Path
        Directory of relative paths.
    crs : str or rasterio.crs.CRS or None
        The DEM's coordinate reference system when the file has none.
    source : str
        Where the scenario came from, for error messages.

    Returns
    -------
    Terrain
        The DEM.
    """
    if "dem" not in tt:
        raise ScenarioError(f"{source}: terrain.dem (the DEM raster file) is required")
    dem_path = base / str(tt["dem"])
    if not dem_path.exists():
        raise ScenarioError(f"{source}: terrain.dem = {tt['dem']!r}: file not found ({dem_path})")
    return read_dem(dem_path, crs=crs if crs is not None else tt.get("crs"))


def _check_material_name(name, names: list, source: str) -> None:
    """Refuse a ``terrain.material`` that is not one of the scenario's materials ``names``."""
    if name not in names:
        raise ScenarioError(f"{source}: terrain.material = {name!r} is not a defined material ({', '.join(names)})")


def _material_grid(tt: dict, terrain: Terrain, base: Path, names: list, source: str) -> MaterialGrid:
    """The material of each DEM cell: from a coded raster, from polygons, or one material everywhere.

    Parameters
    ----------
    tt : dict
        The ``[terrain]`` table.
    terrain : Terrain
        The DEM.
    base : pathlib.Path
        Directory of relative paths.
    names : list of str
        The scenario's materials, in order.
    source : str
        Where the scenario came from, for error messages.

    Returns
    -------
    MaterialGrid
        Material index per cell.
    """
    if "material_raster" in tt:
        codes = _material_codes(tt, source)
        return read_material_raster(base / str(tt["material_raster"]), terrain, codes, names)
    if "material_polygons" in tt:
        return _material_polygon_grid(tt, terrain, base, names, source)
    mname = tt.get("material", names[0])
    _check_material_name(mname, names, source)
    return MaterialGrid(index=np.full(terrain.shape, names.index(mname), dtype=np.int64), names=tuple(names))


def _material_codes(tt: dict, source: str) -> dict:
    """``terrain.material_codes`` as integer raster code -> material name.

    Parameters
    ----------
    tt : dict
        The ``[terrain]`` table with ``material_raster``; its ``material_codes`` must be a table of integer keys.
    source : str
        Named in the error messages.

    Returns
    -------
    dict
        int -> str.
    """
    if "material_codes" not in tt or not isinstance(tt["material_codes"], dict):
        raise ScenarioError(f"{source}: terrain.material_raster needs terrain.material_codes = "
                            "{ code = \"material\", ... }")
    codes = {}
    for k, v in tt["material_codes"].items():
        try:
            codes[int(k)] = str(v)
        except ValueError:
            raise ScenarioError(f"{source}: terrain.material_codes key {k!r} is not an integer code") from None
    return codes


def _material_polygon_grid(tt: dict, terrain: Terrain, base: Path, names: list, source: str) -> MaterialGrid:
    """The material grid from ``terrain.material_polygons`` (see :func:`simulation.sources.read_material_polygons`).

    Parameters
    ----------
    tt, terrain, base, names, source
        As in :func:`_material_grid`; ``tt`` holds ``material_polygons`` and ``material_field``, optionally
        ``material_values``, ``material`` (where no polygon lies) and ``material_layer``.

    Returns
    -------
    MaterialGrid
        Material index per cell.
    """
    from .sources import read_material_polygons
    if "material_field" not in tt:
        raise ScenarioError(f"{source}: terrain.material_polygons needs terrain.material_field (the attribute "
                            "naming each polygon's material)")
    mv = tt.get("material_values")
    if mv is not None and not isinstance(mv, dict):
        raise ScenarioError(f"{source}: terrain.material_values must be a table {{ value = \"material\" }}")
    if "material" in tt:
        _check_material_name(tt["material"], names, source)
    poly_path = base / str(tt["material_polygons"])
    if not poly_path.exists():
        raise ScenarioError(f"{source}: terrain.material_polygons = {tt['material_polygons']!r}: file not "
                            f"found ({poly_path})")
    return read_material_polygons(poly_path, terrain, names, field_name=str(tt["material_field"]),
                                  values=None if mv is None else {str(k): str(v) for k, v in mv.items()},
                                  default=tt.get("material"), layer=tt.get("material_layer"))


def _parse_sources(sd: dict, terrain: Terrain, base: Path, nodata_rule: str, source: str) -> Sources:
    """The ``[sources]`` table: where blocks start (checked on the DEM) and their release state.

    Parameters
    ----------
    sd : dict
        The ``[sources]`` table (its keys are listed in the module docstring).
    terrain : Terrain
        The DEM the sources must lie on (off it or on a nodata hole: refused).
    base : pathlib.Path
        Directory against which ``sources.file`` is resolved.
    nodata_rule : str
        "error": refuse sources whose fall lines meet a nodata hole.
    source : str
        Where the scenario came from, for error messages.

    Returns
    -------
    Sources
        The checked sources.
    """
    _check_keys(sd, {"points", "polygon", "line", "file", "layer", "slope_above_deg", "slope_units", "height_m",
                     "mass_kg", "density_kg_m3", "speed_ms", "vz_ms", "angular_velocity_rads", "shape",
                     "velocity_ms", "radius_m", "deviation_factor"}, "sources.", source)
    geometry = [k for k in ("points", "polygon", "line", "file") if k in sd]
    slope_rule = "slope_above_deg" in sd
    if len(geometry) > 1 or (not geometry and not slope_rule):
        raise ScenarioError(f"{source}: [sources] needs exactly one of points = [[x, y], ...], polygon = [[x, y], ...],"
                            " line = [[x, y], ...] or file = \"sources.gpkg\" (points, lines or polygons), and/or "
                            f"slope_above_deg = <angle> or \"loye2009\"; got {geometry}")
    try:
        places = _source_places(sd, terrain, base, source, slope_rule)
    except TerrainError as exc:
        raise ScenarioError(str(exc)) from None
    if nodata_rule == "error":
        _check_fall_lines(terrain, places, source)
    if "mass_kg" not in sd:
        raise ScenarioError(f"{source}: sources.mass_kg is required (a number or a distribution table)")
    shape = sd.get("shape", "sphere")
    if shape not in INERTIA_FACTORS:
        raise ScenarioError(f"{source}: sources.shape = {shape!r} is not one of {sorted(INERTIA_FACTORS)}")
    height = Distribution.parse(sd.get("height_m", 1.0), "sources.height_m", source, lo=0.0, hi=1e4)
    per_point = _point_states(sd, places["points"], terrain, height, source)
    return Sources(
        **places, **per_point,
        height_m=height,
        mass_kg=(Distribution("constant", {"value": float(per_point["point_mass"].mean())})
                 if per_point["point_mass"] is not None else
                 Distribution.parse(sd["mass_kg"], "sources.mass_kg", source, lo=0.0, hi=1e9, lo_open=True)),
        density_kg_m3=_number(sd.get("density_kg_m3", DEFAULT_DENSITY_KG_M3), "sources.density_kg_m3", source,
                              lo=DENSITY_RANGE_KG_M3[0], hi=DENSITY_RANGE_KG_M3[1]),
        speed_ms=Distribution.parse(sd.get("speed_ms", 0.0), "sources.speed_ms", source, lo=0.0, hi=200),
        vz_ms=Distribution.parse(sd.get("vz_ms", 0.0), "sources.vz_ms", source, lo=-200, hi=200),
        angular_velocity_rads=Distribution.parse(sd.get("angular_velocity_rads", 0.0),
                                                 "sources.angular_velocity_rads", source, lo=-1e3, hi=1e3),
        deviation_factor=Distribution.parse(sd.get("deviation_factor", DEFAULT_DEVIATION_FACTOR),
                                            "sources.deviation_factor", source, lo=0.0, hi=100.0),
        shape=shape)


def _per_point(value, n: int, width: int, where: str, source: str, *, positive: bool) -> np.ndarray:
    """A per-point field: one entry per release point, or a single entry for all; (n,) or (n, 3) floats."""
    what = "numbers" if width == 1 else "[vx, vy, vz] triples [m/s]"
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"{source}: {where} must be {what}, one per release point or one for all; got "
                            f"{value!r}") from None
    one = a.ndim == (0 if width == 1 else 1)
    if one:
        a = np.broadcast_to(a, (n,) if width == 1 else (n, width)).copy()
    if a.shape != ((n,) if width == 1 else (n, width)):
        raise ScenarioError(f"{source}: {where} must be {what}, one per release point ({n}) or one for all; got "
                            f"shape {np.shape(value)}")
    bad = ~np.isfinite(a) if width == 1 else ~np.isfinite(a).all(axis=1)
    if positive:
        bad |= ~(a > 0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ScenarioError(f"{source}: {where}[{i}] = {a[i].tolist()} must be a finite number"
                            + (" > 0" if positive else "") + f" (release point {i + 1})")
    return a


def _point_states(sd: dict, points, terrain: Terrain, height: Distribution, source: str) -> dict:
    """Per-point release states of ``[sources]`` (``velocity_ms`` triples, a ``mass_kg`` list, ``radius_m``),
    checked before any work: one per release point (or one for all), radius > 0, and a velocity that does not
    point into the ground where a block can start on it (release height 0)."""
    out = {"point_velocity": None, "point_mass": None, "point_radius": None}
    listed_mass = isinstance(sd.get("mass_kg"), (list, tuple))
    wanted = [k for k, on in (("velocity_ms", "velocity_ms" in sd), ("mass_kg", listed_mass),
                              ("radius_m", "radius_m" in sd)) if on]
    if not wanted:
        return out
    if points is None:
        raise ScenarioError(f"{source}: sources.{wanted[0]} gives each release point its own value: it needs "
                            "sources.points (or a file of points), not a polygon, line or slope rule")
    n = len(points)
    if "velocity_ms" in sd:
        clash = [k for k in ("speed_ms", "vz_ms") if k in sd]
        if clash:
            raise ScenarioError(f"{source}: sources.velocity_ms gives the whole release velocity; remove "
                                f"sources.{clash[0]} (speed_ms and vz_ms are for releases along the fall line)")
        v = _per_point(sd["velocity_ms"], n, 3, "sources.velocity_ms", source, positive=False)
        gx, gy = terrain.gradient(points[:, 0], points[:, 1])
        normal = (-gx * v[:, 0] - gy * v[:, 1] + v[:, 2]) / np.sqrt(1 + gx ** 2 + gy ** 2)
        p = height.params
        can_touch = (height.kind == "constant" and p["value"] == 0) or p.get("low", 1.0) == 0
        into = (normal < -1e-9 * (1 + np.linalg.norm(v, axis=1))) & can_touch
        if into.any():
            i = int(np.flatnonzero(into)[0])
            raise ScenarioError(f"{source}: sources.velocity_ms[{i}] = {v[i].tolist()} m/s points into the ground at "
                                f"release point {i + 1} ({points[i, 0]:g}, {points[i, 1]:g}): its component along the "
                                f"ground's normal is {normal[i]:.3g} m/s and the block can start on the ground "
                                "(height_m 0). Check the sign of vz, or give height_m > 0 for a block thrown down")
        out["point_velocity"] = v
    if listed_mass:
        out["point_mass"] = _per_point(sd["mass_kg"], n, 1, "sources.mass_kg", source, positive=True)
    if "radius_m" in sd:
        out["point_radius"] = _per_point(sd["radius_m"], n, 1, "sources.radius_m", source, positive=True)
    return out


def _parse_collectors(tables, source: str) -> tuple:
    """The ``[[collectors]]`` tables: plan lines and barriers, with unique names.

    Parameters
    ----------
    tables : list of dict
        The ``[[collectors]]`` tables.
    source : str
        Where the scenario came from, for error messages.

    Returns
    -------
    tuple of PlanCollector
        In the order given.
    """
    collectors = tuple(_parse_collector(c, f"collectors[{i}]", source) for i, c in enumerate(tables))
    cnames = [c.name for c in collectors]
    if len(set(cnames)) != len(cnames):
        raise ScenarioError(f"{source}: collector names must be unique; got {cnames}")
    return collectors


def _parse_collector(c, where: str, source: str) -> PlanCollector:
    """One ``[[collectors]]`` table: a name, a plan line of distinct vertices and, for a barrier, its net.

    Parameters
    ----------
    c : dict
        The table, named ``where`` (e.g. ``collectors[0]``) in ``source`` by the error messages.
    where, source : str
        See ``c``.

    Returns
    -------
    PlanCollector
        The checked collector or barrier.
    """
    if not isinstance(c, dict):
        raise ScenarioError(f"{source}: {where} must be a table with name and line")
    _check_keys(c, {"name", "line", "height_m", "capacity_kj"}, f"{where}.", source)
    if "name" not in c or "line" not in c:
        raise ScenarioError(f"{source}: {where} needs a name and a line = [[x, y], ...]")
    line = _plan_points(c["line"], f"{where}.line", source, min_points=2)
    if np.any(np.hypot(*np.diff(line, axis=0).T) == 0):
        raise ScenarioError(f"{source}: {where}.line ({c['name']!r}) has two coinciding vertices")
    h = None if c.get("height_m") is None else _number(c["height_m"], f"{where}.height_m", source, lo=0.0,
                                                       lo_open=True, hi=100.0)
    cap = None if c.get("capacity_kj") is None else _number(c["capacity_kj"], f"{where}.capacity_kj", source,
                                                            lo=0.0, lo_open=True)
    if cap is not None and h is None:
        raise ScenarioError(f"{source}: {where}.height_m is required for a barrier (capacity_kj given)")
    return PlanCollector(str(c["name"]), line, h, cap)


def is_terrain_scenario_file(path) -> bool:
    """True when the scenario TOML file has a ``[terrain]`` table (a 3-D scenario); False for any other file
    (a 2-D scenario, or a file :func:`simulation.load_scenario` will report on).

    Parameters
    ----------
    path : str or pathlib.Path
        Scenario TOML file.

    Returns
    -------
    bool
        True for a 3-D scenario.
    """
    try:
        with open(path, "rb") as fh:
            return isinstance(tomllib.load(fh).get("terrain"), dict)
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return False


def _check_fall_lines(terrain, places, source):
    """``[terrain] nodata = "error"``: refuse, before any work, a DEM whose steepest-descent paths from the
    sources (every point, or 500 points drawn with a fixed seed from a polygon, lines or cells) meet a hole."""
    from .terrain import fall_line_to_nodata
    if places["points"] is not None:
        pts = places["points"]
    else:
        tmp = Sources(points=None, polygon=places["polygon"], height_m=None, mass_kg=None, density_kg_m3=0.0,
                      speed_ms=None, vz_ms=None, angular_velocity_rads=None, lines=places["lines"],
                      cells=places["cells"])
        pts = sample_sources(tmp, terrain, np.random.default_rng(0), 500)
    k, at = fall_line_to_nodata(terrain, pts)
    if k >= 0:
        raise ScenarioError(f"{source}: terrain.nodata = \"error\": the fall line from the source point "
                            f"({pts[k, 0]:.2f}, {pts[k, 1]:.2f}) reaches a nodata hole of the DEM {terrain.source} "
                            f"next to ({at[0]:.2f}, {at[1]:.2f}); fill the DEM there, or set terrain.nodata = "
                            "\"leave\" (blocks reaching a hole leave the simulation, counted in the summary)")


def _source_places(sd, terrain, base, source, slope_rule) -> dict:
    """Where the [sources] table releases blocks: points, polygon, lines or DEM cells (see :class:`Sources`), each
    checked on the DEM before any work."""
    from .sources import SlopeThreshold, loye_threshold, rasterise, read_vector_layer, source_cells
    out = {"points": None, "polygon": None, "lines": None, "cells": None, "threshold": None, "basis": ""}
    within = None
    if "points" in sd:
        out["points"] = terrain.check_points(_plan_points(sd["points"], "sources.points", source),
                                             f"{source}: sources.points")
        out["basis"] = f"{len(out['points'])} release points"
    elif "polygon" in sd:
        poly = _plan_points(sd["polygon"], "sources.polygon", source, min_points=3)
        terrain.check_points(poly, f"{source}: sources.polygon")
        out["polygon"] = poly
        out["basis"] = "uniform in the source polygon"
        if slope_rule:
            xc, yc = terrain.cell_centres()
            within = _in_polygon(poly, xc, yc)
    elif "line" in sd:
        line = _plan_points(sd["line"], "sources.line", source, min_points=2)
        terrain.check_points(line, f"{source}: sources.line")
        out["lines"] = (line,)
        out["basis"] = "uniform along the source line"
    elif "file" in sd:
        path = base / str(sd["file"])
        if not path.exists():
            raise ScenarioError(f"{source}: sources.file = {sd['file']!r}: file not found ({path})")
        vl = read_vector_layer(path, sd.get("layer"), terrain)
        kind = vl.kind
        where = f"{source}: sources.file {vl.source}"
        if kind == "point":
            pts = []
            for g in vl.geometries:
                pts += [g["coordinates"]] if g["type"] == "Point" else list(g["coordinates"])
            out["points"] = terrain.check_points(np.asarray(pts, dtype=float), where)
            out["basis"] = f"{len(pts)} release points from {vl.source}"
        elif kind == "line":
            lines = []
            for g in vl.geometries:
                parts = [g["coordinates"]] if g["type"] == "LineString" else g["coordinates"]
                for part in parts:
                    ln = np.asarray(part, dtype=float)
                    terrain.check_points(ln, where)
                    lines.append(ln)
            out["lines"] = tuple(lines)
            out["basis"] = f"uniform along {len(lines)} source lines from {vl.source}"
        else:
            within = rasterise(terrain, [(g, 1) for g in vl.geometries]).astype(bool) & np.isfinite(terrain.z)
            if not within.any():
                raise ScenarioError(f"{where}: no DEM cell centre lies inside the source polygons (are they outside "
                                    f"the DEM {terrain.source}, or smaller than a cell?)")
            if not slope_rule:
                out["cells"] = np.flatnonzero(within)
                out["basis"] = f"uniform in the {int(within.sum())} DEM cells inside the source polygons of {vl.source}"
    if slope_rule:
        rule = sd["slope_above_deg"]
        if rule == "loye2009":
            units = sd.get("slope_units", 4)
            th = loye_threshold(terrain, units)
        elif isinstance(rule, (int, float)) and not isinstance(rule, bool) and 0 < rule < 90:
            th = SlopeThreshold(float(rule), "given")
        else:
            raise ScenarioError(f"{source}: sources.slope_above_deg = {rule!r} must be an angle in (0, 90) deg or "
                                "\"loye2009\" (the Loye et al. 2009 rule)")
        if out["points"] is not None or out["lines"] is not None:
            raise ScenarioError(f"{source}: sources.slope_above_deg selects DEM cells: combine it with a polygon (or "
                                "polygons in sources.file), not with points or lines")
        cells = source_cells(terrain, th, within)
        if cells.size == 0:
            raise ScenarioError(f"{source}: no DEM cell is steeper than {th.angle_deg:.1f} deg"
                                + (" inside the source polygon(s)" if within is not None else ""))
        out.update(cells=cells, threshold=th, polygon=None,
                   basis=th.label() + (" inside the source polygon(s)" if within is not None else "")
                   + f"; {cells.size} cells")
    return out


def load_terrain_scenario(path, crs=None) -> TerrainScenario:
    """Read a 3-D scenario TOML file (a ``[terrain]`` table; see this module's docstring).

    Parameters
    ----------
    path : str or pathlib.Path
        Scenario TOML file.
    crs : str or rasterio.crs.CRS, optional
        The DEM's coordinate reference system when the file has none.

    Returns
    -------
    TerrainScenario
        The checked scenario.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"scenario file not found: {path}")
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: not valid TOML: {exc}") from exc
    return terrain_scenario_from_dict(data, source=str(path), base_dir=path.parent, crs=crs)


def _in_polygon(poly: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Even-odd rule: True for plan points inside the polygon."""
    inside = np.zeros(x.shape, dtype=bool)
    px, py = poly[:, 0], poly[:, 1]
    for k in range(len(poly)):
        xa, ya, xb, yb = px[k - 1], py[k - 1], px[k], py[k]
        cond = (ya > y) != (yb > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = xa + (y - ya) * (xb - xa) / (yb - ya)
        inside ^= cond & (x < xc)
    return inside


def source_point_index(sources: Sources, rng: np.random.Generator, n: int) -> np.ndarray:
    """Which release point each of n blocks starts from (uniform among ``sources.points``).

    Parameters
    ----------
    sources : Sources
        Sources given as points.
    rng : numpy.random.Generator
        Random generator (the one :func:`sample_sources` uses).
    n : int
        Number of blocks.

    Returns
    -------
    numpy.ndarray of int, shape (n,)
    """
    return rng.integers(0, len(sources.points), n)


def sample_sources(sources: Sources, terrain: Terrain, rng: np.random.Generator, n: int) -> np.ndarray:
    """n plan release points (n, 2): uniform among ``points``, or uniform inside ``polygon`` (rejection
    sampling in its bounding box; points on nodata holes are rejected too).

    Parameters
    ----------
    sources : Sources
        The release sources (points, lines or polygon).
    terrain : Terrain
        The DEM.
    rng : numpy.random.Generator
        Random generator.
    n : int
        Number of release points.

    Returns
    -------
    numpy.ndarray
        Plan release points (x, y) [m], shape (n, 2).
    """
    if sources.points is not None:
        return sources.points[source_point_index(sources, rng, n)]
    if sources.lines is not None:
        segs = np.concatenate([np.stack([ln[:-1], ln[1:]], axis=1) for ln in sources.lines])
        length = np.hypot(*(segs[:, 1] - segs[:, 0]).T)
        k = np.searchsorted(np.cumsum(length), rng.uniform(0, length.sum(), n), side="right").clip(0, len(segs) - 1)
        f = rng.uniform(size=n)[:, None]
        return segs[k, 0] + f * (segs[k, 1] - segs[k, 0])
    if sources.cells is not None:
        ny, nx = terrain.shape
        x0, y0, x1, y1 = terrain.bounds
        out = np.empty((0, 2))
        for _ in range(1000):
            m = max(2 * (n - len(out)), 64)
            c = sources.cells[rng.integers(0, sources.cells.size, m)]
            i, j = np.divmod(c, nx)
            cand = np.column_stack([terrain.x0 + (j + rng.uniform(-0.5, 0.5, m)) * terrain.dx,
                                    terrain.y0 + (i + rng.uniform(-0.5, 0.5, m)) * terrain.dy])
            cand[:, 0] = cand[:, 0].clip(x0, x1)     # edge cells: the domain ends at their centres
            cand[:, 1] = cand[:, 1].clip(y0, y1)
            out = np.vstack([out, cand[terrain.contains(cand[:, 0], cand[:, 1])]])
            if len(out) >= n:
                return out[:n]
        raise ScenarioError("sources: could not place release points in the source cells (all on nodata?)")
    poly = sources.polygon
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    out = np.empty((0, 2))
    for _ in range(1000):
        m = max(2 * (n - len(out)), 64)
        cand = rng.uniform(lo, hi, size=(m, 2))
        ok = _in_polygon(poly, cand[:, 0], cand[:, 1]) & terrain.contains(cand[:, 0], cand[:, 1])
        out = np.vstack([out, cand[ok]])
        if len(out) >= n:
            return out[:n]
    raise ScenarioError(f"sources.polygon: could not place {n} release points on the terrain inside the polygon "
                        "(is it on nodata, or degenerate?)")


def fall_line(terrain: Terrain, x, y) -> tuple[np.ndarray, np.ndarray]:
    """Unit horizontal direction of steepest descent at plan points (+x where the ground is flat).

    Parameters
    ----------
    terrain : Terrain
        The DEM.
    x, y : array_like
        Plan coordinates [m].

    Returns
    -------
    ux, uy : numpy.ndarray
        Components of the unit horizontal direction of steepest descent [-].
    """
    gx, gy = terrain.gradient(x, y)
    n = np.hypot(gx, gy)
    flat = ~(n > 1e-12)
    ux = np.where(flat, 1.0, -gx / np.where(flat, 1.0, n))
    uy = np.where(flat, 0.0, -gy / np.where(flat, 1.0, n))
    return ux, uy


def _lipschitz(z: np.ndarray, dx: float, dy: float) -> float:
    """Upper bound of |grad z| on the bilinear surface: within a cell dz/dx lies between its two x-edge
    differences and dz/dy between its y-edge ones, so sqrt(max|dz/dx|^2 + max|dz/dy|^2) bounds the slope."""
    gx = np.nanmax(np.abs(np.diff(z, axis=1))) / dx
    gy = np.nanmax(np.abs(np.diff(z, axis=0))) / dy
    return float(math.hypot(gx, gy)) * (1.0 + 1e-9) + 1e-12
