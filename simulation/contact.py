"""Contact laws of a block with the ground, shared by the 2-D kernel and any other kernel.

Every function here is a numba ``njit`` function of scalars (no arrays, no objects), so a kernel in
another geometry (a 3-D kernel working in the local frame of the impacted facet) calls the same laws:
pass the velocity decomposed in the local frame of the (possibly roughness-tilted) surface and the
block's radius and inertia factor, get the outgoing state back.  Units: m, s, rad; velocities in m/s.

Conventions: ``vn`` is the velocity component along the outward normal (negative when approaching),
``vt`` the component along the surface tangent, ``w`` the angular velocity [rad/s] with the sign
convention that rolling without slip means ``vt = r w``, so the slip velocity of the contact point is
``vt - r w``; ``k`` is the inertia factor I / (m r^2) (2/5 solid sphere, 1/2 cylinder or disc).

What the module holds
---------------------
* the impact (rebound) laws: normal restitution by law, optionally scaled by the impact velocity, and the
  tangential laws below (:func:`rebound`, and its older form :func:`impact_body`);
* the roughness tilt amplitude relative to the block radius (:func:`roughness_tilt_max`);
* the switch between flight and ground contact (:func:`contact_speed`): a physical hop height, with the
  scenario's ``contact_velocity_ms`` only a numerical floor under it;
* rolling and sliding in contact (:func:`contact_acceleration`, :func:`roll_on_speed`), with the bounded
  size law of the rolling resistance (:func:`rolling_resistance`, :data:`ROLLING_RESISTANCE_CAP_DEG`) and each
  block's own phi_g (:func:`block_ground_resistance`);
* the steep-face rule (:func:`steep_face_launch`): on faces steeper than a stated angle a block does not
  roll in contact; it leaves the face and meets it again in impacts.

Impact of a rotating body on a slope surface (Wyllie 2014, chapters 4 and 5)
-----------------------------------------------------------------------------

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
* ``ET_COULOMB``: Wyllie's e_T bounded by Coulomb's law.  The tangential impulse per unit mass
  that e_T asks for, (1 - e_T)|v_t|, cannot exceed mu times the normal impulse, mu (1 + e_N)|v_n|
  (Coulomb friction during the impact; Stronge 2000, ch. 4; the same bound that decides stick or
  slip in the Stronge law above and in the "Bourrier" rebound model of PlatRock).  So
  e_T,eff = 1 - min(1 - e_T, mu (1 + e_N) |v_n| / |v_t|):
  a steep impact loses what Wyllie measured (e_T 0.3-0.8 at his five sites, where impacts were
  mostly steeper than 20 deg), a grazing one only what friction can take, and in the limit of a
  grazing touch nothing.  With e_T = 0.55, mu = tan 30 deg and e_N = 0.3 the bound acts below an
  impact angle of 31 deg; at 5 deg the block keeps 87 % of its tangential speed (the constant law:
  55 %), so results no longer depend on how many micro-bounces the kinks of a profile produce.
  The spin decays by the same factor as v_t.  Wang et al. (2018, NHESS 18:3045) measured the same
  trend in the laboratory (R_t grows as the impact angle falls).

Velocity scaling of e_N (any law)
---------------------------------
With a finite ``v0`` (``normal_restitution.velocity_scale_ms`` in a scenario), e_N is divided by
1 + (|v_n| / v0)^2: the CRSP "scale by velocity" form of Pfeiffer & Bowen (1989), v0 = 9.144 m/s
(30 ft/s) in CRSP, applied on top of the constant or Wyllie law so that fast impacts on soft ground
rebound less (plastic indentation; Bourrier et al. 2009 measured R_n falling with V_n on soil).

Normal-velocity scaling of e_T (constant and Coulomb laws)
----------------------------------------------------------
With a finite ``vt0`` (``tangential.normal_scale_ms`` in a scenario) the tangential state after the law is
scaled by sqrt(SF), SF = 1 / ((|v_n| / (vt0 e_N))^2 + 1): the scaling factor of Pfeiffer & Bowen (1989) on the
tangential energy, vt0 = 76.2 m/s (250 ft/s) in CRSP, with e_N the material's normal coefficient before any
velocity scaling (CRSP's R_n: the constant, the velocity law's e_N, or -- an ASSUMPTION, CRSP has no angle law --
Wyllie's angle-dependent value, about 0.2 at a steep impact where CRSP's R_n is typically 0.3-0.35, so the same
vt0 takes more; clipped to [0.05, 1], an ASSUMPTION that keeps the factor finite and only matters at grazing
angles, where it is about 1).  A block landing hard (a high normal velocity, as after a free fall from a
wall onto a bench) keeps less of its tangential speed than one that grazes the ground; at |v_n| = 18 m/s and
e_N = 0.25 it keeps 73 % of what the law leaves, at 5 m/s 97 %.  It only removes energy.
"""
from __future__ import annotations

import math

from numba import njit

from .units import SPHERE_INERTIA

EN_CONSTANT, EN_WYLLIE, EN_VELOCITY = 0, 1, 2
ET_FRICTION, ET_CONSTANT, ET_COULOMB = 0, 1, 2
EN_WYLLIE_MAX = 2.5
CRSP_VELOCITY_SCALE_MS = 9.144    # 30 ft/s (Pfeiffer & Bowen 1989)
CRSP_TANGENTIAL_SCALE_MS = 76.2   # 250 ft/s, the scaling factor SF of Pfeiffer & Bowen (1989)


@njit(cache=True)
def wyllie_normal_restitution(impact_angle_deg):
    """e_N = 19.5 theta^-1.03 (theta in degrees), capped at 2.5 (Wyllie 2014).

    Parameters
    ----------
    impact_angle_deg : float
        Impact angle theta between the incoming velocity and the surface [deg].

    Returns
    -------
    float
        Normal coefficient of restitution e_N [-], at most ``EN_WYLLIE_MAX``.

    References
    ----------
    Wyllie, D.C. (2014) Calibration of rock fall modeling parameters. IJRMMS 67: 170-180.
    """
    theta = max(impact_angle_deg, 1e-6)
    return min(19.5 * theta ** -1.03, EN_WYLLIE_MAX)


@njit(cache=True)
def normal_restitution(law, e_n, vn, vt):
    """Coefficient e_N for an impact with normal velocity vn (< 0) and tangential vt.

    Parameters
    ----------
    law : int
        ``EN_CONSTANT``, ``EN_WYLLIE`` or ``EN_VELOCITY``.
    e_n : float
        e_N for the constant and velocity laws; the deviation added to the law's value for Wyllie's law [-].
    vn : float
        Incoming normal velocity [m/s] (< 0).
    vt : float
        Incoming tangential velocity [m/s].

    Returns
    -------
    float
        Normal coefficient of restitution e_N for this impact [-].

    References
    ----------
    Wyllie, D.C. (2014) Calibration of rock fall modeling parameters. IJRMMS 67: 170-180.
    Pfeiffer & Bowen (1989), the CRSP velocity scaling of e_N.
    """
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

    Parameters
    ----------
    vn : float
        Incoming normal velocity [m/s] (< 0).
    vt : float
        Incoming tangential velocity [m/s].
    w : float
        Incoming spin [rad/s].
    r : float
        Block radius [m].
    e_n : float
        Normal coefficient of restitution [-].
    mu : float
        Friction coefficient tan(phi) [-].

    Returns
    -------
    vt_out : float
        Outgoing tangential velocity [m/s].
    w_out : float
        Outgoing spin [rad/s].
    stuck : bool
        True when the contact stuck (the sphere leaves rolling).

    References
    ----------
    Stronge (2000), as set out by Wyllie (2014, ch. 5).
    """
    return stronge_body(vn, vt, w, r, e_n, mu, SPHERE_INERTIA)


@njit(cache=True)
def stronge_body(vn, vt, w, r, e_n, mu, k):
    """Rough impact of a round body with inertia I = k m r^2 (k = 0.4 sphere, 0.5 cylinder or disc).

    Parameters
    ----------
    vn : float
        Incoming normal velocity [m/s] (< 0).
    vt : float
        Incoming tangential velocity [m/s].
    w : float
        Incoming spin [rad/s].
    r : float
        Block radius [m].
    e_n : float
        Normal coefficient of restitution [-].
    mu : float
        Friction coefficient tan(phi) [-].
    k : float
        Inertia factor I / (m r^2) [-].

    Returns
    -------
    vt_out : float
        Outgoing tangential velocity [m/s].
    w_out : float
        Outgoing spin [rad/s].
    stuck : bool
        True when the contact stuck (the body leaves rolling).

    References
    ----------
    Stronge (2000), as set out by Wyllie (2014, ch. 5).
    """
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
    """Outgoing (vn', vt', w', e_N used) of a solid sphere; see :func:`impact_body`.

    Parameters
    ----------
    vn, vt, w : float
        Incoming normal velocity [m/s] (< 0), tangential velocity [m/s] and spin [rad/s].
    r : float
        Block radius [m].
    en_law : int
        ``EN_CONSTANT``, ``EN_WYLLIE`` or ``EN_VELOCITY``.
    e_n : float
        Normal coefficient (or its deviation for Wyllie's law) [-].
    et_law : int
        ``ET_FRICTION``, ``ET_CONSTANT`` or ``ET_COULOMB``.
    e_t : float
        Tangential coefficient [-].
    mu : float
        Friction coefficient tan(phi) [-].
    allow_energy_gain : bool
        When False the kinetic energy never increases.

    Returns
    -------
    tuple of float
        Outgoing vn' [m/s], vt' [m/s], w' [rad/s] and the e_N used [-].
    """
    return impact_body(vn, vt, w, r, en_law, e_n, et_law, e_t, mu, allow_energy_gain, SPHERE_INERTIA)


@njit(cache=True)
def impact_body(vn, vt, w, r, en_law, e_n, et_law, e_t, mu, allow_energy_gain, k_inertia):
    """Outgoing (vn', vt', w', e_N used) for an incoming (vn < 0, vt, w) on a surface, without velocity scaling.

    The same as :func:`rebound` with ``v0`` = inf (kept with this argument order for callers that use it).

    Parameters
    ----------
    vn, vt, w : float
        Incoming normal velocity [m/s] (< 0), tangential velocity [m/s] and spin [rad/s].
    r : float
        Block radius [m].
    en_law : int
        ``EN_CONSTANT``, ``EN_WYLLIE`` or ``EN_VELOCITY``.
    e_n : float
        Normal coefficient (or its deviation for Wyllie's law) [-].
    et_law : int
        ``ET_FRICTION``, ``ET_CONSTANT`` or ``ET_COULOMB``.
    e_t : float
        Tangential coefficient [-].
    mu : float
        Friction coefficient tan(phi) [-].
    allow_energy_gain : bool
        When False the kinetic energy never increases.
    k_inertia : float
        Inertia factor I / (m r^2) [-].

    Returns
    -------
    tuple of float
        Outgoing vn' [m/s], vt' [m/s], w' [rad/s] and the e_N used [-].
    """
    return rebound(vn, vt, w, r, k_inertia, en_law, e_n, math.inf, et_law, e_t, mu, allow_energy_gain)


@njit(cache=True)
def velocity_scaled(e_n, vn, v0):
    """e_N / (1 + (vn / v0)^2): the Pfeiffer & Bowen (1989) velocity scaling; ``v0`` [m/s] inf = none.

    Parameters
    ----------
    e_n : float
        Normal coefficient of restitution [-].
    vn : float
        Normal impact velocity [m/s].
    v0 : float
        Velocity scale [m/s] (inf: no scaling).

    Returns
    -------
    float
        The scaled e_N [-].

    References
    ----------
    Pfeiffer & Bowen (1989), the CRSP "scale by velocity" form, v0 = 9.144 m/s.
    """
    if v0 == math.inf or v0 <= 0.0:
        return e_n
    return e_n / (1.0 + (vn / v0) ** 2)


@njit(cache=True)
def tangential_scaling(vn, e_n, vt0):
    """sqrt(SF), SF = 1 / ((vn / (vt0 e_N))^2 + 1): Pfeiffer & Bowen's (1989) normal-velocity scaling of the
    tangential energy, as a factor on the tangential velocity and spin (module docstring).

    Parameters
    ----------
    vn : float
        Normal impact velocity [m/s].
    e_n : float
        The material's e_N before any velocity scaling [-] (CRSP's R_n); clipped to [0.05, 1].
    vt0 : float
        Velocity scale [m/s] (76.2 m/s = 250 ft/s in CRSP; inf: none).

    Returns
    -------
    float
        The factor in (0, 1] [-].

    References
    ----------
    Pfeiffer & Bowen (1989), Bull. Assoc. Eng. Geol. 26(1):135-146, the CRSP scaling factor
    SF = R_t / ((V_n / (250 ft/s R_n))^2 + 1) on the tangential energy (its R_t is the law's e_T here).
    """
    if vt0 == math.inf or vt0 <= 0.0:
        return 1.0
    en = min(max(e_n, 0.05), 1.0)
    return 1.0 / math.sqrt((vn / (vt0 * en)) ** 2 + 1.0)


@njit(cache=True)
def coulomb_tangential(vn, vt, w, e_t, e_n, mu):
    """Tangential law ``ET_COULOMB``: (vt', w') with e_T bounded by Coulomb friction (module docstring).

    Parameters
    ----------
    vn : float
        Incoming normal velocity [m/s] (< 0).
    vt, w : float
        Incoming tangential velocity [m/s] and spin [rad/s].
    e_t : float
        Wyllie's tangential coefficient for a steep impact (0-1).
    e_n : float
        The normal coefficient of this impact (kinematic, as used for the normal rebound).
    mu : float
        Friction coefficient tan(phi) of the impact.

    Returns
    -------
    (vt', w') : the tangential velocity [m/s] and spin [rad/s] after the impact, both scaled by the same
    factor e_T,eff in [e_T, 1] (e_t is clipped to [0, 1]); unchanged when vt = 0.
    """
    e = min(max(e_t, 0.0), 1.0)
    avt = abs(vt)
    if avt <= 0.0:
        return vt, w
    loss = min(1.0 - e, mu * (1.0 + e_n) * (-vn) / avt) if vn < 0.0 else 0.0
    f = 1.0 - max(loss, 0.0)
    return f * vt, f * w


@njit(cache=True)
def rebound(vn, vt, w, r, k, en_law, e_n, v0, et_law, e_t, mu, allow_energy_gain, vt0=math.inf):
    """Outgoing state of a round block after an impact on a surface: (vn', vt', w', e_N used).

    Parameters
    ----------
    vn, vt, w : float
        Incoming normal velocity [m/s] (< 0 when approaching), tangential velocity [m/s] and spin [rad/s],
        in the frame of the (roughness-tilted) surface.
    r : float
        Block radius [m].
    k : float
        Inertia factor I / (m r^2) (0.4 sphere, 0.5 cylinder or disc).
    en_law : int
        ``EN_CONSTANT``, ``EN_WYLLIE`` or ``EN_VELOCITY``.
    e_n : float
        e_N for the constant and velocity laws; the deviation added to the law's value for Wyllie's law.
    v0 : float
        Velocity scale [m/s] of the Pfeiffer & Bowen scaling applied after the law (inf: none).
    et_law : int
        ``ET_FRICTION`` (Stronge rough body), ``ET_CONSTANT`` or ``ET_COULOMB``.
    e_t : float
        Tangential coefficient (constant and Coulomb laws).
    mu : float
        Friction coefficient tan(phi) (Stronge and Coulomb laws).
    allow_energy_gain : bool
        When False the kinetic energy per unit mass (translational + rotational) never increases.
    vt0 : float, optional
        Velocity scale [m/s] of the Pfeiffer & Bowen scaling of the tangential energy after a constant or
        Coulomb law (:func:`tangential_scaling`; inf, the default: none).

    Returns
    -------
    (vn', vt', w', e_N) with vn' >= 0.
    """
    en_law_value = normal_restitution(en_law, e_n, vn, vt)
    en = velocity_scaled(en_law_value, vn, v0)
    # the tangential scaling takes the material's e_N before any velocity scaling (CRSP's R_n): the velocity
    # law's own e_n, Wyllie's angle law with its deviation, or the constant
    en_material = e_n if en_law == EN_VELOCITY else en_law_value
    if et_law == ET_FRICTION:
        vt2, w2, stuck = stronge_body(vn, vt, w, r, en, mu, k)
    elif et_law == ET_COULOMB:
        vt2, w2 = coulomb_tangential(vn, vt, w, e_t, min(en, EN_WYLLIE_MAX), mu)
    else:
        vt2 = e_t * vt
        w2 = e_t * w
    if et_law != ET_FRICTION and vn < 0.0:
        s_t = tangential_scaling(vn, en_material, vt0)
        vt2 *= s_t
        w2 *= s_t
    vn2 = -en * vn
    if not allow_energy_gain:
        kr2 = k * r * r
        e_in = vn * vn + vt * vt + kr2 * w * w                 # twice the kinetic energy per unit mass
        e_tan = vt2 * vt2 + kr2 * w2 * w2
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


@njit(cache=True)
def roll_on_speed(v_along, w, r, k):
    """Speed [m/s] along the surface of a round body that starts rolling without slip.

    Angular momentum about the contact point is conserved through the (slip-killing) transition:
    m v r + k m r^2 w = (m r + k m r^2 / r) v'  =>  v' = (v + k r w) / (1 + k), w' = v' / r,
    with I = k m r^2 (k = 2/5 sphere, 1/2 cylinder) and w > 0 meaning rolling in the +v direction.
    Kinetic energy never increases through it (it falls by 1/2 m k (v - r w)^2 / (1 + k)).

    Parameters
    ----------
    v_along : float
        Speed along the surface before the transition [m/s].
    w : float
        Spin [rad/s] (> 0 rolling in the +v direction).
    r : float
        Block radius [m].
    k : float
        Inertia factor I / (m r^2) [-].

    Returns
    -------
    float
        Speed along the surface once rolling without slip [m/s].
    """
    return (v_along + k * r * w) / (1.0 + k)


@njit(cache=True)
def roughness_tilt_max(roughness_m, r):
    """Largest tilt [rad] of the surface normal at an impact: atan(roughness / r).

    The asperity amplitude seen by a block depends on its size: a block of radius r resting on asperities
    of height h tilts by up to atan(h / r) (the CRSP "random impact angle variation limited by rock size
    and slope irregularity", Pfeiffer & Bowen 1989; PlatRock and Rockyfor3D use the same ratio; Dorren
    2016).  The kernel draws the tilt uniformly within +- this angle, so larger blocks see a smoother slope.

    Parameters
    ----------
    roughness_m : float
        Asperity height of the surface [m].
    r : float
        Block radius [m].

    Returns
    -------
    float
        Largest tilt of the surface normal [rad] (0 for r <= 0).

    References
    ----------
    Pfeiffer & Bowen (1989), CRSP; Dorren (2016), Rockyfor3D.
    """
    return math.atan(roughness_m / r) if r > 0.0 else 0.0


@njit(cache=True)
def contact_speed(v_floor, g, cos_beta, hop_height_m):
    """Normal speed [m/s] below which a rebound (or the take-off at a convex edge) is ground contact.

    A block whose rebound would rise less than ``hop_height_m`` [m] above the surface (normal to it,
    under the normal gravity g cos(beta)) does not fly: it rolls or slides over the asperities, and the
    rolling resistance stands for what those asperities take.  The speed is sqrt(2 g cos(beta) h),
    never below ``v_floor`` (the scenario's ``contact_velocity_ms``, a purely numerical threshold that
    only ends trains of ever smaller hops).  With h = 0 it is the floor (the former behaviour).

    Parameters
    ----------
    v_floor : float
        Numerical floor of the contact speed [m/s].
    g : float
        Gravitational acceleration [m/s^2].
    cos_beta : float
        Cosine of the slope angle [-].
    hop_height_m : float
        Least rebound height that counts as flight [m].

    Returns
    -------
    float
        Normal contact speed [m/s].
    """
    hop = math.sqrt(2.0 * g * max(cos_beta, 0.0) * hop_height_m) if hop_height_m > 0.0 else 0.0
    return max(v_floor, hop)


#: The default largest rolling-resistance angle [deg] the size term can raise a material's resistance to
#: (:func:`rolling_resistance`; a material's ``rolling_resistance_cap_deg``): 38 deg, the steepest angle at which
#: loose rock debris stands.  Basis: talus slopes stand at 30-38 deg, the dynamic angle of repose of their debris
#: (Evans & Hungr 1993, Can. Geotech. J. 30:620; Kirkby & Statham 1975, J. Geol. 83:349; Statham 1976, Earth Surf.
#: Process. 1:43: screes stand below the angle of repose of their debris and are sorted, the small stones stopping
#: high) [R].  A stone that sinks between asperities of its own size sits in the hollows as a grain of loose debris
#: does, so the steepest slope on which it is held is the debris' angle of repose; a resistance above it would hold
#: small blocks on slopes steeper than any loose debris stands at.  It equals the talus preset's phi_g
#: (simulation.materials: chosen above the steepest usual talus so that blocks can stop on it) and lies within the
#: rolling friction of soil and vegetated ground, 0.5-0.8 or 27-39 deg (Dorren 2003, Progr. Phys. Geogr. 27:69)
#: [R].  The value is ASSUMED: no published maximum rolling-friction angle of small blocks was found.  A terrain
#: whose asperities are boulders larger than the blocks (coarse talus) traps them in its hollows, and the lumped
#: resistance then stands for impacts as well: such a material may state its own, higher cap.
ROLLING_RESISTANCE_CAP_DEG = 38.0


@njit(cache=True)
def block_ground_resistance(mu_0, phi_g_deg, phi_g_std_deg, z_b):
    """The rolling-resistance coefficient tan(phi_g) [-] of one block: phi_g + z_b sd, clipped to 0-89 deg.

    A block's own shape and angularity make it roll farther or less far than the mean block on every ground (a
    rounder block farther): ``z_b`` is the block's standard normal deviate, the same on every material, and
    ``phi_g_std_deg`` the material's spread of phi_g between blocks (``ground_friction_std_deg``).  With no spread it
    is ``mu_0`` itself, so runs without one give the same numbers as before.

    Parameters
    ----------
    mu_0 : float
        tan(phi_g) of the material [-].
    phi_g_deg : float
        phi_g of the material [deg].
    phi_g_std_deg : float
        Its spread between blocks [deg] (0: none).
    z_b : float
        The block's standard normal deviate [-].

    Returns
    -------
    float
        The block's tan(phi_g) [-], before the size term of :func:`rolling_resistance`.
    """
    if phi_g_std_deg <= 0.0 or z_b == 0.0:
        return mu_0
    return math.tan(math.radians(min(max(phi_g_deg + z_b * phi_g_std_deg, 0.0), 89.0)))


@njit(cache=True)
def rolling_resistance(mu_0, size_k, roughness_m, r, mu_cap, size_exp):
    """Rolling-resistance coefficient [-] of a block of radius r [m]: a bounded size law.

    mu = mu_0 + s c / sqrt(s^2 + c^2), with s = size_k * (roughness_m / r)^size_exp the size term of Kirkby &
    Statham (1975; their form has size_exp = 1) and c = max(mu_cap - mu_0, 0) the room left below the material's
    cap ``mu_cap`` (tan of its
    ``rolling_resistance_cap_deg``, by default :data:`ROLLING_RESISTANCE_CAP_DEG`).  ``mu_0`` = tan(phi_g) is the
    resistance of a block much larger than the asperities; the size term makes smaller blocks, which sink between
    asperities of height ``roughness_m`` [m], stop sooner: the friction of a stone moving over scree falls as its
    size grows relative to the surface stones (Kirkby & Statham 1975, J. Geol. 83:349, mu = tan(phi) + K d/D, d and
    D the sizes of surface and moving stones [R]; Statham 1976, Earth Surf. Process. 1:43, the resulting downslope
    size sorting of screes).

    The exponent ``size_exp`` lets the data set how fast the resistance rises as blocks get smaller (1: Kirkby &
    Statham's d/D; below 1 more slowly, above 1 faster): fitted with K, it carries the uncertainty of the size
    dependence beyond the block sizes a calibration saw.

    The size term saturates smoothly (the root-sum-square of s and c, S = s / sqrt(1 + (s / c)^2)): for blocks
    large against the asperities (s << c) it is Kirkby & Statham's mu_0 + s (at s = c / 2 it is 89 % of s), and as
    r -> 0 it tends to the cap, never above it, so a small block cannot meet more resistance than the terrain's
    cap.  It is continuous and non-increasing in r and continuous in every argument.  With ``size_k`` = 0, no
    roughness, or ``mu_0`` >= ``mu_cap``, it is mu_0 (a typed or fitted phi_g above the cap is kept).

    Parameters
    ----------
    mu_0 : float
        Rolling-resistance coefficient of a large block, tan(phi_g) [-].
    size_k : float
        Size coefficient K [-].
    roughness_m : float
        Asperity height of the surface [m] (a property of the terrain: the material's ``roughness_m``).
    r : float
        Block radius [m].
    mu_cap : float
        Largest coefficient the size term can raise the resistance to [-] (tan of the cap angle).
    size_exp : float
        Exponent of the size ratio roughness / r [-] (1: Kirkby & Statham's form).

    Returns
    -------
    float
        Rolling-resistance coefficient [-], between mu_0 and max(mu_0, mu_cap).

    References
    ----------
    Kirkby, M.J. & Statham, I. (1975), J. Geol. 83: 349 (mu = tan(phi) + K d/D).
    Evans, S.G. & Hungr, O. (1993), Can. Geotech. J. 30: 620 (talus slopes of 30-38 deg).
    Dorren, L.K.A. (2003), Progr. Phys. Geogr. 27: 69 (rolling friction of soft ground 0.5-0.8).
    """
    if size_k <= 0.0 or r <= 0.0 or roughness_m <= 0.0:
        return mu_0
    room = mu_cap - mu_0
    if room <= 0.0:
        return mu_0
    ratio = roughness_m / r
    s = size_k * (ratio if size_exp == 1.0 else ratio ** size_exp)
    return mu_0 + s * room / math.hypot(s, room)        # hypot: no underflow of s^2 + c^2 to 0


@njit(cache=True)
def contact_acceleration(g, sin_beta, cos_beta, direction, mu_r, k, roll):
    """Acceleration [m/s^2] along the motion of a block in ground contact on a straight slope.

    ``sin_beta``, ``cos_beta``: of the slope angle (beta > 0 rising in +x); ``direction`` +1 / -1 the
    sense of motion along +x; ``mu_r`` the rolling-resistance (or sliding friction) coefficient tan(phi_g).
    Rolling (``roll``): a = (-g sin(beta) direction - mu_r g cos(beta)) / (1 + k), the resisting torque
    being mu_r N r (a round body of inertia k m r^2 rolling without slip; 5/7 for a sphere, 2/3 for a
    cylinder); sliding: the same without the 1 / (1 + k).

    Parameters
    ----------
    g : float
        Gravitational acceleration [m/s^2].
    sin_beta, cos_beta : float
        Sine and cosine of the slope angle [-].
    direction : float
        Sense of motion along +x (+1 or -1).
    mu_r : float
        Rolling-resistance or sliding-friction coefficient [-].
    k : float
        Inertia factor I / (m r^2) [-].
    roll : bool
        True when rolling, False when sliding.

    Returns
    -------
    float
        Acceleration along the motion [m/s^2].
    """
    a = -g * sin_beta * direction - mu_r * g * cos_beta
    return a / (1.0 + k) if roll else a


@njit(cache=True)
def steep_face_launch(v_along, v_sep):
    """Velocity (vt, vn) [m/s] in the frame of a face too steep to roll on, for a block that leaves it.

    The speed |v_along| is kept (no energy is created): the velocity is turned away from the face until
    its outward normal component is ``v_sep`` (the contact speed), or straight out when the block is
    slower than that.  The block then flies and meets the face again in impacts, so on a cliff it bounces
    down the face instead of rolling on it.

    Parameters
    ----------
    v_along : float
        Velocity along the face [m/s] (signed).
    v_sep : float
        Outward normal speed to leave with [m/s].

    Returns
    -------
    tuple of float
        (vt, vn) in the frame of the face [m/s].
    """
    u = abs(v_along)
    vn = min(v_sep, u)
    vt = math.sqrt(max(u * u - vn * vn, 0.0))
    return (vt if v_along >= 0.0 else -vt), vn


#: A block that leaves faces too steep to roll on this many times in a row without moving more than
#: :data:`STEEP_TRAP_RADIUS_M` (horizontally, along each axis) from where that run began is held there: it sits in a
#: notch or pit whose flanks are all too steep to roll on, and would otherwise hop in place until its event limit.
#: From rest on a plain steep face a block leaves the half metre within about ten launches.
STEEP_TRAP_LAUNCHES = 100
STEEP_TRAP_RADIUS_M = 0.5


@njit(cache=True)
def steep_trap(count, x_start, y_start, x, y):
    """Count a launch from a steep face at (x, y) [m]; (count, x_start, y_start, trapped).

    The run of launches restarts at (x, y) when the block is farther than :data:`STEEP_TRAP_RADIUS_M` from where
    the run began; ``trapped`` is True once the run reaches :data:`STEEP_TRAP_LAUNCHES` (the block is then held).

    Parameters
    ----------
    count : int
        Launches so far in the run (0: none).
    x_start, y_start : float
        Where the run began [m].
    x, y : float
        Where the block leaves the face now [m] (y = 0 on a 2-D profile).

    Returns
    -------
    tuple
        (count, x_start, y_start, trapped).
    """
    if count > 0 and abs(x - x_start) <= STEEP_TRAP_RADIUS_M and abs(y - y_start) <= STEEP_TRAP_RADIUS_M:
        count += 1
    else:
        count, x_start, y_start = 1, x, y
    return count, x_start, y_start, count >= STEEP_TRAP_LAUNCHES


# ---- ground contact with a velocity-squared drag: dv/dt = a - c v^2 along the motion ----------------------
# A block rolling over asperities (talus boulders, tussocks) or ploughing soft ground loses at each asperity
# a share of its kinetic energy, and meets more asperities per second the faster it goes: a resistance that
# grows as v^2 (the "drag" of RAMMS::ROCKFALL's soft-ground contact, and the v^2 term of Voellmy's law; here
# c = rolling_drag / r [1/m], so a block twice as large, stepping over the same asperities with half as
# many contacts per metre, feels half the drag).  With c = 0 the motion is the constant-acceleration one.
# Closed forms along the distance s: v^2(s) = a/c + (u^2 - a/c) exp(-2 c s); times from dv/dt = a - c v^2.

@njit(cache=True)
def contact_speed_at(u, a, c, s):
    """Speed [m/s] after a distance s [m] in contact from speed u [m/s], acceleration a [m/s^2] along the
    motion and drag coefficient c [1/m] (dv/dt = a - c v^2); 0 once the block has stopped.

    Parameters
    ----------
    u : float
        Initial speed [m/s].
    a : float
        Acceleration along the motion [m/s^2].
    c : float
        Drag coefficient [1/m].
    s : float
        Distance travelled in contact [m].

    Returns
    -------
    float
        Speed after the distance [m/s].
    """
    if c <= 1e-12:
        return math.sqrt(max(u * u + 2.0 * a * s, 0.0))
    ac = a / c
    return math.sqrt(max(ac + (u * u - ac) * math.exp(-2.0 * c * s), 0.0))


@njit(cache=True)
def contact_stop_distance(u, a, c):
    """Distance [m] at which a block in contact (speed u, acceleration a, drag c; see :func:`contact_speed_at`)
    comes to rest; inf when it never does (a >= 0).

    Parameters
    ----------
    u : float
        Initial speed [m/s].
    a : float
        Acceleration along the motion [m/s^2].
    c : float
        Drag coefficient [1/m].

    Returns
    -------
    float
        Stopping distance [m] (inf when the block never stops).
    """
    if a >= 0.0:
        return math.inf
    if c <= 1e-12:
        return u * u / (-2.0 * a)
    big_a = -a / c
    return math.log((u * u + big_a) / big_a) / (2.0 * c)


@njit(cache=True)
def contact_time(u, v, a, c, s):
    """Time [s] to go from speed u to speed v >= 0 [m/s] over the distance s [m] (dv/dt = a - c v^2); -1 when
    the block does not move (u = 0 and no acceleration).

    Parameters
    ----------
    u : float
        Initial speed [m/s].
    v : float
        Final speed [m/s].
    a : float
        Acceleration along the motion [m/s^2].
    c : float
        Drag coefficient [1/m].
    s : float
        Distance travelled [m].

    Returns
    -------
    float
        Time [s], -1 when the block does not move.
    """
    if c <= 1e-12:
        if abs(a) > 1e-12:
            return (v - u) / a
        return s / u if u > 0.0 else -1.0
    if a < 0.0:                                  # decelerating everywhere: dv/dt = -c (A + v^2)
        ra = math.sqrt(-a / c)
        return (math.atan(u / ra) - math.atan(v / ra)) / (c * ra)
    if a == 0.0:                                 # dv/dt = -c v^2
        return (1.0 / v - 1.0 / u) / c if u > 0.0 and v > 0.0 else -1.0
    vt = math.sqrt(a / c)                        # terminal speed
    if abs(u - vt) <= 1e-9 * vt and abs(v - vt) <= 1e-9 * vt:
        return s / vt
    t = 0.0
    if u < vt and v < vt:
        t = (math.atanh(v / vt) - math.atanh(u / vt)) / (c * vt)
    elif u > vt and v > vt:
        t = (_acoth(v / vt) - _acoth(u / vt)) / (c * vt)
    else:                                        # rounding at the terminal speed: uniform motion
        t = s / max(0.5 * (u + v), 1e-300)
    return t


@njit(cache=True)
def _acoth(x):
    return 0.5 * math.log((x + 1.0) / (x - 1.0))
