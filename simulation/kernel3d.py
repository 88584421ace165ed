"""The compiled 3-D trajectory kernel: lumped-mass blocks on a raster DEM surface.

The kernel's helpers live beside it: :mod:`simulation.kernel3d_surface` (the bilinear surface, why bilinear
cells, the per-cell lookups and the exact impact of a flight), :mod:`simulation.kernel3d_contact` (impact
and contact helpers, the lateral deviation at impacts) and :mod:`simulation.kernel3d_records` (pixel passages,
collector crossings, path points).

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
                      rebound, roll_on_speed, rolling_resistance, steep_trap)
from .kernel import BARRIER_CAUGHT, BARRIER_THROUGH, _GOLDEN, _normal, _uniform
from .kernel3d_contact import (DEVIATION_MAX_RAD, _axis_cos, _contact_time, _leave_face, _stop_fraction, _turn,
                               deviation_sd)
from .kernel3d_records import _collector_hits, _flight_passages, _pass_add, _pass_flush, _record_cross, _record_path
from .kernel3d_surface import _cell_of, _downhill, _find_impact, _height, _surface, cell_roughness


RUNNING, STOPPED, LEFT_TERRAIN, NODATA, MAX_EVENTS, CAUGHT = 0, 1, 2, 3, 4, 5
STOP_REASONS = {STOPPED: "stopped", LEFT_TERRAIN: "left terrain (edge)", NODATA: "left terrain (nodata)",
                MAX_EVENTS: "event limit reached", CAUGHT: "caught by barrier"}
MODE_FLIGHT, MODE_CONTACT, MODE_STOP = 0, 1, 2


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
