"""The compiled 3-D trajectory kernel: lumped-mass blocks on a raster DEM surface.

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

Physics (shared with the 2-D kernel :mod:`simulation.kernel`)
-------------------------------------------------------------
* Flight: exact parabola (no drag).
* Impact: in the frame of the local 3-D normal of the bilinear surface, tilted by the material's
  roughness (two angles, along and across the direction of travel, each uniform in +-atan(roughness /
  radius) as in 2-D), the normal and tangential restitution laws of :func:`simulation.contact.rebound`
  (the same compiled function the 2-D kernel calls, with the Pfeiffer & Bowen velocity scaling of e_N) act on
  the normal speed, the tangential speed and the spin.  Spin is carried as a scalar about the horizontal axis
  normal to the direction of travel; when the direction of travel turns, only the component of the spin about
  the new axis is kept (w cos of the turn), which never adds energy.
* Ground contact (rolling or sliding, as the material says): a rebound normal speed below the contact
  speed of :func:`simulation.contact.contact_speed` (``v_contact``, or the speed of a hop as high as the
  material's ``hop_height_m`` when that is larger) turns the block into contact, with
  :func:`simulation.kernel.roll_on_speed` for the transition to rolling; the block then moves along the surface in steps of at most half a cell with the
  gravity component in the tangent plane and the rolling-resistance (or sliding) friction of the 2-D
  contact law, a = f (g_t - mu_r g cos(theta) v/|v|) - c |v| v, f = 1 / (1 + k) rolling (5/7 for a sphere), 1
  sliding, mu_r = tan(phi_g) + s c / sqrt(s^2 + c^2), s = K (roughness / r)^a, c the room below the material's cap
  (38 deg by default; the bounded size law of :func:`simulation.contact.rolling_resistance`, the 2-D kernel's) and the
  velocity-squared drag c = rolling_drag / r [1/m].  The speed after each step comes from the work-energy
  balance over the step's 3-D path (drop minus friction work; with drag, the closed form of
  :func:`simulation.contact.contact_speed_at` along the step), so no step can gain energy; the velocity is
  re-projected onto the new tangent plane and its normal component lost (the 2-D rule at a slope change);
  where that normal component points away from the ground and exceeds the contact speed, the block takes off.
* Steep faces (``sin_max_roll`` < 1, the scenario's ``settings.max_rolling_slope_deg``): no rolling or sliding
  in contact on a surface steeper than that; a block that would enter or stay in contact there leaves it
  with its speed kept (:func:`simulation.contact.steep_face_launch`) and meets it again in impacts, as in 2-D;
  one that keeps leaving steep faces in one place (a notch or pit with flanks too steep to roll on) is held
  there (:func:`simulation.contact.steep_trap`).
* Stop: slower than ``v_stop`` where the slope angle is within the ground friction angle; a block at
  momentary rest on a steeper slope restarts down the fall line, and one that comes to rest a second
  time within half a cell of its previous rest is held there (a pit or trough between flanks).
* A block that reaches the DEM's edge or a nodata hole leaves the simulation there.
* Collectors and barriers are polylines in plan.  Every crossing of a plan segment is recorded (position
  along the line, velocity, spin, height of the centre above the ground).  A barrier is a collector with a
  net height above the ground (and a capacity, infinite when none is given): the outcome of a crossing is
  decided by the 2-D kernel's :func:`simulation.kernel.barrier_outcome` (over when the block's underside,
  centre height minus radius, is above the net; else caught within the capacity, or through with the
  energy above it); a caught block stops at the line ("caught by barrier"), one that goes through continues
  from the crossing point with the kinetic energy share (E - capacity) / E.  Crossings within one flight or
  contact step are met in the order of the motion.

Energy audit: each block's total energy E = 1/2 m v^2 + 1/2 I w^2 + m g z is evaluated after every impact
and contact step; ``out_excess`` returns the largest rise of E from one such event to the next [J] (0 when
E never rose; rounding-small unless a material allows energy gain).  Between events, flight conserves E
exactly.

Random numbers come from the 2-D kernel's counter-based stream keyed by (run seed, block index): a
block's trajectory is the same whatever chunk or thread it is run in.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .contact import (EN_WYLLIE, block_ground_resistance, contact_speed, contact_speed_at, contact_stop_distance,
                      contact_time, rebound, roll_on_speed, rolling_resistance, steep_face_launch, steep_trap)
from .kernel import (BARRIER_CAUGHT, BARRIER_THROUGH, CROSSED, OUTCOMES, _GOLDEN, _normal, _uniform,  # noqa: F401
                     barrier_outcome)


RUNNING, STOPPED, LEFT_TERRAIN, NODATA, MAX_EVENTS, CAUGHT = 0, 1, 2, 3, 4, 5
STOP_REASONS = {STOPPED: "stopped", LEFT_TERRAIN: "left terrain (edge)", NODATA: "left terrain (nodata)",
                MAX_EVENTS: "event limit reached", CAUGHT: "caught by barrier"}
MODE_FLIGHT, MODE_CONTACT, MODE_STOP = 0, 1, 2


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
def _axis_cos(sx, sy, tx, ty):
    """Cosine between the spin axes of travel directions s and t: each axis is horizontal and normal to the
    direction's horizontal part, so a change of pitch keeps the spin and a turn in plan by phi keeps w cos phi
    (1 when either direction is vertical)."""
    ls = math.sqrt(sx * sx + sy * sy)
    lt = math.sqrt(tx * tx + ty * ty)
    if ls < 1e-12 or lt < 1e-12:
        return 1.0
    return (sx * tx + sy * ty) / (ls * lt)


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
def _stop_fraction(u, u2sq, a_s, c, ds):
    """Share of a contact step [-] after which a block of speed u [m/s] comes to rest: from the work-energy
    balance u2sq = u^2 + 2 a_s ds (no drag), or from :func:`simulation.contact.contact_stop_distance` with
    the drag c [1/m]."""
    if c > 1e-12:
        return min(contact_stop_distance(u, a_s, c) / ds, 1.0) if ds > 1e-12 else 0.0
    return u * u / (u * u - u2sq) if u * u - u2sq > 0 else 0.0


@njit(cache=True)
def _contact_time(u, v, a_s, c, d, dt_euler):
    """Time [s] a contact step takes to cover d [m] from speed u to v [m/s]: 2 d / (u + v), exact for the step's
    constant acceleration, or :func:`simulation.contact.contact_time` with the drag c [1/m] (acceleration a_s);
    the Euler step's ``dt_euler`` when the block does not move."""
    if c > 1e-12:
        t = contact_time(u, v, a_s, c, d)
        return t if t >= 0.0 else dt_euler
    return 2.0 * d / (u + v) if u + v > 1e-12 else dt_euler


@njit(cache=True)
def _leave_face(vx, vy, vz, x, y, z, nx0, ny0, nz0, v_sep, zg, x0, y0, dx, dy):
    """A block leaving a face too steep to roll on (3-D form of the 2-D rule).

    The tangential speed is kept and turned away from the face until its outward normal share is ``v_sep``
    (:func:`simulation.contact.steep_face_launch`; no energy is created).  A block at rest against the face
    is moved 1e-6 m horizontally away from it, z unchanged, so it falls onto the face from just above -- only
    where the surface there is not above the block (at the bottom of a notch it stays, and the run of launches
    in one place ends it: :func:`simulation.contact.steep_trap`).  The step is a fixed length, not a share of
    the coordinates, so a DEM in map coordinates (x ~ 2.6e6 m) behaves as one near the origin.

    Returns
    -------
    tuple of float
        (vx, vy, vz, x, y, z, tx, ty, tz): the new velocity [m/s], position [m] and travel direction.
    """
    vn = vx * nx0 + vy * ny0 + vz * nz0
    tx, ty, tz = vx - vn * nx0, vy - vn * ny0, vz - vn * nz0
    ut = math.sqrt(tx * tx + ty * ty + tz * tz)
    if ut > 1e-12:
        tx, ty, tz = tx / ut, ty / ut, tz / ut
    else:                       # no tangential motion: down the fall line
        tx, ty, tz = _downhill(nx0, ny0, nz0)
    vt_new, vn_new = steep_face_launch(ut, v_sep)
    if vn_new <= 0.0:
        hl = math.sqrt(nx0 * nx0 + ny0 * ny0)
        if hl > 1e-12:
            x2, y2 = x + 1e-6 * nx0 / hl, y + 1e-6 * ny0 / hl
            z2, _, _ = _surface(zg, x0, y0, dx, dy, x2, y2)
            if z2 == z2 and z2 <= z:
                x, y = x2, y2
    return (vt_new * tx + vn_new * nx0, vt_new * ty + vn_new * ny0, vt_new * tz + vn_new * nz0, x, y, z + 1e-9,
            tx, ty, tz)


#: Largest sd of the deviation angle at an impact [rad] (22.5 deg), and the largest deviation (90 deg: a block
#: never turns back at an impact).
DEVIATION_SD_MAX_RAD = math.pi / 8.0
DEVIATION_MAX_RAD = math.pi / 2.0


@njit(cache=True)
def deviation_sd(gain, roughness, r, v, v_scale, factor):
    """Standard deviation [rad] of the random turn of a block's direction of travel at an impact.

    sigma = min(D (roughness / r) s_b / (1 + v / v_D), pi / 8): it grows with the roughness relative to the
    block (the ratio of the roughness tilt, :func:`simulation.contact.roughness_tilt_max`) and with the block's own
    deviation factor s_b (its shape; per block, ``sources.deviation_factor``), and falls with the impact speed,
    as Rockyfor3D's rule has it: after a rebound the fall direction deviates at random, less at high speed
    and more on rough ground (Dorren 2016, "Rockyfor3D (v5.2) revealed", section 3.5 "Calculation of the fall
    direction", pp. 21-23) [R: the form of the dependence is chosen here, D, v_D and the cap are this
    project's defaults, not Rockyfor3D's numbers].  Shape: non-spherical blocks spread laterally more than
    compact ones (RAMMS::ROCKFALL's shape-dependent contacts, Leine et al. 2014; Caviezel et al. 2021) [R].

    Parameters
    ----------
    gain : float
        D, the material's ``lateral_deviation`` [-] (0: no deviation).
    roughness : float
        The material's roughness (asperity height) [m].
    r : float
        Block radius [m].
    v : float
        Impact speed [m/s].
    v_scale : float
        v_D, the material's ``lateral_deviation_speed_ms`` [m/s]: the speed at which the spread halves.
    factor : float
        s_b, the block's deviation factor [-].

    Returns
    -------
    float
        The sd of the deviation angle [rad], at most pi / 8.
    """
    if gain <= 0.0 or roughness <= 0.0 or r <= 0.0 or factor <= 0.0:
        return 0.0
    return min(gain * roughness / r * factor / (1.0 + v / v_scale), DEVIATION_SD_MAX_RAD)


@njit(cache=True, inline="always")
def _turn(vx, vy, vz, nx0, ny0, nz0, delta):
    """(vx, vy, vz) turned by ``delta`` [rad] about the unit normal (nx0, ny0, nz0) (Rodrigues): the speed and the
    normal component are kept, so the turn neither creates energy nor changes the contact decision."""
    c, s = math.cos(delta), math.sin(delta)
    dn = (vx * nx0 + vy * ny0 + vz * nz0) * (1.0 - c)
    cx, cy, cz = ny0 * vz - nz0 * vy, nz0 * vx - nx0 * vz, nx0 * vy - ny0 * vx
    return vx * c + cx * s + nx0 * dn, vy * c + cy * s + ny0 * dn, vz * c + cz * s + nz0 * dn


@njit(cache=True)
def _safe_step(h, vh, vz, g, lip):
    """Longest time [s] a flight at height h [m] above the ground, horizontal speed vh and vertical speed vz
    [m/s], can go without meeting a ground whose slope is at most ``lip``: the root of
    1/2 g t^2 + (lip vh - vz) t = h (the parabola's drop plus the steepest possible rise of the ground)."""
    b = lip * vh - vz
    return (-b + math.sqrt(b * b + 2.0 * g * h)) / g


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


@njit(cache=True, nogil=True)
def simulate3d(blocks, grid, mats, m_drag, collectors, settings, sin_max_roll, rec_pass, stops, crossings, passages,
               paths):
    """Run every block of a chunk on the DEM surface; fill the output arrays in place.

    Grid: ``zg`` (ny, nx) elevations [m] (NaN holes), centre of cell (0, 0) at (x0, y0), cell size dx, dy [m];
    ``lip`` an upper bound of the surface slope (|grad z|) used to step flights safely; ``mat_grid`` material
    index per cell.  Collectors: plan segments (c_ax, c_ay)-(c_bx, c_by) of collector ``c_id``, starting at
    distance ``c_s0`` [m] along their polyline; a barrier segment has a net height ``c_net`` [m] above the
    ground and capacity ``c_cap`` [kJ] (``c_net`` NaN: a plain collector).  With ``rec_pass`` every pixel a
    block crosses is recorded once per visit with the block's largest kinetic energy [kJ] and height above ground
    [m] there (hazard maps).
    Buffers that fill up count the rows that did not fit (``r_count[1]``, ``p_count[1]``): the caller reruns
    the chunk with larger ones (results depend only on the seed and block index).

    Parameters
    ----------
    blocks : simulation.kernel_args.Blocks3D
        The chunk's blocks: global index, release position [m], velocity [m/s], spin [rad/s], mass [kg], radius
        [m], inertia factor [-] and deviation factor s_b [-] (its shape).
    grid : simulation.kernel_args.Grid3D
        Elevations (ny, nx) [m] with NaN holes, centre of cell (0, 0) [m], cell size [m], Lipschitz bound [-],
        material index per cell.
    mats : simulation.kernel_args.MaterialTable
        The material table, with the lateral deviation's gain D [-] (0: none) and speed scale v_D [m/s]
        (:func:`deviation_sd`).
    m_drag : numpy.ndarray
        Per material: rolling drag coefficient [-] (c = m_drag / r [1/m]).
    collectors : simulation.kernel_args.Collectors3D
        The collectors' plan segments, their collector, start along its polyline [m], capacity [kJ] and net
        height [m].
    settings : simulation.kernel_args.KernelSettings
        Gravity, contact and stop speeds, event limit, random key, blocks whose paths are recorded.
    sin_max_roll : float
        Sine of the steepest slope a block may roll or slide on in contact (1: any slope).
    rec_pass : bool
        Record the pixels each block crosses.
    stops : simulation.kernel_args.Stops3D
        Output per block: stop position [m], stop reason code, impacts, travel time [s], largest rise of the
        total energy between events [J], events.
    crossings : simulation.kernel_args.Crossings3D
        Output per crossing, and the counts written and not fitted.
    passages : simulation.kernel_args.Passages3D
        Output per pixel passage: block, cell, largest kinetic energy [kJ] and height above the ground [m], and
        the counts written and not fitted.
    paths : simulation.kernel_args.Paths3D
        Output per path point, and the count written.
    """
    block_ids, bx, by, bz, bvx, bvy, bvz, bw, bmass, bradius, bk, bres, b_dev = blocks
    zg, x0, y0, dx, dy, lip, mat_grid, rough_grid = grid
    (m_en_law, m_en_mean, m_en_std, m_et_law, m_et_mean, m_et_std, m_phi, m_phi_std, m_rough, m_roll, m_mu_ground,
     m_gain, m_en_v0, m_hop, m_size_k, m_mu_cap, m_size_exp, m_et_v0, m_phig, m_phig_std, m_dev, m_dev_v) = mats
    c_ax, c_ay, c_bx, c_by, c_id, c_s0, c_cap, c_net = collectors
    g, v_contact, v_stop, max_events, key, n_path_blocks = settings
    out_x, out_y, out_z, out_reason, out_impacts, out_t, out_excess, out_events = stops
    r_block, r_coll, r_s, r_t, r_x, r_y, r_vx, r_vy, r_vz, r_w, r_h, r_out, r_count = crossings
    p_block, p_cell, p_e, p_h, p_count = passages
    pb, pt, ppx, ppy, ppz, ppv, pmode, pcount = paths
    ny, nx = zg.shape
    step_len = 0.5 * min(dx, dy)
    n_cseg = c_ax.shape[0]
    s_hit = np.empty(max(n_cseg, 1))
    lam_hit = np.empty(max(n_cseg, 1))
    j_hit = np.empty(max(n_cseg, 1), np.int64)
    state = np.empty(1, np.uint64)
    acc = np.empty(3)
    # Per material and block: tan(phi_g) of this block (block_ground_resistance), set once per block where a material
    # has a spread of phi_g between blocks (otherwise the materials' own, for every block).
    mu_blk = m_mu_ground.copy()
    spread = False
    for m in range(m_phig_std.shape[0]):
        spread = spread or m_phig_std[m] > 0.0
    for b in range(block_ids.shape[0]):
        bid = block_ids[b]
        state[0] = key ^ (np.uint64(bid + 1) * _GOLDEN)
        if spread:
            for m in range(mu_blk.shape[0]):
                mu_blk[m] = block_ground_resistance(m_mu_ground[m], m_phig[m], m_phig_std[m], bres[b])
        mass, r, k_in = bmass[b], bradius[b], bk[b]
        inertia = k_in * mass * r * r
        x, y, z = bx[b], by[b], bz[b]
        vx, vy, vz, w = bvx[b], bvy[b], bvz[b], bw[b]
        # spin axis: horizontal, normal to the direction of travel; sx, sy, sz = the travel direction it rolls
        vh0 = math.sqrt(vx * vx + vy * vy)
        sx, sy, sz = (vx / vh0, vy / vh0, 0.0) if vh0 > 0 else (1.0, 0.0, 0.0)
        e0 = 0.5 * mass * (vx * vx + vy * vy + vz * vz) + 0.5 * inertia * w * w + mass * g * z
        excess = 0.0
        e_prev = e0
        t_abs = 0.0
        record = bid < n_path_blocks
        acc[0], acc[1], acc[2] = -1.0, 0.0, 0.0
        zs, gx, gy = _surface(zg, x0, y0, dx, dy, x, y)
        contact = z - zs <= 1e-9
        if contact:
            z = zs
            # project the start velocity on the tangent plane
            nl = math.sqrt(gx * gx + gy * gy + 1.0)
            nxv, nyv, nzv = -gx / nl, -gy / nl, 1.0 / nl
            vn = vx * nxv + vy * nyv + vz * nzv
            vx, vy, vz = vx - vn * nxv, vy - vn * nyv, vz - vn * nzv
            u = math.sqrt(vx * vx + vy * vy + vz * vz)
            if m_roll[mat_grid[min(max(int(round((y - y0) / dy)), 0), ny - 1),
                               min(max(int(round((x - x0) / dx)), 0), nx - 1)]]:
                u2 = roll_on_speed(u, w, r, k_in)
                if u > 0:
                    vx, vy, vz = vx * u2 / u, vy * u2 / u, vz * u2 / u
                w = abs(u2) / r
            else:
                w = 0.0
        if record:
            _record_path(pb, pt, ppx, ppy, ppz, ppv, pmode, pcount, bid, 0.0, x, y, z,
                         math.sqrt(vx * vx + vy * vy + vz * vz), MODE_CONTACT if contact else MODE_FLIGHT)
        reason = RUNNING
        impacts = 0
        events = 0
        last_rest_x, last_rest_y = math.inf, math.inf
        trap_n, trap_x, trap_y = 0, 0.0, 0.0          # the run of launches from steep faces (steep_trap)
        have_s, c_gx, c_gy = False, 0.0, 0.0
        while reason == RUNNING:
            events += 1
            if events > max_events:
                reason = MAX_EVENTS
                break
            if not contact:
                t_hit, status = _find_impact(zg, x0, y0, dx, dy, lip, x, y, z, vx, vy, vz, g)
                # collectors and hazard pixels along the flight (its plan path is a straight line)
                cut = False
                if n_cseg > 0 and t_hit > 0:
                    n_h = _collector_hits(c_ax, c_ay, c_bx, c_by, c_id, c_s0, x, y, x + vx * t_hit,
                                          y + vy * t_hit, s_hit, j_hit, lam_hit)
                    for q in range(n_h):
                        tc = s_hit[q] * t_hit
                        k = j_hit[q]
                        xc, yc = x + vx * tc, y + vy * tc
                        zc = z + vz * tc - 0.5 * g * tc * tc
                        hc = _height(zg, x0, y0, dx, dy, xc, yc, zc)
                        hc = hc if hc == hc else 0.0
                        seg_len = math.sqrt((c_bx[k] - c_ax[k]) ** 2 + (c_by[k] - c_ay[k]) ** 2)
                        outcome, keep = _record_cross(
                            r_block, r_coll, r_s, r_t, r_x, r_y, r_vx, r_vy, r_vz, r_w, r_h, r_out, r_count,
                            bid, c_id[k], c_s0[k] + lam_hit[q] * seg_len, t_abs + tc, xc, yc, vx, vy, vz - g * tc, w,
                            hc, mass, inertia, r, c_cap[k], c_net[k])
                        if outcome == BARRIER_CAUGHT or outcome == BARRIER_THROUGH:
                            # the barrier cuts the flight at the line
                            if rec_pass:
                                _flight_passages(zg, x0, y0, dx, dy, x, y, z, vx, vy, vz, w, tc, g, mass, inertia,
                                                 acc, p_block, p_cell, p_e, p_h, p_count, bid)
                            f = math.sqrt(keep)
                            x, y, z = xc, yc, zc
                            vx, vy, vz, w = vx * f, vy * f, (vz - g * tc) * f, w * f
                            t_abs += tc
                            if outcome == BARRIER_CAUGHT:
                                z = zc - hc
                                reason = CAUGHT
                            if record:
                                _record_path(pb, pt, ppx, ppy, ppz, ppv, pmode, pcount, bid, t_abs, x, y, z,
                                             math.sqrt(vx * vx + vy * vy + vz * vz), MODE_FLIGHT)
                            cut = True
                            break
                if cut:
                    continue
                if rec_pass and t_hit > 0:
                    _flight_passages(zg, x0, y0, dx, dy, x, y, z, vx, vy, vz, w, t_hit, g, mass, inertia,
                                     acc, p_block, p_cell, p_e, p_h, p_count, bid)
                x, y = x + vx * t_hit, y + vy * t_hit
                z = z + vz * t_hit - 0.5 * g * t_hit * t_hit
                vz = vz - g * t_hit
                t_abs += t_hit
                if status == 1 or status == 2:
                    reason = LEFT_TERRAIN if status == 1 else NODATA
                    break
                impacts += 1
                zs, gx, gy = _surface(zg, x0, y0, dx, dy, x, y)
                z = zs
                ci, cj = min(max(int(round((y - y0) / dy)), 0), ny - 1), min(max(int(round((x - x0) / dx)), 0), nx - 1)
                mat = mat_grid[ci, cj]
                rough = cell_roughness(rough_grid, m_rough, mat, ci, cj)
                nl = math.sqrt(gx * gx + gy * gy + 1.0)
                nx0, ny0, nz0 = -gx / nl, -gy / nl, 1.0 / nl
                vn_t = vx * nx0 + vy * ny0 + vz * nz0
                v_in = math.sqrt(vx * vx + vy * vy + vz * vz)
                # travel direction in the tangent plane, and the lateral direction n x t1
                t1x, t1y, t1z = vx - vn_t * nx0, vy - vn_t * ny0, vz - vn_t * nz0
                tl = math.sqrt(t1x * t1x + t1y * t1y + t1z * t1z)
                if tl < 1e-12:          # head-on: take the fall line (on flat ground, +x) as the travel direction
                    t1x, t1y, t1z = _downhill(nx0, ny0, nz0)
                else:
                    t1x, t1y, t1z = t1x / tl, t1y / tl, t1z / tl
                t2x, t2y, t2z = ny0 * t1z - nz0 * t1y, nz0 * t1x - nx0 * t1z, nx0 * t1y - ny0 * t1x
                theta_max = math.atan(rough / r) if r > 0 else 0.0
                d1 = (2.0 * _uniform(state) - 1.0) * theta_max
                d2 = (2.0 * _uniform(state) - 1.0) * theta_max
                a1, a2 = math.tan(d1), math.tan(d2)
                nnx, nny, nnz = nx0 + a1 * t1x + a2 * t2x, ny0 + a1 * t1y + a2 * t2y, nz0 + a1 * t1z + a2 * t2z
                nnl = math.sqrt(nnx * nnx + nny * nny + nnz * nnz)
                nnx, nny, nnz = nnx / nnl, nny / nnl, nnz / nnl
                vn = vx * nnx + vy * nny + vz * nnz
                if vn >= 0.0:
                    nnx, nny, nnz = nx0, ny0, nz0
                    vn = vn_t
                gain = m_gain[mat]
                cap = 10.0 if gain else 1.0
                if m_en_law[mat] == EN_WYLLIE:
                    en = m_en_std[mat] * _normal(state) if m_en_std[mat] > 0 else 0.0
                else:
                    en = min(max(m_en_mean[mat] + m_en_std[mat] * _normal(state), 0.0), cap) \
                        if m_en_std[mat] > 0 else m_en_mean[mat]
                et = min(max(m_et_mean[mat] + m_et_std[mat] * _normal(state), 0.0), cap) \
                    if m_et_std[mat] > 0 else m_et_mean[mat]
                phi = m_phi[mat] + (m_phi_std[mat] * _normal(state) if m_phi_std[mat] > 0 else 0.0)
                mu = math.tan(math.radians(min(max(phi, 0.0), 89.0)))
                # tangential velocity in the (tilted) impact frame
                tx, ty, tz = vx - vn * nnx, vy - vn * nny, vz - vn * nnz
                vt = math.sqrt(tx * tx + ty * ty + tz * tz)
                if vt > 1e-12:
                    tx, ty, tz = tx / vt, ty / vt, tz / vt
                else:
                    tx, ty, tz = sx, sy, sz
                w_eff = w * _axis_cos(sx, sy, tx, ty)      # spin about the axis normal to the travel
                if vn < 0.0:
                    vn2, vt2, w2, _ = rebound(vn, vt, w_eff, r, k_in, m_en_law[mat], en, m_en_v0[mat], m_et_law[mat],
                                              et, mu, gain, m_et_v0[mat])
                else:
                    vn2, vt2, w2 = 0.0, vt, w_eff
                vx, vy, vz = vt2 * tx + vn2 * nnx, vt2 * ty + vn2 * nny, vt2 * tz + vn2 * nnz
                w = w2
                sx, sy, sz = tx, ty, tz
                if m_dev[mat] > 0.0:
                    # lateral deviation: the direction of travel turns about the ground normal by a random angle
                    # (deviation_sd); the spin axis turns with it, speed and normal share are kept
                    sig = deviation_sd(m_dev[mat], rough, r, v_in, m_dev_v[mat], b_dev[b])
                    if sig > 0.0:
                        dlt = min(max(sig * _normal(state), -DEVIATION_MAX_RAD), DEVIATION_MAX_RAD)
                        vx, vy, vz = _turn(vx, vy, vz, nx0, ny0, nz0, dlt)
                        sx, sy, sz = _turn(sx, sy, sz, nx0, ny0, nz0, dlt)
                vn_true = vx * nx0 + vy * ny0 + vz * nz0
                v_thr = contact_speed(v_contact, g, nz0, m_hop[mat])
                if vn_true < v_thr and 1.0 - nz0 * nz0 > sin_max_roll * sin_max_roll:
                    # a face too steep to roll on: the block leaves it again (speed kept), no ground contact --
                    # unless it has kept doing so in one place (a notch or pit with flanks too steep to roll on)
                    trap_n, trap_x, trap_y, trapped = steep_trap(trap_n, trap_x, trap_y, x, y)
                    if trapped:
                        reason = STOPPED
                        vx, vy, vz, w = 0.0, 0.0, 0.0, 0.0
                        break
                    vx, vy, vz, x, y, z, sx, sy, sz = _leave_face(vx, vy, vz, x, y, z, nx0, ny0, nz0, v_thr, zg, x0,
                                                                  y0, dx, dy)
                elif vn_true < v_thr:
                    contact = True
                    vx, vy, vz = vx - vn_true * nx0, vy - vn_true * ny0, vz - vn_true * nz0
                    u = math.sqrt(vx * vx + vy * vy + vz * vz)
                    if u > 1e-12:
                        dxv, dyv, dzv = vx / u, vy / u, vz / u
                    else:
                        dxv, dyv, dzv = sx, sy, sz
                    if m_roll[mat]:
                        u2 = roll_on_speed(u, w * _axis_cos(sx, sy, dxv, dyv), r, k_in)
                        if u2 < 0:
                            dxv, dyv, dzv, u2 = -dxv, -dyv, -dzv, -u2
                        w = u2 / r
                    else:
                        u2 = u
                        w = 0.0
                    vx, vy, vz = u2 * dxv, u2 * dyv, u2 * dzv
                    sx, sy, sz = dxv, dyv, dzv
                e = 0.5 * mass * (vx * vx + vy * vy + vz * vz) + 0.5 * inertia * w * w + mass * g * z
                excess = max(excess, e - e_prev)
                e_prev = e
                if record:
                    _record_path(pb, pt, ppx, ppy, ppz, ppv, pmode, pcount, bid, t_abs, x, y, z,
                                 math.sqrt(vx * vx + vy * vy + vz * vz), MODE_CONTACT if contact else MODE_FLIGHT)
                continue

            # ---- ground contact: one step along the surface ----
            if have_s:            # the surface here was evaluated at the end of the previous step
                gx, gy = c_gx, c_gy
            else:
                zs, gx, gy = _surface(zg, x0, y0, dx, dy, x, y)
            have_s = False
            ci, cj = min(max(int(round((y - y0) / dy)), 0), ny - 1), min(max(int(round((x - x0) / dx)), 0), nx - 1)
            mat = mat_grid[ci, cj]
            nl = math.sqrt(gx * gx + gy * gy + 1.0)
            nx0, ny0, nz0 = -gx / nl, -gy / nl, 1.0 / nl
            if 1.0 - nz0 * nz0 > sin_max_roll * sin_max_roll:
                # no rolling or sliding in contact on a face this steep: the block leaves it (speed kept), unless
                # it has kept doing so in one place (steep_trap)
                trap_n, trap_x, trap_y, trapped = steep_trap(trap_n, trap_x, trap_y, x, y)
                if trapped:
                    reason = STOPPED
                    vx, vy, vz, w = 0.0, 0.0, 0.0, 0.0
                    break
                vn_c = vx * nx0 + vy * ny0 + vz * nz0
                vx, vy, vz = vx - vn_c * nx0, vy - vn_c * ny0, vz - vn_c * nz0
                vx, vy, vz, x, y, z, sx, sy, sz = _leave_face(vx, vy, vz, x, y, z, nx0, ny0, nz0,
                                                              contact_speed(v_contact, g, nz0, m_hop[mat]), zg, x0,
                                                              y0, dx, dy)
                contact = False
                if record:
                    _record_path(pb, pt, ppx, ppy, ppz, ppv, pmode, pcount, bid, t_abs, x, y, z,
                                 math.sqrt(vx * vx + vy * vy + vz * vz), MODE_FLIGHT)
                continue
            mu = rolling_resistance(mu_blk[mat], m_size_k[mat], cell_roughness(rough_grid, m_rough, mat, ci, cj), r,
                                    m_mu_cap[mat], m_size_exp[mat])
            roll = m_roll[mat]
            factor = 1.0 / (1.0 + k_in) if roll else 1.0
            c_drag = m_drag[mat] / r if r > 0.0 else 0.0
            u = math.sqrt(vx * vx + vy * vy + vz * vz)
            if u < v_stop:
                near = abs(x - last_rest_x) <= 0.5 * dx and abs(y - last_rest_y) <= 0.5 * dy
                if math.sqrt(gx * gx + gy * gy) <= mu or near:
                    reason = STOPPED
                    vx, vy, vz, w = 0.0, 0.0, 0.0, 0.0
                    break
                last_rest_x, last_rest_y = x, y
                vx, vy, vz, u = 0.0, 0.0, 0.0, 0.0
                if record:
                    _record_path(pb, pt, ppx, ppy, ppz, ppv, pmode, pcount, bid, t_abs, x, y, z, 0.0, MODE_CONTACT)
            # tangential gravity g_t = g (n_z n - e_z) (down the fall line, magnitude g sin theta)
            gtx, gty, gtz = g * nz0 * nx0, g * nz0 * ny0, g * (nz0 * nz0 - 1.0)
            if u > 1e-12:
                fr = factor * mu * g * nz0 / u + c_drag * u
                ax_, ay_, az_ = factor * gtx - fr * vx, factor * gty - fr * vy, factor * gtz - fr * vz
            else:
                ax_, ay_, az_ = factor * gtx, factor * gty, factor * gtz
            # at most about half a cell per step: u dt <= step and 1/2 |a| dt^2 <= step
            a_mag = math.sqrt(ax_ * ax_ + ay_ * ay_ + az_ * az_)
            dt = min(step_len / max(u, 1e-6), math.sqrt(2.0 * step_len / max(a_mag, 1e-3)))
            if u > 1e-12:
                # and not past the moment friction would bring the block to rest: a longer Euler step reverses
                # the velocity and puts the end of the step behind the block (stops up to 10 % short)
                a_par = (ax_ * vx + ay_ * vy + az_ * vz) / u
                if a_par < 0.0:
                    dt = min(dt, u / -a_par)
            vx1, vy1, vz1 = vx + ax_ * dt, vy + ay_ * dt, vz + az_ * dt
            xn = x + 0.5 * (vx + vx1) * dt
            yn = y + 0.5 * (vy + vy1) * dt
            zn, gxn, gyn = _surface(zg, x0, y0, dx, dy, xn, yn)
            if not zn == zn:
                ue, ve = (xn - x0) / dx, (yn - y0) / dy
                edge = ue < 0.0 or ve < 0.0 or ue > nx - 1 or ve > ny - 1
                reason = LEFT_TERRAIN if edge else NODATA
                break
            ds = math.sqrt((xn - x) ** 2 + (yn - y) ** 2 + (zn - z) ** 2)
            nln = math.sqrt(gxn * gxn + gyn * gyn + 1.0)
            nz_avg = 0.5 * (nz0 + 1.0 / nln)
            # work-energy balance over the step (per unit mass, rolling share f = 1/(1+k)); with drag, the
            # closed form of dv/dt = a_s - c v^2 along the step (a_s: the constant-acceleration share)
            u2sq = u * u + 2.0 * factor * (g * (z - zn) - mu * g * nz_avg * ds)
            a_s = 0.0
            if c_drag > 1e-12:
                a_s = factor * (g * (z - zn) - mu * g * nz_avg * ds) / ds if ds > 1e-12 else 0.0
                d_stop = contact_stop_distance(u, a_s, c_drag)
                u2sq = -1.0 if d_stop < ds else contact_speed_at(u, a_s, c_drag, ds) ** 2
            # collectors crossed on this step (height 0: in contact), up to where the block comes to rest
            if n_cseg > 0:
                n_h = _collector_hits(c_ax, c_ay, c_bx, c_by, c_id, c_s0, x, y, xn, yn, s_hit, j_hit, lam_hit)
                f_end = 1.0 if u2sq > 0.0 else _stop_fraction(u, u2sq, a_s, c_drag, ds)
                cut = False
                for q in range(n_h):
                    fq = s_hit[q]
                    if fq > f_end:
                        break
                    k = j_hit[q]
                    seg_len = math.sqrt((c_bx[k] - c_ax[k]) ** 2 + (c_by[k] - c_ay[k]) ** 2)
                    xq, yq = x + fq * (xn - x), y + fq * (yn - y)
                    if c_net[k] == c_net[k]:
                        # a barrier: the speed from the work-energy balance up to the line itself
                        zq, _, _ = _surface(zg, x0, y0, dx, dy, xq, yq)
                        dsq = math.sqrt((xq - x) ** 2 + (yq - y) ** 2 + (zq - z) ** 2)
                        uq = math.sqrt(max(u * u + 2.0 * factor * (g * (z - zq) - mu * g * nz_avg * dsq), 0.0))
                        dq, aq = dsq, 0.0
                        if c_drag > 1e-12 and dsq > 1e-12:
                            aq = factor * (g * (z - zq) - mu * g * nz_avg * dsq) / dsq
                            uq = contact_speed_at(u, aq, c_drag, dsq)
                    else:
                        zq = z
                        uq = math.sqrt(max(u * u + fq * (u2sq - u * u), 0.0))
                        dq, aq = fq * ds, a_s
                        if c_drag > 1e-12:
                            uq = contact_speed_at(u, a_s, c_drag, fq * ds)
                    tq = _contact_time(u, uq, aq, c_drag, dq, fq * dt)
                    ul = max(math.sqrt(vx1 * vx1 + vy1 * vy1 + vz1 * vz1), 1e-300)
                    wq = uq / r if roll else 0.0
                    outcome, keep = _record_cross(
                        r_block, r_coll, r_s, r_t, r_x, r_y, r_vx, r_vy, r_vz, r_w, r_h, r_out, r_count,
                        bid, c_id[k], c_s0[k] + lam_hit[q] * seg_len, t_abs + tq, xq, yq,
                        vx1 / ul * uq, vy1 / ul * uq, vz1 / ul * uq, wq, 0.0, mass, inertia, r, c_cap[k], c_net[k])
                    if outcome == BARRIER_CAUGHT or outcome == BARRIER_THROUGH:
                        t_abs += tq
                        x, y, z = xq, yq, zq
                        have_s = False
                        if outcome == BARRIER_CAUGHT:
                            vx, vy, vz, w = 0.0, 0.0, 0.0, 0.0
                            reason = CAUGHT
                        else:
                            # on with the energy share kept, along the tangent plane at the line
                            u3 = uq * math.sqrt(keep)
                            _, gxq, gyq = _surface(zg, x0, y0, dx, dy, xq, yq)
                            nlq = math.sqrt(gxq * gxq + gyq * gyq + 1.0)
                            nxq, nyq, nzq = -gxq / nlq, -gyq / nlq, 1.0 / nlq
                            dxv, dyv, dzv = vx1 / ul, vy1 / ul, vz1 / ul
                            dn = dxv * nxq + dyv * nyq + dzv * nzq
                            dxv, dyv, dzv = dxv - dn * nxq, dyv - dn * nyq, dzv - dn * nzq
                            dl = math.sqrt(dxv * dxv + dyv * dyv + dzv * dzv)
                            if dl > 1e-12:
                                vx, vy, vz = u3 * dxv / dl, u3 * dyv / dl, u3 * dzv / dl
                                sx, sy, sz = dxv / dl, dyv / dl, dzv / dl
                            else:
                                vx, vy, vz, u3 = 0.0, 0.0, 0.0, 0.0
                            w = u3 / r if roll else 0.0
                        if rec_pass:
                            sp = math.sqrt(vx * vx + vy * vy + vz * vz)
                            _pass_add(acc, p_block, p_cell, p_e, p_h, p_count, bid,
                                      _cell_of(x0, y0, dx, dy, nx, ny, x, y),
                                      (0.5 * mass * sp * sp + 0.5 * inertia * w * w) / 1000.0, 0.0)
                        e = 0.5 * mass * (vx * vx + vy * vy + vz * vz) + 0.5 * inertia * w * w + mass * g * z
                        excess = max(excess, e - e_prev)
                        e_prev = e
                        if record:
                            _record_path(pb, pt, ppx, ppy, ppz, ppv, pmode, pcount, bid, t_abs, x, y, z,
                                         math.sqrt(vx * vx + vy * vy + vz * vz), MODE_CONTACT)
                        cut = True
                        break
                if cut:
                    if reason != RUNNING:
                        break
                    continue
            if u2sq <= 0.0:
                # the block comes to rest within the step: where the balance reaches zero, if that point is
                # not above what the energy allows; else it stays (a momentary rest decides next)
                fz = _stop_fraction(u, u2sq, a_s, c_drag, ds)
                xr, yr = x + fz * (xn - x), y + fz * (yn - y)
                zr, _, _ = _surface(zg, x0, y0, dx, dy, xr, yr)
                if zr == zr and zr <= z + u * u / (2.0 * factor * g):
                    x, y, z = xr, yr, zr
                t_abs += _contact_time(u, 0.0, a_s, c_drag, fz * ds, fz * dt)
                vx, vy, vz, w = 0.0, 0.0, 0.0, 0.0
                if rec_pass:
                    _pass_add(acc, p_block, p_cell, p_e, p_h, p_count, bid,
                              _cell_of(x0, y0, dx, dy, nx, ny, x, y), 0.0, 0.0)
                continue
            u2 = math.sqrt(u2sq)
            # direction: the Euler velocity re-projected on the new tangent plane; its normal share is lost
            nxn, nyn, nzn = -gxn / nln, -gyn / nln, 1.0 / nln
            l1 = math.sqrt(vx1 * vx1 + vy1 * vy1 + vz1 * vz1)
            if l1 > 1e-12:
                dxv, dyv, dzv = vx1 / l1, vy1 / l1, vz1 / l1
            else:
                dxv, dyv, dzv = gtx, gty, gtz
                ll = max(math.sqrt(dxv * dxv + dyv * dyv + dzv * dzv), 1e-300)
                dxv, dyv, dzv = dxv / ll, dyv / ll, dzv / ll
            dn = dxv * nxn + dyv * nyn + dzv * nzn
            t_abs += _contact_time(u, u2, a_s, c_drag, ds, dt)
            x, y, z = xn, yn, zn
            have_s, c_gx, c_gy = True, gxn, gyn
            leaves = dn * u2 >= v_contact
            if leaves:            # the hop height of the ground there can only raise the threshold
                mat_n = mat_grid[min(max(int(round((yn - y0) / dy)), 0), ny - 1),
                                 min(max(int(round((xn - x0) / dx)), 0), nx - 1)]
                leaves = dn * u2 >= contact_speed(v_contact, g, 1.0 / nln, m_hop[mat_n])
            if leaves:
                # convex edge: the block leaves the ground with its velocity
                contact = False
                vx, vy, vz = u2 * dxv, u2 * dyv, u2 * dzv
                w = u2 / r if roll else 0.0
                z = zn + 1e-9
                have_s = False
                sx, sy, sz = dxv, dyv, dzv
            else:
                px_, py_, pz_ = dxv - dn * nxn, dyv - dn * nyn, dzv - dn * nzn
                pl = math.sqrt(px_ * px_ + py_ * py_ + pz_ * pz_)
                u3 = u2 * pl
                if pl > 1e-12:
                    px_, py_, pz_ = px_ / pl, py_ / pl, pz_ / pl
                    if roll:
                        # the 2-D rule at a slope change: a rolling block re-rolls conserving angular momentum
                        # about the new contact point (its spin about the new axis is kept)
                        u3 = roll_on_speed(u3, u2 / r * _axis_cos(dxv, dyv, px_, py_), r, k_in)
                        if u3 < 0.0:
                            px_, py_, pz_, u3 = -px_, -py_, -pz_, -u3
                    vx, vy, vz = u3 * px_, u3 * py_, u3 * pz_
                    sx, sy, sz = px_, py_, pz_
                else:
                    vx, vy, vz, u3 = 0.0, 0.0, 0.0, 0.0
                w = u3 / r if roll else 0.0
            if rec_pass:
                sp = math.sqrt(vx * vx + vy * vy + vz * vz)
                _pass_add(acc, p_block, p_cell, p_e, p_h, p_count, bid, _cell_of(x0, y0, dx, dy, nx, ny, x, y),
                          (0.5 * mass * sp * sp + 0.5 * inertia * w * w) / 1000.0, 0.0)
            e = 0.5 * mass * (vx * vx + vy * vy + vz * vz) + 0.5 * inertia * w * w + mass * g * z
            excess = max(excess, e - e_prev)
            e_prev = e
            if record:
                _record_path(pb, pt, ppx, ppy, ppz, ppv, pmode, pcount, bid, t_abs, x, y, z,
                             math.sqrt(vx * vx + vy * vy + vz * vz), MODE_CONTACT if contact else MODE_FLIGHT)
        if rec_pass:
            _pass_flush(acc, p_block, p_cell, p_e, p_h, p_count, bid)
        if record:
            _record_path(pb, pt, ppx, ppy, ppz, ppv, pmode, pcount, bid, t_abs, x, y, z,
                         math.sqrt(vx * vx + vy * vy + vz * vz), MODE_STOP)
        out_x[b], out_y[b], out_z[b], out_reason[b], out_impacts[b], out_t[b] = x, y, z, reason, impacts, t_abs
        out_excess[b] = excess
        out_events[b] = events
