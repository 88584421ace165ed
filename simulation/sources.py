"""Rock fall sources and materials from GIS data on a DEM: vector layers, polygon material maps, and the
source-area rule from the slope-angle distribution (Loye et al. 2009).

Vector layers (GeoPackage, shapefile, any OGR format) are read with pyogrio as WKB and decoded here (points,
lines, polygons and their multi- forms, 2-D); polygons are rasterised onto the DEM's grid with GDAL
(``rasterio.features.rasterize``): a cell belongs to a polygon when its centre lies inside it (the cell's
material is then the one at the point the kernel samples), later features over earlier ones where they
overlap.

CRS (stated, not silent): a layer whose CRS differs from the DEM's is refused with both named (reproject it
first, e.g. ``ogr2ogr -t_srs EPSG:2056 out.gpkg in.gpkg``: no reprojection library is a dependency); a layer
without a CRS is taken to be in the DEM's CRS, as a material raster without one is.

Source areas from slope angle
-----------------------------
Loye, Jaboyedoff & Pedrazzini (2009, Nat. Hazards Earth Syst. Sci. 9: 1643-1653) decompose the frequency
distribution of the DEM's slope angles (SAD) into Gaussian distributions, one per morphological unit
(plains, footslopes, steep slopes, rock cliffs), and take as potential sources the cells steeper than the
angle where the "rock cliffs" Gaussian becomes dominant over the "steep slopes" one (abstract and section 3
of the paper).  :func:`loye_threshold` fits the mixture (expectation-maximisation on the 0.1 deg histogram
of the cell slope angles, components started at evenly spaced quantiles) and returns that angle between the
two steepest components' means.  The number of units (4 in the paper) and the resulting threshold are
reported with the run (:class:`SlopeThreshold`); the threshold can also be given directly as a number, the
explicit, labelled parameter ``sources.slope_above_deg``.
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .terrain import MaterialGrid, Terrain, TerrainError

LOYE_2009 = ("Loye, A., Jaboyedoff, M. & Pedrazzini, A. (2009). Identification of potential rockfall source areas "
             "at a regional scale using a DEM-based geomorphometric analysis. Nat. Hazards Earth Syst. Sci. 9: "
             "1643-1653, doi:10.5194/nhess-9-1643-2009")


# ---- vector layers ------------------------------------------------------------------------------------------
def _wkb_geometry(buf: bytes, pos: int = 0):
    """Decode one 2-D WKB geometry at ``pos``: (GeoJSON-like dict, next position)."""
    endian = "<" if buf[pos] == 1 else ">"
    gtype = struct.unpack_from(endian + "I", buf, pos + 1)[0] % 1000
    pos += 5

    def points(p):
        n = struct.unpack_from(endian + "I", buf, p)[0]
        xy = np.frombuffer(buf, dtype=endian + "f8", count=2 * n, offset=p + 4).reshape(n, 2)
        return xy.tolist(), p + 4 + 16 * n

    if gtype == 1:
        x, y = struct.unpack_from(endian + "2d", buf, pos)
        return {"type": "Point", "coordinates": [x, y]}, pos + 16
    if gtype == 2:
        xy, pos = points(pos)
        return {"type": "LineString", "coordinates": xy}, pos
    if gtype == 3:
        n = struct.unpack_from(endian + "I", buf, pos)[0]
        pos += 4
        rings = []
        for _ in range(n):
            xy, pos = points(pos)
            rings.append(xy)
        return {"type": "Polygon", "coordinates": rings}, pos
    if gtype in (4, 5, 6, 7):
        n = struct.unpack_from(endian + "I", buf, pos)[0]
        pos += 4
        parts = []
        for _ in range(n):
            g, pos = _wkb_geometry(buf, pos)
            parts.append(g)
        if gtype == 7:
            return {"type": "GeometryCollection", "geometries": parts}, pos
        kind = {4: "MultiPoint", 5: "MultiLineString", 6: "MultiPolygon"}[gtype]
        return {"type": kind, "coordinates": [p["coordinates"] for p in parts]}, pos
    raise TerrainError(f"WKB geometry type {gtype} is not supported (points, lines, polygons and their multi- forms)")


def _simple_kind(geom) -> str:
    t = geom["type"]
    return {"Point": "point", "MultiPoint": "point", "LineString": "line", "MultiLineString": "line",
            "Polygon": "polygon", "MultiPolygon": "polygon"}.get(t, t)


@dataclass(frozen=True)
class VectorLayer:
    """Features of one vector layer: ``geometries`` (GeoJSON-like dicts, 2-D), ``fields`` (name -> array),
    ``crs`` (as read, or None) and ``source`` (file and layer, for messages)."""

    geometries: list = field(repr=False)
    fields: dict = field(repr=False)
    crs: object
    source: str

    @property
    def kind(self) -> str:
        """"point", "line" or "polygon" when every feature is of that kind (multi- forms included)."""
        kinds = {_simple_kind(g) for g in self.geometries}
        if len(kinds) != 1:
            raise TerrainError(f"{self.source}: mixes geometry kinds {sorted(kinds)}; give points, lines or "
                               "polygons in one layer")
        return kinds.pop()


def read_vector_layer(path, layer=None, terrain: Terrain | None = None) -> VectorLayer:
    """Read a vector layer with pyogrio (GeoPackage, shapefile, GeoJSON, ...); with ``terrain``, refuse a layer in
    another CRS than the DEM's (see the module docstring).

    Parameters
    ----------
    path : str or pathlib.Path
        Vector file.
    layer : str or int, optional
        Layer name or index (default: the first layer).
    terrain : Terrain, optional
        The DEM whose CRS the layer must share.

    Returns
    -------
    VectorLayer
        The layer's geometries [m], fields and CRS.
    """
    from pyogrio.errors import DataSourceError, DataLayerError
    from pyogrio.raw import read
    path = Path(path)
    src = f"{path}" + (f" (layer {layer!r})" if layer is not None else "")
    if not path.exists():
        raise FileNotFoundError(f"vector file not found: {path}")
    try:
        meta, _, geoms, values = read(path, layer=layer, force_2d=True)
    except (DataSourceError, DataLayerError) as exc:
        raise TerrainError(f"{src}: not a vector layer OGR can read ({exc})") from None
    if geoms is None or len(geoms) == 0:
        raise TerrainError(f"{src}: the layer has no features")
    decoded = []
    for i, g in enumerate(geoms):
        if g is None:
            raise TerrainError(f"{src}: feature {i} has no geometry")
        decoded.append(_wkb_geometry(bytes(g))[0])
    crs = meta.get("crs")
    if terrain is not None and crs is not None and terrain.crs is not None:
        from rasterio.crs import CRS
        if CRS.from_user_input(crs) != terrain.crs:
            raise TerrainError(f"{src}: the layer's CRS {crs} is not the DEM's {terrain.crs.to_string()} "
                               f"({terrain.source}); reproject the layer first (e.g. ogr2ogr -t_srs "
                               f"{terrain.crs.to_string()} out.gpkg {path.name})")
    return VectorLayer(decoded, dict(zip(meta["fields"], values)), crs, src)


def rasterise(terrain: Terrain, shapes) -> np.ndarray:
    """Burn (geometry, integer value) pairs onto the DEM's grid (a cell takes the value of the last feature
    whose polygon contains its centre; 0 elsewhere); the result in the terrain's internal order.

    Parameters
    ----------
    terrain : Terrain
        The DEM whose grid is burnt onto.
    shapes : iterable of (dict, int)
        (GeoJSON-like polygon geometry, integer value) pairs.

    Returns
    -------
    numpy.ndarray of int64
        Values on the grid, shape (ny, nx), in the terrain's internal order.
    """
    from rasterio.features import rasterize
    ny, nx = terrain.shape
    shapes = list(shapes)
    if not shapes:
        return np.zeros((ny, nx), dtype=np.int64)
    out = rasterize(shapes, out_shape=(ny, nx), transform=terrain.transform, fill=0, dtype="int32",
                    all_touched=False)
    return (out if terrain.south_up else out[::-1]).astype(np.int64)


def read_material_polygons(path, terrain: Terrain, material_names, *, field_name: str, values: dict | None = None,
                           default: str | None = None, layer=None) -> MaterialGrid:
    """A material map from polygons (GeoPackage, shapefile ...), rasterised onto the DEM's grid.

    Parameters
    ----------
    path : str or Path
        The vector file.
    terrain : Terrain
        The DEM (its grid, transform and CRS).
    material_names : sequence of str
        The scenario's materials.
    field_name : str
        The attribute holding each polygon's class.
    values : dict, optional
        Attribute value -> material name; default: the attribute values are material names.
    default : str, optional
        Material of cells no polygon covers; None: every cell on the DEM (not nodata) must be covered (an error
        names an uncovered cell).
    layer : str or int, optional
        The layer (default the first).

    Returns
    -------
    MaterialGrid
    """
    names = list(material_names)
    vl = read_vector_layer(path, layer, terrain)
    if vl.kind != "polygon":
        raise TerrainError(f"{vl.source}: a material map must hold polygons; it holds {vl.kind}s")
    if field_name not in vl.fields:
        raise TerrainError(f"{vl.source}: no attribute {field_name!r}; attributes are {sorted(vl.fields)}")
    shapes = []
    for i, (g, v) in enumerate(zip(vl.geometries, vl.fields[field_name])):
        key = v.item() if hasattr(v, "item") else v
        name = str(key) if values is None else values.get(str(key), values.get(key))
        if name is None or name not in names:
            what = f"maps to {name!r}, which" if values is not None and name is not None else "is not mapped to a " \
                "material or"
            raise TerrainError(f"{vl.source}: feature {i} has {field_name} = {key!r}, which {what} is not a "
                               f"material of the scenario ({', '.join(names)})")
        shapes.append((g, names.index(name) + 1))
    burnt = rasterise(terrain, shapes)
    holes = burnt == 0
    if default is not None:
        if default not in names:
            raise TerrainError(f"default material {default!r} is not a material of the scenario ({', '.join(names)})")
        burnt[holes] = names.index(default) + 1
    else:
        bad = holes & np.isfinite(terrain.z)
        if bad.any():
            i, j = np.argwhere(bad)[0]
            raise TerrainError(f"{vl.source}: the cell centred at ({terrain.x0 + j * terrain.dx:.2f}, "
                               f"{terrain.y0 + i * terrain.dy:.2f}) lies in no polygon and no default material is "
                               "given ([terrain] material = \"...\")")
    return MaterialGrid(index=burnt - 1, names=tuple(names))


# ---- sources from slope angle (Loye et al. 2009) -------------------------------------------------------------
@dataclass(frozen=True)
class SlopeThreshold:
    """A source-area threshold on the slope angle [deg] and how it was set.

    ``angle_deg`` the threshold; ``basis`` "given" or "Loye et al. (2009)"; with the Loye rule, the mixture's
    ``means_deg``, ``stds_deg`` and ``weights`` (ascending means) and ``n_units``.
    """

    angle_deg: float
    basis: str
    means_deg: tuple = ()
    stds_deg: tuple = ()
    weights: tuple = ()
    n_units: int = 0

    def label(self) -> str:
        """One line for outputs: the threshold and where it came from (an explicit parameter or the rule).

        Returns
        -------
        str
            The threshold [deg] and its origin.
        """
        if self.basis == "given":
            return f"source cells: slope angle > {self.angle_deg:.1f} deg (sources.slope_above_deg, given)"
        units = ", ".join(f"{m:.1f}+-{s:.1f} deg ({w:.0%})" for m, s, w in zip(self.means_deg, self.stds_deg,
                                                                             self.weights))
        return (f"source cells: slope angle > {self.angle_deg:.1f} deg, where the steepest of {self.n_units} "
                f"Gaussian units of the DEM's slope-angle distribution becomes dominant over the next "
                f"(Loye et al. 2009; units {units})")

    def summary(self):
        """One row per Gaussian unit (mean, standard deviation, weight), the threshold in the attrs.

        Returns
        -------
        pandas.DataFrame
            Columns ``mean_deg``, ``std_deg`` [deg] and ``weight`` [-], one row per unit.
        """
        import pandas as pd
        df = pd.DataFrame({"mean_deg": self.means_deg, "std_deg": self.stds_deg, "weight": self.weights})
        df.attrs["threshold_deg"] = self.angle_deg
        return df


def gaussian_mixture_1d(values, n_units: int = 4, *, bin_deg: float = 0.1, iterations: int = 500, tol: float = 1e-10):
    """Fit a mixture of ``n_units`` Gaussians to angles [deg] by expectation-maximisation on their histogram
    (bins of ``bin_deg``), started at evenly spaced quantiles; returns (means, stds, weights), ascending means.

    Parameters
    ----------
    values : array_like
        Slope angles [deg].
    n_units : int, optional
        Number of Gaussian units.
    bin_deg : float, optional
        Histogram bin width [deg].
    iterations : int, optional
        Largest number of EM iterations.
    tol : float, optional
        Convergence tolerance on the log-likelihood [-].

    Returns
    -------
    means, stds : numpy.ndarray
        Means and standard deviations of the units [deg], ascending means.
    weights : numpy.ndarray
        Weights of the units [-].
    """
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size < 20 * n_units:
        raise TerrainError(f"{v.size} slope angles are too few to fit {n_units} Gaussian units")
    edges = np.arange(0.0, 90.0 + bin_deg, bin_deg)
    count, _ = np.histogram(v, edges)
    x = 0.5 * (edges[:-1] + edges[1:])
    keep = count > 0
    x, c = x[keep], count[keep].astype(float)
    mu = np.quantile(v, (np.arange(n_units) + 0.5) / n_units)
    sd = np.full(n_units, max(np.std(v) / n_units, bin_deg))
    w = np.full(n_units, 1.0 / n_units)
    last = -np.inf
    for _ in range(iterations):
        dens = w[:, None] * np.exp(-0.5 * ((x[None, :] - mu[:, None]) / sd[:, None]) ** 2) / (sd[:, None]
                                                                                            * math.sqrt(2 * math.pi))
        tot = np.maximum(dens.sum(axis=0), 1e-300)
        ll = float(np.sum(c * np.log(tot)))
        r = dens / tot * c[None, :]
        nk = np.maximum(r.sum(axis=1), 1e-12)
        w = nk / nk.sum()
        mu = (r * x[None, :]).sum(axis=1) / nk
        sd = np.sqrt(np.maximum((r * (x[None, :] - mu[:, None]) ** 2).sum(axis=1) / nk, bin_deg ** 2 / 12 + 1e-6))
        if ll - last < tol * abs(ll):
            break
        last = ll
    o = np.argsort(mu)
    return mu[o], sd[o], w[o]


def _dominance_angle(m1, s1, w1, m2, s2, w2) -> float:
    """The angle between m1 < m2 where w2 N(m2, s2) rises above w1 N(m1, s1) (a quadratic's root); NaN if none."""
    a = 1 / (2 * s1 ** 2) - 1 / (2 * s2 ** 2)
    b = m2 / s2 ** 2 - m1 / s1 ** 2
    c = m1 ** 2 / (2 * s1 ** 2) - m2 ** 2 / (2 * s2 ** 2) + math.log((w2 * s1) / (w1 * s2))
    roots = [-c / b] if abs(a) < 1e-15 else (
        [(-b + sg * math.sqrt(b * b - 4 * a * c)) / (2 * a) for sg in (1, -1)] if b * b - 4 * a * c >= 0 else [])
    inside = [r for r in roots if m1 <= r <= m2]
    return min(inside) if inside else math.nan


def loye_threshold(terrain: Terrain, n_units: int = 4) -> SlopeThreshold:
    """The source-area slope threshold of Loye et al. (2009) on this DEM (see the module docstring).

    Parameters
    ----------
    terrain : Terrain
        The DEM; its cell slope angles (:meth:`Terrain.slope_deg`) form the distribution.
    n_units : int
        Gaussian units in the decomposition (4 in the paper: plains, footslopes, steep slopes, rock cliffs).

    Returns
    -------
    SlopeThreshold
        The angle [deg] between the two steepest units' means where the steepest becomes dominant.

    References
    ----------
    Loye, Jaboyedoff & Pedrazzini (2009), Nat. Hazards Earth Syst. Sci. 9: 1643-1653 (abstract; section 3).
    """
    if isinstance(n_units, bool) or not isinstance(n_units, (int, np.integer)) or not 2 <= n_units <= 8:
        raise TerrainError(f"n_units = {n_units!r} must be a whole number of Gaussian units in 2-8 (4 in Loye et al.)")
    angles = terrain.slope_deg()
    mu, sd, w = gaussian_mixture_1d(angles[np.isfinite(angles)], int(n_units))
    t = _dominance_angle(mu[-2], sd[-2], w[-2], mu[-1], sd[-1], w[-1])
    if not math.isfinite(t):
        raise TerrainError(f"{terrain.source}: the steepest of {n_units} Gaussian units of the slope-angle "
                           f"distribution (mean {mu[-1]:.1f} deg) never becomes dominant over the next "
                           f"({mu[-2]:.1f} deg): no Loye et al. (2009) threshold; give sources.slope_above_deg")
    return SlopeThreshold(float(t), "Loye et al. (2009)", tuple(map(float, mu)), tuple(map(float, sd)),
                          tuple(map(float, w)), int(n_units))


def source_cells(terrain: Terrain, threshold: SlopeThreshold, within=None) -> np.ndarray:
    """Flat indices (internal order) of the DEM cells steeper than the threshold (and, with ``within``, a
    boolean (ny, nx) mask, inside it).

    Parameters
    ----------
    terrain : Terrain
        The DEM.
    threshold : SlopeThreshold
        The slope-angle threshold.
    within : numpy.ndarray of bool, optional
        (ny, nx) mask the cells must lie inside.

    Returns
    -------
    numpy.ndarray of int
        Flat cell indices in the terrain's internal order.
    """
    mask = np.nan_to_num(terrain.slope_deg(), nan=-1.0) > threshold.angle_deg
    if within is not None:
        mask &= within
    return np.flatnonzero(mask)


__all__ = ["LOYE_2009", "SlopeThreshold", "VectorLayer", "gaussian_mixture_1d", "loye_threshold",
           "rasterise", "read_material_polygons", "read_vector_layer", "source_cells"]
