"""Slope profiles: a 2-D polyline of ground vertices, each segment with a material.

The profile must be a function of x (x strictly increasing): overhangs are not
supported.  For the flight solver the segments are arranged in a binary tree
whose nodes hold the highest ground elevation of the segments below them, so
the first segment a parabola can reach is found by descending the tree:
O(log S) nodes per flight for S segments, never a test of every segment.
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
    tree_zmax: np.ndarray = field(repr=False, default=None)
    n_leaves: int = 0

    @classmethod
    def build(cls, x, z, material_index, material_names, source: str = "profile") -> "Profile":
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
        tree = np.full(2 * n_leaves, -np.inf)
        tree[n_leaves:n_leaves + mi.size] = np.maximum(z[:-1], z[1:])
        for node in range(n_leaves - 1, 0, -1):
            tree[node] = max(tree[2 * node], tree[2 * node + 1])
        return cls(x=x, z=z, material_index=mi, material_names=tuple(material_names), tree_zmax=tree,
                   n_leaves=n_leaves)

    @property
    def n_segments(self) -> int:
        return self.x.size - 1

    @property
    def angles_rad(self) -> np.ndarray:
        """Segment inclination, positive when the ground rises with x [rad]."""
        return np.arctan2(np.diff(self.z), np.diff(self.x))

    def ground(self, x) -> np.ndarray:
        """Ground elevation at x [m] (linear between vertices)."""
        return np.interp(x, self.x, self.z)

    def segment_at(self, x) -> np.ndarray:
        """Index of the segment below x (the left one at a vertex)."""
        return np.clip(np.searchsorted(self.x, x, side="right") - 1, 0, self.n_segments - 1)

    def contains(self, x) -> bool:
        return bool(self.x[0] <= x <= self.x[-1])
