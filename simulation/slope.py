"""Slope profiles: a 2-D polyline of ground vertices, each segment with a material.

The profile must be a function of x (x strictly increasing): overhangs are not
supported.  For the flight solver the segments are arranged in a binary tree;
each node stores how far the ground rises above the chord joining the ends of
its segments, so ``ground <= chord + offset`` bounds the ground over the node.
A parabola whose height above the chord exceeds the offset at both ends of the
node's range (it is concave, so that suffices) cannot land there.  The first
segment a flight reaches is found by a finger search in this tree: O(log d)
nodes for a flight over d segments, never a test of every segment.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Profile:
    """Ground vertices ``x``, ``z`` [m] and one material index per segment."""

    x: np.ndarray
    z: np.ndarray
    material_index: np.ndarray
    material_names: tuple
    tree_offset: np.ndarray = field(repr=False, default=None)
    n_leaves: int = 0
    run_first: np.ndarray = field(repr=False, default=None)
    run_last: np.ndarray = field(repr=False, default=None)

    @classmethod
    def build(cls, x, z, material_index, material_names, source: str = "profile") -> "Profile":
        """Profile from vertex coordinates [m] and per-segment material indices, checked (x strictly increasing).

        Parameters
        ----------
        x, z : array_like
            Vertex coordinates [m]: horizontal distance (strictly increasing) and elevation.
        material_index : array_like of int
            Material of each segment (one fewer than vertices), an index into ``material_names``.
        material_names : sequence of str
            Names of the materials.
        source : str
            Where the profile came from, named in errors.

        Returns
        -------
        Profile
            With the search tree (largest height of a vertex above each node's chord [m]) and the runs of
            collinear same-material segments the kernel uses.

        Raises
        ------
        ValueError
            Naming ``source`` and the vertex or segment at fault (x not increasing, not finite, counts differ).
        """
        x = np.asarray(x, dtype=float)
        z = np.asarray(z, dtype=float)
        mi = np.asarray(material_index, dtype=np.int64)
        if x.ndim != 1 or x.size < 2 or x.size != z.size:
            raise ValueError(f"{source}: x and z need the same number (>= 2) of vertices; got {x.size} and {z.size}")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(z))):
            raise ValueError(f"{source}: vertex coordinates must be finite numbers")
        dx = np.diff(x)
        if np.any(dx == 0):
            i = int(np.argmax(dx == 0))
            raise ValueError(f"{source}: segment {i} from vertex {i} to {i + 1} has zero length in x "
                             f"(x = {x[i]:g} twice); vertical faces and zero-length segments are not supported")
        if np.any(dx < 0):
            i = int(np.argmax(dx < 0))
            raise ValueError(f"{source}: x goes backwards between vertex {i} (x = {x[i]:g}) and vertex {i + 1} "
                             f"(x = {x[i + 1]:g}); overhangs are not supported, x must increase")
        if mi.size != x.size - 1:
            raise ValueError(f"{source}: {x.size - 1} segments need {x.size - 1} materials; got {mi.size}")
        n_leaves = 1
        while n_leaves < mi.size:
            n_leaves *= 2
        # For each tree node covering segments lo..hi: the largest height of a vertex above the chord
        # joining the node's end vertices (ground <= chord + offset over the node's x-range).
        tree = np.full(2 * n_leaves, -np.inf)
        for node in range(1, 2 * n_leaves):
            depth = node.bit_length() - 1
            size = n_leaves >> depth
            lo = (node - (1 << depth)) * size
            if lo >= mi.size:
                continue
            hi = min(lo + size - 1, mi.size - 1)
            xs, zs = x[lo:hi + 2], z[lo:hi + 2]
            chord = zs[0] + (zs[-1] - zs[0]) * (xs - xs[0]) / (xs[-1] - xs[0])
            tree[node] = float(np.max(zs - chord))
        # Runs of collinear segments of one material: ground contact crosses them in one step.
        angle = np.arctan2(np.diff(z), dx)
        same = (np.abs(np.diff(angle)) < 1e-12) & (mi[1:] == mi[:-1])
        run_first = np.arange(mi.size)
        run_last = np.arange(mi.size)
        for k in range(1, mi.size):
            if same[k - 1]:
                run_first[k] = run_first[k - 1]
        for k in range(mi.size - 2, -1, -1):
            if same[k]:
                run_last[k] = run_last[k + 1]
        return cls(x=x, z=z, material_index=mi, material_names=tuple(material_names), tree_offset=tree,
                   n_leaves=n_leaves, run_first=run_first, run_last=run_last)

    @property
    def n_segments(self) -> int:
        """Number of straight segments."""
        return self.x.size - 1

    def ground(self, x) -> np.ndarray:
        """Ground elevation at x [m] (linear between vertices).

        Parameters
        ----------
        x : float or array_like
            Horizontal position(s) [m].

        Returns
        -------
        numpy.ndarray or float
            Elevation of the ground [m] (the end vertices' elevation beyond the profile).
        """
        return np.interp(x, self.x, self.z)

    def segment_at(self, x) -> np.ndarray:
        """Index of the segment below x (the left one at a vertex).

        Parameters
        ----------
        x : float or array_like
            Horizontal position(s) [m].

        Returns
        -------
        numpy.ndarray or int
            Segment index, clipped to 0 .. n_segments - 1.
        """
        return np.clip(np.searchsorted(self.x, x, side="right") - 1, 0, self.n_segments - 1)

    def downslope_direction(self, x):
        """(cos, sin) of the unit vector along the ground at x [m] pointing down the slope (+x on flat ground).

        The segment under x decides (the left one at a vertex).  Arrays in, arrays out.

        Parameters
        ----------
        x : float or array_like
            Horizontal position(s) [m].

        Returns
        -------
        tuple of numpy.ndarray
            (cos, sin) components [-] of the downslope unit vector.
        """
        k = self.segment_at(np.asarray(x, dtype=float))
        dx, dz = self.x[k + 1] - self.x[k], self.z[k + 1] - self.z[k]
        length = np.hypot(dx, dz)
        sign = np.where(dz > 0.0, -1.0, 1.0)          # rising in +x: downhill is -x
        return sign * dx / length, sign * dz / length

    def contains(self, x) -> bool:
        """Whether abscissa ``x`` [m] lies within the profile.

        Parameters
        ----------
        x : float
            Horizontal position [m].

        Returns
        -------
        bool
        """
        return bool(self.x[0] <= x <= self.x[-1])
