"""What the 3-D kernel records along a trajectory: the pixels a block crosses, with its largest kinetic
energy [kJ] and height above the ground [m] in each (hazard maps); the crossings of collectors and
barriers, with the barrier's outcome; the path points of the first blocks.
"""
from __future__ import annotations

import math

from numba import njit

from .kernel import CROSSED, barrier_outcome
from .kernel3d_surface import _height


@njit(cache=True)
def _pass_flush(acc, p_block, p_cell, p_e, p_h, p_count, bid):
    """Write the block's accumulated passage of its current pixel (max energy [kJ] and height [m])."""
    cell = int(acc[0])
    if cell >= 0:
        i = p_count[0]
        if i < p_block.shape[0]:
            p_block[i], p_cell[i], p_e[i], p_h[i] = bid, cell, acc[1], acc[2]
            p_count[0] = i + 1
        else:
            p_count[1] += 1
    acc[0], acc[1], acc[2] = -1.0, 0.0, 0.0


@njit(cache=True, inline="always")
def _pass_add(acc, p_block, p_cell, p_e, p_h, p_count, bid, cell, e_kj, h):
    if cell != int(acc[0]):
        _pass_flush(acc, p_block, p_cell, p_e, p_h, p_count, bid)
        acc[0] = cell
    acc[1] = max(acc[1], e_kj)
    acc[2] = max(acc[2], h)


@njit(cache=True)
def _flight_passages(zg, x0, y0, dx, dy, xa, ya, za, vx, vy, vz, w, t_end, g, mass, inertia,
                     acc, p_block, p_cell, p_e, p_h, p_count, bid):
    """Every pixel the flight from (xa, ya, za) crosses in plan during [0, t_end] (a grid traversal along the
    straight plan path, Amanatides & Woo 1987), with the block's kinetic energy [kJ] and height above ground
    [m] at the entry, middle and exit of each pixel (the maxima are kept)."""
    ny, nx = zg.shape
    xb, yb = xa + vx * t_end, ya + vy * t_end
    ua, va = (xa - x0) / dx + 0.5, (ya - y0) / dy + 0.5
    ub, vb = (xb - x0) / dx + 0.5, (yb - y0) / dy + 0.5
    j, i = int(math.floor(ua)), int(math.floor(va))
    jb, ib = int(math.floor(ub)), int(math.floor(vb))
    du, dv = ub - ua, vb - va
    sj = 1 if du > 0 else -1
    si = 1 if dv > 0 else -1
    tdu = abs(1.0 / du) if du != 0.0 else math.inf
    tdv = abs(1.0 / dv) if dv != 0.0 else math.inf
    tmu = ((j + 1 - ua) if du > 0 else (ua - j)) * tdu if du != 0.0 else math.inf
    tmv = ((i + 1 - va) if dv > 0 else (va - i)) * tdv if dv != 0.0 else math.inf
    s_in = 0.0
    for _ in range(4 * (nx + ny) + 4):
        s_out = min(tmu, tmv, 1.0)
        if 0 <= i < ny and 0 <= j < nx:
            for f in (s_in, 0.5 * (s_in + s_out), s_out):
                t = f * t_end
                zc = za + vz * t - 0.5 * g * t * t
                hh = _height(zg, x0, y0, dx, dy, xa + vx * t, ya + vy * t, zc)
                vzz = vz - g * t
                e = (0.5 * mass * (vx * vx + vy * vy + vzz * vzz) + 0.5 * inertia * w * w) / 1000.0
                _pass_add(acc, p_block, p_cell, p_e, p_h, p_count, bid, i * nx + j, e,
                          hh if hh == hh else 0.0)
        if (i == ib and j == jb) or s_out >= 1.0:
            break
        s_in = s_out
        if tmu < tmv:
            j += sj
            tmu += tdu
        else:
            i += si
            tmv += tdv


@njit(cache=True)
def _collector_hits(c_ax, c_ay, c_bx, c_by, c_id, c_s0, xa, ya, xb, yb, s_hit, j_hit, lam_hit):
    """Collector segments crossed by the plan segment (xa, ya) -> (xb, yb): fills s_hit (fraction along the
    motion, in (0, 1]), j_hit (segment) and lam_hit (fraction along the collector segment), sorted by s_hit
    (the order of the motion); returns the count.  A crossing within 1e-9 m of the start is not counted (the
    block starts on the line it has just crossed, after a barrier let it through)."""
    n = 0
    ex, ey = xb - xa, yb - ya
    s_min = 1e-9 / max(math.sqrt(ex * ex + ey * ey), 1e-300)
    for k in range(c_ax.shape[0]):
        fx, fy = c_bx[k] - c_ax[k], c_by[k] - c_ay[k]
        den = ex * fy - ey * fx
        if den == 0.0:
            continue
        gx, gy = c_ax[k] - xa, c_ay[k] - ya
        s = (gx * fy - gy * fx) / den
        lam = (gx * ey - gy * ex) / den
        if s_min < s <= 1.0 and 0.0 <= lam <= 1.0:
            # insertion in order of s (a handful of hits at most)
            q = n
            while q > 0 and s_hit[q - 1] > s:
                s_hit[q], j_hit[q], lam_hit[q] = s_hit[q - 1], j_hit[q - 1], lam_hit[q - 1]
                q -= 1
            s_hit[q], j_hit[q], lam_hit[q] = s, k, lam
            n += 1
    return n


@njit(cache=True)
def _record_cross(r_block, r_coll, r_s, r_t, r_x, r_y, r_vx, r_vy, r_vz, r_w, r_h, r_out, r_count,
                  bid, coll, s_along, t, x, y, vx, vy, vz, w, h, mass, inertia, r, cap_kj, net_m):
    """Record a crossing; at a barrier (``net_m`` not NaN) decide its outcome first with
    :func:`simulation.kernel.barrier_outcome`.  Returns (outcome, share of kinetic energy kept)."""
    outcome = CROSSED
    keep = 1.0
    if net_m == net_m:
        e = (0.5 * mass * (vx * vx + vy * vy + vz * vz) + 0.5 * inertia * w * w) / 1000.0
        outcome, keep = barrier_outcome(e, h, r, cap_kj, net_m)
    i = r_count[0]
    if i < r_block.shape[0]:
        r_block[i], r_coll[i], r_s[i], r_t[i], r_x[i], r_y[i] = bid, coll, s_along, t, x, y
        r_vx[i], r_vy[i], r_vz[i], r_w[i], r_h[i], r_out[i] = vx, vy, vz, w, h, outcome
        r_count[0] = i + 1
    else:
        r_count[1] += 1
    return outcome, keep


@njit(cache=True, inline="always")
def _record_path(pb, pt, px, py, pz, pv, pmode, pcount, bid, t, x, y, z, v, mode):
    i = pcount[0]
    if i < pb.shape[0]:
        pb[i], pt[i], px[i], py[i], pz[i], pv[i], pmode[i] = bid, t, x, y, z, v, mode
        pcount[0] = i + 1
