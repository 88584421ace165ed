"""Road centrelines and section lines for GIS: chainage <-> coordinates, GeoPackage/GeoJSON in and out.

A corridor's sections are chainage intervals along a road.  :class:`Centreline` links chainage to map
coordinates (a projected CRS, metres): :meth:`Centreline.point_at` gives the point at a chainage,
:meth:`Centreline.chainage_at` the chainage of the nearest point of the line to a coordinate, and
:meth:`Centreline.cut` the line of a chainage interval (what a section's geometry is).

Chainage along the line is its length from the first vertex plus ``chainage_start_m``, unless calibration
points are given: points with a known chainage (e.g. a road register's metre values, such as NVDB's
``veglenkeMeter``), which pin the chainage at their nearest position on the line; between them chainage is
linear in the distance along the line, beyond the first and last one it runs one metre per metre.  This is the
linear referencing of a "calibrated route" (the road's own metre system where the drawn line is
generalised, so that the register's metre values are kept exactly at the calibration points).

Files are read and written with pyogrio (GDAL): GeoPackage, GeoJSON or shapefile in, GeoPackage out.
Geometries travel as WKB, parsed and written here with numpy (2-D LineString / MultiLineString / Point), so no
geometry library is needed.  Coordinates must be in a projected CRS in metres; a geographic CRS (degrees) is
refused with the reason, because lengths and chainages would be in degrees.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..core.validation import RiskrfError

#: CRS names that are geographic (degrees): refused for chainage work.
GEOGRAPHIC_CRS = {"EPSG:4326", "EPSG:4258", "EPSG:4269", "EPSG:4230", "EPSG:4283", "EPSG:4167", "OGC:CRS84",
                  "CRS84"}


class GISError(RiskrfError, ValueError):
    """A centreline or calibration file is unusable; the message names the file, layer, feature and value."""


# ---------------------------------------------------------------------------------------------------------
# WKB (ISO and EWKB flags; 2-D, Z and M dimensions read, XY kept)
# ---------------------------------------------------------------------------------------------------------
def _wkb_geoms(buf: bytes, where: str):
    """Parts of a WKB geometry as (kind, xy array) tuples: kind "point" or "line"."""
    out = []

    def geom(off):
        order = "<" if buf[off] == 1 else ">"
        (code,) = struct.unpack_from(order + "I", buf, off + 1)
        off += 5
        has_z = bool(code & 0x80000000) or (code % 10000) // 1000 in (1, 3)
        has_m = bool(code & 0x40000000) or (code % 10000) // 1000 in (2, 3)
        if code & 0x20000000:                     # EWKB SRID
            off += 4
        base = (code & 0x0FFFFFFF) % 1000
        dims = 2 + has_z + has_m
        if base == 1:
            xy = np.frombuffer(buf, order + "f8", dims, off).reshape(1, dims)[:, :2]
            out.append(("point", xy.astype(float)))
            return off + 8 * dims
        if base == 2:
            (n,) = struct.unpack_from(order + "I", buf, off)
            xy = np.frombuffer(buf, order + "f8", n * dims, off + 4).reshape(n, dims)[:, :2]
            out.append(("line", xy.astype(float)))
            return off + 4 + 8 * n * dims
        if base in (4, 5, 7):                     # multipoint, multilinestring, collection
            (n,) = struct.unpack_from(order + "I", buf, off)
            off += 4
            for _ in range(n):
                off = geom(off)
            return off
        raise GISError(f"{where}: geometry type code {code} is not a point or line")

    geom(0)
    return out


def linestring_wkb(xy) -> bytes:
    """ISO WKB (little endian) of a 2-D LineString with vertices ``xy`` (n x 2, metres).

    Parameters
    ----------
    xy : array_like
        Vertices (n, 2) [m].

    Returns
    -------
    bytes

    References
    ----------
    OGC 06-103r4, OpenGIS Implementation Standard for Geographic information - Simple feature access - Part 1,
    section 8.2 (well-known binary).
    """
    xy = np.ascontiguousarray(np.asarray(xy, dtype="<f8").reshape(-1, 2))
    return struct.pack("<BII", 1, 2, len(xy)) + xy.tobytes()


def _read_layer(path: Path, layer, what: str):
    import pyogrio
    from pyogrio.raw import read
    path = Path(path)
    if not path.exists():
        raise GISError(f"{what} not found: {path}")
    try:
        meta, _, geoms, fields = read(path, layer=layer)
    except Exception as exc:                              # noqa: BLE001 (GDAL's own message, with the file)
        layers = ""
        try:
            layers = f"; layers: {[str(x[0]) for x in pyogrio.list_layers(path)]}"
        except Exception:                                 # noqa: BLE001
            pass
        raise GISError(f"{what} {path} (layer {layer!r}): {exc}{layers}") from None
    crs = meta.get("crs")
    where = f"{what} {path} (layer {layer or 'first'})"
    if not crs:
        raise GISError(f"{where}: no CRS; give the file a projected CRS in metres (e.g. EPSG:25833)")
    if str(crs).upper() in GEOGRAPHIC_CRS:
        raise GISError(f"{where}: CRS {crs} is geographic (degrees); chainages and lengths need a projected CRS in "
                       "metres: reproject the file (e.g. to the UTM zone of the road)")
    table = pd.DataFrame({name: values for name, values in zip(meta["fields"], fields)})
    return str(crs), geoms, table, where


# ---------------------------------------------------------------------------------------------------------
# centreline
# ---------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Centreline:
    """A road centreline in a projected CRS with its chainage [m].

    ``xy``: vertices (n x 2, metres); ``distance_m``: distance along the line at each vertex (0 at the first);
    ``calibration``: (distance along the line [m], chainage [m]) pairs, increasing in both, that define chainage
    (:func:`numpy.interp` between them, one metre per metre beyond them).
    """

    xy: np.ndarray = field(repr=False)
    crs: str
    calibration: tuple = field(repr=False, default=((0.0,), (0.0,)))
    source: str = ""
    distance_m: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        # distance along the line at each vertex [m] (0 at the first vertex), computed once
        object.__setattr__(self, "distance_m", np.r_[0.0, np.cumsum(np.hypot(*np.diff(self.xy, axis=0).T))])

    @property
    def length_m(self) -> float:
        """Length of the drawn line [m]."""
        return float(self.distance_m[-1])

    @property
    def chainage_range_m(self) -> tuple[float, float]:
        """Chainage of the first and last vertex [m]."""
        c = self._chainage(np.array([0.0, self.length_m]))
        return float(c[0]), float(c[1])

    def _chainage(self, s):
        ds, dc = (np.asarray(a, dtype=float) for a in self.calibration)
        s = np.asarray(s, dtype=float)
        c = np.interp(s, ds, dc)
        return np.where(s < ds[0], dc[0] + (s - ds[0]), np.where(s > ds[-1], dc[-1] + (s - ds[-1]), c))

    def _distance(self, chainage):
        ds, dc = (np.asarray(a, dtype=float) for a in self.calibration)
        c = np.asarray(chainage, dtype=float)
        s = np.interp(c, dc, ds)
        return np.where(c < dc[0], ds[0] + (c - dc[0]), np.where(c > dc[-1], ds[-1] + (c - dc[-1]), s))

    def point_at(self, chainage):
        """Coordinates (x, y) [m] of the points at ``chainage`` [m] (scalar or array); outside the line: an error.

        Parameters
        ----------
        chainage : float or array_like
            Chainage [m].

        Returns
        -------
        tuple of numpy.ndarray
            (x, y) [m].
        """
        c = np.atleast_1d(np.asarray(chainage, dtype=float))
        lo, hi = self.chainage_range_m
        bad = (c < lo - 1e-6) | (c > hi + 1e-6) | ~np.isfinite(c)
        if bad.any():
            raise GISError(f"{self.source}: chainage {c[bad][0]:g} m lies outside the centreline ({lo:g} to {hi:g} m)")
        s = np.clip(self._distance(c), 0.0, self.length_m)
        d = self.distance_m
        i = np.clip(np.searchsorted(d, s, side="right") - 1, 0, len(d) - 2)
        seg = d[i + 1] - d[i]
        t = np.where(seg > 0, (s - d[i]) / np.where(seg > 0, seg, 1.0), 0.0)
        xy = self.xy[i] + t[:, None] * (self.xy[i + 1] - self.xy[i])
        return (xy[0, 0], xy[0, 1]) if np.ndim(chainage) == 0 else (xy[:, 0], xy[:, 1])

    def chainage_at(self, x, y):
        """Chainage [m] of the nearest point of the line to (x, y) [m], and the offset from the line [m].

        Scalars or arrays; each point is projected onto every segment (O(points x segments)).

        Parameters
        ----------
        x, y : float or array_like
            Plan coordinates [m].

        Returns
        -------
        tuple of numpy.ndarray
            (chainage [m], offset [m]).
        """
        p = np.column_stack([np.atleast_1d(x), np.atleast_1d(y)]).astype(float)
        a, b = self.xy[:-1], self.xy[1:]
        ab = b - a
        l2 = np.einsum("ij,ij->i", ab, ab)
        t = np.clip(np.einsum("kij,ij->ki", p[:, None, :] - a[None], ab) / np.where(l2 > 0, l2, 1.0), 0.0, 1.0)
        near = a[None] + t[..., None] * ab[None]
        dist = np.hypot(*(p[:, None, :] - near).transpose(2, 0, 1))
        k = np.argmin(dist, axis=1)
        rows = np.arange(len(p))
        s = self.distance_m[k] + t[rows, k] * np.sqrt(l2[k])
        c, off = self._chainage(s), dist[rows, k]
        return (float(c[0]), float(off[0])) if np.ndim(x) == 0 else (c, off)

    def cut(self, chainage_from_m: float, chainage_to_m: float) -> np.ndarray:
        """Vertices (k x 2) [m] of the line from ``chainage_from_m`` to ``chainage_to_m`` (the section's geometry).

        Parameters
        ----------
        chainage_from_m, chainage_to_m : float
            Start and end chainage [m].

        Returns
        -------
        numpy.ndarray
            (k, 2) vertices [m].
        """
        if not chainage_to_m > chainage_from_m:
            raise GISError(f"chainage_to = {chainage_to_m:g} must exceed chainage_from = {chainage_from_m:g}")
        x0, y0 = self.point_at(np.array([chainage_from_m, chainage_to_m]))
        s0, s1 = self._distance(np.array([chainage_from_m, chainage_to_m]))
        d = self.distance_m
        i0, i1 = np.searchsorted(d, s0, side="right"), np.searchsorted(d, s1, side="left")   # vertices inside
        return np.vstack([[x0[0], y0[0]], self.xy[i0:i1], [x0[1], y0[1]]])

    def cuts(self, chainage_from_m, chainage_to_m) -> list:
        """:meth:`cut` for many intervals at once (arrays of equal length): a list of vertex arrays, O(intervals
        x log vertices) plus the vertices returned.

        Parameters
        ----------
        chainage_from_m, chainage_to_m : array_like
            Start and end chainages [m], of equal length.

        Returns
        -------
        list of numpy.ndarray
            One (k, 2) vertex array [m] per interval.
        """
        c0, c1 = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (chainage_from_m, chainage_to_m))
        if c0.shape != c1.shape:
            raise ValueError(f"{c0.size} start chainages for {c1.size} end chainages")
        if np.any(~(c1 > c0)):
            i = int(np.flatnonzero(~(c1 > c0))[0])
            raise GISError(f"chainage_to = {c1[i]:g} must exceed chainage_from = {c0[i]:g}")
        x0, y0 = self.point_at(c0)
        x1, y1 = self.point_at(c1)
        d = self.distance_m
        i0 = np.searchsorted(d, self._distance(c0), side="right")
        i1 = np.searchsorted(d, self._distance(c1), side="left")
        return [np.vstack([[a, b], self.xy[j:k], [e, f]]) for a, b, j, k, e, f in zip(x0, y0, i0, i1, x1, y1)]

    def summary(self) -> pd.DataFrame:
        """One row: CRS, vertices, drawn length [m], chainage range [m], calibration points, source.

        Returns
        -------
        pandas.DataFrame
        """
        lo, hi = self.chainage_range_m
        return pd.DataFrame([{"crs": self.crs, "vertices": len(self.xy), "length_m": self.length_m,
                              "chainage_from_m": lo, "chainage_to_m": hi,
                              "calibration_points": len(self.calibration[0]), "source": self.source}])


def centreline_from_vertices(xy, *, crs: str, chainage_start_m: float = 0.0, calibration=None,
                             source: str = "") -> Centreline:
    """A :class:`Centreline` from vertices ``xy`` (n x 2, metres, n >= 2).

    ``calibration``: optional (chainage [m], x [m], y [m]) rows: points of known chainage, projected onto the
    line; their distances along the line and chainages must both increase.  Without it chainage is
    ``chainage_start_m`` + distance along the line.

    Parameters
    ----------
    xy : array_like
        Vertices (n, 2) [m].
    crs : str
        Projected coordinate reference system (metres).
    chainage_start_m : float
        Chainage of the first vertex [m].
    calibration : array_like, optional
        (chainage [m], x [m], y [m]) rows.
    source : str
        Name used in messages.

    Returns
    -------
    Centreline
    """
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    where = source or "centreline"
    if len(xy) < 2 or not np.isfinite(xy).all():
        raise GISError(f"{where}: a centreline needs at least two finite vertices; got {len(xy)}")
    keep = np.r_[True, np.any(np.diff(xy, axis=0) != 0, axis=1)]          # repeated vertices carry nothing
    xy = xy[keep]
    if len(xy) < 2:
        raise GISError(f"{where}: the centreline has zero length")
    line = Centreline(xy=xy, crs=crs, calibration=((0.0,), (float(chainage_start_m),)), source=where)
    if calibration is None:
        return line
    cal = np.asarray(calibration, dtype=float).reshape(-1, 3)
    probe = Centreline(xy=xy, crs=crs, source=where)             # chainage = distance: projection gives distance
    dist, offset = probe.chainage_at(cal[:, 1], cal[:, 2])
    order = np.argsort(cal[:, 0], kind="stable")
    c_sorted, s_sorted = cal[order, 0], np.asarray(dist)[order]
    if np.any(np.diff(c_sorted) <= 0) or np.any(np.diff(s_sorted) <= 0):
        i = int(np.flatnonzero((np.diff(c_sorted) <= 0) | (np.diff(s_sorted) <= 0))[0]) + 1
        raise GISError(f"{where}: calibration point of chainage {c_sorted[i]:g} m lies at {s_sorted[i]:.1f} m along "
                       f"the line, not after the previous one (chainage {c_sorted[i - 1]:g} m at "
                       f"{s_sorted[i - 1]:.1f} m): chainages and positions must both increase along the line")
    return Centreline(xy=xy, crs=crs, calibration=(tuple(s_sorted), tuple(c_sorted)), source=where)


def read_centreline(path, *, layer=None, chainage_start_m: float = 0.0, calibration_layer=None,
                    calibration_field: str = "chainage_m") -> Centreline:
    """Read a road centreline (GeoPackage, GeoJSON, shapefile; one LineString, or a MultiLineString whose parts
    join end to end) and optional calibration points (a point layer of the same file with ``calibration_field``
    [m]).  The CRS must be projected (metres).

    Parameters
    ----------
    path : str or path
        The vector file.
    layer : str or int, optional
        The line layer.
    chainage_start_m : float
        Chainage of the first vertex [m] (without calibration points).
    calibration_layer : str or int, optional
        The point layer of known chainages.
    calibration_field : str
        Its chainage field [m].

    Returns
    -------
    Centreline
    """
    crs, geoms, _, where = _read_layer(Path(path), layer, "centreline")
    parts = []
    for i, g in enumerate(geoms):
        if g is None:
            continue
        parts += [xy for kind, xy in _wkb_geoms(bytes(g), f"{where}, feature {i}") if kind == "line"]
    if not parts:
        raise GISError(f"{where}: no line geometry")
    xy = parts[0]
    for k, nxt in enumerate(parts[1:], 1):
        if np.hypot(*(nxt[0] - xy[-1])) > 1e-3:
            raise GISError(f"{where}: line part {k} starts {np.hypot(*(nxt[0] - xy[-1])):.2f} m from the end of the "
                           "previous part; give one continuous line (parts in order, end to start)")
        xy = np.vstack([xy, nxt[1:]])
    cal = None
    if calibration_layer is not None:
        ccrs, cgeoms, table, cwhere = _read_layer(Path(path), calibration_layer, "calibration points")
        if ccrs != crs:
            raise GISError(f"{cwhere}: CRS {ccrs} differs from the centreline's {crs}")
        if calibration_field not in table:
            raise GISError(f"{cwhere}: no field {calibration_field!r}; fields: {list(table.columns)}")
        rows = []
        for i, (g, c) in enumerate(zip(cgeoms, table[calibration_field])):
            pts = [xy_ for kind, xy_ in _wkb_geoms(bytes(g), f"{cwhere}, feature {i}") if kind == "point"]
            if not pts:
                raise GISError(f"{cwhere}: feature {i} is not a point")
            rows.append((float(c), pts[0][0, 0], pts[0][0, 1]))
        cal = rows
    return centreline_from_vertices(xy, crs=crs, chainage_start_m=chainage_start_m, calibration=cal,
                                    source=f"{Path(path).name}" + (f" layer {layer}" if layer else ""))


def write_centreline(line: Centreline, path, *, layer: str = "centreline", calibration_layer: str | None = None,
                     calibration_chainage_m=None) -> None:
    """Write ``line`` as one LineString (and optionally its calibration points with a ``chainage_m`` field) to a
    GeoPackage.

    Parameters
    ----------
    line : Centreline
        The centreline.
    path : str or path
        The GeoPackage.
    layer : str
        Line layer name.
    calibration_layer : str, optional
        Point layer name, when calibration points are written.
    calibration_chainage_m : array_like, optional
        Their chainages [m].
    """
    from pyogrio.raw import write
    path = Path(path)
    write(path, np.array([linestring_wkb(line.xy)], dtype=object),
          [np.array([line.chainage_range_m[0]]), np.array([line.chainage_range_m[1]])],
          fields=["chainage_from_m", "chainage_to_m"], geometry_type="LineString", crs=line.crs, driver="GPKG",
          layer=layer)
    if calibration_layer is not None:
        c = np.asarray(calibration_chainage_m, dtype=float)
        x, y = line.point_at(c)
        pts = np.array([struct.pack("<BIdd", 1, 1, a, b) for a, b in zip(x, y)], dtype=object)
        write(path, pts, [c], fields=["chainage_m"], geometry_type="Point", crs=line.crs, driver="GPKG",
              layer=calibration_layer, append=True)


# ---------------------------------------------------------------------------------------------------------
# section lines out
# ---------------------------------------------------------------------------------------------------------
def write_lines_gpkg(path, table: pd.DataFrame, lines, *, crs: str, layer: str = "sections") -> Path:
    """Write one LineString per row of ``table`` (its columns as fields) to a GeoPackage at ``path``.

    ``lines``: a sequence of (k x 2) vertex arrays [m], one per row.  Object columns are written as text,
    booleans as integers 0/1, other numbers as they are.  Written to a temporary name, then renamed.

    Parameters
    ----------
    path : str or path
        The GeoPackage.
    table : pandas.DataFrame
        One row per line (fields).
    lines : sequence of numpy.ndarray
        (k, 2) vertex arrays [m].
    crs : str
        Coordinate reference system.
    layer : str
        Layer name.

    Returns
    -------
    pathlib.Path
    """
    import os

    from pyogrio.raw import write
    if len(lines) != len(table):
        raise ValueError(f"{len(lines)} lines for {len(table)} rows")
    if str(crs).upper() in GEOGRAPHIC_CRS:
        raise GISError(f"CRS {crs} is geographic; section lines are written in a projected CRS in metres")
    path = Path(path)
    geoms = np.array([linestring_wkb(xy) for xy in lines], dtype=object)
    fields, names = [], []
    for c in table.columns:
        v = table[c]
        if v.dtype == bool:
            arr = v.astype(np.int32).to_numpy()
        elif pd.api.types.is_numeric_dtype(v.dtype) and not pd.api.types.is_extension_array_dtype(v.dtype):
            arr = v.to_numpy()
        elif pd.api.types.is_extension_array_dtype(v.dtype) and pd.api.types.is_numeric_dtype(v.dtype):
            arr = v.astype(float).to_numpy()
        else:
            arr = np.array(["" if (x is None or (isinstance(x, float) and np.isnan(x))) else str(x) for x in v],
                           dtype=object)
        fields.append(arr)
        names.append(str(c))
    tmp = path.with_name(path.stem + ".partial" + path.suffix)
    if tmp.exists():
        tmp.unlink()
    write(tmp, geoms, fields, fields=names, geometry_type="LineString", crs=crs, driver="GPKG", layer=layer)
    os.replace(tmp, path)
    return path
