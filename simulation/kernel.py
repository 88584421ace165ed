"""The compiled trajectory kernel: one block at a time, event to event.

Events are impacts, segment ends during ground contact, collector crossings and
stops.  Between events motion is exact: parabolic flight (no time stepping),
constant-acceleration rolling or sliding along a straight segment.  The next
impact segment is found by a finger search in the profile's chord-offset tree
(:mod:`simulation.slope`, the search in :mod:`simulation.impact_search`), so the cost per impact grows as
log d for a flight over d segments, not as the number of segments S.

Random numbers come from a counter-based SplitMix64 stream keyed by (run seed,
block index): a block's trajectory is the same whatever chunk it is run in.

Everything here is numba-compiled plain functions on arrays; the Python layer
(:mod:`simulation.engine`) prepares the arrays and turns outputs into tables.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .contact import (EN_WYLLIE, contact_acceleration, contact_speed, contact_speed_at,  # noqa: F401
                      block_ground_resistance, contact_stop_distance, contact_time, rebound, roll_on_speed,
                      rolling_resistance, roughness_tilt_max,
                      steep_face_launch, steep_trap)
from .impact_search import _run_hit, _seg_in, _tree_impact, chord_slopes, find_impact  # noqa: F401
from .units import J_PER_KJ

# Stop reasons.
RUNNING, STOPPED, LEFT_PROFILE, CAUGHT, MAX_EVENTS = 0, 1, 2, 3, 4
STOP_REASONS = {STOPPED: "stopped", LEFT_PROFILE: "left profile", CAUGHT: "caught by barrier",
                MAX_EVENTS: "event limit reached"}
# Collector outcomes.
CROSSED, BARRIER_CAUGHT, BARRIER_THROUGH, BARRIER_OVER = 0, 1, 2, 3
OUTCOMES = {CROSSED: "crossed", BARRIER_CAUGHT: "caught", BARRIER_THROUGH: "through", BARRIER_OVER: "over"}
# Path modes: the state after a recorded event.
MODE_FLIGHT, MODE_CONTACT, MODE_STOP = 0, 1, 2
# Recorded events (SimulationResult.events).
(EV_RELEASE, EV_IMPACT, EV_TAKEOFF, EV_CONTACT, EV_VERTEX, EV_REST, EV_BARRIER, EV_STOP, EV_LEFT, EV_CAUGHT,
 EV_LIMIT) = range(11)
EVENTS = {EV_RELEASE: "release", EV_IMPACT: "impact", EV_TAKEOFF: "take-off", EV_CONTACT: "ground contact",
          EV_VERTEX: "slope change", EV_REST: "momentary rest", EV_BARRIER: "through barrier", EV_STOP: "stop",
          EV_LEFT: "left profile", EV_CAUGHT: "caught by barrier", EV_LIMIT: "event limit"}

# The helpers that take arrays and allocate none are compiled with numba's ``_nrt=False`` (its njit option for code
# without the runtime's reference counting): numba otherwise increments and decrements the count of every array
# argument at each call, atomic operations that took about a quarter of the kernel's time (6-12 per impact
# search; measured with perf, 2026-12-07).  The numbers are unchanged; under NUMBA_DISABLE_JIT the option is moot.
# contact.rebound and _record_path are called, not inlined into the event loop by numba (``inline="always"``):
# inlining copied their code into each of the kernel's specialisations before type inference, which made compiling
# the four specialisations 32.6 s against 22.3-28.2 s, and did not make the kernel faster (LLVM still inlines what
# pays; tests/benchmarks/bench_simulator.py after the change, 2026-12-08: peer profile 2.95x commit 06331e7 side by
# side, barrier scenario 459,980-495,323 trajectories/s on one core).  _record_path is compiled once per pair of
# literal mode and event codes its call sites pass (10 small versions); it runs only for the few recorded blocks.

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)


@njit(cache=True, _nrt=False)
def _next_u64(state):
    s = state[0] + _GOLDEN
    state[0] = s
    z = s
    z = (z ^ (z >> np.uint64(30))) * _M1
    z = (z ^ (z >> np.uint64(27))) * _M2
    return z ^ (z >> np.uint64(31))


@njit(cache=True, _nrt=False)
def _uniform(state):
    return (_next_u64(state) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True, _nrt=False)
def _normal(state):
    u1 = _uniform(state)
    u2 = _uniform(state)
    return math.sqrt(-2.0 * math.log(max(u1, 1e-300))) * math.cos(2.0 * math.pi * u2)


@njit(cache=True, _nrt=False)
def _seg_of(px, x):
    """Segment index under x by bisection (left segment at a vertex)."""
    return _seg_in(px, x, np.int64(0), px.shape[0] - 2)     # int64, not a literal: one compiled version


@njit(cache=True, _nrt=False)
def _first_at_least(a, v):
    """Index of the first element of the ascending array ``a`` that is >= v (``numpy.searchsorted``, side
    "left"; written out because numba's version costs about a second of compilation).  A NaN ``v`` gives 0
    where numpy gives ``a.size``; the kernel only passes finite positions."""
    lo, hi = 0, a.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if a[mid] < v:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, _nrt=False)
def _ground(px, pz, x):
    k = _seg_of(px, x)
    return pz[k] + (pz[k + 1] - pz[k]) * (x - px[k]) / (px[k + 1] - px[k])


@njit(cache=True, _nrt=False)
def _record_crossing(r_block, r_coll, r_t, r_vx, r_vz, r_w, r_h, r_outcome, r_count, block, coll, t, vx, vz, w, h,
                     outcome):
    """Append one collector crossing; when the chunk's buffer is full, count the row that did not fit
    (the engine then runs the chunk again with a buffer of the exact size: no crossing is ever dropped)."""
    i = r_count[0]
    if i < r_block.shape[0]:
        r_block[i], r_coll[i], r_t[i] = block, coll, t
        r_vx[i], r_vz[i], r_w[i], r_h[i], r_outcome[i] = vx, vz, w, h, outcome
        r_count[0] = i + 1
    else:
        r_count[1] += 1


@njit(cache=True)
def _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, block, t, x, z, vx, vz, w, mode, event):
    """Append one event of a recorded block: state after the event, the mode that follows and the event code."""
    i = pcount[0]
    if i < pb.shape[0]:
        pb[i], pt[i], pxs[i], pzs[i], pvx[i], pvz[i], pw[i] = block, t, x, z, vx, vz, w
        pmode[i], pev[i] = mode, event
        pcount[0] = i + 1


@njit(cache=True)
def barrier_outcome(energy_kj, centre_height_m, radius_m, capacity_kj, height_m):
    """Outcome of a block meeting a flexible barrier, and the share of its kinetic energy kept.

    The simulated point is the lumped mass's centre (which, as in every lumped-mass model, meets the
    ground as a point), so the block passes over when its underside (centre height minus radius) is
    above the barrier height; otherwise the barrier holds it when the energy is within the capacity (MEL) and lets it
    through with the excess energy (E - capacity) when not.  Returns (outcome, energy share kept).

    Parameters
    ----------
    energy_kj : float
        Kinetic energy of the block [kJ].
    centre_height_m : float
        Height of the block centre above the ground at the barrier [m].
    radius_m : float
        Block radius [m].
    capacity_kj : float
        Capacity (MEL) of the barrier [kJ].
    height_m : float
        Barrier height [m].

    Returns
    -------
    outcome : int
        ``BARRIER_CAUGHT``, ``BARRIER_THROUGH`` or ``BARRIER_OVER``.
    share : float
        Share of the kinetic energy kept [-].
    """
    if centre_height_m - radius_m > height_m:
        return BARRIER_OVER, 1.0
    if energy_kj <= capacity_kj:
        return BARRIER_CAUGHT, 0.0
    return BARRIER_THROUGH, (energy_kj - capacity_kj) / energy_kj


@njit(cache=True)
def _kinetic_kj(mass, speed2, inertia, w):
    """Kinetic energy [kJ] (1/2 m v^2 + 1/2 I w^2) / J_PER_KJ, with ``speed2`` = v^2 and I = k m r^2 [kg m^2].

    The compiled copy of :func:`simulation.units.kinetic_energy_kj` (same formula): that one is a plain
    Python function, which numba cannot call from compiled code, so the kernel keeps this one copy.
    """
    return (0.5 * mass * speed2 + 0.5 * inertia * w * w) / J_PER_KJ


@njit(cache=True, _nrt=False)
def _meet_collector(r_block, r_coll, r_t, r_vx, r_vz, r_w, r_h, r_outcome, r_count, block, coll, t, vx, vz, w, h,
                    speed2, mass, inertia, r, capacity_kj, barrier_height_m):
    """A block meets collector ``coll``: at a barrier (capacity not NaN) decide the outcome with
    :func:`barrier_outcome`, then record the crossing.  One home for the flight and the contact phases.

    ``speed2`` [m^2/s^2] is the squared speed of the centre, ``inertia`` I = k m r^2 [kg m^2].
    Returns (outcome, share of kinetic energy kept).
    """
    outcome = CROSSED
    keep = 1.0
    if not math.isnan(capacity_kj):
        e = _kinetic_kj(mass, speed2, inertia, w)
        outcome, keep = barrier_outcome(e, h, r, capacity_kj, barrier_height_m)
    _record_crossing(r_block, r_coll, r_t, r_vx, r_vz, r_w, r_h, r_outcome, r_count, block, coll, t, vx, vz, w, h,
                     outcome)
    return outcome, keep


@njit(cache=True, _nrt=False)
def _record_barrier_event(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, block, t, x, z, vx, vz, w, caught,
                          moving_mode):
    """Record the state after a barrier: stopped (caught) or moving on in ``moving_mode`` with the energy kept."""
    _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, block, t, x, z, vx, vz, w,
                 MODE_STOP if caught else moving_mode, EV_CAUGHT if caught else EV_BARRIER)


@njit(cache=True, inline="always")
def _envelope_add(env_acc, i, v, h, e):
    """Add one passage at bin i: count, max/sum of speed [m/s], height [m] and energy [kJ]."""
    env_acc[i, 0] += 1.0
    env_acc[i, 1] = max(env_acc[i, 1], v)
    env_acc[i, 2] = max(env_acc[i, 2], h)
    env_acc[i, 3] = max(env_acc[i, 3], e)
    env_acc[i, 4] += v
    env_acc[i, 5] += h
    env_acc[i, 6] += e


@njit(cache=True, _nrt=False)
def _envelope_flight(env_x, env_acc, xa, xb, x0, z0, vx, vz, w, g, px, pz, mass, inertia):
    """Envelope bins between xa and xb crossed in flight (parabola from x0, z0 with vx, vz; spin w constant)."""
    i0 = _first_at_least(env_x, min(xa, xb))
    i1 = _first_at_least(env_x, max(xa, xb))
    for i in range(i0, i1):
        xc = env_x[i]
        t = (xc - x0) / vx
        vzz = vz - g * t
        v = math.sqrt(vx * vx + vzz * vzz)
        _envelope_add(env_acc, i, v, z0 + vz * t - 0.5 * g * t * t - _ground(px, pz, xc),
                      _kinetic_kj(mass, v * v, inertia, w))


@njit(cache=True, _nrt=False)
def _envelope_contact(env_x, env_acc, xa, xb, x0, mass, inertia, r, contact_speed0, contact_a, contact_dir, cosb,
                      roll, drag):
    """Envelope bins between xa and xb crossed in ground contact (acceleration contact_a - drag v^2 along the
    slope from speed contact_speed0 at x0; spin v/r when rolling, none when sliding; height 0)."""
    i0 = _first_at_least(env_x, min(xa, xb))
    i1 = _first_at_least(env_x, max(xa, xb))
    for i in range(i0, i1):
        s = contact_dir * (env_x[i] - x0) / cosb
        sp = contact_speed_at(contact_speed0, contact_a, drag, s)
        _envelope_add(env_acc, i, sp, 0.0, _kinetic_kj(mass, sp * sp, inertia, sp / r if roll else 0.0))


@njit(cache=True, nogil=True)
def simulate(blocks, profile, mats, m_drag, collectors, envelope, settings, sin_max_roll, stops, crossings, paths):
    """Run every block of a chunk; fill the per-block and per-crossing output arrays in place.

    Energy: between events motion is exact (flight conserves kinetic + potential energy; rolling
    and sliding lose mu m g cos(beta) per metre); impacts, the transition to rolling
    (:func:`roll_on_speed`), slope changes in contact (the normal component is lost) and barriers
    only remove energy, unless a material sets ``allow_energy_gain``.
    ``c_order`` lists the collectors by increasing x, the order in which a block moving downslope crosses them
    (sorted by the caller: a sort compiled here would add about 2 s to the first compilation).
    The contact laws are those of :mod:`simulation.contact`: ``m_en_v0`` the velocity scale of e_N [m/s] (inf:
    none), ``m_hop`` the hop height [m] below which a rebound is ground contact (:func:`contact_speed`), and
    ``m_size_k`` the size coefficient of the rolling resistance (:func:`rolling_resistance`, the bounded size law:
    never above tan(:data:`simulation.contact.ROLLING_RESISTANCE_CAP_DEG`) from the size term), ``m_drag`` the rolling drag (the contact's v^2 resistance c = m_drag / r [1/m], :func:`contact_speed_at`),
    ``sin_max_roll`` the sine of the steepest slope a block may roll or slide on in contact (1: any slope);
    on steeper segments it leaves the face (:func:`steep_face_launch`) and meets it in impacts.

    Parameters
    ----------
    blocks : simulation.kernel_args.Blocks2D
        The chunk's blocks: global index, release position [m], velocity [m/s], spin [rad/s], mass [kg], radius
        [m] and inertia factor [-].
    profile : simulation.kernel_args.Profile2D
        The slope section: vertices [m], chord-offset tree, material and straight run of each segment.
    mats : simulation.kernel_args.MaterialTable
        The material table (its lateral-deviation fields are the 3-D kernel's).
    m_drag : numpy.ndarray or None
        Per material: rolling drag coefficient [-] (c = m_drag / r [1/m]).  None where no material has one: numba
        then compiles a version without the drag terms (c = 0 in every contact step, the same numbers as an
        array of zeros; :func:`simulation.engine.kernel_features`).
    collectors : simulation.kernel_args.Collectors2D
        Collector positions [m], barrier capacities [kJ] and heights [m], and the collectors in increasing x.
    envelope : simulation.kernel_args.Envelope2D
        Envelope bin centres [m] and accumulator, added to in place.
    settings : simulation.kernel_args.KernelSettings
        Gravity, contact and stop speeds, event limit, random key, blocks whose paths are recorded.
    sin_max_roll : float or None
        Sine of the steepest slope a block may roll or slide on [-].  None where no segment is steeper: the
        version compiled for it has no steep-face tests (they would all be false).
    stops : simulation.kernel_args.Stops2D
        Output per block: stop position [m], stop reason code (``STOP_REASONS``), impacts, travel time [s].
    crossings : simulation.kernel_args.Crossings2D
        Output per crossing, and the counts written and not fitted.
    paths : simulation.kernel_args.Paths2D
        Output per path point, and the count written.
    """
    block_ids, bx, bz, bvx, bvz, bw, bmass, bradius, bk, bres = blocks
    px, pz, tree, n_leaves, seg_mat, run_first, run_last = profile
    (m_en_law, m_en_mean, m_en_std, m_et_law, m_et_mean, m_et_std, m_phi, m_phi_std, m_rough, m_roll, m_mu_ground,
     m_gain, m_en_v0, m_hop, m_size_k, m_mu_cap, m_size_exp, m_et_v0, m_phig, m_phig_std, _m_dev, _m_dev_v) = mats
    c_x, c_cap, c_h, c_order = collectors
    env_x, env_acc = envelope
    g, v_contact, v_stop, max_events, key, n_path_blocks = settings
    out_x, out_z, out_reason, out_impacts, out_t = stops
    r_block, r_coll, r_t, r_vx, r_vz, r_w, r_h, r_outcome, r_count = crossings
    pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount = paths
    n_coll = c_x.shape[0]
    n_seg = px.shape[0] - 1
    state = np.empty(1, np.uint64)
    stack = np.empty((3, 128), np.int64)
    # Per segment, once per chunk, by the very expressions the event loop used to evaluate at every event (so
    # the numbers are the same): sine and cosine of the slope angle atan2(dz, dx) (impacts) and the direction
    # cosines dx / l, dz / l (ground contact).
    n_arr = max(n_seg, 0)                          # a call on no profile (the precompile's) has none
    seg_beta, seg_sin_beta, seg_cos_beta = np.empty(n_arr), np.empty(n_arr), np.empty(n_arr)
    seg_cos, seg_sin = np.empty(n_arr), np.empty(n_arr)
    seg_slope = chord_slopes(px, pz, n_leaves)
    for k in range(n_seg):
        beta = math.atan2(pz[k + 1] - pz[k], px[k + 1] - px[k])
        seg_beta[k], seg_sin_beta[k], seg_cos_beta[k] = beta, math.sin(beta), math.cos(beta)
        cosb_raw = px[k + 1] - px[k]
        sinb_raw = pz[k + 1] - pz[k]
        ls = math.sqrt(cosb_raw * cosb_raw + sinb_raw * sinb_raw)
        seg_cos[k], seg_sin[k] = cosb_raw / ls, sinb_raw / ls
    # Per segment: the normal speed below which a rebound (with the impact's cosine) or a take-off (with the contact's)
    # is ground contact, contact_speed of the segment's material.
    seg_v_impact, seg_v_contact = np.empty(n_arr), np.empty(n_arr)
    for k in range(n_seg):
        seg_v_impact[k] = contact_speed(v_contact, g, seg_cos_beta[k], m_hop[seg_mat[k]])
        seg_v_contact[k] = contact_speed(v_contact, g, seg_cos[k], m_hop[seg_mat[k]])
    # Per material: the impact friction coefficient where it has no spread (the loop's expression with phi + 0.0).
    mat_mu = np.empty(m_phi.shape[0])
    for m in range(m_phi.shape[0]):
        mat_mu[m] = math.tan(math.radians(min(max(m_phi[m] + 0.0, 0.0), 89.0)))
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
        x, z, vx, vz, w = bx[b], bz[b], bvx[b], bvz[b], bw[b]
        t_abs = 0.0
        seg = _seg_of(px, x)
        record = bid < n_path_blocks
        h0 = z - (pz[seg] + (pz[seg + 1] - pz[seg]) * (x - px[seg]) / (px[seg + 1] - px[seg]))
        contact = h0 <= 1e-9
        if record:
            _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, vx, vz, w,
                         MODE_CONTACT if contact else MODE_FLIGHT, EV_RELEASE)
        if contact:
            z = z - h0
            dxs, dzs = px[seg + 1] - px[seg], pz[seg + 1] - pz[seg]
            ls = math.sqrt(dxs * dxs + dzs * dzs)
            v_along = (vx * dxs + vz * dzs) / ls
            if m_roll[seg_mat[seg]]:
                v_along = roll_on_speed(v_along, w, r, k_in)
                w = v_along / r
            else:
                w = 0.0
        else:
            v_along = 0.0
        reason = RUNNING
        impacts = 0
        events = 0
        trap_n, trap_x, trap_y = 0, 0.0, 0.0          # the run of launches from steep faces (steep_trap)
        theta_mat, theta_max = -1, 0.0                 # roughness tilt of this block on material theta_mat
        mu_mat, mu_roll = -1, 0.0                      # rolling resistance of this block on material mu_mat
        while reason == RUNNING:
            events += 1
            if events > max_events:
                reason = MAX_EVENTS
                if record:
                    _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, vx, vz, w,
                                 MODE_STOP, EV_LIMIT)
                break
            if not contact:
                # find_impact, its first test (the run the block leaves from) written out here: the flights that
                # land on that run then cost no call with the whole profile as arguments
                if abs(vx) < 1e-12:
                    t_hit, k = find_impact(px, pz, seg_slope, tree, n_leaves, run_first, run_last, x, z, vx, vz, g,
                                           seg, stack)
                else:
                    t_hit, k = _run_hit(px, pz, seg_slope, run_first[seg], run_last[seg], x, z, vx, vz, g)
                    if k < 0:
                        t_hit, k = _tree_impact(px, pz, seg_slope, tree, n_leaves, x, z, vx, vz, g, seg, stack)
                if t_hit == math.inf:          # vertical motion already at the ground: settle into contact
                    contact = True
                    z = _ground(px, pz, x)
                    v_along = 0.0
                    w = 0.0
                    continue
                x_end = x + vx * t_hit
                # Collector crossings on this flight, in time order; a barrier may cut the flight.
                cut = False
                # The crossing time (c_x - x) / vx is divided out only for a collector within the flight's x-range:
                # it is <= 0 when c_x - x and vx differ in sign, and > t_hit when |c_x - x| exceeds |vx| t_hit by
                # more than rounding (the 1e-12 margin), so the test below would reject those anyway.
                reach = abs(vx) * t_hit * (1.0 + 1e-12)
                for jj in range(n_coll):
                    j = c_order[jj] if vx > 0 else c_order[n_coll - 1 - jj]
                    dxc = c_x[j] - x
                    if abs(vx) <= 1e-12 or (dxc <= 0.0 if vx > 0 else dxc >= 0.0) or abs(dxc) > reach:
                        continue
                    tc = dxc / vx
                    if not (1e-12 < tc <= t_hit):
                        continue
                    zc = z + vz * tc - 0.5 * g * tc * tc
                    vzc = vz - g * tc
                    h = zc - _ground(px, pz, c_x[j])
                    outcome, keep = _meet_collector(r_block, r_coll, r_t, r_vx, r_vz, r_w, r_h, r_outcome, r_count,
                                                    bid, j, t_abs + tc, vx, vzc, w, h, vx * vx + vzc * vzc, mass,
                                                    inertia, r, c_cap[j], c_h[j])
                    if outcome == BARRIER_CAUGHT or outcome == BARRIER_THROUGH:
                        if env_x.shape[0] > 0:
                            _envelope_flight(env_x, env_acc, x, c_x[j], x, z, vx, vz, w, g, px, pz, mass, inertia)
                        t_abs += tc
                        x, z = c_x[j], zc
                        seg = _seg_of(px, x)
                        f = math.sqrt(keep)
                        vx, vz, w = vx * f, vzc * f, w * f
                        if outcome == BARRIER_CAUGHT:
                            z = _ground(px, pz, x)
                            reason = CAUGHT
                        if record:
                            _record_barrier_event(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z,
                                                  vx, vz, w, reason == CAUGHT, np.int64(MODE_FLIGHT))
                        cut = True
                        break
                if cut:
                    continue
                if env_x.shape[0] > 0:
                    _envelope_flight(env_x, env_acc, x, x_end, x, z, vx, vz, w, g, px, pz, mass, inertia)
                z_end = z + vz * t_hit - 0.5 * g * t_hit * t_hit
                vz_end = vz - g * t_hit
                t_abs += t_hit
                x, z, vz = x_end, z_end, vz_end
                if k < 0:
                    reason = LEFT_PROFILE
                    if record:
                        _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, vx, vz, w,
                                     MODE_STOP, EV_LEFT)
                    break
                seg = k
                # The hit is accepted within a rounding tolerance of the segment's ends: bring it onto the
                # segment itself, so the block is never placed on the line's extension below a neighbour.
                x = min(max(x, px[k]), px[k + 1])
                z = pz[k] + (pz[k + 1] - pz[k]) * (x - px[k]) / (px[k + 1] - px[k])
                # Impact on segment k.
                impacts += 1
                mat = seg_mat[k]
                sin_beta, cos_beta = seg_sin_beta[k], seg_cos_beta[k]
                if mat != theta_mat:
                    theta_mat, theta_max = mat, roughness_tilt_max(m_rough[mat], r)
                delta = (2.0 * _uniform(state) - 1.0) * theta_max
                bp = seg_beta[k] + delta
                sin_bp, cos_bp = math.sin(bp), math.cos(bp)
                vn = -vx * sin_bp + vz * cos_bp
                if vn >= 0.0:
                    sin_bp, cos_bp = sin_beta, cos_beta
                    vn = -vx * sin_bp + vz * cos_bp
                vt = vx * cos_bp + vz * sin_bp
                gain = m_gain[mat]
                cap = 10.0 if gain else 1.0
                if m_en_law[mat] == EN_WYLLIE:       # the law gives the value; the spread is a deviation
                    en = m_en_std[mat] * _normal(state) if m_en_std[mat] > 0 else 0.0
                else:
                    en = min(max(m_en_mean[mat] + m_en_std[mat] * _normal(state), 0.0), cap) \
                        if m_en_std[mat] > 0 else m_en_mean[mat]
                et = min(max(m_et_mean[mat] + m_et_std[mat] * _normal(state), 0.0), cap) \
                    if m_et_std[mat] > 0 else m_et_mean[mat]
                if m_phi_std[mat] > 0:
                    phi = m_phi[mat] + m_phi_std[mat] * _normal(state)
                    mu = math.tan(math.radians(min(max(phi, 0.0), 89.0)))
                else:
                    mu = mat_mu[mat]
                if vn < 0.0:
                    vn2, vt2, w, _ = rebound(vn, vt, w, r, k_in, m_en_law[mat], en, m_en_v0[mat], m_et_law[mat], et,
                                            mu, gain, m_et_v0[mat])
                else:
                    vn2, vt2 = 0.0, vt
                vx = vt2 * cos_bp - vn2 * sin_bp
                vz = vt2 * sin_bp + vn2 * cos_bp
                vn_true = -vx * sin_beta + vz * cos_beta
                v_thr = seg_v_impact[k]
                if sin_max_roll is not None and vn_true < v_thr and abs(sin_beta) > sin_max_roll:
                    # A face too steep to roll on: the block leaves it again (speed kept), no ground contact --
                    # unless it has kept doing so in one place (a notch with flanks too steep to roll on).
                    trap_n, trap_x, trap_y, trapped = steep_trap(trap_n, trap_x, trap_y, x, 0.0)
                    if trapped:
                        reason = STOPPED
                        w = 0.0
                        if record:
                            _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, 0.0,
                                         0.0, 0.0, MODE_STOP, EV_STOP)
                        break
                    vt_true = vx * cos_beta + vz * sin_beta
                    vt_new, vn_new = steep_face_launch(vt_true, v_thr)
                    vx = vt_new * cos_beta - vn_new * sin_beta
                    vz = vt_new * sin_beta + vn_new * cos_beta
                    vn_true = vn_new
                    if vn_new <= 0.0:            # at rest against the face: step off it horizontally
                        x = _step_off(px, k, x, sin_beta)
                if record:
                    _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, vx, vz, w,
                                 MODE_FLIGHT, EV_IMPACT)
                if vn_true < v_thr and (sin_max_roll is None or not abs(sin_beta) > sin_max_roll):
                    # Ground contact: the normal component is lost; a rolling material makes the block roll
                    # without slip, conserving angular momentum about the contact point.
                    contact = True
                    v_along = vx * cos_beta + vz * sin_beta
                    if m_roll[mat]:
                        v_along = roll_on_speed(v_along, w, r, k_in)
                        w = v_along / r
                    else:
                        w = 0.0
                    vx, vz = v_along * cos_beta, v_along * sin_beta
                    if record:
                        _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, vx, vz, w,
                                     MODE_CONTACT, EV_CONTACT)
                continue

            # ---- ground contact on segment `seg`: roll or slide with constant acceleration ----
            k = seg
            mat = seg_mat[k]
            cosb, sinb = seg_cos[k], seg_sin[k]
            if mat != mu_mat:
                mu_mat = mat
                mu_roll = rolling_resistance(mu_blk[mat], m_size_k[mat], m_rough[mat], r, m_mu_cap[mat], m_size_exp[mat])
            mu = mu_roll
            roll = m_roll[mat]
            trapped = False
            if sin_max_roll is not None and abs(sinb) > sin_max_roll:
                # No rolling or sliding in contact on a face this steep: the block leaves it (speed kept), unless
                # it has kept doing so in one place (steep_trap: then it is held, below).
                trap_n, trap_x, trap_y, trapped = steep_trap(trap_n, trap_x, trap_y, x, 0.0)
            if sin_max_roll is not None and abs(sinb) > sin_max_roll and not trapped:
                vt_new, vn_new = steep_face_launch(v_along, seg_v_contact[k])
                vx = vt_new * cosb - vn_new * sinb
                vz = vt_new * sinb + vn_new * cosb
                if vn_new <= 0.0:
                    x = _step_off(px, k, x, sinb)
                contact = False
                if record:
                    _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, vx, vz, w,
                                 MODE_FLIGHT, EV_TAKEOFF)
                continue
            if trapped or abs(v_along) < v_stop or v_along == 0.0:
                if trapped or abs(sinb) <= mu * cosb or _at_trough(px, pz, k, x):
                    reason = STOPPED
                    w = 0.0
                    if record:
                        _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, 0.0, 0.0,
                                     0.0, MODE_STOP, EV_STOP)
                    break
                direction = -1.0 if sinb > 0 else 1.0
                v_along = 0.0
            else:
                direction = 1.0 if v_along > 0 else -1.0
            a_dir = contact_acceleration(g, sinb, cosb, direction, mu, k_in, roll)   # along the motion
            drag = 0.0 if m_drag is None else (m_drag[mat] / r if r > 0.0 else 0.0)
            u = abs(v_along)
            # Collinear segments of the same material are crossed in one step.
            if direction > 0:
                k_far = run_last[k]
                dist = (px[k_far + 1] - x) / cosb
            else:
                k_far = run_first[k]
                dist = (x - px[k_far]) / cosb
            d_stop = contact_stop_distance(u, a_dir, drag)
            stops_here = d_stop < dist
            if stops_here:
                d_step = d_stop
                u_end = 0.0
                t_step = contact_time(u, 0.0, a_dir, drag, d_step)
            else:
                u_end = contact_speed_at(u, a_dir, drag, dist)
                t_step = contact_time(u, u_end, a_dir, drag, dist)
                if t_step < 0.0:
                    reason = STOPPED
                    if record:
                        _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, 0.0, 0.0,
                                     0.0, MODE_STOP, EV_STOP)
                    break
                d_step = dist
            x_new = x + direction * d_step * cosb
            # Collector crossings during this contact step.
            cut = False
            # The distance along the slope to a collector, direction (c_x - x) / cosb (cosb > 0), is divided out only
            # where it can lie within the step (as in the flight above).
            reach = d_step * cosb * (1.0 + 1e-12)
            for jj in range(n_coll):
                j = c_order[jj] if direction > 0 else c_order[n_coll - 1 - jj]
                ahead = direction * (c_x[j] - x)
                if ahead <= 0.0 or ahead > reach:
                    continue
                s_c = ahead / cosb
                if not (1e-12 < s_c <= d_step):
                    continue
                uc = contact_speed_at(u, a_dir, drag, s_c)
                tc = contact_time(u, uc, a_dir, drag, s_c)
                wc = direction * uc / r if roll else 0.0
                vxc, vzc = direction * uc * cosb, direction * uc * sinb
                outcome, keep = _meet_collector(r_block, r_coll, r_t, r_vx, r_vz, r_w, r_h, r_outcome, r_count,
                                                bid, j, t_abs + tc, vxc, vzc, wc, 0.0, uc * uc, mass, inertia, r,
                                                c_cap[j], c_h[j])
                if outcome == BARRIER_CAUGHT or outcome == BARRIER_THROUGH:
                    if env_x.shape[0] > 0:
                        _envelope_contact(env_x, env_acc, x, c_x[j], x, mass, inertia, r, u, a_dir, direction,
                                          cosb, roll, drag)
                    t_abs += tc
                    x = c_x[j]
                    z = _ground(px, pz, x)
                    seg = min(max(_seg_of(px, x), min(k, k_far)), max(k, k_far))
                    f = math.sqrt(keep)
                    v_along = direction * uc * f
                    w = wc * f
                    if outcome == BARRIER_CAUGHT:
                        reason = CAUGHT
                    if record:
                        _record_barrier_event(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z,
                                              v_along * cosb, v_along * sinb, w, reason == CAUGHT,
                                              np.int64(MODE_CONTACT))
                    cut = True
                    break
            if cut:
                continue
            if env_x.shape[0] > 0:
                _envelope_contact(env_x, env_acc, x, x_new, x, mass, inertia, r, u, a_dir, direction, cosb, roll, drag)
            t_abs += t_step
            x = x_new
            z = pz[k] + (pz[k + 1] - pz[k]) * (x - px[k]) / (px[k + 1] - px[k])
            w = direction * u_end / r if roll else 0.0
            if stops_here:
                v_along = 0.0
                if k_far != k:
                    seg = min(max(_seg_of(px, x), min(k, k_far)), max(k, k_far))
                if record:
                    _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, 0.0, 0.0, 0.0,
                                 MODE_CONTACT, EV_REST)
                continue
            # Reached a vertex: next segment, or off the profile.
            k2 = k_far + 1 if direction > 0 else k_far - 1
            vxe, vze = direction * u_end * cosb, direction * u_end * sinb
            if k2 < 0 or k2 >= n_seg:
                reason = LEFT_PROFILE
                vx, vz = vxe, vze
                if record:
                    _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, vxe, vze, w,
                                 MODE_STOP, EV_LEFT)
                break
            cos2, sin2 = seg_cos[k2], seg_sin[k2]
            # A convex edge launches the block when its speed away from the next segment reaches the
            # contact velocity; below it the block stays in contact (as a landing below it would), so a
            # finely kinked terrain profile is not turned into thousands of micro-flights and impacts.
            if -vxe * sin2 + vze * cos2 >= seg_v_contact[k2]:
                contact = False            # convex edge: the block takes off
                vx, vz = vxe, vze
                seg = k2
                if record:
                    _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z, vx, vz, w,
                                 MODE_FLIGHT, EV_TAKEOFF)
            else:
                # Concave edge, or a convex one crossed in contact: the velocity normal to the next segment
                # is lost; a rolling block re-rolls conserving angular momentum about the new contact point.
                seg = k2
                v_along = vxe * cos2 + vze * sin2
                if m_roll[seg_mat[k2]]:
                    v_along = roll_on_speed(v_along, w, r, k_in)
                    w = v_along / r
                else:
                    w = 0.0
                if abs(v_along) < v_stop and _at_trough(px, pz, k2, x):
                    v_along = 0.0         # at rest in a trough (V-notch): held by both flanks
                if record:
                    _record_path(pb, pt, pxs, pzs, pvx, pvz, pw, pmode, pev, pcount, bid, t_abs, x, z,
                                 v_along * cos2, v_along * sin2, w, MODE_CONTACT, EV_VERTEX)
        out_x[b], out_z[b], out_reason[b], out_impacts[b], out_t[b] = x, z, reason, impacts, t_abs


@njit(cache=True, _nrt=False)
def _step_off(px, k, x, sin_beta):
    """x moved off a steep face horizontally, away from the rock (by 1e-6 of a metre, within segment k), so a
    block at rest against the face falls onto it from just above (no energy is created: z is unchanged)."""
    dx = 1e-6 * (1.0 + abs(x))
    x2 = x + dx if sin_beta < 0.0 else x - dx
    return min(max(x2, px[k]), px[k + 1])


@njit(cache=True, _nrt=False)
def _at_trough(px, pz, k, x):
    """True when x is a vertex of segment k that is a local minimum of the profile (both neighbours rise
    away from it): a block at rest there is held whatever the flank angles (the V-notch)."""
    n_seg = px.shape[0] - 1
    tol = 1e-9 * (1.0 + abs(x))
    if abs(x - px[k]) <= tol:
        i = k                       # vertex i joins segments i-1 and i
    elif abs(x - px[k + 1]) <= tol:
        i = k + 1
    else:
        return False
    if i <= 0 or i >= n_seg:
        return False
    return pz[i - 1] > pz[i] and pz[i + 1] > pz[i]
