"""Where a flight meets a 2-D profile: the impact search of the trajectory kernel (:mod:`simulation.kernel`).

A flight from the straight run the block leaves from is first tested against that run's line (one quadratic);
when it misses, a finger search in the profile's chord-offset tree (:mod:`simulation.slope`) climbs from the
current leaf and descends only into sibling subtrees ahead of the block whose ground the parabola can reach, so a
flight over d segments costs O(log d) tests whatever the number of segments.  The slopes of the segments and of
the tree nodes' chords are worked out once per kernel call (:func:`chord_slopes`).

The helpers take arrays and allocate none, so they are compiled with numba's ``_nrt=False`` (no reference counting
of their array arguments at each call; see :mod:`simulation.kernel`).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, _nrt=False)
def _seg_in(px, x, lo, hi):
    """Segment index under x among segments lo..hi, by bisection."""
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if px[mid] <= x:
            lo = mid
        else:
            hi = mid - 1
    return lo




@njit(cache=True)
def chord_slopes(px, pz, n_leaves):
    """Slope dz / dx [-] of the chord of each node of the profile's search tree (:mod:`simulation.slope`; node
    ``n_leaves + k`` is segment k), by the expressions the impact search used to evaluate at every flight (the chord
    from the node's first vertex to its last, or the profile's last): worked out once per kernel call instead.
    Nodes past the profile's end keep NaN (the search never reads them).

    Parameters
    ----------
    px, pz : numpy.ndarray
        Profile vertices [m].
    n_leaves : int
        Leaves of the search tree (a power of two, at least the number of segments).

    Returns
    -------
    numpy.ndarray
        2 ``n_leaves`` slopes [-], index 0 unused.
    """
    n_seg = px.shape[0] - 1
    out = np.full(2 * n_leaves, np.nan)
    for node in range(1, 2 * n_leaves):
        depth = 0
        while (node >> (depth + 1)) > 0:
            depth += 1
        size = n_leaves >> depth
        lo = (node - (1 << depth)) * size
        if lo >= n_seg:
            continue
        k1 = min(lo + size, n_seg)
        out[node] = (pz[k1] - pz[lo]) / (px[k1] - px[lo])
    return out


@njit(cache=True, _nrt=False)
def _leaf_hit(px, pz, slopes, k, x0, z0, vx, vz, g):
    """Time > 0 at which the parabola comes down through segment k within its x-range, or inf."""
    return _span_hit(px, pz, slopes, k, k, x0, z0, vx, vz, g)


@njit(cache=True, _nrt=False)
def _span_hit(px, pz, slopes, k0, k1, x0, z0, vx, vz, g):
    """Time > 0 at which the parabola comes down through the line of segment k0 within the x-range of
    segments k0..k1 (a straight run), or inf: the larger root of z(t) = line(x(t)); ``slopes`` from
    :func:`chord_slopes` (segment k0's at node n_leaves + k0)."""
    slope = slopes[(slopes.shape[0] >> 1) + k0]
    c0 = z0 - (pz[k0] + slope * (x0 - px[k0]))
    c1 = vz - slope * vx
    disc = c1 * c1 + 2.0 * g * c0
    if disc < 0.0:
        return math.inf
    t = (c1 + math.sqrt(disc)) / g
    if t <= 1e-12:
        # Starting on this line and moving into it (a flight that starts at a concave vertex, into the
        # next segment): the impact is immediate, provided x0 lies within the span.
        if c1 < 0.0 and abs(c0) <= 1e-9 * (1.0 + abs(z0)) and px[k0] - 1e-9 <= x0 <= px[k1 + 1] + 1e-9:
            return 1e-12
        return math.inf
    x = x0 + vx * t
    tol = 1e-9 * (1.0 + abs(x))
    if x < px[k0] - tol or x > px[k1 + 1] + tol:
        return math.inf
    return t


@njit(cache=True, _nrt=False)
def _may_hit(px, pz, slopes, tree, node, lo, hi, n_seg, x0, z0, vx, vz, g, xa_travel, xb_travel):
    """False when the parabola stays above the ground of ``node`` (segments lo..hi, its natural range in the tree)
    over the travelled x-range."""
    if lo >= n_seg:
        return False
    xa = max(px[lo], xa_travel)
    xb = min(px[min(hi + 1, n_seg)], xb_travel)
    if xa > xb:
        return False
    k0 = lo
    slope = slopes[node]              # the chord from vertex lo to vertex min(hi + 1, n_seg): chord_slopes
    ta = (xa - x0) / vx
    tb = (xb - x0) / vx
    ha = z0 + vz * ta - 0.5 * g * ta * ta - (pz[k0] + slope * (xa - px[k0]))
    hb = z0 + vz * tb - 0.5 * g * tb * tb - (pz[k0] + slope * (xb - px[k0]))
    # parabola - chord is concave, so its minimum over [xa, xb] is at an end
    return min(ha, hb) <= tree[node] + 1e-9 * (1.0 + abs(z0))


@njit(cache=True, _nrt=False)
def _descend(px, pz, slopes, tree, root, root_lo, root_hi, x0, z0, vx, vz, g, xa_travel, xb_travel, stack):
    """Earliest hit inside the subtree ``root`` covering segments root_lo..root_hi (near child first).  The caller
    has found that the parabola may reach the root's ground (:func:`_may_hit` true), so the root is not tested again."""
    n_seg = px.shape[0] - 1
    stack[0, 0], stack[1, 0], stack[2, 0] = root, root_lo, root_hi
    top = 1
    at_root = True
    while top > 0:
        top -= 1
        node, lo, hi = stack[0, top], stack[1, top], stack[2, top]
        if at_root:
            at_root = False
        elif not _may_hit(px, pz, slopes, tree, node, lo, hi, n_seg, x0, z0, vx, vz, g, xa_travel, xb_travel):
            continue
        if lo == hi:
            t = _leaf_hit(px, pz, slopes, lo, x0, z0, vx, vz, g)
            if t < math.inf:
                return t, lo
            continue
        mid = (lo + hi) // 2
        if vx > 0:    # push the far (right) child first so the near one is examined first
            stack[0, top], stack[1, top], stack[2, top] = 2 * node + 1, mid + 1, hi
            stack[0, top + 1], stack[1, top + 1], stack[2, top + 1] = 2 * node, lo, mid
        else:
            stack[0, top], stack[1, top], stack[2, top] = 2 * node, lo, mid
            stack[0, top + 1], stack[1, top + 1], stack[2, top + 1] = 2 * node + 1, mid + 1, hi
        top += 2
    return math.inf, -1


@njit(cache=True, _nrt=False)
def _run_hit(px, pz, slopes, k0, k1, x0, z0, vx, vz, g):
    """_span_hit for a straight run k0..k1, with the segment hit: (t, segment) or (inf, -1)."""
    t = _span_hit(px, pz, slopes, k0, k1, x0, z0, vx, vz, g)
    if t == math.inf:
        return math.inf, -1
    return t, _seg_in(px, x0 + vx * t, k0, k1)


@njit(cache=True, _nrt=False)
def find_impact(px, pz, slopes, tree, n_leaves, run_first, run_last, x0, z0, vx, vz, g, seg_now, stack):
    """First (time, segment) where the flight from (x0, z0) meets the ground; segment -1 if it leaves.

    The straight run the block leaves from is tested first (one line, O(1)); then a
    finger search in the chord-offset tree (:mod:`simulation.slope`) climbs from the
    current leaf and descends only into sibling subtrees ahead of the block whose
    ground the parabola can reach.  Cost O(log d) for a flight over d segments,
    independent of the total number of segments.

    Parameters
    ----------
    px, pz : numpy.ndarray
        Profile vertices [m].
    slopes : numpy.ndarray
        Slope dz / dx [-] of each tree node's chord (:func:`chord_slopes`).
    tree : numpy.ndarray
        Chord-offset tree of the profile (``TerrainProfile.tree_offset``) [m].
    n_leaves : int
        Number of leaves of the tree.
    run_first, run_last : numpy.ndarray of int
        First and last segment of the straight run each segment belongs to.
    x0, z0 : float
        Start of the flight [m].
    vx, vz : float
        Velocity at the start [m/s].
    g : float
        Gravitational acceleration [m/s^2].
    seg_now : int
        Segment the block leaves from.
    stack : numpy.ndarray of int
        Work array (3, depth) of the tree search.

    Returns
    -------
    t : float
        Time of flight to the impact [s] (or to leaving the profile).
    k : int
        Segment hit, -1 when the block leaves the profile.
    """
    if abs(vx) < 1e-12:
        return _leaf_hit(px, pz, slopes, seg_now, x0, z0, vx, vz, g), seg_now
    # The straight run (collinear segments of one material) the block leaves from acts as one segment.
    t, k = _run_hit(px, pz, slopes, run_first[seg_now], run_last[seg_now], x0, z0, vx, vz, g)
    if k >= 0:
        return t, k
    return _tree_impact(px, pz, slopes, tree, n_leaves, x0, z0, vx, vz, g, seg_now, stack)


@njit(cache=True, _nrt=False)
def _tree_impact(px, pz, slopes, tree, n_leaves, x0, z0, vx, vz, g, seg_now, stack):
    """:func:`find_impact` after its test of the run the block leaves from (vx not 0): the finger search in the
    chord-offset tree, or the time to leave the profile (segment -1)."""
    n_seg = px.shape[0] - 1
    if vx > 0:
        xa_travel, xb_travel = x0, px[n_seg]
    else:
        xa_travel, xb_travel = px[0], x0
    node, lo, hi = n_leaves + seg_now, seg_now, seg_now
    while node > 1:
        size = hi - lo + 1
        if node % 2 == 0:      # left child: the sibling lies ahead when moving right
            if vx > 0 and _may_hit(px, pz, slopes, tree, node + 1, hi + 1, hi + size, n_seg, x0, z0, vx, vz, g,
                                   xa_travel, xb_travel):
                t, k = _descend(px, pz, slopes, tree, node + 1, hi + 1, hi + size, x0, z0, vx, vz, g,
                                xa_travel, xb_travel, stack)
                if k >= 0:
                    return t, k
            hi += size
        else:                  # right child: the sibling lies ahead when moving left
            if vx < 0 and _may_hit(px, pz, slopes, tree, node - 1, lo - size, lo - 1, n_seg, x0, z0, vx, vz, g,
                                   xa_travel, xb_travel):
                t, k = _descend(px, pz, slopes, tree, node - 1, lo - size, lo - 1, x0, z0, vx, vz, g,
                                xa_travel, xb_travel, stack)
                if k >= 0:
                    return t, k
            lo -= size
        node >>= 1
    # No impact: time to reach the end of the profile.
    if vx > 0:
        return (px[n_seg] - x0) / vx, -1
    return (px[0] - x0) / vx, -1
