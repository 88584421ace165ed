"""2-D slope profiles extracted from 3-D terrain along a plan polyline.

A profile for :mod:`simulation` is a vertical section: distance along a path on
the map [m] against ground elevation [m], one material per segment.  Terrain
usually comes as a point cloud (laser scan, photogrammetry) or a triangulated
surface (TIN, STL), sometimes split into substrate zones.  :func:`profile_from_points`
samples the terrain every ``spacing`` metres along a polyline drawn on the map
(for example from the release point down the fall line) and returns a
:class:`TerrainProfile` whose ``to_dict()`` is a ready ``[profile]`` table of a
scenario.

* Point cloud ``(n, 3)``: the plan coordinates are triangulated (Delaunay) and
  the elevation is interpolated linearly in the triangle containing each
  sample (a TIN through the points).  ``labels`` (one per point) give each
  segment the label of the point nearest to the segment's midpoint.
* Triangles ``(n, 3, 3)`` (e.g. from :func:`read_stl`): the elevation is
  interpolated in the given triangle that contains the sample (in plan);
  ``labels`` (one per triangle) give each segment the label of the triangle
  containing its midpoint.  Several zone meshes are simply concatenated.

``vertical_axis`` says which coordinate column is up (2 for x, y, z survey
data; 1 for the y-up frames of many 3-D tools, e.g. the Authume quarry
terrain).  The other two columns, in their order, are the plan coordinates the
polyline is given in.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ._display import Displayed, axes, short_repr


def read_stl(path) -> np.ndarray:
    """Triangles ``(n, 3, 3)`` [m] of an ASCII or binary STL file (coordinates as stored).

    Parameters
    ----------
    path : str or path
        The STL file.

    Returns
    -------
    numpy.ndarray
        Vertices of each triangle [m].
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"STL file not found: {path}")
    raw = path.read_bytes()
    if raw[:5].lower() == b"solid" and b"facet" in raw[:2000]:
        verts = [line.split()[1:4] for line in raw.decode("ascii", errors="replace").splitlines()
                 if line.strip().startswith("vertex")]
        try:
            tri = np.asarray(verts, dtype=float).reshape(-1, 3, 3)
        except ValueError as exc:
            raise ValueError(f"{path}: malformed ASCII STL ({len(verts)} vertex lines, need a multiple of 3)") \
                from exc
    else:
        if len(raw) < 84:
            raise ValueError(f"{path}: not an STL file (too short for a binary STL header)")
        n = int(np.frombuffer(raw[80:84], dtype="<u4")[0])
        if len(raw) < 84 + 50 * n:
            raise ValueError(f"{path}: binary STL declares {n} triangles but holds {(len(raw) - 84) // 50}")
        rec = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
        tri = np.frombuffer(raw[84:84 + 50 * n], dtype=rec)["v"].astype(float)
    if tri.size == 0:
        raise ValueError(f"{path}: no triangles")
    if not np.all(np.isfinite(tri)):
        raise ValueError(f"{path}: non-finite vertex coordinates")
    return tri


def _polyline(polyline_xy) -> tuple[np.ndarray, np.ndarray]:
    p = np.asarray(polyline_xy, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 2:
        raise ValueError(f"polyline_xy must be >= 2 plan points [[x, y], ...]; got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("polyline_xy holds non-finite coordinates")
    seg = np.hypot(*np.diff(p, axis=0).T)
    if np.any(seg == 0):
        i = int(np.argmax(seg == 0))
        raise ValueError(f"polyline_xy: vertices {i} and {i + 1} coincide at {p[i].tolist()}")
    return p, np.concatenate([[0.0], np.cumsum(seg)])


def _along(p, cum, s):
    """Plan points at distances s [m] along the polyline (extrapolated along the end segments)."""
    i = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(cum) - 2)
    d = (p[i + 1] - p[i]) / (cum[i + 1] - cum[i])[:, None]
    return p[i] + d * (s - cum[i])[:, None]


class _TriangleLocator:
    """Which plan triangle contains each query point, and the barycentric weights there."""

    def __init__(self, tri_plan: np.ndarray):
        from scipy.spatial import cKDTree
        self.tri = tri_plan                                  # (n, 3, 2)
        self.centroid = tri_plan.mean(axis=1)
        self.reach = float(np.max(np.linalg.norm(tri_plan - self.centroid[:, None, :], axis=2)))
        self.tree = cKDTree(self.centroid)

    def locate(self, q: np.ndarray):
        idx = np.full(len(q), -1, dtype=np.int64)
        bary = np.zeros((len(q), 3))
        cands = self.tree.query_ball_point(q, self.reach + 1e-9)
        for k, (pt, cand) in enumerate(zip(q, cands)):
            if not cand:
                continue
            t = self.tri[cand]
            a, b, c = t[:, 0], t[:, 1], t[:, 2]
            v0, v1, v2 = b - a, c - a, pt - a
            den = v0[:, 0] * v1[:, 1] - v1[:, 0] * v0[:, 1]
            ok = np.abs(den) > 1e-15
            with np.errstate(divide="ignore", invalid="ignore"):
                l1 = (v2[:, 0] * v1[:, 1] - v1[:, 0] * v2[:, 1]) / den
                l2 = (v0[:, 0] * v2[:, 1] - v2[:, 0] * v0[:, 1]) / den
            l0 = 1.0 - l1 - l2
            inside = ok & (l0 >= -1e-9) & (l1 >= -1e-9) & (l2 >= -1e-9)
            if inside.any():
                j = int(np.argmax(inside))
                idx[k] = cand[j]
                bary[k] = (l0[j], l1[j], l2[j])
        return idx, bary


@dataclass(frozen=True, repr=False)
class TerrainProfile(Displayed):
    """A vertical section of terrain along a plan polyline.

    ``distance_m`` (the profile's x, 0 at the polyline's first vertex unless
    ``start_m`` moved it), ``elevation_m`` (the profile's z), ``plan_xy`` the
    plan position of every vertex, ``materials`` one label per segment (or
    None without labels).  ``to_dict()`` gives the scenario ``[profile]`` table.
    """

    distance_m: np.ndarray
    elevation_m: np.ndarray
    plan_xy: np.ndarray = field(repr=False)
    materials: tuple | None
    polyline_xy: np.ndarray = field(repr=False)
    spacing_m: float = 0.5

    def project(self, points_xy) -> pd.DataFrame:
        """Distance along the polyline [m] and signed offset from it [m] of plan points.

        The offset (distance to the path) is positive to the left of the direction of travel.  Points
        are projected on the nearest polyline segment (the end segments are
        extended), so a stop point's ``distance_m`` is its horizontal runout as
        the 2-D profile sees it.

        Parameters
        ----------
        points_xy : array_like
            Plan points (n, 2) [m].

        Returns
        -------
        pandas.DataFrame
            ``distance_m`` and ``offset_m`` [m] per point.
        """
        q = np.atleast_2d(np.asarray(points_xy, dtype=float))
        if q.ndim != 2 or q.shape[1] != 2:
            raise ValueError(f"points_xy must be plan points [[x, y], ...]; got shape {q.shape}")
        p, cum = _polyline(self.polyline_xy)
        a, b = p[:-1], p[1:]
        d = b - a
        L2 = np.sum(d * d, axis=1)
        best = np.full(len(q), np.inf)
        s_out = np.zeros(len(q))
        off_out = np.zeros(len(q))
        for i in range(len(a)):
            t = np.sum((q - a[i]) * d[i], axis=1) / L2[i]
            lo = -np.inf if i == 0 else 0.0
            hi = np.inf if i == len(a) - 1 else 1.0
            t = np.clip(t, lo, hi)
            foot = a[i] + t[:, None] * d[i]
            r = q - foot
            dist = np.hypot(r[:, 0], r[:, 1])
            better = dist < best
            best = np.where(better, dist, best)
            s_out = np.where(better, cum[i] + t * np.sqrt(L2[i]), s_out)
            cross = (d[i, 0] * r[:, 1] - d[i, 1] * r[:, 0]) / np.sqrt(L2[i])
            off_out = np.where(better, np.copysign(dist, cross), off_out)
        return pd.DataFrame({"distance_m": s_out, "offset_m": off_out})

    def __repr__(self) -> str:
        x, z = self.distance_m, self.elevation_m
        return short_repr(self, f"{x.size} vertices", f"{x[0]:.4g}-{x[-1]:.4g} m", f"z {z.min():.5g}-{z.max():.5g} m",
                          materials=None if self.materials is None else len(set(self.materials)))

    def plot(self, ax=None):
        """The section: elevation against distance along the polyline, coloured by material when labelled.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            x: distance along the polyline [m]; z: elevation [m], equal scales.
        """
        ax = axes(ax)
        x, z = self.distance_m, self.elevation_m
        if self.materials is None:
            ax.plot(x, z, color="0.3")
        else:
            names = list(dict.fromkeys(self.materials))
            for s, m in enumerate(self.materials):
                k = names.index(m)
                ax.plot(x[s:s + 2], z[s:s + 2], color=f"C{k}", lw=2, label=m if s == self.materials.index(m) else None)
            ax.legend(fontsize="small")
        ax.set_xlabel("distance along the section [m]")
        ax.set_ylabel("elevation [m]")
        ax.set_aspect("equal", adjustable="datalim")
        return ax

    def to_dict(self, decimals: int = 3) -> dict:
        """The scenario ``[profile]`` table: ``x``, ``z`` [m] and ``materials`` (when labelled).

        Parameters
        ----------
        decimals : int
            Decimals kept [m].

        Returns
        -------
        dict
        """
        out = {"x": [round(float(v), decimals) for v in self.distance_m],
               "z": [round(float(v), decimals) for v in self.elevation_m]}
        if self.materials is not None:
            out["materials"] = [str(m) for m in self.materials]
        return out

    def summary(self) -> pd.DataFrame:
        """One row per run of consecutive segments with the same material: extent, drop, mean slope.

        Returns
        -------
        pandas.DataFrame
            ``material``, ``from_m``, ``to_m``, ``z_from_m``, ``z_to_m`` [m], ``mean_slope_deg`` [deg].
        """
        x, z = self.distance_m, self.elevation_m
        mats = self.materials if self.materials is not None else ("",) * (len(x) - 1)
        rows, start = [], 0
        for i in range(1, len(mats) + 1):
            if i == len(mats) or mats[i] != mats[start]:
                dx = x[i] - x[start]
                rows.append({"material": mats[start], "from_m": x[start], "to_m": x[i],
                             "z_from_m": z[start], "z_to_m": z[i],
                             "mean_slope_deg": float(np.degrees(np.arctan2(z[start] - z[i], dx)))})
                start = i
        return pd.DataFrame(rows)


def profile_from_points(points, polyline_xy, *, spacing: float = 0.5, labels=None, vertical_axis: int = 2,
                        start_m: float = 0.0, end_m: float | None = None, trim: bool = False) -> TerrainProfile:
    """Extract a 2-D slope profile from a point cloud or triangulated terrain along a plan polyline.

    Parameters
    ----------
    points : array (n, 3) or (n, 3, 3)
        Terrain points [m] (a point cloud, triangulated in plan) or triangles
        [m] (a TIN or STL mesh, used as given; :func:`read_stl` reads one).
    polyline_xy : array (k, 2)
        The path on the map [m], in the two horizontal coordinates of
        ``points`` in their column order, from the top of the slope down.
    spacing : float
        Distance between profile vertices along the path [m] (> 0).  About
        the terrain's resolution: finer spacing only interpolates.
    labels : sequence, optional
        Substrate zone per point (point cloud) or per triangle (mesh); each
        profile segment gets the zone at its midpoint (nearest point, or the
        containing triangle).  These become the scenario's material names.
    vertical_axis : int
        Column of ``points`` that is elevation (2 for x, y, z; 1 for y-up frames).
    start_m, end_m : float
        Extent of the profile as distances along the path [m]; ``start_m``
        may be negative (the path is extended backwards along its first
        segment, e.g. behind a release point), ``end_m`` defaults to the
        path's length and may exceed it (extended along the last segment).
    trim : bool
        Cut the profile where the path first leaves the terrain (and start it
        where the path first meets it) instead of raising.

    Returns
    -------
    TerrainProfile
        Distances start_m, start_m + spacing, ..., end_m and the elevations
        there.  Every sample must lie on the terrain: a ValueError names the
        first distance (and plan position) where it does not.
    """
    pts = np.asarray(points, dtype=float)
    if vertical_axis not in (0, 1, 2):
        raise ValueError(f"vertical_axis must be 0, 1 or 2; got {vertical_axis!r}")
    if pts.ndim == 2 and pts.shape[1] == 3:
        mesh = False
    elif pts.ndim == 3 and pts.shape[1:] == (3, 3):
        mesh = True
    else:
        raise ValueError(f"points must be a point cloud (n, 3) or triangles (n, 3, 3); got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        raise ValueError("points hold non-finite coordinates")
    if isinstance(spacing, bool) or not isinstance(spacing, (int, float, np.floating)) or not spacing > 0:
        raise ValueError(f"spacing must be a positive distance in m; got {spacing!r}")
    plan_cols = [c for c in range(3) if c != vertical_axis]
    p, cum = _polyline(polyline_xy)
    end = float(cum[-1]) if end_m is None else float(end_m)
    if not end > start_m:
        raise ValueError(f"end_m = {end:g} must exceed start_m = {start_m:g}")
    n_steps = int(np.floor((end - start_m) / spacing + 1e-9))
    s = start_m + spacing * np.arange(n_steps + 1)
    if s[-1] < end - 1e-9:
        s = np.append(s, end)
    q = _along(p, cum, s)

    if mesh:
        tri_plan = pts[:, :, plan_cols]
        tri_z = pts[:, :, vertical_axis]
    else:
        from scipy.spatial import Delaunay
        if len(pts) < 3:
            raise ValueError(f"a point cloud needs at least 3 points; got {len(pts)}")
        dl = Delaunay(pts[:, plan_cols])
        tri_plan = pts[dl.simplices][:, :, plan_cols]
        tri_z = pts[dl.simplices][:, :, vertical_axis]
    loc = _TriangleLocator(tri_plan)
    idx, bary = loc.locate(q)
    if trim and np.any(idx < 0) and np.any(idx >= 0):
        first = int(np.argmax(idx >= 0))
        gone = idx[first:] < 0
        last = first + (int(np.argmax(gone)) if gone.any() else len(gone))
        if last - first < 2:
            raise ValueError(f"the path crosses the terrain for less than two samples (from {s[first]:.2f} m)")
        s, q, idx, bary = s[first:last], q[first:last], idx[first:last], bary[first:last]
    if np.any(idx < 0):
        k = int(np.argmax(idx < 0))
        raise ValueError(f"the path leaves the terrain at distance {s[k]:.2f} m (plan {q[k].round(3).tolist()}); "
                         f"shorten it (end_m) or extend the terrain")
    z = np.sum(tri_z[idx] * bary, axis=1)

    materials = None
    if labels is not None:
        lab = np.asarray(labels, dtype=object)
        expected = len(pts)
        if lab.shape != (expected,):
            raise ValueError(f"labels: need one per {'triangle' if mesh else 'point'} ({expected}); "
                             f"got shape {lab.shape}")
        mid = _along(p, cum, 0.5 * (s[:-1] + s[1:]))
        if mesh:
            midx, _ = loc.locate(mid)
            if np.any(midx < 0):   # a midpoint in a gap between zone meshes: take the nearest triangle
                from scipy.spatial import cKDTree
                _, near = cKDTree(loc.centroid).query(mid[midx < 0])
                midx[midx < 0] = near
            materials = tuple(str(v) for v in lab[midx])
        else:
            from scipy.spatial import cKDTree
            _, near = cKDTree(pts[:, plan_cols]).query(mid)
            materials = tuple(str(v) for v in lab[near])
    return TerrainProfile(distance_m=s, elevation_m=z, plan_xy=q, materials=materials, polyline_xy=p,
                          spacing_m=float(spacing))
