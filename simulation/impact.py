"""Impact of a rotating sphere on a slope surface (Wyllie 2014, chapters 4 and 5).

Every function here is compiled with numba and works on scalars in the local
frame of the (possibly roughness-tilted) surface: ``vn`` is the velocity
component along the outward normal (negative when approaching), ``vt`` the
component along the surface tangent, ``w`` the angular velocity [rad/s] with
the sign convention that rolling without slip means ``vt = r w``, so the slip
velocity of the contact point is ``vt - r w``.

Normal restitution laws (``EN_*`` codes)
---------------------------------------
* ``EN_CONSTANT``: e_N given (sampled per impact when a spread is given).
* ``EN_WYLLIE``: e_N = 19.5 theta_i^-1.03 with theta_i the impact angle in degrees between the
  incoming velocity and the surface (Wyllie 2014, "Calibration of rock fall modeling parameters",
  IJRMMS 67:170-180: field impacts at five sites; and the "Coefficient of restitution" part of
  Wyllie's 2014 UBC PhD thesis, "Rock fall engineering: development and calibration of an improved
  model ...", on which his book Rock Fall Engineering draws; the book's equation number is not cited
  because no copy was at hand to check it).  It exceeds 1 below theta_i = 17.9 deg: Wyllie's
  definition is kinematic (normal speeds), and at shallow angles the normal rebound is fed by the
  tangential velocity lost to friction and rotation.  It is capped at ``EN_WYLLIE_MAX`` = 2.5, the
  largest value Wyllie measured.
* ``EN_VELOCITY``: e_N / (1 + (|v_n| / 9.144 m/s)^2), the CRSP "scale by
  velocity" form (Pfeiffer & Bowen 1989; RocFall "scale Rn by velocity").

Spread of Wyllie's law: the scenario's ``std`` is added to the law's value at each
impact (``e_n`` passed to :func:`normal_restitution` is then that deviation).

Energy guard (unless ``allow_energy_gain``): no impact creates kinetic energy, and a
shallow impact is never lossless.  Wyllie's e_N is kinematic (a ratio of normal speeds
measured in the field, Wyllie 2014 section 5.3; Wyllie, IJRMMS 67: 170-180): it exceeds 1
at shallow angles because the rebound is fed by the tangential motion (block shape and
rotation).  So with Wyllie's law (or a typed e_N > 1) the normal impact itself returns only
the share sin^2(theta_i) of its elastic part, min(e_N, 1)^2 v_n^2, where theta_i is the
impact angle; the rest of the rebound e_N^2 v_n^2 is drawn from the tangential and rotational
energy that the tangential law leaves, and if that is not enough the rebound is reduced.
The rebound speed is Wyllie's e_N |v_n| whenever the tangential energy suffices (at 90 deg
e_N = 0.19 exactly); what the normal impact does not return is paid by the tangential motion,
e_N^2 v_n^2 cos^2(theta_i) per unit mass, so at intermediate angles an impact also costs some
tangential energy (a rolling block at 30 deg with e_T = 1 keeps 82 % of its energy, not the 87 % a
purely normal loss would give), while a grazing impact loses nearly all of 1/2 m v_n^2: a rolling block
hopping at 17.9 deg (e_N = 1) loses sin^2 cos^2 = 8.6 % of its translational energy at every
impact, and
the loss is continuous in the angle.  This split is a modelling choice, stated as one.
With a constant or velocity-scaled e_N <= 1 the laws dissipate by themselves (Stronge 2000)
and the guard acts only on a tangential coefficient e_T > 1.  The energy out never exceeds
the energy in.

Tangential laws (``ET_*`` codes)
--------------------------------
* ``ET_FRICTION``: the rough rotating sphere of Stronge (2000) as set out by
  Wyllie (2014, ch. 5): the normal impulse is m (1 + e_N)|v_n|; the tangential
  impulse needed to stop slip is (2/7) m |slip| for a solid sphere (I = 2/5 m r^2),
  |slip| / (1 + 1/k) m for a round body with I = k m r^2 (k = 1/2: cylinder, disc).
  If that is within mu (1 + e_N)|v_n| the contact sticks and the sphere leaves
  rolling with v_t' = 5/7 v_t + 2/7 r w, w' = v_t'/r; otherwise it slips
  throughout and friction mu (1 + e_N)|v_n| acts against the slip.
* ``ET_CONSTANT``: v_t' = e_T v_t (the lumped-mass tangential coefficient of
  RocFall/CRSP); the spin decays by the same factor.
"""
from __future__ import annotations

import math

from numba import njit

from .units import SPHERE_INERTIA

EN_CONSTANT, EN_WYLLIE, EN_VELOCITY = 0, 1, 2
ET_FRICTION, ET_CONSTANT = 0, 1
EN_WYLLIE_MAX = 2.5
CRSP_VELOCITY_SCALE_MS = 9.144    # 30 ft/s (Pfeiffer & Bowen 1989)


@njit(cache=True)
def wyllie_normal_restitution(impact_angle_deg):
    """e_N = 19.5 theta^-1.03 (theta in degrees), capped at 2.5 (Wyllie 2014)."""
    theta = max(impact_angle_deg, 1e-6)
    return min(19.5 * theta ** -1.03, EN_WYLLIE_MAX)


@njit(cache=True)
def normal_restitution(law, e_n, vn, vt):
    """Coefficient e_N for an impact with normal velocity vn (< 0) and tangential vt."""
    if law == EN_WYLLIE:
        angle = math.degrees(math.atan2(-vn, abs(vt)))
        return min(max(wyllie_normal_restitution(angle) + e_n, 0.0), EN_WYLLIE_MAX)   # e_n: this impact's deviation
    if law == EN_VELOCITY:
        return e_n / (1.0 + (vn / CRSP_VELOCITY_SCALE_MS) ** 2)
    return e_n


@njit(cache=True)
def stronge_sphere(vn, vt, w, r, e_n, mu):
    """Tangential velocity and spin after a rough impact of a solid sphere (I = 0.4 m r^2).

    Returns (vt_out, w_out, stuck).  ``vn`` < 0 is the incoming normal velocity.
    """
    return stronge_body(vn, vt, w, r, e_n, mu, SPHERE_INERTIA)


@njit(cache=True)
def stronge_body(vn, vt, w, r, e_n, mu, k):
    """Rough impact of a round body with inertia I = k m r^2 (k = 0.4 sphere, 0.5 cylinder or disc)."""
    pn = (1.0 + e_n) * (-vn)              # normal impulse per unit mass
    slip = vt - r * w
    # Impulse per unit mass that brings the slip to zero: slip / (1 + 1/k) = 2/7 slip for a solid sphere.
    p_stick = slip / (1.0 + 1.0 / k)
    if abs(p_stick) <= mu * pn:
        vt_out = vt - p_stick             # sphere: 5/7 vt + 2/7 r w
        return vt_out, vt_out / r, True
    pt = mu * pn if slip > 0 else -mu * pn
    return vt - pt, w + pt / (k * r), False


@njit(cache=True)
def impact(vn, vt, w, r, en_law, e_n, et_law, e_t, mu, allow_energy_gain):
    """Outgoing (vn', vt', w', e_N used) of a solid sphere; see :func:`impact_body`."""
    return impact_body(vn, vt, w, r, en_law, e_n, et_law, e_t, mu, allow_energy_gain, SPHERE_INERTIA)


@njit(cache=True)
def impact_body(vn, vt, w, r, en_law, e_n, et_law, e_t, mu, allow_energy_gain, k_inertia):
    """Outgoing (vn', vt', w', e_N used) for an incoming (vn < 0, vt, w) on a surface.

    Kinetic energy per unit mass (translational + rotational, I = k m r^2)
    never increases unless ``allow_energy_gain``.
    """
    en = normal_restitution(en_law, e_n, vn, vt)
    if et_law == ET_FRICTION:
        vt2, w2, stuck = stronge_body(vn, vt, w, r, en, mu, k_inertia)
    else:
        vt2 = e_t * vt
        w2 = e_t * w
    vn2 = -en * vn
    if not allow_energy_gain:
        k = k_inertia * r * r
        e_in = vn * vn + vt * vt + k * w * w                 # twice the kinetic energy per unit mass
        e_tan = vt2 * vt2 + k * w2 * w2
        # Kinematic e_N (Wyllie's law, or a typed e_N > 1): the normal impact returns the share
        # sin^2(theta_i) of its elastic part, the rest of the rebound comes from the tangential motion.
        # Otherwise the laws themselves dissipate.
        budget = e_in
        if en_law == EN_WYLLIE or en > 1.0:
            sin2 = vn * vn / max(vn * vn + vt * vt, 1e-300)
            budget = e_in - vn * vn * (1.0 - min(en, 1.0) ** 2 * sin2)
        room = budget - vn2 * vn2                             # energy left for the tangential state
        if room < 0.0:
            vn2 = math.sqrt(max(budget, 0.0))
            en = vn2 / -vn if vn < 0 else 0.0
            room = 0.0
        if e_tan > room:
            s = math.sqrt(room / e_tan)
            vt2 *= s
            w2 *= s
    return vn2, vt2, w2, en
