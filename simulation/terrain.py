"""3-D terrain from raster digital elevation models (GeoTIFF, ESRI ASCII grid).

A DEM is read with rasterio (GDAL) and kept as a :class:`Terrain`: elevations on a regular grid with the
file's CRS, affine transform and nodata value.  Internally the grid is held in one orientation whatever
the file's (north-up rasters store the northernmost row first, south-up ones the southernmost): row index
increasing with the plan coordinate y, column index with x, elevations at cell centres.  The surface
between cell centres is bilinear (see :mod:`simulation.kernel3d_surface` for why), so the simulated domain is the
rectangle spanned by the cell centres, half a cell inside the raster's outer edge.

Nodata handling (stated, not silent): a nodata (or NaN) cell is a hole.  A bilinear cell that touches a
hole has no surface; a block that reaches such a cell leaves the simulation there, counted as "left
terrain (nodata)" like a block leaving the DEM's edge, and hazard maps report how many did.  A release
point, a profile sample or a collector vertex on a hole is refused before any work, with a clear error.

Rotated or sheared rasters (a transform with rotation terms) are refused: resample them north-up first
(``gdalwarp``).  A DEM without a CRS is refused unless the caller states one (``crs=``): hazard rasters are
written in the DEM's CRS, and an unreferenced grid would silently misplace them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import RiskrfError
from ._display import Displayed, axes, short_repr


class TerrainError(RiskrfError, ValueError):
    """A DEM, material raster, source or path on the terrain is unusable; the message names file and value."""


@dataclass(frozen=True, repr=False)
class Terrain(Displayed):
    """Elevations [m] on a regular grid with georeferencing.

    Attributes
    ----------
    z : ndarray (ny, nx)
        Elevation [m] at cell centres, row ``i`` at plan ``y0 + i dy``, column ``j`` at ``x0 + j dx``
        (row index increasing northwards, whatever the file's order); NaN on nodata cells.
    x0, y0 : float
        Plan coordinates [m, CRS units] of the centre of cell (0, 0) (the south-west one).
    dx, dy : float
        Cell size [m] (> 0).
    crs : object
        The CRS (a ``rasterio.crs.CRS``), or None only for synthetic terrains made in memory.
    transform : affine.Affine
        The file's own transform (orientation as read), used to write rasters back on the same grid.
    south_up : bool
        True when the file stores its southernmost row first (transform ``e`` > 0).
    nodata : float or None
        The file's nodata value.
    source : str
        The file the terrain came from (named in errors).
    """

    z: np.ndarray = field(repr=False)
    x0: float
    y0: float
    dx: float
    dy: float
    crs: object = None
    transform: object = field(default=None, repr=False)
    south_up: bool = False
    nodata: float | None = None
    source: str = "<array>"

    def __repr__(self) -> str:
        ny, nx = self.z.shape
        x0, y0, x1, y1 = self.bounds
        return short_repr(self, repr(Path(str(self.source)).name), f"{ny} x {nx} cells of {self.dx:g} x {self.dy:g} m",
                          f"x {x0:.6g}-{x1:.6g}, y {y0:.6g}-{y1:.6g} m", crs=str(self.crs) if self.crs else None)

    def summary(self):
        """The grid at a glance (one-column table): source, CRS, shape, cell size [m], extent [m], elevation
        range [m], nodata cells and mean slope [deg].

        Returns
        -------
        pandas.DataFrame
            Index: quantity; column ``value``.
        """
        import pandas as pd
        x0, y0, x1, y1 = self.bounds
        z = self.z
        rows = {"source": self.source, "crs": str(self.crs) if self.crs else "none (synthetic)",
                "cells (rows x columns)": f"{z.shape[0]} x {z.shape[1]}", "cell size [m]": f"{self.dx:g} x {self.dy:g}",
                "x extent of cell centres [m]": f"{x0:.6g} to {x1:.6g}",
                "y extent of cell centres [m]": f"{y0:.6g} to {y1:.6g}",
                "elevation [m]": f"{np.nanmin(z):.5g} to {np.nanmax(z):.5g}",
                "nodata cells": int(np.isnan(z).sum()), "mean slope [deg]": round(float(np.nanmean(self.slope_deg())), 2)}
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    def plot(self, ax=None):
        """Plan view: the hillshade of the terrain (:meth:`hillshade`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            x, y: plan coordinates [m, the CRS's units], equal scales.
        """
        ax = axes(ax, figsize=(7.0, 6.0))
        x0, y0, x1, y1 = self.bounds
        ax.imshow(self.hillshade(), origin="lower", cmap="gray", vmin=0, vmax=1,
                  extent=(x0 - self.dx / 2, x1 + self.dx / 2, y0 - self.dy / 2, y1 + self.dy / 2))
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_aspect("equal")
        return ax

    # ---- construction -------------------------------------------------------------------------------
    @classmethod
    def from_array(cls, z, transform, crs=None, nodata=None, source: str = "<array>") -> "Terrain":
        """A terrain from a raster array in file order and its affine transform (north-up: ``e`` < 0,
        south-up: ``e`` > 0).  Cells equal to ``nodata`` or non-finite become holes (NaN).

        Parameters
        ----------
        z : array_like
            Elevations [m], rows in the file's order.
        transform : affine.Affine or sequence
            The raster's affine transform (no rotation or shear).
        crs : rasterio.crs.CRS, optional
            Coordinate reference system.
        nodata : float, optional
            The nodata value.
        source : str
            Name used in messages.

        Returns
        -------
        Terrain
        """
        from affine import Affine
        t = transform if isinstance(transform, Affine) else Affine(*tuple(transform)[:6])
        z = np.array(z, dtype=float)
        if z.ndim != 2 or min(z.shape) < 2:
            raise TerrainError(f"{source}: a DEM needs at least 2 x 2 cells; got shape {z.shape}")
        if t.b != 0 or t.d != 0:
            raise TerrainError(f"{source}: the raster is rotated or sheared (transform {tuple(t)[:6]}); "
                               "resample it north-up first (e.g. gdalwarp)")
        if t.a <= 0 or t.e == 0:
            raise TerrainError(f"{source}: unsupported transform {tuple(t)[:6]} (need a pixel width > 0 and a "
                               "non-zero pixel height)")
        if nodata is not None and not (isinstance(nodata, float) and math.isnan(nodata)):
            z[z == nodata] = np.nan
        z[~np.isfinite(z)] = np.nan
        if np.all(np.isnan(z)):
            raise TerrainError(f"{source}: every cell is nodata")
        ny, nx = z.shape
        dx, dy = float(t.a), abs(float(t.e))
        south_up = t.e > 0
        x0 = t.c + 0.5 * t.a
        if south_up:
            y0 = t.f + 0.5 * t.e
        else:
            y0 = t.f + (ny - 0.5) * t.e
            z = z[::-1].copy()
        return cls(z=z, x0=float(x0), y0=float(y0), dx=dx, dy=dy, crs=crs, transform=t, south_up=bool(south_up),
                   nodata=nodata, source=source)

    @classmethod
    def from_function(cls, f, x_range, y_range, cell: float, crs="EPSG:2056") -> "Terrain":
        """A synthetic north-up terrain with cell centres covering ``x_range`` x ``y_range`` [m] every ``cell``
        m and elevation ``f(x, y)`` [m] (for tests and examples).

        Parameters
        ----------
        f : callable
            ``f(x, y)`` → elevation [m], on arrays.
        x_range, y_range : tuple of float
            (low, high) plan extent of the cell centres [m].
        cell : float
            Cell size [m].
        crs : str
            Coordinate reference system (default Swiss LV95).

        Returns
        -------
        Terrain
        """
        from affine import Affine
        from rasterio.crs import CRS
        xs = np.arange(x_range[0], x_range[1] + 0.5 * cell, cell)
        ys = np.arange(y_range[0], y_range[1] + 0.5 * cell, cell)
        X, Y = np.meshgrid(xs, ys[::-1])
        t = Affine(cell, 0.0, xs[0] - 0.5 * cell, 0.0, -cell, ys[-1] + 0.5 * cell)
        return cls.from_array(f(X, Y), t, CRS.from_user_input(crs) if crs is not None else None,
                              source="<synthetic>")

    # ---- geometry -----------------------------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, int]:
        """(ny, nx) cells."""
        return self.z.shape

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) [m] of the simulated domain: the rectangle of cell centres."""
        ny, nx = self.z.shape
        return self.x0, self.y0, self.x0 + (nx - 1) * self.dx, self.y0 + (ny - 1) * self.dy

    def contains(self, x, y) -> np.ndarray:
        """True where plan points lie in the domain and on a bilinear cell without a nodata corner.

        Parameters
        ----------
        x, y : float or array_like
            Plan coordinates [m, the CRS's units].

        Returns
        -------
        numpy.ndarray of bool
        """
        return np.isfinite(self.elevation(x, y))

    def _cell(self, x, y):
        """(inside, row i, column j, fraction along x, fraction along y) of the bilinear cell under plan points."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        ny, nx = self.z.shape
        u = (x - self.x0) / self.dx
        v = (y - self.y0) / self.dy
        inside = (u >= 0) & (u <= nx - 1) & (v >= 0) & (v <= ny - 1)
        j = np.clip(np.floor(np.where(inside, u, 0)).astype(np.int64), 0, nx - 2)
        i = np.clip(np.floor(np.where(inside, v, 0)).astype(np.int64), 0, ny - 2)
        fu, fv = np.where(inside, u, 0) - j, np.where(inside, v, 0) - i
        return inside, i, j, fu, fv

    def elevation(self, x, y) -> np.ndarray:
        """Bilinear elevation [m] at plan points; NaN outside the domain or on a cell touching nodata.

        Parameters
        ----------
        x, y : float or array_like
            Plan coordinates [m, the CRS's units].

        Returns
        -------
        numpy.ndarray
            Elevation [m].
        """
        inside, i, j, fu, fv = self._cell(x, y)
        z = self.z
        out = (z[i, j] * (1 - fu) * (1 - fv) + z[i, j + 1] * fu * (1 - fv) + z[i + 1, j] * (1 - fu) * fv
               + z[i + 1, j + 1] * fu * fv)
        return np.where(inside, out, np.nan)

    def gradient(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """(dz/dx, dz/dy) of the bilinear surface at plan points [-]; NaN outside.

        Parameters
        ----------
        x, y : float or array_like
            Plan coordinates [m, the CRS's units].

        Returns
        -------
        tuple of numpy.ndarray
            (dz/dx, dz/dy) [-].
        """
        inside, i, j, fu, fv = self._cell(x, y)
        z = self.z
        gx = ((z[i, j + 1] - z[i, j]) * (1 - fv) + (z[i + 1, j + 1] - z[i + 1, j]) * fv) / self.dx
        gy = ((z[i + 1, j] - z[i, j]) * (1 - fu) + (z[i + 1, j + 1] - z[i, j + 1]) * fu) / self.dy
        return np.where(inside, gx, np.nan), np.where(inside, gy, np.nan)

    def cell_centres(self) -> tuple[np.ndarray, np.ndarray]:
        """Plan coordinates (x, y) [m] of the cell centres, arrays of shape (ny, nx) in internal order.

        Returns
        -------
        tuple of numpy.ndarray
        """
        ny, nx = self.z.shape
        return np.meshgrid(self.x0 + self.dx * np.arange(nx), self.y0 + self.dy * np.arange(ny))

    def slope_deg(self) -> np.ndarray:
        """Slope angle [deg] at every cell centre (central differences; internal order).

        Returns
        -------
        numpy.ndarray
            (ny, nx) angles [deg].
        """
        gy, gx = np.gradient(self.z, self.dy, self.dx)
        return np.degrees(np.arctan(np.hypot(gx, gy)))

    def hillshade(self, azimuth_deg: float = 315.0, altitude_deg: float = 45.0) -> np.ndarray:
        """Hillshade in [0, 1] at every cell centre (internal order), sun from ``azimuth_deg`` (clockwise from
        north) at ``altitude_deg`` above the horizon: cos of the angle between the surface normal and the sun
        (Horn-style shading with central differences; Burrough & McDonnell 1998, ch. 8).

        Parameters
        ----------
        azimuth_deg : float
            Sun azimuth [deg], clockwise from north.
        altitude_deg : float
            Sun altitude above the horizon [deg].

        Returns
        -------
        numpy.ndarray
            (ny, nx) shading in [0, 1].

        References
        ----------
        Burrough, P. A. & McDonnell, R. A. (1998). Principles of Geographical Information Systems. Oxford
        University Press, chapter 8.
        """
        gy, gx = np.gradient(self.z, self.dy, self.dx)
        az, alt = math.radians(azimuth_deg), math.radians(altitude_deg)
        sun = np.array([math.sin(az) * math.cos(alt), math.cos(az) * math.cos(alt), math.sin(alt)])
        n = np.stack([-gx, -gy, np.ones_like(gx)])
        n /= np.linalg.norm(n, axis=0)
        return np.clip(np.tensordot(sun, n, axes=1), 0.0, 1.0)

    # ---- writing ------------------------------------------------------------------------------------
    def to_file_order(self, grid: np.ndarray) -> np.ndarray:
        """A (ny, nx) array in internal order (row = increasing y) turned into the file's row order.

        Parameters
        ----------
        grid : numpy.ndarray
            (ny, nx) values in internal order.

        Returns
        -------
        numpy.ndarray
        """
        grid = np.asarray(grid)
        if grid.shape != self.z.shape:
            raise TerrainError(f"grid of shape {grid.shape} is not on the DEM's grid {self.z.shape}")
        return grid if self.south_up else grid[::-1]

    def write_geotiff(self, path, grid, nodata=np.nan, dtype="float32", *, description: str | None = None,
                      unit: str | None = None, tags: dict | None = None) -> Path:
        """Write a (ny, nx) grid in internal order as a single-band GeoTIFF on the DEM's grid and CRS
        (written to a temporary name, then renamed: never half-written).

        Parameters
        ----------
        path : str or path
            The GeoTIFF written.
        grid : numpy.ndarray
            (ny, nx) values in internal order.
        nodata : float
            The nodata value written.
        dtype : str
            Pixel type.
        description : str, optional
            The band's description (the quantity, e.g. "passing energy p95"); also band tag ``quantity``.
        unit : str, optional
            The band's unit (GDAL unit type, e.g. "kJ"); also band tag ``unit``.
        tags : dict, optional
            Dataset-level metadata tags (GDAL metadata items).

        Returns
        -------
        pathlib.Path
        """
        import rasterio
        path = Path(path)
        data = self.to_file_order(grid).astype(dtype)
        tmp = path.with_name(path.name + ".part")
        profile = dict(driver="GTiff", height=data.shape[0], width=data.shape[1], count=1, dtype=dtype,
                       crs=self.crs, transform=self.transform, nodata=nodata, compress="deflate")
        with rasterio.open(tmp, "w", **profile) as dst:
            dst.write(data, 1)
            if description is not None:
                dst.set_band_description(1, description)
                dst.update_tags(1, quantity=description)
            if unit is not None:
                dst.set_band_unit(1, unit)
                dst.update_tags(1, unit=unit)
            if tags:
                dst.update_tags(**{str(k): str(v) for k, v in tags.items()})
        tmp.replace(path)
        return path

    def check_points(self, xy, what: str) -> np.ndarray:
        """Plan points (n, 2) checked to lie on the terrain: a TerrainError naming ``what``, the first point
        outside (or on a nodata hole) and the domain otherwise.

        Parameters
        ----------
        xy : array_like
            Plan points (n, 2) [m].
        what : str
            What they are, for the message.

        Returns
        -------
        numpy.ndarray
            (n, 2) float array [m].
        """
        p = np.atleast_2d(np.asarray(xy, dtype=float))
        if p.ndim != 2 or p.shape[1] != 2 or not np.all(np.isfinite(p)):
            raise TerrainError(f"{what}: need plan points [[x, y], ...]; got {np.asarray(xy).tolist()!r}")
        ok = self.contains(p[:, 0], p[:, 1])
        if not ok.all():
            k = int(np.argmax(~ok))
            x0, y0, x1, y1 = self.bounds
            inside = x0 <= p[k, 0] <= x1 and y0 <= p[k, 1] <= y1
            why = "on a nodata hole of" if inside else "outside"
            raise TerrainError(f"{what}: point {k} ({p[k, 0]:.2f}, {p[k, 1]:.2f}) is {why} the DEM {self.source} "
                               f"(domain x {x0:.2f}-{x1:.2f}, y {y0:.2f}-{y1:.2f})")
        return p


def fall_line_to_nodata(terrain: Terrain, xy, max_steps: int | None = None):
    """Follow the steepest descent on the DEM's cells (D8: to the lowest of the 8 neighbours) from each plan
    point until a pit, the DEM's edge or a cell next to a nodata hole (where the bilinear surface ends).

    A pre-flight check: bouncing blocks may leave the fall line, so it finds the holes that the terrain leads
    blocks to, not every hole a block could reach.

    Parameters
    ----------
    terrain : Terrain
        The DEM.
    xy : array_like
        Plan points (n, 2) [m].
    max_steps : int, optional
        Most cells followed from each point.

    Returns
    -------
    tuple
        (index of the first point whose fall line meets a hole, or -1; the plan point [m] of the cell where it
        does, or None).
    """
    z = terrain.z
    ny, nx = z.shape
    hole = np.isnan(z)
    if not hole.any():
        return -1, None
    near = hole.copy()                       # cells touching a hole (8-neighbourhood)
    pad = np.pad(hole, 1, constant_values=False)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            near |= pad[1 + di:1 + di + ny, 1 + dj:1 + dj + nx]
    zf = np.where(hole, np.inf, z)
    zp = np.pad(zf, 1, constant_values=np.inf)
    p = np.atleast_2d(np.asarray(xy, dtype=float))
    i = np.clip(np.rint((p[:, 1] - terrain.y0) / terrain.dy).astype(np.int64), 0, ny - 1)
    j = np.clip(np.rint((p[:, 0] - terrain.x0) / terrain.dx).astype(np.int64), 0, nx - 1)
    alive = np.ones(len(p), dtype=bool)
    offs = [(di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj]
    dist = np.array([np.hypot(di * terrain.dy, dj * terrain.dx) for di, dj in offs])
    for _ in range(max_steps or 4 * (nx + ny)):
        hit = alive & near[i, j]
        if hit.any():
            k = int(np.argmax(hit))
            return k, (float(terrain.x0 + j[k] * terrain.dx), float(terrain.y0 + i[k] * terrain.dy))
        drops = np.stack([(zf[i, j] - zp[1 + i + di, 1 + j + dj]) / d for (di, dj), d in zip(offs, dist)])
        best = np.argmax(drops, axis=0)
        down = drops[best, np.arange(len(p))] > 0
        edge = (i == 0) | (j == 0) | (i == ny - 1) | (j == nx - 1)
        alive &= down & ~edge
        if not alive.any():
            break
        step = np.array(offs)[best]
        i = np.where(alive, i + step[:, 0], i)
        j = np.where(alive, j + step[:, 1], j)
    return -1, None


def _crs_from(value, where: str):
    from rasterio.crs import CRS
    from rasterio.errors import CRSError
    try:
        return CRS.from_user_input(value)
    except (CRSError, ValueError, TypeError) as exc:
        raise TerrainError(f"{where}: crs = {value!r} is not a CRS rasterio understands ({exc})") from None


def read_dem(path, crs=None, band: int = 1) -> Terrain:
    """Read a DEM (GeoTIFF, ESRI ASCII grid ``.asc``, or any single-band raster GDAL reads) as a :class:`Terrain`.

    Parameters
    ----------
    path : str or Path
        The raster file.
    crs : str or CRS, optional
        The CRS to use when the file has none (e.g. an ESRI ASCII grid without a ``.prj``), such as
        ``"EPSG:2154"``.  If the file has a CRS and ``crs`` names another, that is an error.
    band : int
        The band holding elevations [m].

    Returns
    -------
    Terrain
        With the file's CRS, transform and nodata; nodata cells as NaN holes.
    """
    import rasterio
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"DEM file not found: {path}")
    try:
        ds = rasterio.open(path)
    except rasterio.errors.RasterioIOError as exc:
        raise TerrainError(f"{path}: not a raster GDAL can read ({exc})") from None
    with ds:
        if not 1 <= band <= ds.count:
            raise TerrainError(f"{path}: band {band} does not exist (the file has {ds.count})")
        file_crs = ds.crs
        if crs is not None:
            given = _crs_from(crs, str(path))
            if file_crs is not None and given != file_crs:
                raise TerrainError(f"{path}: the file's CRS is {file_crs.to_string()} but crs = {crs!r} was given; "
                                   "drop the crs argument or reproject the DEM")
            file_crs = given
        if file_crs is None:
            raise TerrainError(f"{path}: the DEM has no CRS (no .prj or georeferencing); state it with crs= "
                               "(the [terrain] crs field, or --crs), e.g. crs = \"EPSG:2056\"")
        z = ds.read(band).astype(float)
        return Terrain.from_array(z, ds.transform, crs=file_crs, nodata=ds.nodata, source=str(path))


@dataclass(frozen=True)
class MaterialGrid:
    """Material index per DEM cell (internal order), and the material names the indices refer to."""

    index: np.ndarray = field(repr=False)
    names: tuple

    def at(self, terrain: Terrain, x, y) -> np.ndarray:
        """Material index of the cell containing each plan point (nearest cell centre).

        Parameters
        ----------
        terrain : Terrain
            The DEM whose grid the raster shares.
        x, y : float or array_like
            Plan coordinates [m].

        Returns
        -------
        numpy.ndarray of int
        """
        ny, nx = self.index.shape
        j = np.clip(np.rint((np.asarray(x, float) - terrain.x0) / terrain.dx).astype(np.int64), 0, nx - 1)
        i = np.clip(np.rint((np.asarray(y, float) - terrain.y0) / terrain.dy).astype(np.int64), 0, ny - 1)
        return self.index[i, j]


def _read_on_dem_grid(path, terrain: Terrain, what: str, resampling: str):
    """Band 1 of a raster that must lie on the DEM's grid: the same shape, transform (to 1e-6 of a cell) and CRS
    (a raster without CRS is taken to share the DEM's); a clear error otherwise, naming both grids.

    Parameters
    ----------
    path : str or path
        The raster file.
    terrain : Terrain
        The DEM.
    what : str
        What the raster is, for messages (``"material raster"``).
    resampling : str
        The resampling to advise when it is on another grid.

    Returns
    -------
    tuple
        (values in the DEM's internal orientation, the raster's nodata value or None).
    """
    import rasterio
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{what} not found: {path}")
    with rasterio.open(path) as ds:
        t, tt = ds.transform, terrain.transform
        same = (ds.height, ds.width) == terrain.shape and all(
            abs(a - b) <= 1e-6 * max(terrain.dx, terrain.dy) for a, b in zip(tuple(t)[:6], tuple(tt)[:6]))
        if not same:
            raise TerrainError(f"{path}: the {what} is on another grid than the DEM {terrain.source} "
                               f"(its {ds.height} x {ds.width} cells, transform {tuple(t)[:6]}; the DEM's "
                               f"{terrain.shape[0]} x {terrain.shape[1]}, {tuple(tt)[:6]}); resample it onto the "
                               f"DEM's grid (e.g. gdalwarp -te/-tr with {resampling})")
        if ds.crs is not None and terrain.crs is not None and ds.crs != terrain.crs:
            raise TerrainError(f"{path}: the {what}'s CRS {ds.crs.to_string()} is not the DEM's "
                               f"{terrain.crs.to_string()}")
        raw = ds.read(1)
        nodata = ds.nodata
    return (raw if terrain.south_up else raw[::-1]), nodata


#: Largest roughness height a roughness raster may give [m] (the material field's limit).
MAX_ROUGHNESS_M = 10.0


def read_roughness_raster(path, terrain: Terrain) -> np.ndarray:
    """A roughness raster on the DEM's grid: the asperity height of each cell [m], as Rockyfor3D's mean obstacle
    height (Dorren 2016, Rockyfor3D (v5.2) revealed, ecorisQ).  Where it has a value it replaces the material's
    ``roughness_m`` in the 3-D kernel (the impact tilt, the lateral deviation and the rolling resistance's size
    term); its nodata cells (and NaN) keep the material's.  It must lie on the DEM's grid (as a material raster).

    Parameters
    ----------
    path : str or path
        The raster file.
    terrain : Terrain
        The DEM.

    Returns
    -------
    numpy.ndarray
        Roughness per cell [m] (ny, nx) in the DEM's internal orientation, NaN where the material's applies.

    Raises
    ------
    TerrainError
        On another grid or CRS than the DEM, or a value below 0 or above :data:`MAX_ROUGHNESS_M` (naming a cell).
    """
    raw, nodata = _read_on_dem_grid(path, terrain, "roughness raster", "bilinear or average resampling")
    rough = raw.astype(float)
    if nodata is not None:
        rough[raw == nodata] = np.nan
    bad = np.isfinite(rough) & ((rough < 0.0) | (rough > MAX_ROUGHNESS_M))
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise TerrainError(f"{path}: roughness {rough[i, j]:g} m (cell row "
                           f"{i if terrain.south_up else rough.shape[0] - 1 - i}, column {j}) is outside 0-"
                           f"{MAX_ROUGHNESS_M:g} m")
    return np.ascontiguousarray(rough)


def read_material_raster(path, terrain: Terrain, codes: dict, material_names) -> MaterialGrid:
    """A material raster on the DEM's grid: integer codes per cell, mapped to material names by ``codes``
    (``{code: name}``).  The raster must have the DEM's shape, transform (to 1e-6 of a cell) and CRS (a
    raster without CRS is taken to share the DEM's); a clear error otherwise, naming both grids.  A code not
    in ``codes`` (outside the DEM's nodata holes) is an error naming it and a cell where it occurs.

    Parameters
    ----------
    path : str or path
        The raster file.
    terrain : Terrain
        The DEM.
    codes : dict
        Integer code → material name.
    material_names : sequence of str
        The scenario's materials, in order.

    Returns
    -------
    MaterialGrid
    """
    names = list(material_names)
    raw, nodata = _read_on_dem_grid(path, terrain, "material raster", "nearest neighbour")
    index = np.zeros(raw.shape, dtype=np.int64)
    known = np.zeros(raw.shape, dtype=bool)
    for code, name in codes.items():
        if name not in names:
            raise TerrainError(f"{path}: code {code} maps to material {name!r}, which the scenario does not define "
                               f"({', '.join(names)})")
        sel = raw == int(code)
        index[sel] = names.index(name)
        known |= sel
    bad = ~known & np.isfinite(terrain.z)
    if nodata is not None:
        bad &= raw != nodata
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise TerrainError(f"{path}: code {raw[i, j].item()!r} (cell row {i if terrain.south_up else raw.shape[0] - 1 - i}, "
                           f"column {j}) has no material; codes given: {sorted(codes)}")
    return MaterialGrid(index=index, names=tuple(names))


def profile_from_grid(dem: Terrain, polyline_xy, spacing: float | None = None, *, start_m: float = 0.0,
                      end_m: float | None = None, materials: MaterialGrid | None = None):
    """Cut a 2-D slope profile from a DEM along a plan polyline (the raster counterpart of
    :func:`simulation.profile_from_points`).

    Parameters
    ----------
    dem : Terrain
        From :func:`read_dem` (or :meth:`Terrain.from_array`).
    polyline_xy : array (k, 2)
        The path on the map [m, the DEM's CRS], from the top of the slope down.
    spacing : float, optional
        Distance between profile vertices along the path [m]; default the DEM's cell size (finer only
        interpolates the bilinear surface).
    start_m, end_m : float
        Extent along the path [m] (``end_m`` defaults to the path's length; both may extend it).
    materials : MaterialGrid, optional
        Material per cell; each segment takes the material of the cell under its midpoint.

    Returns
    -------
    TerrainProfile
        ``to_dict()`` gives a scenario ``[profile]`` table.  Elevations are the DEM's bilinear surface, the
        same surface the 3-D kernel moves on.  A sample outside the DEM or on a nodata hole is a TerrainError
        naming the distance along the path and the plan point.
    """
    from .profile_extraction import TerrainProfile, _along, _polyline
    if spacing is None:
        spacing = min(dem.dx, dem.dy)
    if isinstance(spacing, bool) or not isinstance(spacing, (int, float, np.floating)) or not spacing > 0:
        raise TerrainError(f"spacing must be a positive distance in m; got {spacing!r}")
    p, cum = _polyline(polyline_xy)
    end = float(cum[-1]) if end_m is None else float(end_m)
    if not end > start_m:
        raise TerrainError(f"end_m = {end:g} must exceed start_m = {start_m:g}")
    n_steps = int(np.floor((end - start_m) / spacing + 1e-9))
    s = start_m + spacing * np.arange(n_steps + 1)
    if s[-1] < end - 1e-9:
        s = np.append(s, end)
    q = _along(p, cum, s)
    z = dem.elevation(q[:, 0], q[:, 1])
    if np.any(np.isnan(z)):
        k = int(np.argmax(np.isnan(z)))
        x0, y0, x1, y1 = dem.bounds
        inside = x0 <= q[k, 0] <= x1 and y0 <= q[k, 1] <= y1
        why = "crosses a nodata hole of" if inside else "leaves"
        raise TerrainError(f"the path {why} the DEM {dem.source} at distance {s[k]:.2f} m (plan "
                           f"{q[k].round(3).tolist()}); shorten it (end_m), move it or fill the DEM")
    mats = None
    if materials is not None:
        mid = _along(p, cum, 0.5 * (s[:-1] + s[1:]))
        idx = materials.at(dem, mid[:, 0], mid[:, 1])
        mats = tuple(materials.names[i] for i in idx)
    return TerrainProfile(distance_m=s, elevation_m=z, plan_xy=q, materials=mats, polyline_xy=p,
                          spacing_m=float(spacing))
