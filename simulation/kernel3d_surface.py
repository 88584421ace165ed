"""The 3-D kernel's ground: the bilinear DEM surface, its per-cell lookups (elevation and gradient, pixel,
fall line, roughness) and the exact impact of a flight on it.

Surface: bilinear cells
-----------------------
The ground is the bilinear interpolant of the DEM's cell-centre elevations: in the cell between centres
(i, j) and (i+1, j+1), z = z00 (1-u)(1-v) + z10 u (1-v) + z01 (1-u) v + z11 u v with u, v in [0, 1].
Bilinear cells rather than two triangles per cell because

* the raster *is* the data: the surface passes through every DEM value and is what GIS tools (GDAL's
  bilinear resampling, :func:`simulation.profile_from_grid`) report, so a 2-D section cut from the DEM and
  the 3-D kernel move on the same ground;
* it has no arbitrary diagonal: splitting each square into two triangles picks one diagonal, which carves
  a systematic ridge or furrow along it and steers blocks along 45 deg directions (a direction bias of
  the triangulation, not of the terrain);
* the cell holding a point is found in O(1) from the regular grid, with no triangle mesh to store.

The impact of a flight is found exactly: along the straight plan line of a flight, one bilinear cell is a
quadratic in time, as is the parabola, so the kernel visits the cells under the flight in order and solves
one quadratic per cell (:func:`_find_impact`); high above the ground it skips ahead by steps that provably
cannot reach it (a Lipschitz bound on the surface slope, :func:`_safe_step`).
"""
from __future__ import annotations

import math

from numba import njit


@njit(cache=True, inline="always")
def _surface(zg, x0, y0, dx, dy, x, y):
    """(z, dz/dx, dz/dy) of the bilinear surface at (x, y); z is NaN outside the grid or on a hole."""
    ny, nx = zg.shape
    u = (x - x0) / dx
    v = (y - y0) / dy
    if not (u >= 0.0 and v >= 0.0 and u <= nx - 1 and v <= ny - 1):
        return math.nan, 0.0, 0.0
    j = min(int(u), nx - 2)
    i = min(int(v), ny - 2)
    fu = u - j
    fv = v - i
    z00 = zg[i, j]
    z10 = zg[i, j + 1]
    z01 = zg[i + 1, j]
    z11 = zg[i + 1, j + 1]
    a = z10 - z00
    b = z01 - z00
    c = z11 - z10 - z01 + z00
    z = z00 + a * fu + b * fv + c * fu * fv
    return z, (a + c * fv) / dx, (b + c * fu) / dy


@njit(cache=True, inline="always")
def _height(zg, x0, y0, dx, dy, x, y, z):
    """Height [m] of (x, y, z) above the surface (NaN off the terrain)."""
    zs, _, _ = _surface(zg, x0, y0, dx, dy, x, y)
    return z - zs


@njit(cache=True, inline="always")
def _cell_of(x0, y0, dx, dy, nx, ny, x, y):
    """Flat index (row * nx + column, internal order) of the DEM pixel containing (x, y), or -1."""
    j = int(math.floor((x - x0) / dx + 0.5))
    i = int(math.floor((y - y0) / dy + 0.5))
    if i < 0 or j < 0 or i >= ny or j >= nx:
        return -1
    return i * nx + j


@njit(cache=True, inline="always")
def _downhill(nx0, ny0, nz0):
    """Unit vector down the fall line in the tangent plane of the surface with unit normal (nx0, ny0, nz0);
    +x on flat ground."""
    tx, ty, tz = nz0 * nx0, nz0 * ny0, nz0 * nz0 - 1.0
    tl = math.sqrt(tx * tx + ty * ty + tz * tz)
    if tl < 1e-12:
        return 1.0, 0.0, 0.0
    return tx / tl, ty / tl, tz / tl


@njit(cache=True)
def _safe_step(h, vh, vz, g, lip):
    """Longest time [s] a flight at height h [m] above the ground, horizontal speed vh and vertical speed vz
    [m/s], can go without meeting a ground whose slope is at most ``lip``: the root of
    1/2 g t^2 + (lip vh - vz) t = h (the parabola's drop plus the steepest possible rise of the ground)."""
    b = lip * vh - vz
    return (-b + math.sqrt(b * b + 2.0 * g * h)) / g


@njit(cache=True, inline="always")
def _first_descending_root(A, B, C, hi):
    """Smallest tau in [0, hi] where A tau^2 + B tau + C crosses zero going down (derivative <= 0), or -1."""
    best = -1.0
    if A == 0.0:
        if B != 0.0:
            r = -C / B
            if 0.0 <= r <= hi and B <= 0.0:
                best = r
        return best
    disc = B * B - 4.0 * A * C
    if disc < 0.0:
        return -1.0
    sq = math.sqrt(disc)
    q = -0.5 * (B + sq) if B >= 0.0 else -0.5 * (B - sq)
    r1 = q / A
    r2 = C / q if q != 0.0 else r1
    lo_r, hi_r = min(r1, r2), max(r1, r2)
    for r in (lo_r, hi_r):
        if 0.0 <= r <= hi and 2.0 * A * r + B <= 0.0 and (C > 0.0 or r > 0.0 or B < 0.0):
            return r
    return -1.0


@njit(cache=True)
def _find_impact(zg, x0, y0, dx, dy, lip, x, y, z, vx, vy, vz, g):
    """First time t >= 0 at which the flight from (x, y, z) meets the surface, exactly.

    Along a straight plan line the bilinear surface of one cell is a quadratic in time (u and v are linear
    in t, z = z00 + a u + b v + c u v), and so is the parabola: within each cell the height above ground is a
    quadratic whose first descending root is the impact.  The cells along the plan line are visited in
    order (a grid traversal, Amanatides & Woo 1987); high above the ground whole stretches are skipped with
    :func:`_safe_step`.  Returns (t, status): 0 an impact at t; 1 the flight leaves the grid at t; 2 it
    reaches a cell touching a nodata hole at t (still in the air)."""
    ny, nx = zg.shape
    vh = math.sqrt(vx * vx + vy * vy)
    au, av = vx / dx, vy / dy
    cell = min(dx, dy)
    t = 0.0
    relocate = True
    i = j = 0
    for _ in range(100_000_000):
        px = x + vx * t
        py = y + vy * t
        u = (px - x0) / dx
        v = (py - y0) / dy
        if relocate:
            if not (u >= -1e-9 and v >= -1e-9 and u <= nx - 1 + 1e-9 and v <= ny - 1 + 1e-9):
                return t, 1
            j = min(max(int(math.floor(u)), 0), nx - 2)
            i = min(max(int(math.floor(v)), 0), ny - 2)
            if u - j <= 0.0 and au < 0.0 and j > 0:
                j -= 1
            if v - i <= 0.0 and av < 0.0 and i > 0:
                i -= 1
            relocate = False
        if i < 0 or j < 0 or i > ny - 2 or j > nx - 2:
            return t, 1
        fu0 = min(max(u - j, 0.0), 1.0)
        fv0 = min(max(v - i, 0.0), 1.0)
        z00 = zg[i, j]
        z10 = zg[i, j + 1]
        z01 = zg[i + 1, j]
        z11 = zg[i + 1, j + 1]
        a = z10 - z00
        b = z01 - z00
        c = z11 - z10 - z01 + z00
        C = z + vz * t - 0.5 * g * t * t - (z00 + a * fu0 + b * fv0 + c * fu0 * fv0)
        if not C == C:
            return t, 2
        vzt = vz - g * t
        if C > 2.0 * cell * (1.0 + lip):
            ts = _safe_step(C, vh, vzt, g, lip)
            if ts * vh > cell:
                t += ts
                relocate = True
                continue
        tu = math.inf
        if au > 0.0:
            tu = max((1.0 - fu0) / au, 0.0)
        elif au < 0.0:
            tu = max(-fu0 / au, 0.0)
        tv = math.inf
        if av > 0.0:
            tv = max((1.0 - fv0) / av, 0.0)
        elif av < 0.0:
            tv = max(-fv0 / av, 0.0)
        te = min(tu, tv)
        A = -0.5 * g - c * au * av
        B = vzt - (a * au + b * av + c * (fu0 * av + fv0 * au))
        if C <= 0.0 and B <= 0.0:
            return t, 0           # at (or rounding-below) the ground and moving into it: the impact is now
        r = _first_descending_root(A, B, C, te)
        if r >= 0.0:
            return t + r, 0
        if te == math.inf:
            return t, 1
        t += te
        if tu <= tv:
            j += 1 if au > 0.0 else -1
        if tv <= tu:
            i += 1 if av > 0.0 else -1
    return t, 1


@njit(cache=True, nogil=True)
def cell_roughness(rough_grid, m_rough, mat, i, j):
    """Roughness height [m] of cell (i, j): the roughness raster's value there, or the cell material's
    ``roughness_m`` where the raster has none (NaN) or no raster was given (``rough_grid`` of shape (0, 0)).

    Parameters
    ----------
    rough_grid : numpy.ndarray
        Roughness per cell [m] (ny, nx), NaN where the material's applies, or of shape (0, 0).
    m_rough : numpy.ndarray
        Per material: roughness [m].
    mat : int
        Material index of the cell.
    i, j : int
        Row and column of the cell.

    Returns
    -------
    float
        Roughness height [m].
    """
    if rough_grid.shape[0] > 0:
        v = rough_grid[i, j]
        if v == v:
            return v
    return m_rough[mat]
