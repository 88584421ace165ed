"""The 3-D kernel's impact and contact helpers: the spin kept when the direction of travel turns, the time
and the stopping share of a contact step, a block leaving a face too steep to roll on, and the
random lateral deviation of the direction of travel at an impact (:func:`deviation_sd`).
"""
from __future__ import annotations

import math

from numba import njit

from .contact import contact_stop_distance, contact_time, steep_face_launch
from .kernel3d_surface import _downhill, _surface


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
